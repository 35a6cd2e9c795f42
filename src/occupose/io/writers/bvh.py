"""BVH of every track from joint positions alone (docs/outputs.md): no inverse kinematics.

Layout: one ``ROOT world`` at the origin, and under it each track's skeleton, its joints
named ``t<id>_<joint>`` (``t3_left_knee``), rooted at its pelvis and following
:data:`occupose.joints.BONES`. Every joint has 6 channels, ``Xposition Yposition
Zposition Zrotation Xrotation Yrotation``; the rotations are always 0, so each joint's
position channels are its position relative to its parent's (the pelvis: relative to
the origin), which BVH readers put in place of the ``OFFSET``. ``OFFSET`` is each bone's
mean vector over the frames where the joint and its parent are both known (0 where never
both known), so the skeleton at rest is the track's mean shape.

Units: centimetres. Axes: y up, as BVH expects: a world point (x, y, z), z up, is written
(x, z, -y); a camera-frame point (OpenCV: x right, y down, z forward) is written (x, -y, -z).

BVH cannot mark a joint missing. A known joint is written where it is, whatever is
known of its parent; in a frame where a joint is unknown it is at its parent plus the
OFFSET, and where the pelvis is unknown it is at the nearest earlier frame's known pelvis
(before the first: the first; never known: the origin). Visibility is not in the file: use JSON or C3D.
"""

from __future__ import annotations

import re
from collections import deque
from pathlib import Path

import numpy as np

from occupose.io._skeleton import yup_from_zup
from occupose.io.writers import Tracks
from occupose.joints import BONES, JOINT_INDEX, JOINTS, NUM_JOINTS

_CHANNELS = "CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation"
_CM_PER_M = 100.0


def _tree() -> tuple[list[int], list[int]]:
    """(joints in parent-first order from the pelvis, each joint's parent index or -1)."""
    neighbours: dict[int, list[int]] = {j: [] for j in range(NUM_JOINTS)}
    for a, b in BONES:
        neighbours[a].append(b)
        neighbours[b].append(a)
    root = JOINT_INDEX["pelvis"]
    order, parents, queue = [], [-1] * NUM_JOINTS, deque([root])
    seen = {root}
    while queue:
        j = queue.popleft()
        order.append(j)
        for k in neighbours[j]:
            if k not in seen:
                seen.add(k)
                parents[k] = j
                queue.append(k)
    return order, parents


_ORDER, _PARENTS = _tree()
_CHILDREN = {j: [k for k in _ORDER if _PARENTS[k] == j] for j in range(NUM_JOINTS)}


def _bvh_axes(points: np.ndarray, in_camera: bool) -> np.ndarray:
    """(..., 3) metres in the tracks' frame -> (..., 3) centimetres, BVH axes (y up)."""
    turned = points * np.array([1.0, -1.0, -1.0]) if in_camera else yup_from_zup(points)
    return turned * _CM_PER_M


def _fill_nearest(values: np.ndarray, known: np.ndarray) -> np.ndarray:
    """(T, 3) ``values`` with the rows not ``known`` ((T,) bool, at least one True) taken from
    the nearest earlier known row, or before the first from the first."""
    index = np.where(known, np.arange(len(known)), -1)
    index = np.maximum.accumulate(index)
    index[index < 0] = np.flatnonzero(known)[0]
    return values[index]


def relative_channels(joints: np.ndarray, known: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """One track's BVH motion in its own frame's axes and units.

    joints : (T, 15, 3) positions, NaN where unknown; known : (T, 15) bool
    Returns (offsets (15, 3): each joint's mean vector from its parent where both are
    known, else 0, the pelvis's 0; channels (T, 15, 3): each joint's position relative to
    its parent's as written, the pelvis's absolute). A known joint is written where it is;
    an unknown one at its parent plus its offset, an unknown pelvis as the module says.
    """
    offsets = np.zeros((NUM_JOINTS, 3))
    written = np.zeros(joints.shape)  # the positions the file gives, parent first
    for j in _ORDER:
        p = _PARENTS[j]
        if p < 0:
            if known[:, j].any():
                written[:, j] = _fill_nearest(joints[:, j], known[:, j])
            continue
        both = known[:, j] & known[:, p]
        if both.any():
            offsets[j] = (joints[both, j] - joints[both, p]).mean(axis=0)
        written[:, j] = np.where(known[:, j, None], joints[:, j], written[:, p] + offsets[j])
    channels = written.copy()
    channels[:, _ORDER[1:]] -= written[:, [_PARENTS[j] for j in _ORDER[1:]]]
    return offsets, channels


def bvh_text(tracks: Tracks) -> str:
    """The BVH file of ``tracks`` (module docstring) as text."""
    lines = ["HIERARCHY", "ROOT world", "{", "\tOFFSET 0.000000 0.000000 0.000000", f"\t{_CHANNELS}"]
    motion = [np.zeros((tracks.joints.shape[0], 3))]
    for p, ident in enumerate(tracks.ids):
        offsets, channels = relative_channels(_bvh_axes(tracks.joints[:, p], tracks.in_camera), tracks.known[:, p])
        def emit(j: int, depth: int) -> None:
            pad = "\t" * depth
            lines.append(f"{pad}JOINT t{ident}_{JOINTS[j]}")
            lines.append(f"{pad}{{")
            lines.append(f"{pad}\tOFFSET {offsets[j][0]:.6f} {offsets[j][1]:.6f} {offsets[j][2]:.6f}")
            lines.append(f"{pad}\t{_CHANNELS}")
            motion.append(channels[:, j])
            for k in _CHILDREN[j]:
                emit(k, depth + 1)
            if not _CHILDREN[j]:
                lines.extend([f"{pad}\tEnd Site", f"{pad}\t{{", f"{pad}\t\tOFFSET 0.000000 0.000000 0.000000",
                              f"{pad}\t}}"])
            lines.append(f"{pad}}}")

        emit(_ORDER[0], 1)
    lines.append("}")
    num_frames = tracks.joints.shape[0]
    lines += ["MOTION", f"Frames: {num_frames}", f"Frame Time: {1.0 / tracks.fps:.9f}"]
    values = np.stack(motion, axis=1)  # (T, joints, 3)
    rotations = np.zeros_like(values)
    rows = np.concatenate([values, rotations], axis=2).reshape(num_frames, -1)
    lines += [" ".join(f"{v:.4f}" for v in row) for row in rows]
    return "\n".join(lines) + "\n"


def write_bvh(path: Path, tracks: Tracks) -> None:
    """Write ``tracks`` as BVH to ``path`` (module docstring)."""
    Path(path).write_text(bvh_text(tracks), encoding="utf-8")


_OURS = re.compile(r"HIERARCHY\s+ROOT world\s+\{\s+OFFSET 0\.000000 0\.000000 0\.000000\s+" + re.escape(_CHANNELS))


def is_occupose_bvh(path: Path) -> bool:
    """Whether ``path`` starts as this writer's BVH files do (the ``ROOT world`` of 6 channels)."""
    try:
        with open(path, encoding="utf-8") as handle:
            head = handle.read(200)
    except (OSError, ValueError):
        return False
    return _OURS.match(head) is not None
