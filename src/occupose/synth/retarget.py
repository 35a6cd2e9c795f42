"""Putting mocap clips into a scene: resampling in time, the facing of a body, placing a clip.

The generator's side of :mod:`occupose.io.mocap`: that module reads clips and reduces them to
the 15 canonical joints of :mod:`occupose.joints`; these functions retime a canonical
sequence to the scene's frame rate (:func:`resample`), measure which way a body faces
(:func:`facing_from_joints`) and move a sequence to a start position and heading on the
floor (:func:`place`). Joints are (..., 15, 3) float64, world metres, z up.
"""

from __future__ import annotations

import math

import numpy as np

from occupose._validate import joints_array
from occupose.io.mocap import ANKLE_HEIGHT
from occupose.joints import BONES, JOINT_INDEX


def resample(joints, fps_in: float, fps_out: float) -> np.ndarray:
    """Resample a sequence in time by linear interpolation.

    joints : (T, ..., 3) float, any points over T frames at ``fps_in``.
    Returns (T', ..., 3) at ``fps_out`` covering the same time span: frame k is at time
    k / fps_out, T' = floor((T - 1) * fps_out / fps_in) + 1.
    """
    joints = np.asarray(joints, dtype=np.float64)
    if joints.ndim < 2 or joints.shape[0] < 1 or joints.shape[-1] != 3:
        raise ValueError(f"joints must have shape (T, ..., 3) with T >= 1, got {joints.shape}")
    if not (fps_in > 0 and fps_out > 0):
        raise ValueError(f"fps_in and fps_out must be positive, got {fps_in} and {fps_out}")
    num_in = joints.shape[0]
    num_out = int(math.floor((num_in - 1) * fps_out / fps_in + 1e-9)) + 1
    src = np.arange(num_out) * (fps_in / fps_out)
    i0 = np.minimum(np.floor(src).astype(np.int64), num_in - 1)
    i1 = np.minimum(i0 + 1, num_in - 1)
    w = (src - i0).reshape((-1,) + (1,) * (joints.ndim - 1))
    return (1.0 - w) * joints[i0] + w * joints[i1]


def facing_from_joints(joints) -> np.ndarray:
    """Heading of a body, radians counterclockwise from +x about z, in (-pi, pi].

    joints : (..., 15, 3) canonical joints, world frame, z up. Facing is
    (left_hip - right_hip) x z, projected on the floor. Returns (...,).
    """
    joints = joints_array(joints, min_ndim=2)
    left = joints[..., JOINT_INDEX["left_hip"], :] - joints[..., JOINT_INDEX["right_hip"], :]
    # (lx, ly, lz) x (0, 0, 1) = (ly, -lx, 0)
    return np.arctan2(-left[..., 0], left[..., 1])


def place(joints, start_xy=(0.0, 0.0), heading: float = 0.0, fps: float = 30.0,
          ankle_height: float = ANKLE_HEIGHT) -> np.ndarray:
    """Put a canonical sequence into a scene.

    joints : (T, 15, 3) canonical joints, metres, z up, sampled at ``fps``.
    Rotates about z and translates so that in frame 0 the pelvis is above ``start_xy``
    (metres) and the body faces ``heading`` (radians, 0 = +x, counterclockwise; see
    :func:`facing_from_joints`), then shifts z so the lowest ankle over the first second
    is ``ankle_height`` metres above the floor (z = 0). Returns (T, 15, 3).
    """
    joints = joints_array(joints, min_ndim=3)
    if joints.ndim != 3 or joints.shape[0] < 1:
        raise ValueError(f"joints must have shape (T, 15, 3) with T >= 1, got {joints.shape}")
    if not fps > 0:
        raise ValueError(f"fps must be positive, got {fps}")
    start = np.asarray(start_xy, dtype=np.float64)
    if start.shape != (2,):
        raise ValueError(f"start_xy must be two numbers (x, y) in metres, got {start_xy!r}")
    angle = heading - facing_from_joints(joints[0])
    c, s = math.cos(angle), math.sin(angle)
    rot = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
    pelvis0 = joints[0, JOINT_INDEX["pelvis"]].copy()
    pelvis0[2] = 0.0
    out = (joints - pelvis0) @ rot.T
    out[..., :2] += start
    first = out[: max(1, int(round(fps))), [JOINT_INDEX["left_ankle"], JOINT_INDEX["right_ankle"]], 2]
    out[..., 2] += ankle_height - first.min()
    return out


#: The canonical skeleton as a tree from the pelvis: (parent, child) joint indices, parents first.
_TREE = tuple((JOINT_INDEX[a], JOINT_INDEX[b]) for a, b in (
    ("pelvis", "neck"), ("neck", "head"),
    ("neck", "left_shoulder"), ("left_shoulder", "left_elbow"), ("left_elbow", "left_wrist"),
    ("neck", "right_shoulder"), ("right_shoulder", "right_elbow"), ("right_elbow", "right_wrist"),
    ("pelvis", "left_hip"), ("left_hip", "left_knee"), ("left_knee", "left_ankle"),
    ("pelvis", "right_hip"), ("right_hip", "right_knee"), ("right_knee", "right_ankle"),
))


def retarget_lengths(joints, bone_lengths, ankle_height: float = ANKLE_HEIGHT, fps: float = 30.0) -> np.ndarray:
    """Give a canonical sequence another body's bone lengths, keeping its bone directions.

    joints : (T, 15, 3) canonical joints, metres, z up, floor at z = 0 (e.g. a placed clip)
    bone_lengths : (14,) metres, in the order of :data:`occupose.joints.BONES`
    ankle_height : the new body's ankle joints above the floor standing, metres
    fps : the sequence's frame rate

    Every bone keeps its direction in every frame and gets its new length, built out from
    the pelvis. The pelvis path is scaled about its first frame's floor point by the ratio
    of the new to the old leg length (thigh + shin, medians over frames), as stride
    lengths scale with leg length; then z is shifted so the lowest ankle over the first
    second is ``ankle_height`` above the floor. Returns (T, 15, 3).
    """
    joints = joints_array(joints, min_ndim=3)
    if joints.ndim != 3 or joints.shape[0] < 1:
        raise ValueError(f"joints must have shape (T, 15, 3) with T >= 1, got {joints.shape}")
    lengths = np.asarray(bone_lengths, np.float64)
    if lengths.shape != (len(BONES),) or not np.all(np.isfinite(lengths) & (lengths > 0)):
        raise ValueError(f"bone_lengths must be {len(BONES)} positive lengths in metres, got {bone_lengths!r}")
    by_pair = {frozenset(bone): length for bone, length in zip(BONES, lengths)}
    old = {frozenset(bone): np.linalg.norm(joints[:, bone[1]] - joints[:, bone[0]], axis=-1) for bone in BONES}
    legs = [frozenset((JOINT_INDEX[f"{s}_{a}"], JOINT_INDEX[f"{s}_{b}"]))
            for s in ("left", "right") for a, b in (("hip", "knee"), ("knee", "ankle"))]
    ratio = sum(by_pair[k] for k in legs) / sum(float(np.median(old[k])) for k in legs)
    pelvis = joints[:, JOINT_INDEX["pelvis"]]
    floor = np.array([pelvis[0, 0], pelvis[0, 1], 0.0])
    out = np.empty_like(joints)
    out[:, JOINT_INDEX["pelvis"]] = floor + ratio * (pelvis - floor)
    for parent, child in _TREE:
        bone = joints[:, child] - joints[:, parent]
        norm = np.maximum(np.linalg.norm(bone, axis=-1, keepdims=True), 1e-9)
        out[:, child] = out[:, parent] + bone / norm * by_pair[frozenset((parent, child))]
    ankles = out[: max(1, int(round(fps))), [JOINT_INDEX["left_ankle"], JOINT_INDEX["right_ankle"]], 2]
    out[..., 2] += ankle_height - ankles.min()
    return out
