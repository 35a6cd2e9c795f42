"""Checks for placing people in a scene: in a camera's view, clear of furniture and of each
other, partly hidden behind furniture.

Joints are canonical joint trajectories (T, 15, 3) float64, world metres, z up; furniture
is a :class:`~occupose.geometry.primitives.Primitives` batch whose boxes are tested (its
other primitives are ignored).
"""

from __future__ import annotations

import numpy as np

from occupose.camera import Camera, pixels_from_points
from occupose.geometry.primitives import BOX, Primitives

#: Pixels a joint must stay inside the image border to count as in view.
IMAGE_MARGIN_PX = 4


def in_view(joints: np.ndarray, camera: Camera, near: float, far: float) -> np.ndarray:
    """(T,) bool: frames whose every joint projects inside the image (``IMAGE_MARGIN_PX``
    from the border) at a depth in [near, far] metres."""
    joints = np.asarray(joints, np.float64)
    uv, z = pixels_from_points(joints.reshape(-1, 3), camera)
    with np.errstate(invalid="ignore"):
        ok = ((z >= near) & (z <= far) & (uv[:, 0] >= IMAGE_MARGIN_PX) & (uv[:, 0] <= camera.width - 1 - IMAGE_MARGIN_PX)
              & (uv[:, 1] >= IMAGE_MARGIN_PX) & (uv[:, 1] <= camera.height - 1 - IMAGE_MARGIN_PX))
    return ok.reshape(joints.shape[:-1]).all(axis=-1)


def _boxes(prims: Primitives) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Centres (K, 3), world_from_local rotations (K, 3, 3) and half extents (K, 3) of the boxes."""
    boxes = prims.kind == BOX
    return prims.center[boxes], prims.axes[boxes], prims.size[boxes]


def inside_boxes(points: np.ndarray, prims: Primitives, margin: float = 0.0) -> np.ndarray:
    """(N,) bool: points (N, 3) inside some box of ``prims`` grown by ``margin`` metres."""
    points = np.asarray(points, np.float64).reshape(-1, 3)
    centers, axes, half = _boxes(prims)
    if not len(centers):
        return np.zeros(len(points), bool)
    local = np.einsum("nkj,kji->nki", points[:, None, :] - centers[None], axes)  # (N, K, 3)
    return np.any(np.all(np.abs(local) <= half[None] + margin, axis=-1), axis=1)


def box_corners(prims: Primitives) -> np.ndarray:
    """(8 K, 3) the corners of every box of ``prims``."""
    centers, axes, half = _boxes(prims)
    signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], np.float64)
    return (centers[:, None] + np.einsum("kij,kcj->kci", axes, signs[None] * half[:, None])).reshape(-1, 3)


def hidden_from(camera: Camera, points: np.ndarray, prims: Primitives) -> np.ndarray:
    """(N,) bool: points (N, 3) whose line of sight from the camera's centre crosses a box
    of ``prims`` before reaching them (slab test)."""
    points = np.asarray(points, np.float64).reshape(-1, 3)
    centers, axes, half = _boxes(prims)
    if not len(centers):
        return np.zeros(len(points), bool)
    eye = camera.world_from_camera[:3, 3]
    origin = np.einsum("kj,kji->ki", eye[None] - centers, axes)            # (K, 3) eye in box frames
    direction = np.einsum("nj,kji->nki", points - eye, axes)               # (N, K, 3), segment 0..1
    with np.errstate(divide="ignore", invalid="ignore"):
        t1 = (-half[None] - origin[None]) / direction
        t2 = (half[None] - origin[None]) / direction
    parallel = np.abs(direction) < 1e-12
    inside_slab = np.abs(origin[None]) <= half[None]
    lo = np.where(parallel, np.where(inside_slab, -np.inf, np.inf), np.minimum(t1, t2)).max(axis=-1)
    hi = np.where(parallel, np.where(inside_slab, np.inf, -np.inf), np.maximum(t1, t2)).min(axis=-1)
    return np.any((lo <= hi) & (hi > 0.0) & (lo < 1.0), axis=1)


def clear_of_people(joints: np.ndarray, others: list[np.ndarray], min_pelvis: float, min_joint: float) -> bool:
    """Whether ``joints`` (T, 15, 3) keeps, in every frame, its pelvis (joint 2) at least
    ``min_pelvis`` metres (horizontally) and every joint at least ``min_joint`` metres from
    each trajectory of ``others``."""
    for other in others:
        gap = np.linalg.norm(joints[:, 2, :2] - other[:, 2, :2], axis=-1)
        if np.any(gap < min_pelvis):
            return False
        pairs = np.linalg.norm(joints[:, :, None] - other[:, None], axis=-1)
        if np.any(pairs < min_joint):
            return False
    return True
