"""Pinhole depth cameras: intrinsics, world<-camera poses, back-projection and projection.

Conventions (DESIGN.md): the world frame is in metres with z up and the floor at z = 0;
the camera frame is OpenCV's (x right, y down in the image, z forward); depth is the z
coordinate in the camera frame, not the length of the ray. Pixel ``(u, v)`` is column
``u``, row ``v``; its centre has integer coordinates, and a flat pixel index is
``v * width + u``. Lens distortion is not modelled.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Mapping

import numpy as np

from occupose.config import GridConfig

#: Keys of a camera entry in ``recording.json``, in the order they are written.
CAMERA_KEYS: tuple[str, ...] = (
    "name", "width", "height", "fx", "fy", "cx", "cy", "depth_scale", "world_from_camera",
)

_RIGID_TOL = 1e-6
_FRAMES = ("world", "camera")


def _check_rigid(matrix: np.ndarray, what: str) -> None:
    """Raise ValueError unless ``matrix`` is a finite (4, 4) rigid transform."""
    if matrix.shape != (4, 4):
        raise ValueError(f"{what} must be a (4, 4) matrix, got shape {matrix.shape}")
    if not np.all(np.isfinite(matrix)):
        raise ValueError(f"{what} must be finite, got {matrix.tolist()}")
    if np.max(np.abs(matrix[3] - (0.0, 0.0, 0.0, 1.0))) > _RIGID_TOL:
        raise ValueError(f"{what} must have last row [0, 0, 0, 1], got {matrix[3].tolist()}")
    rotation = matrix[:3, :3]
    with np.errstate(over="ignore", invalid="ignore"):  # entries near the float limit: not rigid, no warning
        error = np.max(np.abs(rotation.T @ rotation - np.eye(3)))
        det = np.linalg.det(rotation)
    if not error <= _RIGID_TOL:  # NaN (inf - inf) fails too
        raise ValueError(
            f"{what} is not rigid: its rotation block is not orthonormal "
            f"(max |R^T R - I| = {error:.3g}, tolerance {_RIGID_TOL:g})"
        )
    if not abs(det - 1.0) <= _RIGID_TOL:
        raise ValueError(f"{what} is not a proper rotation: det(R) = {det:.6g}, expected +1")


def _positive_int(value: Any, what: str) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value <= 0:
        raise ValueError(f"{what} must be a positive integer, got {value!r}")
    return int(value)


def _finite_float(value: Any, what: str, *, positive: bool = False) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise ValueError(f"{what} must be a number, got {value!r}")
    try:
        number = float(value)
    except OverflowError:  # an integer beyond the largest float
        number = math.inf
    if not math.isfinite(number) or (positive and number <= 0.0):
        raise ValueError(f"{what} must be a {'positive ' if positive else ''}finite number, got {value!r}")
    return number


@dataclass(frozen=True, eq=False)
class Camera:
    """A calibrated pinhole depth camera placed in the world.

    Attributes
    ----------
    name : str
        Identifier, also the camera's folder name in a recording (no path separators).
    width, height : int
        Image size in pixels.
    fx, fy : float
        Focal lengths in pixels.
    cx, cy : float
        Principal point in pixels (pixel centres at integer coordinates).
    depth_scale : float
        Metres per raw uint16 depth unit (0.001: raw values are millimetres).
    world_from_camera : (4, 4) float64
        Rigid transform taking camera-frame points (OpenCV axes) to world points;
        stored as a read-only copy. Defaults to the identity.
    """

    name: str
    width: int
    height: int
    fx: float
    fy: float
    cx: float
    cy: float
    depth_scale: float = 0.001
    world_from_camera: np.ndarray = field(default_factory=lambda: np.eye(4))

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name.strip():
            raise ValueError(f"camera name must be a non-empty string, got {self.name!r}")
        if any(c in self.name for c in "/\\") or self.name in (".", "..") or self.name != self.name.strip():
            raise ValueError(
                f"camera name {self.name!r} must be usable as a folder name "
                "(no '/', '\\', surrounding spaces, '.' or '..')"
            )
        object.__setattr__(self, "width", _positive_int(self.width, f"camera {self.name!r}: width"))
        object.__setattr__(self, "height", _positive_int(self.height, f"camera {self.name!r}: height"))
        for key in ("fx", "fy", "depth_scale"):
            value = _finite_float(getattr(self, key), f"camera {self.name!r}: {key}", positive=True)
            object.__setattr__(self, key, value)
        for key in ("cx", "cy"):
            object.__setattr__(self, key, _finite_float(getattr(self, key), f"camera {self.name!r}: {key}"))
        try:
            pose = np.array(self.world_from_camera, dtype=np.float64)
        except (TypeError, ValueError, OverflowError) as error:
            raise ValueError(
                f"camera {self.name!r}: world_from_camera must be a (4, 4) array of numbers ({error})"
            ) from None
        _check_rigid(pose, f"camera {self.name!r}: world_from_camera")
        pose.setflags(write=False)
        object.__setattr__(self, "world_from_camera", pose)

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Camera):
            return NotImplemented
        return all(getattr(self, k) == getattr(other, k) for k in CAMERA_KEYS[:-1]) and bool(
            np.array_equal(self.world_from_camera, other.world_from_camera)
        )

    __hash__ = None  # compared by value (including the pose array), so not hashable

    @property
    def camera_from_world(self) -> np.ndarray:
        """(4, 4) float64: the inverse rigid transform, world points to camera frame."""
        rotation = self.world_from_camera[:3, :3]
        inverse = np.eye(4)
        inverse[:3, :3] = rotation.T
        inverse[:3, 3] = -rotation.T @ self.world_from_camera[:3, 3]
        return inverse

    @property
    def intrinsic_matrix(self) -> np.ndarray:
        """(3, 3) float64: the pinhole matrix K = [[fx, 0, cx], [0, fy, cy], [0, 0, 1]]."""
        return np.array([[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]])

    @property
    def position(self) -> np.ndarray:
        """(3,) float64, metres, world frame: the camera's optical centre."""
        return self.world_from_camera[:3, 3].copy()

    @property
    def down_angle(self) -> float:
        """Radians the optical axis points below the horizontal (world z up; negative: up)."""
        return float(np.arcsin(np.clip(-self.world_from_camera[2, 2], -1.0, 1.0)))

    def to_dict(self) -> dict[str, Any]:
        """The camera as a ``recording.json`` camera entry (plain JSON types, keys in CAMERA_KEYS order)."""
        return {
            "name": self.name, "width": self.width, "height": self.height,
            "fx": self.fx, "fy": self.fy, "cx": self.cx, "cy": self.cy,
            "depth_scale": self.depth_scale,
            "world_from_camera": self.world_from_camera.tolist(),
        }


def camera_from_dict(entry: Mapping[str, Any], source: str = "camera entry") -> Camera:
    """Build a Camera from a ``recording.json`` camera entry.

    Every key of CAMERA_KEYS is required and no other key is allowed. ``source`` names
    where the entry came from (for example ``"rec/recording.json: cameras[0]"``) and
    starts every error message. Raises ValueError on any missing, unknown or bad value.
    """
    if not isinstance(entry, Mapping):
        raise ValueError(f"{source}: expected an object with keys {list(CAMERA_KEYS)}, got {type(entry).__name__}")
    missing = [k for k in CAMERA_KEYS if k not in entry]
    if missing:
        raise ValueError(f"{source}: missing key(s) {missing}; a camera needs {list(CAMERA_KEYS)}")
    unknown = sorted(set(entry) - set(CAMERA_KEYS))
    if unknown:
        raise ValueError(f"{source}: unknown key(s) {unknown}; a camera has exactly {list(CAMERA_KEYS)}")
    pose = entry["world_from_camera"]
    if not (
        isinstance(pose, (list, tuple))
        and len(pose) == 4
        and all(isinstance(row, (list, tuple)) and len(row) == 4 for row in pose)
        and all(isinstance(x, (int, float)) and not isinstance(x, bool) for row in pose for x in row)
    ):
        raise ValueError(f"{source}: world_from_camera must be a 4x4 list of numbers, got {pose!r}")
    try:
        return Camera(**{k: entry[k] for k in CAMERA_KEYS})
    except ValueError as error:
        raise ValueError(f"{source}: {error}") from None


def _camera_points(depth: np.ndarray, camera: Camera) -> tuple[np.ndarray, np.ndarray]:
    """Checked depth image -> (camera-frame points (N, 3) float64, flat pixel indices (N,) int64)."""
    depth = np.asarray(depth)
    if depth.shape != (camera.height, camera.width):
        raise ValueError(
            f"depth image for camera {camera.name!r} must have shape "
            f"({camera.height}, {camera.width}), got {depth.shape}"
        )
    flat = depth.reshape(-1)
    if depth.dtype == np.uint16:
        pixels = np.flatnonzero(flat)
    elif depth.dtype.kind == "f":
        with np.errstate(invalid="ignore"):
            pixels = np.flatnonzero(np.isfinite(flat) & (flat > 0))
    else:
        raise ValueError(
            f"depth image for camera {camera.name!r} must be uint16 raw values or float metres, got {depth.dtype}"
        )
    pixels = pixels.astype(np.int64, copy=False)
    return _points_at(flat, pixels, camera), pixels


def _points_at(flat: np.ndarray, pixels: np.ndarray, camera: Camera) -> np.ndarray:
    """(N, 3) float64 camera-frame points of the measured pixels ``pixels`` ((N,) int64 flat
    indices) of a depth image ``flat`` ((H * W,) uint16 raw or float metres)."""
    z = flat[pixels] * camera.depth_scale if flat.dtype == np.uint16 else flat[pixels].astype(np.float64)
    v, u = np.divmod(pixels, camera.width)
    points = np.empty((pixels.size, 3))
    points[:, 0] = (u - camera.cx) * z / camera.fx
    points[:, 1] = (v - camera.cy) * z / camera.fy
    points[:, 2] = z
    return points


def _check_frame(frame: str) -> None:
    if frame not in _FRAMES:
        raise ValueError(f"frame must be one of {list(_FRAMES)}, got {frame!r}")


def points_from_depth(
    depth: np.ndarray, camera: Camera, *, frame: str = "world"
) -> tuple[np.ndarray, np.ndarray]:
    """Back-project every measured pixel of a depth image to a 3D point.

    Parameters
    ----------
    depth : (H, W) uint16 raw values (metres = value * camera.depth_scale) or float metres
        H, W = camera.height, camera.width. 0 means no measurement; for float images
        NaN, inf and negative values are also treated as no measurement. Those pixels
        are dropped.
    camera : Camera
    frame : {"world", "camera"}
        Frame of the returned points.

    Returns
    -------
    points : (N, 3) float64, metres, in ``frame``
    pixels : (N,) int64, flat pixel index ``v * W + u`` of each point, increasing
    """
    _check_frame(frame)
    points, pixels = _camera_points(depth, camera)
    return _in_frame(points, camera, frame), pixels


def points_at_pixels(depth: np.ndarray, pixels: np.ndarray, camera: Camera, *, frame: str = "world") -> np.ndarray:
    """The 3D points of chosen measured pixels of a depth image, as `points_from_depth` gives them.

    depth : (H, W) uint16 raw values or float metres, H, W = camera.height, camera.width
    pixels : (N,) int64 flat pixel indices ``v * W + u`` of pixels with a measurement (the
        caller has checked: e.g. those whose point `cells_from_depth` put in a cell)
    Returns (N, 3) float64, metres, in ``frame``: bit for bit the rows of
    ``points_from_depth(depth, camera)`` at those pixels.
    """
    _check_frame(frame)
    depth = np.asarray(depth)
    if depth.shape != (camera.height, camera.width) or not (depth.dtype == np.uint16 or depth.dtype.kind == "f"):
        raise ValueError(f"depth image for camera {camera.name!r} must be a ({camera.height}, {camera.width}) "
                         f"uint16 or float image, got {depth.dtype} {depth.shape}")
    pixels = np.asarray(pixels, np.int64)
    return _in_frame(_points_at(depth.reshape(-1), pixels, camera), camera, frame)


def _in_frame(points: np.ndarray, camera: Camera, frame: str) -> np.ndarray:
    """(N, 3) camera-frame points in ``frame`` ("world" or "camera")."""
    if frame == "world":
        pose = camera.world_from_camera
        points = points @ pose[:3, :3].T + pose[:3, 3]
    return points


def pixels_from_points(
    points: np.ndarray, camera: Camera, *, frame: str = "world"
) -> tuple[np.ndarray, np.ndarray]:
    """Project 3D points into the camera image.

    Parameters
    ----------
    points : (N, 3) float, metres, in ``frame`` ("world" or "camera")
    camera : Camera

    Returns
    -------
    uv : (N, 2) float64, pixel coordinates (u = column, v = row; pixel centres are integers)
    z : (N,) float64, metres, depth along the camera's z axis. Points behind the camera
        have z < 0 and points in its plane z = 0; their ``uv`` is meaningless (inf or NaN
        at z = 0), so callers mask with ``z > 0``. No check against the image bounds.
    """
    _check_frame(frame)
    points = np.asarray(points, dtype=np.float64)
    if points.ndim != 2 or points.shape[1] != 3:
        raise ValueError(f"points must have shape (N, 3), got {points.shape}")
    if frame == "world":
        pose = camera.world_from_camera
        # camera = R^T (world - t), written row-wise as (world - t) @ R
        points = (points - pose[:3, 3]) @ pose[:3, :3]
    z = points[:, 2].copy()
    uv = np.empty((points.shape[0], 2))
    with np.errstate(divide="ignore", invalid="ignore"):
        uv[:, 0] = camera.fx * points[:, 0] / z + camera.cx
        uv[:, 1] = camera.fy * points[:, 1] / z + camera.cy
    return uv, z


def raw_depth_from_metres(depth: np.ndarray, camera: Camera) -> np.ndarray:
    """Quantise a float depth image to the camera's raw uint16 units.

    Parameters
    ----------
    depth : (H, W) float, metres; 0, NaN, inf or negative mean no measurement

    Returns
    -------
    raw : (H, W) uint16, ``round(depth / depth_scale)``; 0 where there is no measurement
        and where the depth is beyond the largest raw value (65535 * depth_scale metres).
    """
    depth = np.asarray(depth)
    if depth.shape != (camera.height, camera.width) or depth.dtype.kind != "f":
        raise ValueError(
            f"depth for camera {camera.name!r} must be a float ({camera.height}, {camera.width}) "
            f"image in metres, got {depth.dtype} {depth.shape}"
        )
    with np.errstate(invalid="ignore"):
        units = np.rint(depth.astype(np.float64) / camera.depth_scale)
        valid = np.isfinite(units) & (units > 0) & (units <= np.iinfo(np.uint16).max)
    return np.where(valid, units, 0).astype(np.uint16)


def look_at(eye, target, up=(0.0, 0.0, 1.0)) -> np.ndarray:
    """Pose of a camera at ``eye`` looking at ``target``, OpenCV axes.

    The camera's z axis points from ``eye`` to ``target``, its x axis (image right) is
    horizontal with respect to ``up``, and its y axis (image down) points away from
    ``up`` as far as possible. When the viewing direction is parallel to ``up`` (a
    ceiling camera looking straight down, for example), world +y is used as the
    image-up hint instead, or world +z when the view is also along y: a camera
    looking straight down then sees world +x to the right and world +y up the image.

    Parameters
    ----------
    eye, target : (3,) float, metres, world frame; must differ
    up : (3,) float, non-zero; the world direction that should appear up in the image

    Returns
    -------
    world_from_camera : (4, 4) float64 rigid transform
    """
    eye, target, up = (np.asarray(a, dtype=np.float64) for a in (eye, target, up))
    for name, value in (("eye", eye), ("target", target), ("up", up)):
        if value.shape != (3,) or not np.all(np.isfinite(value)):
            raise ValueError(f"{name} must be a finite (3,) vector, got {value.tolist()}")
    forward = target - eye
    distance = np.linalg.norm(forward)
    if distance == 0.0:
        raise ValueError(f"eye and target must differ, both are {eye.tolist()}")
    if np.linalg.norm(up) == 0.0:
        raise ValueError("up must be a non-zero vector")
    forward /= distance
    for hint in (up / np.linalg.norm(up), np.array([0.0, 1.0, 0.0]), np.array([0.0, 0.0, 1.0])):
        right = np.cross(forward, hint)
        norm = np.linalg.norm(right)
        if norm > 1e-6:
            break
    right /= norm
    down = np.cross(forward, right)
    pose = np.eye(4)
    pose[:3, 0], pose[:3, 1], pose[:3, 2], pose[:3, 3] = right, down, forward, eye
    return pose


@dataclass(frozen=True)
class SensorSpec:
    """Nominal intrinsics and working range of a depth sensor model.

    width, height : int, pixels; fx, fy, cx, cy : float, pixels;
    near, far : float, metres, nominal measuring range;
    noise : str, name of the sensor noise model in occupose.sensors ("structured_light" for
        Kinect v1 and, for want of a stereo model, the active-stereo RealSense; "tof").
    """

    name: str
    width: int
    height: int
    fx: float
    fy: float
    cx: float
    cy: float
    near: float
    far: float
    noise: str


#: Depth sensors by name. Intrinsics from ../shared/data/README.md; Azure Kinect NFOV
#: unbinned from the real factory calibration in ../shared/data/sensors/azure_kinect
#: (normalised cx, cy, fx, fy of the 1024 x 1024 depth sensor, taken to 640 x 576 as the
#: Azure Kinect SDK does: the crop starts 192 px from the left and 180 px from the top, not
#: centred, so cy is 348.83 and not 304.83, the value this preset had until 2026-12-07; the
#: nominal 75 x 65 degree field of view includes lens distortion a pinhole cannot carry).
#: Ranges from the makers' specs (Kinect v1: the raw stream's practical 0.5-4.5 m, wider
#: than the 0.8-4.0 m its Windows SDK reports by default).
CAMERA_PRESETS: dict[str, SensorSpec] = {
    spec.name: spec
    for spec in (
        SensorSpec("kinect_v1", 640, 480, 594.21, 591.04, 339.5, 242.7, 0.5, 4.5, "structured_light"),
        SensorSpec("kinect_v2", 512, 424, 365.5, 365.5, 254.9, 205.4, 0.5, 4.5, "tof"),
        SensorSpec("azure_nfov", 640, 576, 504.61, 504.73, 332.78, 348.83, 0.5, 3.86, "tof"),
        SensorSpec("realsense_d435", 640, 480, 382.6, 382.6, 319.0, 246.3, 0.3, 3.0, "structured_light"),
    )
}


def sensor_spec(name: str) -> SensorSpec:
    """The SensorSpec registered under ``name``; ValueError listing valid names otherwise."""
    try:
        return CAMERA_PRESETS[name]
    except (KeyError, TypeError):
        raise ValueError(f"unknown camera preset {name!r}; valid names: {sorted(CAMERA_PRESETS)}") from None


def camera_preset(name: str, *, world_from_camera=None, camera_name: str = "cam0") -> Camera:
    """A Camera with the intrinsics of preset ``name`` (see CAMERA_PRESETS).

    world_from_camera : (4, 4) rigid transform or None for the identity.
    Raw depth is in millimetres (depth_scale 0.001).
    """
    spec = sensor_spec(name)
    return Camera(
        name=camera_name, width=spec.width, height=spec.height,
        fx=spec.fx, fy=spec.fy, cx=spec.cx, cy=spec.cy,
        world_from_camera=np.eye(4) if world_from_camera is None else world_from_camera,
    )


def matching_preset(camera: Camera, tolerance: float | None = None) -> str | None:
    """The name of the sensor preset (CAMERA_PRESETS) ``camera`` is, or None.

    A camera is a preset when its image size is the preset's and each of its fx, fy, cx,
    cy is within ``tolerance`` (a share, default ``grid.preset_tolerance``: 0.05) of the
    preset's value: a real calibration differs from the nominal intrinsics by a few
    percent. The presets have one resolution each, so a camera of another size (a binned
    or cropped mode) matches none. When several presets match, the closest one (smallest
    largest relative difference) is taken.
    """
    if not isinstance(camera, Camera):
        raise ValueError(f"camera must be an occupose.camera.Camera, got {type(camera).__name__}")
    tolerance = GridConfig.preset_tolerance if tolerance is None else tolerance
    if isinstance(tolerance, bool) or not isinstance(tolerance, (int, float)) or not 0.0 <= tolerance < 1.0:
        raise ValueError(f"tolerance must be a share in [0, 1), got {tolerance!r}")
    best, best_off = None, math.inf
    for spec in CAMERA_PRESETS.values():
        if (spec.width, spec.height) != (camera.width, camera.height):
            continue
        off = max(abs(getattr(camera, k) - getattr(spec, k)) / abs(getattr(spec, k)) for k in ("fx", "fy", "cx", "cy"))
        if off <= tolerance and off < best_off:
            best, best_off = spec.name, off
    return best
