"""Chaining motion segments (real mocap slices or procedural actions) into one trajectory.

Each segment is a joint trajectory ``(T, 15, 3)``. :func:`chain` moves every segment
rigidly (rotation about z and a horizontal translation) so that it starts where the
previous one ended, facing the previous segment's final heading or a heading given for the
segment, and fades the remaining pose difference out over the segment's first frames, so
the result has no jumps.
"""

from __future__ import annotations

import numpy as np

from occupose.joints import JOINT_INDEX as J
from occupose.synth.retarget import facing_from_joints as facing


def rigid_z(joints: np.ndarray, angle: float, pivot_xy, to_xy) -> np.ndarray:
    """Rotate ``joints`` (..., 3) by ``angle`` about the vertical through ``pivot_xy``,
    then move that pivot to ``to_xy``."""
    c, s = np.cos(angle), np.sin(angle)
    out = np.array(joints, np.float64, copy=True)
    x = out[..., 0] - pivot_xy[0]
    y = out[..., 1] - pivot_xy[1]
    out[..., 0] = c * x - s * y + to_xy[0]
    out[..., 1] = s * x + c * y + to_xy[1]
    return out


def smoothstep(n: int) -> np.ndarray:
    """(n,) ramp from 0 (exclusive) to 1 with zero slope at both ends."""
    t = np.arange(1, n + 1) / (n + 1)
    return t * t * (3 - 2 * t)


def chain(segments: list[np.ndarray], headings: list[float | None] | None = None,
          blend_frames: int = 10) -> np.ndarray:
    """Join joint trajectories end to start.

    segments : list of (T_i, 15, 3) float64, metres, world (z up); the first one stays
        where it is, later ones are moved to start at the previous end.
    headings : per segment, None to keep the previous final heading, or an absolute
        heading in radians for the segment's first frame (a turn at the junction).
    blend_frames : frames over which a segment's start pose is faded in.
    Returns (sum T_i, 15, 3).
    """
    if not segments:
        raise ValueError("chain needs at least one segment")
    headings = headings or [None] * len(segments)
    if len(headings) != len(segments):
        raise ValueError(f"{len(segments)} segments but {len(headings)} headings")
    out = [np.asarray(segments[0], np.float64)]
    for seg, heading in zip(segments[1:], headings[1:]):
        seg = np.asarray(seg, np.float64)
        prev = out[-1][-1]
        target = facing(prev) if heading is None else heading
        pivot = seg[0, J["pelvis"], :2]
        moved = rigid_z(seg, target - facing(seg[0]), pivot, prev[J["pelvis"], :2])
        n = min(blend_frames, len(moved))
        offset = prev - moved[0]
        moved[:n] += (1.0 - smoothstep(n))[:, None, None] * offset[None]
        out.append(moved)
    return np.concatenate(out, axis=0)
