"""The floor plane under a camera, found in its depth images: a camera's world pose from its data.

A recording from a real camera has no world pose (z up, the floor at z = 0). The floor is
the lowest large plane the camera sees: :func:`fit_floor` finds the largest planes of a
point cloud one after another (RANSAC, each refined by least squares), keeps those that
could be the floor (nothing seen beyond them, the camera at a plausible height above them),
takes the one whose normal best agrees with the up direction (the IMU's, where there is
one; else the image's: a camera is mounted image-up), and then the lowest plane parallel to
it (the first choice may be a table top). :meth:`Floor.world_from_camera` is the camera pose
it gives: z up, the floor at z = 0, the camera above the origin looking along world +y.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from occupose.camera import Camera, points_from_depth
from occupose.geometry import _floor_kernels


@dataclass(frozen=True)
class Floor:
    """The floor seen by a camera.

    normal : (3,) float64 unit vector, camera frame (OpenCV axes), pointing up (toward the camera)
    height : metres of the camera's optical centre above the floor plane
    share : share of the fitted points on the plane
    """

    normal: np.ndarray
    height: float
    share: float

    @property
    def tilt(self) -> float:
        """Degrees the optical axis points below the horizontal (90: straight down)."""
        return math.degrees(math.asin(float(np.clip(-self.normal[2], -1.0, 1.0))))

    @property
    def roll(self) -> float:
        """Degrees the image's x axis (right) rises above the horizontal."""
        return math.degrees(math.asin(float(np.clip(self.normal[0], -1.0, 1.0))))

    def world_from_camera(self) -> np.ndarray:
        """(4, 4) float64 rigid transform, camera frame to a world frame with z up, the floor
        at z = 0 and the camera at (0, 0, height) looking along +y (straight down: its image's
        top towards +y)."""
        up = self.normal
        forward = np.array([0.0, 0.0, 1.0]) - up[2] * up  # the optical axis on the floor
        if np.linalg.norm(forward) < 1e-6:
            forward = np.array([0.0, -1.0, 0.0]) + up[1] * up  # looking straight down: image up
        forward /= np.linalg.norm(forward)
        pose = np.eye(4)
        pose[:3, :3] = np.stack([np.cross(forward, up), forward, up])  # rows: world axes in the camera frame
        pose[2, 3] = self.height
        return pose


def median_depth(depths) -> np.ndarray:
    """(H, W) float32 per-pixel median of depth images (float metres, 0 = none) over the
    pixels measured in each; 0 where none is."""
    stack = np.stack([np.where(d > 0, d, np.nan) for d in depths]).astype(np.float32)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # pixels measured in no image
        median = np.nanmedian(stack, axis=0)
    return np.nan_to_num(median, nan=0.0)


def _plane(points: np.ndarray) -> tuple[np.ndarray, float]:
    """Least-squares plane of (N, 3) points: (unit normal towards the origin's side, offset
    d > 0 with n . x + d = 0 on the plane, d the origin's distance)."""
    centre = points.mean(axis=0)
    normal = np.linalg.svd(points - centre, full_matrices=False)[2][2]
    offset = -float(normal @ centre)
    return (normal, offset) if offset >= 0 else (-normal, -offset)


def plane_inliers(points: np.ndarray, tolerance: np.ndarray, normals: np.ndarray, offsets: np.ndarray) -> np.ndarray:
    """(H,) int64: how many of the points (N, 3) metres lie within their ``tolerance`` (N,)
    metres of each plane ``normals[h] . p + offsets[h] = 0`` (normals (H, 3) unit vectors,
    offsets (H,) metres)."""
    x, y, z = (np.ascontiguousarray(points[:, i], dtype=np.float64) for i in range(3))
    counts = np.empty(len(normals), np.int64)
    _floor_kernels.plane_inliers(x, y, z, np.ascontiguousarray(tolerance, dtype=np.float64),
                                 np.ascontiguousarray(normals, dtype=np.float64),
                                 np.ascontiguousarray(offsets, dtype=np.float64), counts)
    return counts


def fit_floor(points: np.ndarray, config, *, gravity: np.ndarray | None = None, seed: int = 0) -> Floor | None:
    """The floor among (N, 3) camera-frame points (metres), or None when no plane can be it.

    config : :class:`occupose.config.FloorConfig`
    gravity : (3,) camera-frame direction of gravity (an IMU's accelerometer), or None
    seed : of the RANSAC samples
    """
    points = np.asarray(points, dtype=np.float64)
    rng = np.random.default_rng(seed)
    if len(points) > config.points:
        points = points[np.sort(rng.choice(len(points), config.points, replace=False))]
    if len(points) < 3:
        return None
    tolerance = config.tolerance_m + config.tolerance_rel * points[:, 2]
    candidates = []  # (normal, offset, share)
    remaining = np.ones(len(points), bool)
    for _ in range(config.planes):
        pool = np.flatnonzero(remaining)
        if len(pool) < 3:
            break
        a, b, c = (points[rng.choice(pool, config.iterations)] for _ in range(3))
        normals = np.cross(b - a, c - a)
        lengths = np.linalg.norm(normals, axis=1)
        keep = lengths > 1e-9
        normals, a = normals[keep] / lengths[keep, None], a[keep]
        if not len(normals):
            break
        offsets = -np.einsum("ij,ij->i", normals, a)
        counts = plane_inliers(points[pool], tolerance[pool], normals, offsets)
        best = int(np.argmax(counts))
        if counts[best] < config.min_share * len(points):
            break
        on = remaining & (np.abs(points @ normals[best] + offsets[best]) < tolerance)
        normal, offset = _plane(points[on])
        on = np.abs(points @ normal + offset) < tolerance
        below = np.mean(points @ normal + offset < -3 * tolerance)
        if below <= config.max_below and config.min_height <= offset <= config.max_height:
            candidates.append((normal, offset, float(on.mean())))
        remaining &= ~on
    if not candidates:
        return None
    if gravity is not None:
        up = -np.asarray(gravity, dtype=np.float64) / np.linalg.norm(gravity)
        candidates = [c for c in candidates if c[0] @ up >= math.cos(math.radians(config.gravity_deg))]
        if not candidates:
            return None
        chosen = max(candidates, key=lambda c: c[0] @ up * c[2])
    else:
        chosen = max(candidates, key=lambda c: c[2] * (config.image_up - c[0][1]))
        if config.image_up - chosen[0][1] <= 0:
            return None
    parallel = math.cos(math.radians(config.parallel_deg))
    lowest = max((c for c in candidates if c[0] @ chosen[0] >= parallel), key=lambda c: c[1])
    return Floor(lowest[0], float(lowest[1]), lowest[2])


def find_floor(camera: Camera, depths, config, *, gravity: np.ndarray | None = None) -> Floor | None:
    """The floor under ``camera`` from its first depth images (an iterable of (H, W) float
    metres, 0 = none; their per-pixel median is fitted, :func:`median_depth`), or None."""
    points, _ = points_from_depth(median_depth(list(depths)), camera, frame="camera")
    return fit_floor(points, config, gravity=gravity)
