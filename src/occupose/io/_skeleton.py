"""What the mocap readers (:mod:`occupose.io.bvh`, :mod:`occupose.io.asf_amc`) share (private):
forward kinematics over all frames at once, the turn from the files' y up to the world's
z up, and the check of an explicit ``units`` (metres per file unit)."""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

# (x, y, z) y-up -> (x, -z, y) z-up, as a matrix applied to column vectors.
_ZUP_FROM_YUP = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]])


def matrices_from_euler(letters: str, angles: np.ndarray, degrees: bool, intrinsic: bool) -> np.ndarray:
    """(T, 3, 3) rotation matrices; letters like "zxy" in application order of the file."""
    if not letters:
        return np.broadcast_to(np.eye(3), (angles.shape[0], 3, 3))
    seq = letters.upper() if intrinsic else letters.lower()
    return Rotation.from_euler(seq, angles, degrees=degrees).as_matrix()


def positions_from_kinematics(parents: np.ndarray, offsets: np.ndarray, locals_: list,
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


def zup_from_yup(points: np.ndarray) -> np.ndarray:
    return points @ _ZUP_FROM_YUP.T


def metres_per_unit(units) -> float:
    """An explicit ``units``: a positive number of metres per file unit (ValueError otherwise,
    naming ``'auto'``, which each reader resolves itself)."""
    if isinstance(units, str):
        raise ValueError(f"units must be 'auto' or metres per file unit (a number), got {units!r}")
    scale = float(units)
    if not scale > 0:
        raise ValueError(f"units must be positive metres per file unit, got {units!r}")
    return scale


def yup_from_zup(points: np.ndarray) -> np.ndarray:
    """The inverse of :func:`zup_from_yup`: (x, y, z) z-up -> (x, z, -y) y-up."""
    return points @ _ZUP_FROM_YUP
