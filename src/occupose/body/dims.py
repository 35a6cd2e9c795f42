"""Body proportions: segment lengths of a person, and how to measure them on joints.

:class:`BodyDims` holds the lengths a skeleton of the 15 canonical joints needs (metres);
:data:`DEFAULT_DIMS` is an average adult 1.72 m tall. The tracker's body models are built
from a BodyDims (:mod:`occupose.body.model`), and a person's is measured on their points
(:mod:`occupose.body.size`) or, for a clip of joints, by :func:`dims_from_joints`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace

import numpy as np

from occupose.joints import BONES, JOINT_INDEX, NUM_JOINTS


@dataclass(frozen=True)
class BodyDims:
    """Segment lengths of a body, metres. The default is an average adult 1.72 m tall.

    ``spine`` is pelvis -> neck, ``neck_head`` neck -> centre of the head (the top of the
    head is taken another ``neck_head`` higher), ``shoulder_width`` the lateral offset of
    each shoulder from the neck and ``shoulder_drop`` how far the shoulders sit below the
    neck along the trunk, ``pelvis_width`` hip to hip, ``ankle_height`` the ankle joints
    above the floor when standing, ``seat_clearance`` the hip joints above a seat when
    sitting (the thickness of the buttocks and thighs).
    """

    pelvis_width: float = 0.19
    spine: float = 0.58
    neck_head: float = 0.11
    shoulder_width: float = 0.18
    shoulder_drop: float = 0.06
    upper_arm: float = 0.30
    forearm: float = 0.25
    thigh: float = 0.42
    shin: float = 0.42
    ankle_height: float = 0.08
    seat_clearance: float = 0.09

    def __post_init__(self):
        for f in fields(self):
            value = getattr(self, f.name)
            if not (math.isfinite(value) and value >= 0.0):
                raise ValueError(f"BodyDims.{f.name} must be a finite length >= 0 metres, got {value!r}")
        for name in ("spine", "neck_head", "upper_arm", "forearm", "thigh", "shin"):
            if getattr(self, name) <= 0.0:
                raise ValueError(f"BodyDims.{name} must be > 0 metres, got {getattr(self, name)!r}")

    @property
    def hip_height(self) -> float:
        """The hip joints above the floor standing with straight legs, metres."""
        return self.ankle_height + self.shin + self.thigh

    @property
    def height(self) -> float:
        """Standing height (floor to top of the head), metres."""
        return self.hip_height + self.spine + 2.0 * self.neck_head

    def scaled(self, height: float) -> BodyDims:
        """The same proportions scaled to a standing height of ``height`` metres."""
        if not (math.isfinite(height) and 0.5 <= height <= 2.5):
            raise ValueError(f"height must be a standing height in metres in [0.5, 2.5], got {height!r}")
        k = height / self.height
        return replace(self, **{f.name: getattr(self, f.name) * k for f in fields(self)})


DEFAULT_DIMS = BodyDims()


def bone_lengths_from_dims(dims: BodyDims) -> np.ndarray:
    """Lengths of :data:`occupose.joints.BONES` for a body, (len(BONES),) float64 metres."""
    shoulder = math.hypot(dims.shoulder_width, dims.shoulder_drop)
    by_pair = {
        ("head", "neck"): dims.neck_head, ("neck", "pelvis"): dims.spine,
        ("neck", "shoulder"): shoulder, ("shoulder", "elbow"): dims.upper_arm,
        ("elbow", "wrist"): dims.forearm, ("pelvis", "hip"): dims.pelvis_width / 2.0,
        ("hip", "knee"): dims.thigh, ("knee", "ankle"): dims.shin,
    }
    names = {i: name.split("_")[-1] for name, i in JOINT_INDEX.items()}
    return np.array([by_pair[names[a], names[b]] for a, b in BONES])


def dims_from_joints(joints) -> BodyDims:
    """Body dimensions of a canonical joint trajectory, e.g. a real mocap clip.

    joints : (T, 15, 3) float, world metres, z up, floor z = 0.
    Bone lengths are medians over frames, averaged over the two sides. The shoulder drop
    is the median offset of the shoulders below the neck along the pelvis -> neck axis.
    The ankle height is the 5th percentile over frames of the lower ankle's height (so the
    clip's floor must be at z = 0); the seat clearance is scaled from the default by height.
    """
    joints = np.asarray(joints, dtype=np.float64)
    if joints.ndim != 3 or joints.shape[1:] != (NUM_JOINTS, 3) or joints.shape[0] < 1:
        raise ValueError(f"joints must have shape (T, {NUM_JOINTS}, 3) with T >= 1, got {joints.shape}")
    if not np.all(np.isfinite(joints)):
        raise ValueError("joints must be finite")
    j = {name: joints[:, i] for name, i in JOINT_INDEX.items()}

    def length(a, b):
        return float(np.median(np.linalg.norm(j[b] - j[a], axis=-1)))

    def both(a, b):
        return 0.5 * (length(f"left_{a}", f"left_{b}") + length(f"right_{a}", f"right_{b}"))

    axis = j["neck"] - j["pelvis"]
    axis /= np.maximum(np.linalg.norm(axis, axis=-1, keepdims=True), 1e-9)
    drops = [-np.sum((j[f"{side}_shoulder"] - j["neck"]) * axis, axis=-1) for side in ("left", "right")]
    drop = max(float(np.median(np.concatenate(drops))), 0.0)
    shoulder = 0.5 * (length("neck", "left_shoulder") + length("neck", "right_shoulder"))
    ankle = np.minimum(j["left_ankle"][:, 2], j["right_ankle"][:, 2])
    dims = BodyDims(
        pelvis_width=length("left_hip", "right_hip"),
        spine=length("pelvis", "neck"),
        neck_head=length("neck", "head"),
        shoulder_width=math.sqrt(max(shoulder**2 - drop**2, 0.0)),
        shoulder_drop=min(drop, shoulder),
        upper_arm=both("shoulder", "elbow"),
        forearm=both("elbow", "wrist"),
        thigh=both("hip", "knee"),
        shin=both("knee", "ankle"),
        ankle_height=max(float(np.percentile(ankle, 5)), 0.0),
    )
    return replace(dims, seat_clearance=DEFAULT_DIMS.seat_clearance * dims.height / DEFAULT_DIMS.height)
