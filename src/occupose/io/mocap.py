"""Real motion capture: clips, reading them, canonical joints, the shared clips.

A loaded clip is a :class:`Clip`: every joint of the file's skeleton (BVH ``End Site``
blocks included, named ``<parent>_end``) as positions in world metres, z up. Files are
y up; they are turned to z up by ``(x, y, z) -> (x, -z, y)`` (a rotation of +90 degrees
about x, so left stays left). :func:`load_clip` reads a ``.bvh`` file
(:func:`occupose.io.bvh.load_bvh`) or a CMU ``.amc`` motion with its ``.asf`` skeleton
(:func:`occupose.io.asf_amc.load_asf_amc`); those modules give each format's units and
rotation conventions. :func:`canonical_from_clip` then reduces a clip to the 15 canonical
joints of :mod:`occupose.joints` (:mod:`occupose.synth.retarget` puts them in a scene), and
:func:`list_clips` / :func:`find_clip` find the shared clips.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import NamedTuple

import numpy as np

from occupose._validate import joints_array
from occupose.joints import BONES, JOINT_INDEX, NUM_JOINTS
from occupose.paths import mocap_dir

#: Height of the ankle joint above the floor when standing, metres.
ANKLE_HEIGHT = 0.08
#: Distance from the clip's head joint to the centre of the head, metres.
HEAD_OFFSET = 0.10
#: Distance from the centre of the head to its top, metres (for :func:`standing_height`).
HEAD_TOP = 0.10


@dataclass(frozen=True, eq=False)
class Clip:
    """A mocap clip: every joint of the file's skeleton over time.

    names : tuple of J joint names as in the file (BVH end sites: ``<parent>_end``;
        ASF: ``root`` then the bone names, each joint at its bone's far end).
    parents : (J,) int64, index of each joint's parent, -1 for the root; parents come
        before their children.
    fps : frames per second.
    positions : (T, J, 3) float64, metres, world frame, z up.
    source : ``"cmu"`` | ``"bandai"`` (recognised BVH skeletons), ``"asf"`` (CMU ASF/AMC),
        or ``"bvh"`` (any other BVH skeleton; has no canonical mapping).
    """

    names: tuple[str, ...]
    parents: np.ndarray
    fps: float
    positions: np.ndarray
    source: str

    def __post_init__(self):
        object.__setattr__(self, "names", tuple(self.names))
        object.__setattr__(self, "parents", np.asarray(self.parents, dtype=np.int64))
        object.__setattr__(self, "positions", np.asarray(self.positions, dtype=np.float64))
        num = len(self.names)
        if self.parents.shape != (num,) or self.positions.ndim != 3 or self.positions.shape[1:] != (num, 3):
            raise ValueError(
                f"Clip expects parents (J,) and positions (T, J, 3) with J={num} names; "
                f"got parents {self.parents.shape} and positions {self.positions.shape}"
            )
        if np.any(self.parents >= np.arange(num)) or np.any(self.parents < -1):
            raise ValueError(f"Clip parents must come before their children (-1: root), got {self.parents}")

    @property
    def num_frames(self) -> int:
        return self.positions.shape[0]

    def index(self, name: str) -> int:
        """Index of the joint called ``name``; ValueError listing the names if absent."""
        try:
            return self.names.index(name)
        except ValueError:
            raise ValueError(f"joint {name!r} not in clip; joints: {', '.join(self.names)}") from None


# ---------------------------------------------------------------------------------------
# Reading a clip


def load_clip(path, units="auto") -> Clip:
    """Load a ``.bvh`` file, or a CMU ``.amc`` file with its ``<subject>.asf`` beside it
    (``01_01.amc`` -> ``01.asf``)."""
    from occupose.io.asf_amc import load_asf_amc  # the readers import Clip from this module
    from occupose.io.bvh import load_bvh

    path = Path(path)
    if path.suffix.lower() == ".bvh":
        return load_bvh(path, units)
    if path.suffix.lower() == ".amc":
        asf = path.with_name(path.stem.split("_")[0] + ".asf")
        return load_asf_amc(asf, path, units)
    raise ValueError(f"expected a .bvh or .amc file, got {path}")


# ---------------------------------------------------------------------------------------
# Canonical joints


class _Mapping(NamedTuple):
    joints: dict[str, tuple[str, ...]]  # canonical -> clip joints averaged (head excluded)
    head: str  # the clip's head joint
    head_tip: str | None  # joint above it along the head (used when not at the same place)
    head_base: str  # joint below it (fallback direction base -> head)


def _limbs(left_right: dict[str, tuple[str, str]], **extra) -> dict[str, tuple[str, ...]]:
    out = {f"{side}_{joint}": (names[k],) for joint, names in left_right.items()
           for k, side in enumerate(("left", "right"))}
    return out | extra


_MAPPINGS: dict[str, _Mapping] = {
    "cmu": _Mapping(
        _limbs(
            {"shoulder": ("LeftArm", "RightArm"), "elbow": ("LeftForeArm", "RightForeArm"),
             "wrist": ("LeftHand", "RightHand"), "hip": ("LeftUpLeg", "RightUpLeg"),
             "knee": ("LeftLeg", "RightLeg"), "ankle": ("LeftFoot", "RightFoot")},
            neck=("Neck1",), pelvis=("LeftUpLeg", "RightUpLeg"),
        ),
        head="Head", head_tip="Head_end", head_base="Neck1",
    ),
    "bandai": _Mapping(
        _limbs(
            {"shoulder": ("UpperArm_L", "UpperArm_R"), "elbow": ("LowerArm_L", "LowerArm_R"),
             "wrist": ("Hand_L", "Hand_R"), "hip": ("UpperLeg_L", "UpperLeg_R"),
             "knee": ("LowerLeg_L", "LowerLeg_R"), "ankle": ("Foot_L", "Foot_R")},
            neck=("Neck",), pelvis=("UpperLeg_L", "UpperLeg_R"),
        ),
        head="Head", head_tip="Head_end", head_base="Neck",
    ),
    "asf": _Mapping(
        _limbs(
            {"shoulder": ("lclavicle", "rclavicle"), "elbow": ("lhumerus", "rhumerus"),
             "wrist": ("lwrist", "rwrist"), "hip": ("lhipjoint", "rhipjoint"),
             "knee": ("lfemur", "rfemur"), "ankle": ("ltibia", "rtibia")},
            neck=("lowerneck",), pelvis=("lhipjoint", "rhipjoint"),
        ),
        head="upperneck", head_tip="head", head_base="lowerneck",
    ),
}


def canonical_from_clip(clip: Clip) -> np.ndarray:
    """The 15 canonical joints (order :data:`occupose.joints.JOINTS`) of a clip.

    Returns (T, 15, 3) float64, metres, world frame, z up. Pelvis is the midpoint of the
    hip joints. The head centre is :data:`HEAD_OFFSET` (0.10 m) above the clip's head
    joint along the head: towards the joint at the head's tip (the BVH head end site, the
    ASF head bone's end) where that is more than 1 cm away, otherwise (Bandai, whose end
    sites have zero length) along the direction neck -> head joint.
    """
    if clip.source not in _MAPPINGS:
        raise ValueError(f"no canonical joint mapping for clip source {clip.source!r}; "
                         f"valid sources: {', '.join(_MAPPINGS)}")
    mapping = _MAPPINGS[clip.source]
    out = np.empty((clip.num_frames, NUM_JOINTS, 3))
    for name, sources in mapping.joints.items():
        out[:, JOINT_INDEX[name]] = np.mean([clip.positions[:, clip.index(s)] for s in sources], axis=0)
    head = clip.positions[:, clip.index(mapping.head)]
    base = clip.positions[:, clip.index(mapping.head_base)]
    up = head - base
    if mapping.head_tip is not None and mapping.head_tip in clip.names:
        tip = clip.positions[:, clip.index(mapping.head_tip)] - head
        if np.median(np.linalg.norm(tip, axis=-1)) > 0.01:
            up = tip
    up = up / np.maximum(np.linalg.norm(up, axis=-1, keepdims=True), 1e-9)
    out[:, JOINT_INDEX["head"]] = head + HEAD_OFFSET * up
    return out


# ---------------------------------------------------------------------------------------
# Operations on canonical joints


def bone_lengths(joints) -> np.ndarray:
    """Lengths of :data:`occupose.joints.BONES`: joints (..., 15, 3) -> (..., len(BONES)), metres."""
    joints = joints_array(joints, min_ndim=2)
    a = np.array([b[0] for b in BONES])
    b = np.array([b[1] for b in BONES])
    return np.linalg.norm(joints[..., b, :] - joints[..., a, :], axis=-1)


def standing_height(joints) -> np.ndarray:
    """Body height estimated from canonical joints, metres: (..., 15, 3) -> (...,).

    Top of the head (head centre + :data:`HEAD_TOP` 0.10 m) minus the floor under the
    lower ankle (its z minus :data:`ANKLE_HEIGHT` 0.08 m). Meaningful for upright frames.
    """
    joints = joints_array(joints, min_ndim=2)
    ankles = np.minimum(joints[..., JOINT_INDEX["left_ankle"], 2], joints[..., JOINT_INDEX["right_ankle"], 2])
    return joints[..., JOINT_INDEX["head"], 2] + HEAD_TOP - (ankles - ANKLE_HEIGHT)


# ---------------------------------------------------------------------------------------
# The shared clips

_KINDS = {"cmu": ("cmu",), "bandai1": ("bandai1",), "bandai2": ("bandai2",), "bandai": ("bandai1", "bandai2")}
_FOLDERS = ("cmu", "bandai1", "bandai2")


def list_clips(kind: str | None = None) -> list[Path]:
    """Sorted paths of the shared mocap clips (``.bvh`` files and CMU ``.amc`` motions).

    kind : None (all), ``"cmu"``, ``"bandai1"``, ``"bandai2"`` or ``"bandai"`` (both).
    Returns an empty list when the shared data is absent (see :mod:`occupose.paths`).
    Load an entry with :func:`load_clip`.
    """
    if kind is not None and kind not in _KINDS:
        raise ValueError(f"unknown clip kind {kind!r}; valid: None, {', '.join(_KINDS)}")
    root = mocap_dir()
    if root is None:
        return []
    folders = _KINDS[kind] if kind is not None else _FOLDERS
    return sorted(p for f in folders for ext in ("*.bvh", "*.amc") for p in (root / f).glob(ext))


def find_clip(name_substring: str, kind: str | None = None) -> Path | None:
    """The one shared clip whose file name is ``name_substring`` or contains it.

    Returns None when the shared data is absent (callers fall back to procedural motion).
    Raises FileNotFoundError when nothing matches and ValueError, listing the candidates,
    when several do (an exact file name or stem wins over substrings).
    """
    clips = list_clips(kind)
    if not clips:
        return None
    exact = [p for p in clips if name_substring in (p.name, p.stem)]
    matches = exact if len(exact) == 1 else [p for p in clips if name_substring in p.name]
    if not matches:
        raise FileNotFoundError(f"no shared mocap clip matches {name_substring!r} (under {mocap_dir()})")
    if len(matches) > 1:
        shown = ", ".join(p.name for p in matches[:10]) + (" ..." if len(matches) > 10 else "")
        raise ValueError(f"{len(matches)} clips match {name_substring!r}: {shown}; be more specific")
    return matches[0]
