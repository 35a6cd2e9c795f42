"""Real motion capture: BVH and ASF/AMC loading, forward kinematics, canonical joints.

A loaded clip is a :class:`Clip`: every joint of the file's skeleton (BVH ``End Site``
blocks included, named ``<parent>_end``) as positions in world metres, z up. Files are
y up; they are turned to z up by ``(x, y, z) -> (x, -z, y)`` (a rotation of +90 degrees
about x, so left stays left). :func:`canonical_from_clip` then reduces a clip to the 15
canonical joints of :mod:`occupose.joints` (:mod:`occupose.synth.retarget` puts them in a
scene).

Units (``units="auto"``): BVH files are recognised by their joint names:

- ``"cmu"`` skeletons (``LeftUpLeg``, ``LeftArm``, ...; the CMU database as BVH) are in
  the CMU ASF length unit, 1 unit = 0.0254 / 0.45 m (the ASF declares ``length 0.45``);
- ``"bandai"`` skeletons (``UpperLeg_L``, ``UpperArm_L``, ...; Bandai-Namco motion
  datasets 1 and 2) are in centimetres, 0.01 m per unit.

An ASF file declares its own unit (``:units length L``: 1 unit = 0.0254 / L m). Any other
skeleton needs an explicit ``units`` (metres per file unit).

Rotations: a BVH ``CHANNELS`` line lists its rotations in intrinsic order (``Zrotation
Xrotation Yrotation`` means R = Rz Rx Ry), and a joint's position channels, where present,
replace the matching components of its ``OFFSET``. ASF/AMC follows the CMU viewer: a
bone's world rotation is ``parent @ C @ M @ C^-1`` with ``C`` from the bone's ``axis``
and ``M`` from the frame's dof values, both applied in the order written (``axis ... XYZ``
and ``dof rx ry rz`` mean Rz Ry Rx, x applied first).
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path
from typing import NamedTuple

import numpy as np
from scipy.spatial.transform import Rotation

from occupose.joints import BONES, JOINT_INDEX, NUM_JOINTS
from occupose.paths import mocap_dir

#: Height of the ankle joint above the floor when standing, metres.
ANKLE_HEIGHT = 0.08
#: Distance from the clip's head joint to the centre of the head, metres.
HEAD_OFFSET = 0.10
#: Distance from the centre of the head to its top, metres (for :func:`standing_height`).
HEAD_TOP = 0.10

CMU_UNIT = 0.0254 / 0.45

# (x, y, z) y-up -> (x, -z, y) z-up, as a matrix applied to column vectors.
_ZUP_FROM_YUP = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])


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
# Forward kinematics (shared by both formats)


def _matrices_from_euler(letters: str, angles: np.ndarray, degrees: bool, intrinsic: bool) -> np.ndarray:
    """(T, 3, 3) rotation matrices; letters like "zxy" in application order of the file."""
    if not letters:
        return np.broadcast_to(np.eye(3), (angles.shape[0], 3, 3))
    seq = letters.upper() if intrinsic else letters.lower()
    return Rotation.from_euler(seq, angles, degrees=degrees).as_matrix()


def _positions_from_kinematics(parents: np.ndarray, offsets: np.ndarray, locals_: list,
                               own_frame: bool = False) -> np.ndarray:
    """Forward kinematics over all frames at once.

    parents : (J,) parent-first indices. offsets : (T, J, 3), each joint's position
    relative to its parent (the root's: its position). locals_ : J arrays (T, 3, 3), each
    joint's rotation relative to its parent (the root's: to the world). A BVH offset is
    rotated by the parent's world rotation (``own_frame=False``); an ASF bone vector by
    the bone's own (``own_frame=True``). Returns positions (T, J, 3), file coordinates.
    """
    num_frames, num_joints = offsets.shape[:2]
    positions = np.empty((num_frames, num_joints, 3))
    world = [None] * num_joints
    for j in range(num_joints):
        p = parents[j]
        if p < 0:
            positions[:, j] = offsets[:, j]
            world[j] = locals_[j]
            continue
        world[j] = np.matmul(world[p], locals_[j])
        frame = world[j] if own_frame else world[p]
        positions[:, j] = positions[:, p] + np.einsum("tij,tj->ti", frame, offsets[:, j])
    return positions


def _zup_from_yup(points: np.ndarray) -> np.ndarray:
    return points @ _ZUP_FROM_YUP.T


# ---------------------------------------------------------------------------------------
# BVH

_SKELETON_STYLES = {
    # source: (joint names that identify it, metres per file unit)
    "cmu": (("LeftUpLeg", "RightUpLeg", "LeftArm", "RightArm", "Neck1", "Head"), CMU_UNIT),
    "bandai": (("UpperLeg_L", "UpperLeg_R", "UpperArm_L", "UpperArm_R", "Neck", "Head"), 0.01),
}

_CHANNELS = ("Xposition", "Yposition", "Zposition", "Xrotation", "Yrotation", "Zrotation")


class _Tokens:
    """Whitespace tokens of a text with their line numbers, for error messages."""

    def __init__(self, text: str, path: Path):
        self.path = path
        self.items = [(tok, n) for n, line in enumerate(text.splitlines(), 1) for tok in line.split()]
        self.pos = 0
        self.last_line = text.count("\n") + 1

    def error(self, message: str, line: int | None = None) -> ValueError:
        if line is None:
            line = self.items[self.pos][1] if self.pos < len(self.items) else self.last_line
        return ValueError(f"{self.path}:{line}: malformed BVH: {message}")

    def next(self, what: str) -> tuple[str, int]:
        if self.pos >= len(self.items):
            raise self.error(f"expected {what}, got the end of the HIERARCHY section")
        item = self.items[self.pos]
        self.pos += 1
        return item

    def expect(self, word: str) -> int:
        tok, line = self.next(repr(word))
        if tok != word:
            raise self.error(f"expected {word!r}, got {tok!r}", line)
        return line

    def number(self, what: str, kind=float):
        tok, line = self.next(what)
        try:
            return kind(tok)
        except ValueError:
            raise self.error(f"expected {what}, got {tok!r}", line) from None


def load_bvh(path, units="auto") -> Clip:
    """Load a BVH file into a :class:`Clip` (world metres, z up).

    path : str or Path of a ``.bvh`` file (y up, as BVH files are).
        fps is 1 / ``Frame Time``, snapped to a whole number within 0.001.
    units : ``"auto"`` (by skeleton style, see the module docstring) or metres per file unit.

    Raises FileNotFoundError for a missing file, ValueError naming the file and line for
    malformed input, and ValueError asking for ``units`` when ``"auto"`` does not know the
    skeleton.
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"BVH file {path} does not exist")
    text = path.read_text(errors="replace")
    head, sep, motion = text.partition("MOTION")
    if not sep:
        raise ValueError(f"{path}: malformed BVH: no MOTION section")
    tokens = _Tokens(head, path)
    tokens.expect("HIERARCHY")
    names, parents, offsets, channels = [], [], [], []
    _parse_bvh_joint(tokens, "ROOT", -1, names, parents, offsets, channels)
    if tokens.pos != len(tokens.items):
        raise tokens.error(f"expected MOTION after the root joint, got {tokens.items[tokens.pos][0]!r}")

    num_channels = sum(len(c) for c in channels)
    motion_line0 = head.count("\n") + 1
    data, frame_time = _parse_bvh_motion(motion, num_channels, path, motion_line0)

    source = next((s for s, (need, _) in _SKELETON_STYLES.items() if set(need) <= set(names)), "bvh")
    scale = _units_for(units, source, path)

    num_frames = data.shape[0]
    offsets_t = np.broadcast_to(np.asarray(offsets, dtype=np.float64), (num_frames, len(names), 3)).copy()
    locals_ = []
    column = 0
    for j, chans in enumerate(channels):
        letters, rot_cols = "", []
        for k, chan in enumerate(chans):
            axis = "xyz".index(chan[0].lower())
            if chan.endswith("position"):
                offsets_t[:, j, axis] = data[:, column + k]
            else:
                letters += chan[0].lower()
                rot_cols.append(column + k)
        locals_.append(_matrices_from_euler(letters, data[:, rot_cols], degrees=True, intrinsic=True))
        column += len(chans)
    parents_arr = np.asarray(parents, dtype=np.int64)
    positions = _positions_from_kinematics(parents_arr, offsets_t, locals_)
    return Clip(
        names=tuple(names),
        parents=parents_arr,
        fps=_fps_from_frame_time(frame_time),
        positions=_zup_from_yup(positions) * scale,
        source=source,
    )


def _parse_bvh_joint(tokens: _Tokens, keyword: str, parent: int, names, parents, offsets, channels):
    tokens.expect(keyword)
    name, line = tokens.next("a joint name")
    if name == "{":
        raise tokens.error(f"{keyword} without a name", line)
    if name in names:
        raise tokens.error(f"joint name {name!r} used twice", line)
    index = len(names)
    names.append(name)
    parents.append(parent)
    tokens.expect("{")
    tokens.expect("OFFSET")
    offsets.append([tokens.number("an OFFSET number") for _ in range(3)])
    chans = []
    if tokens.pos < len(tokens.items) and tokens.items[tokens.pos][0] == "CHANNELS":
        tokens.next("CHANNELS")
        count = tokens.number("a channel count", int)
        for _ in range(count):
            chan, line = tokens.next("a channel name")
            if chan not in _CHANNELS:
                raise tokens.error(f"unknown channel {chan!r}; valid: {', '.join(_CHANNELS)}", line)
            if chan in chans:
                raise tokens.error(f"channel {chan!r} repeated for joint {name!r}", line)
            chans.append(chan)
    channels.append(tuple(chans))
    while True:
        tok, line = tokens.next("JOINT, End Site or '}'")
        if tok == "}":
            return
        if tok == "JOINT":
            tokens.pos -= 1
            _parse_bvh_joint(tokens, "JOINT", index, names, parents, offsets, channels)
        elif tok == "End":
            tokens.expect("Site")
            tokens.expect("{")
            tokens.expect("OFFSET")
            end_offset = [tokens.number("an OFFSET number") for _ in range(3)]
            tokens.expect("}")
            end_name = f"{name}_end"
            suffix = 1
            while end_name in names:
                suffix += 1
                end_name = f"{name}_end{suffix}"
            names.append(end_name)
            parents.append(index)
            offsets.append(end_offset)
            channels.append(())
        else:
            raise tokens.error(f"expected JOINT, End Site or '}}', got {tok!r}", line)


def _parse_bvh_motion(motion: str, num_channels: int, path: Path, line0: int):
    """(frames (T, C) float64, frame time s) from the text after ``MOTION``."""
    lines = motion.splitlines()

    def header(i: int, label: str) -> str:
        if i >= len(lines) or not lines[i].strip().startswith(label):
            got = lines[i].strip() if i < len(lines) else "end of file"
            raise ValueError(f"{path}:{line0 + i}: malformed BVH: expected {label!r}, got {got!r}")
        return lines[i].split(":", 1)[1].strip()

    # lines[0] is the rest of the MOTION line.
    try:
        num_frames = int(header(1, "Frames:"))
        frame_time = float(header(2, "Frame Time:"))
    except ValueError as err:
        if "malformed" in str(err):
            raise
        raise ValueError(f"{path}:{line0 + 1}: malformed BVH: bad Frames/Frame Time value ({err})") from None
    if num_frames < 1 or not frame_time > 0:
        raise ValueError(f"{path}:{line0 + 1}: malformed BVH: need Frames >= 1 and Frame Time > 0, "
                         f"got {num_frames} and {frame_time}")
    rows = []
    for i in range(3, len(lines)):
        values = lines[i].split()
        if not values:
            continue
        if len(values) != num_channels:
            raise ValueError(f"{path}:{line0 + i}: malformed BVH: expected {num_channels} values "
                             f"(the channels of the hierarchy), got {len(values)}")
        try:
            rows.append([float(v) for v in values])
        except ValueError:
            raise ValueError(f"{path}:{line0 + i}: malformed BVH: non-numeric value in frame") from None
    if len(rows) != num_frames:
        raise ValueError(f"{path}:{line0 + 1}: malformed BVH: header says {num_frames} frames, "
                         f"file has {len(rows)}")
    return np.asarray(rows, dtype=np.float64).reshape(num_frames, num_channels), frame_time


def _fps_from_frame_time(frame_time: float) -> float:
    """1 / frame_time, snapped to a whole number when the file rounded it (0.0083333 -> 120)."""
    fps = 1.0 / frame_time
    return float(round(fps)) if abs(fps - round(fps)) < 1e-3 else fps


def _units_for(units, source: str, path: Path) -> float:
    if isinstance(units, str):
        if units != "auto":
            raise ValueError(f"units must be 'auto' or metres per file unit (a number), got {units!r}")
        if source not in _SKELETON_STYLES:
            raise ValueError(
                f"{path}: cannot pick units automatically for an unknown skeleton (neither CMU- "
                f"nor Bandai-style joint names); pass units= metres per file unit, e.g. 0.01 for cm"
            )
        return _SKELETON_STYLES[source][1]
    scale = float(units)
    if not scale > 0:
        raise ValueError(f"units must be positive metres per file unit, got {units!r}")
    return scale


# ---------------------------------------------------------------------------------------
# ASF / AMC


class _Bone(NamedTuple):
    name: str
    direction: np.ndarray  # (3,) unit, file frame
    length: float
    axis: np.ndarray  # (3,) angles
    axis_order: str  # e.g. "xyz"
    dof: tuple[str, ...]  # e.g. ("rx", "ry", "rz")


def load_asf_amc(asf_path, amc_path, units="auto") -> Clip:
    """Load a CMU ASF skeleton and an AMC motion into a :class:`Clip` (world metres, z up).

    The clip's joints are ``root`` (the root's position) and one joint per ASF bone, at
    that bone's far end: ``lhipjoint`` is the left hip joint, ``lfemur`` the knee,
    ``ltibia`` the ankle, ``lclavicle`` the shoulder, ``lhumerus`` the elbow, ``lwrist``
    the wrist (``lradius`` ends 0.1 m short of it: ``lwrist`` is the forearm's twist
    segment, the hand's flexion starts at its end), ``lowerneck`` the neck, ``upperneck``
    the base of the head, ``head`` the end of the head bone. fps is 120 (the CMU capture
    rate; AMC files do not store it).

    units : ``"auto"`` (from the ASF's ``:units length L``, 1 unit = 0.0254 / L m) or
        metres per file unit.
    """
    asf_path, amc_path = Path(asf_path), Path(amc_path)
    for p in (asf_path, amc_path):
        if not p.is_file():
            raise FileNotFoundError(f"ASF/AMC file {p} does not exist")
    root, bones, hierarchy, length_unit, degrees = _parse_asf(asf_path)
    if isinstance(units, str) and units == "auto":
        if length_unit is None:
            raise ValueError(f"{asf_path}: no ':units length' to pick units from; pass units=")
        scale = 0.0254 / length_unit
    else:
        scale = _units_for(units, "asf", asf_path)

    # Parent-first order by walking the hierarchy from the root.
    names, parents = ["root"], [-1]
    stack = [("root", 0)]
    while stack:
        parent, pidx = stack.pop()
        for child in reversed(hierarchy.get(parent, ())):
            if child not in bones or child in names:
                raise ValueError(f"{asf_path}: hierarchy names bone {child!r} twice or without bonedata")
            names.append(child)
            parents.append(pidx)
            stack.append((child, len(names) - 1))

    dof_names = {"root": root["order"]} | {b.name: b.dof for b in bones.values()}
    frames = _parse_amc(amc_path, dof_names)
    num_frames = len(frames)

    locals_ = []
    vectors = np.zeros((num_frames, len(names), 3))
    for j, name in enumerate(names):
        values = np.array([frame[name] for frame in frames]).reshape(num_frames, -1)
        dof = dof_names[name]
        rot = [k for k, d in enumerate(dof) if d.startswith("r")]
        letters = "".join(dof[k][1] for k in rot)
        motion = _matrices_from_euler(letters, values[:, rot], degrees, intrinsic=False)
        if name == "root":
            c = _matrices_from_euler(root["axis_order"], root["orientation"][None], degrees, False)[0]
            for k, d in enumerate(dof):
                if d.startswith("t"):
                    vectors[:, j, "xyz".index(d[1])] = values[:, k]
            vectors[:, j] += root["position"]
        else:
            bone = bones[name]
            c = _matrices_from_euler(bone.axis_order, bone.axis[None], degrees, intrinsic=False)[0]
            vectors[:, j] = bone.length * bone.direction
        locals_.append(c @ motion @ c.T)
    positions = _positions_from_kinematics(np.asarray(parents), vectors, locals_, own_frame=True)
    return Clip(
        names=tuple(names),
        parents=np.asarray(parents, dtype=np.int64),
        fps=120.0,
        positions=_zup_from_yup(positions) * scale,
        source="asf",
    )


def _parse_asf(path: Path):
    """(root dict, bones by name, hierarchy parent -> children, length unit or None, degrees)."""
    lines = path.read_text(errors="replace").splitlines()
    section = None
    root = {"order": (), "axis_order": "xyz", "position": np.zeros(3), "orientation": np.zeros(3)}
    bones: dict[str, _Bone] = {}
    hierarchy: dict[str, list[str]] = {}
    length_unit, degrees = None, True
    current: dict | None = None

    def fail(n: int, message: str) -> ValueError:
        return ValueError(f"{path}:{n}: malformed ASF: {message}")

    def floats(n: int, words: list[str], count: int) -> np.ndarray:
        try:
            values = np.array([float(w) for w in words[:count]])
        except ValueError:
            raise fail(n, f"expected {count} numbers, got {' '.join(words)!r}") from None
        if values.size != count:
            raise fail(n, f"expected {count} numbers, got {' '.join(words)!r}")
        return values

    for n, raw in enumerate(lines, 1):
        words = raw.split()
        if not words or words[0].startswith("#"):
            continue
        key = words[0]
        if key.startswith(":"):
            section = key[1:]
            continue
        if section == "units":
            if key == "length":
                length_unit = float(floats(n, words[1:], 1)[0])
            elif key == "angle":
                degrees = words[1].lower().startswith("deg")
        elif section == "root":
            if key == "order":
                root["order"] = tuple(w.lower() for w in words[1:])
                bad = [d for d in root["order"] if d not in ("tx", "ty", "tz", "rx", "ry", "rz")]
                if bad:
                    raise fail(n, f"root order may hold TX TY TZ RX RY RZ, got {bad}")
            elif key == "axis":
                root["axis_order"] = words[1].lower()
            elif key in ("position", "orientation"):
                root[key] = floats(n, words[1:], 3)
        elif section == "bonedata":
            if key == "begin":
                current = {"dof": (), "line": n}
            elif key == "end":
                if current is None or not {"name", "direction", "length", "axis"} <= set(current):
                    raise fail(n, "bone block without name, direction, length and axis")
                norm = np.linalg.norm(current["direction"])
                bones[current["name"]] = _Bone(
                    current["name"], current["direction"] / (norm if norm > 0 else 1.0),
                    current["length"], current["axis"], current["axis_order"], current["dof"],
                )
                current = None
            elif current is None:
                raise fail(n, f"{key!r} outside a begin/end bone block")
            elif key == "name":
                current["name"] = words[1]
            elif key == "direction":
                current["direction"] = floats(n, words[1:], 3)
            elif key == "length":
                current["length"] = float(floats(n, words[1:], 1)[0])
            elif key == "axis":
                current["axis"] = floats(n, words[1:], 3)
                current["axis_order"] = words[4].lower() if len(words) > 4 else "xyz"
            elif key == "dof":
                dof = tuple(w.lower() for w in words[1:])
                bad = [d for d in dof if d not in ("rx", "ry", "rz")]
                if bad:
                    raise fail(n, f"only rotational dof (rx, ry, rz) are supported for bones, got {bad}")
                current["dof"] = dof
        elif section == "hierarchy" and key not in ("begin", "end"):
            hierarchy.setdefault(key, []).extend(words[1:])
    if not bones or "root" not in hierarchy:
        raise ValueError(f"{path}: malformed ASF: no bonedata or no hierarchy from 'root'")
    return root, bones, hierarchy, length_unit, degrees


def _parse_amc(path: Path, dof_names: dict[str, tuple[str, ...]]) -> list[dict[str, list[float]]]:
    """One dict per frame: bone name -> its dof values (bones missing from a frame: zeros)."""
    frames: list[dict[str, list[float]]] = []
    defaults = {name: [0.0] * len(d) for name, d in dof_names.items()}
    for n, raw in enumerate(path.read_text(errors="replace").splitlines(), 1):
        words = raw.split()
        if not words or words[0].startswith(("#", ":")):
            continue
        if len(words) == 1 and re.fullmatch(r"\d+", words[0]):
            frames.append(dict(defaults))
            continue
        if not frames:
            raise ValueError(f"{path}:{n}: malformed AMC: bone values before the first frame number")
        name = words[0]
        if name not in dof_names:
            raise ValueError(f"{path}:{n}: malformed AMC: bone {name!r} is not in the ASF skeleton")
        if len(words) - 1 != len(dof_names[name]):
            raise ValueError(f"{path}:{n}: malformed AMC: bone {name!r} has {len(dof_names[name])} dof "
                             f"in the ASF, got {len(words) - 1} values")
        try:
            frames[-1][name] = [float(w) for w in words[1:]]
        except ValueError:
            raise ValueError(f"{path}:{n}: malformed AMC: non-numeric value for {name!r}") from None
    if not frames:
        raise ValueError(f"{path}: malformed AMC: no frames")
    return frames


def load_clip(path, units="auto") -> Clip:
    """Load a ``.bvh`` file, or a CMU ``.amc`` file with its ``<subject>.asf`` beside it
    (``01_01.amc`` -> ``01.asf``)."""
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


def _check_joints(joints, name: str = "joints", min_ndim: int = 2) -> np.ndarray:
    joints = np.asarray(joints, dtype=np.float64)
    if joints.ndim < min_ndim or joints.shape[-2:] != (NUM_JOINTS, 3):
        raise ValueError(f"{name} must have shape (..., {NUM_JOINTS}, 3) with at least {min_ndim} "
                         f"dimensions, got {joints.shape}")
    return joints


def bone_lengths(joints) -> np.ndarray:
    """Lengths of :data:`occupose.joints.BONES`: joints (..., 15, 3) -> (..., len(BONES)), metres."""
    joints = _check_joints(joints, min_ndim=2)
    a = np.array([b[0] for b in BONES])
    b = np.array([b[1] for b in BONES])
    return np.linalg.norm(joints[..., b, :] - joints[..., a, :], axis=-1)


def standing_height(joints) -> np.ndarray:
    """Body height estimated from canonical joints, metres: (..., 15, 3) -> (...,).

    Top of the head (head centre + :data:`HEAD_TOP` 0.10 m) minus the floor under the
    lower ankle (its z minus :data:`ANKLE_HEIGHT` 0.08 m). Meaningful for upright frames.
    """
    joints = _check_joints(joints, min_ndim=2)
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
