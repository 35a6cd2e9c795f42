"""What a likelihood sees of one person in one frame: per-camera images and 3D points.

Built once per frame (by the tracker from its segmentation, or in tests from the
synthetic renderer's person image) and handed to every likelihood of that frame.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from occupose.camera import Camera, points_from_depth
from occupose.likelihood._capsules import PointBlocks, blocked_points

#: Share of the mask's bounding box added on each side when a View's ``roi`` is not given
#: (room for particles whose limbs reach beyond the observed silhouette).
ROI_MARGIN = 0.15


def roi_from_mask(mask: np.ndarray, margin: float = ROI_MARGIN) -> tuple[int, int, int, int]:
    """Bounding box of a mask's True pixels, grown by ``margin`` of its size on each side.

    mask : (H, W) bool. Returns (v0, v1, u0, u1) int, half-open (rows v0..v1-1, columns
    u0..u1-1), clipped to the image; (0, 0, 0, 0) for an empty mask.
    """
    mask = np.asarray(mask, dtype=bool)
    if mask.ndim != 2:
        raise ValueError(f"mask must be a 2-D (H, W) array, got shape {mask.shape}")
    if margin < 0:
        raise ValueError(f"margin must be >= 0, got {margin!r}")
    rows, cols = np.flatnonzero(mask.any(axis=1)), np.flatnonzero(mask.any(axis=0))
    if rows.size == 0:
        return (0, 0, 0, 0)
    grow_v = int(np.ceil(margin * (rows[-1] + 1 - rows[0])))
    grow_u = int(np.ceil(margin * (cols[-1] + 1 - cols[0])))
    height, width = mask.shape
    return (max(int(rows[0]) - grow_v, 0), min(int(rows[-1]) + 1 + grow_v, height),
            max(int(cols[0]) - grow_u, 0), min(int(cols[-1]) + 1 + grow_u, width))


@dataclass(frozen=True, eq=False)
class View:
    """One camera's images of the scene, with the person's pixels marked.

    camera : Camera
    depth : (H, W) float32, metres, camera z of the whole image (the free-space and render
        terms read the background too); 0 = no measurement. Stored as a C-contiguous
        float32 copy; uint16 raw images are converted with ``camera.depth_scale``.
    mask : (H, W) bool, the person's pixels
    color : (H, W, 3) uint8 RGB registered to the depth image, or None
    roi : (v0, v1, u0, u1) int, half-open pixel box of the person (rows v0..v1-1, columns
        u0..u1-1); None gives :func:`roi_from_mask` of the mask.
    """

    camera: Camera
    depth: np.ndarray
    mask: np.ndarray
    color: np.ndarray | None = None
    roi: tuple[int, int, int, int] | None = None

    def __post_init__(self) -> None:
        camera = self.camera
        if not isinstance(camera, Camera):
            raise ValueError(f"camera must be an occupose.camera.Camera, got {type(camera).__name__}")
        shape = (camera.height, camera.width)
        depth = np.asarray(self.depth)
        if depth.shape != shape or not (depth.dtype == np.uint16 or depth.dtype.kind == "f"):
            raise ValueError(f"depth of camera {camera.name!r} must be a {shape} float (metres) or uint16 "
                             f"image, got {depth.dtype} {depth.shape}")
        if depth.dtype == np.uint16:
            depth = depth * camera.depth_scale
        with np.errstate(invalid="ignore"):
            depth = np.where(np.isfinite(depth) & (depth > 0), depth, 0).astype(np.float32)
        mask = np.asarray(self.mask)
        if mask.shape != shape or mask.dtype != bool:
            raise ValueError(f"mask of camera {camera.name!r} must be a {shape} bool image, got "
                             f"{mask.dtype} {mask.shape}")
        color = self.color
        if color is not None:
            color = np.asarray(color)
            if color.shape != (*shape, 3) or color.dtype != np.uint8:
                raise ValueError(f"color of camera {camera.name!r} must be a {(*shape, 3)} uint8 image or "
                                 f"None, got {color.dtype} {color.shape}")
            color = np.ascontiguousarray(color)
        roi = roi_from_mask(mask) if self.roi is None else self.roi
        try:
            v0, v1, u0, u1 = (int(x) for x in roi)
        except (TypeError, ValueError):
            raise ValueError(f"roi must be four integers (v0, v1, u0, u1), got {roi!r}") from None
        if not (0 <= v0 <= v1 <= shape[0] and 0 <= u0 <= u1 <= shape[1]):
            raise ValueError(f"roi (v0, v1, u0, u1) = {roi!r} must lie in the {shape} image with v0 <= v1, u0 <= u1")
        object.__setattr__(self, "depth", np.ascontiguousarray(depth))
        object.__setattr__(self, "mask", np.ascontiguousarray(mask))
        object.__setattr__(self, "color", color)
        object.__setattr__(self, "roi", (v0, v1, u0, u1))

    @cached_property
    def points(self) -> np.ndarray:
        """(N, 3) world metres, read-only: the measured pixels (depth > 0) of the mask,
        back-projected, row-major (made once: the observation and the tracker's size
        measurements of a frame share them)."""
        points = points_from_depth(np.where(self.mask, self.depth, 0.0), self.camera)[0]
        points.flags.writeable = False
        return points


@dataclass(frozen=True, eq=False)
class Observation:
    """One person in one frame.

    points : (N, 3) float64, metres, world frame: the person's 3D points (subsampled)
    views : tuple of View, one per camera
    """

    points: np.ndarray
    views: tuple[View, ...]

    def __post_init__(self) -> None:
        points = np.asarray(self.points, dtype=np.float64)
        if points.ndim != 2 or points.shape[1] != 3 or not np.all(np.isfinite(points)):
            raise ValueError(f"points must be a finite (N, 3) array of world metres, got shape {points.shape}")
        views = tuple(self.views)
        if not all(isinstance(view, View) for view in views):
            raise ValueError("views must be a sequence of occupose.likelihood.View")
        object.__setattr__(self, "points", np.ascontiguousarray(points))
        object.__setattr__(self, "views", views)

    @cached_property
    def blocks(self) -> PointBlocks:
        """The points in spatially compact blocks for the points kernels, made once (the
        points likelihood and the arm proposals of a frame share them)."""
        return blocked_points(self.points)


def observation_from_views(views, max_points: int = 2000) -> Observation:
    """The Observation whose points are the person's pixels of every view, back-projected.

    views : sequence of View; the points are the measured pixels (depth > 0) of each mask,
    in world metres, views in order, pixels row-major; when there are more than
    ``max_points`` (>= 1), ``max_points`` of them evenly spaced in that order are kept
    (deterministic).
    """
    views = tuple(views)
    if isinstance(max_points, bool) or not isinstance(max_points, (int, np.integer)) or max_points < 1:
        raise ValueError(f"max_points must be a positive integer, got {max_points!r}")
    chunks = [np.zeros((0, 3))]
    for view in views:
        if not isinstance(view, View):
            raise ValueError(f"views must be a sequence of View, got a {type(view).__name__}")
        chunks.append(view.points)
    points = np.concatenate(chunks)
    if len(points) > max_points:
        points = points[np.linspace(0, len(points) - 1, max_points).round().astype(np.int64)]
    return Observation(points, views)
