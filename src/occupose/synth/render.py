"""Ray-cast depth, colour, person and body-part images of solid primitives.

Every pixel casts one ray through its centre (pixel ``(u, v)`` is column ``u``, row ``v``,
centres at integer coordinates) and takes the nearest exact analytic hit among the
boxes, ellipsoids and round cones of a :class:`~occupose.geometry.primitives.Primitives`
batch. Depth is the camera z of the hit (not the ray length); colour is the albedo
shaded by a headlight (Lambert term of a light at the camera plus ambient).

Speed: each primitive is cast only into the pixels of its screen bounding rectangle.
For video, render the static scene (room, furniture) once and pass it as
``background=`` so that each frame only casts the moving primitives over a copy of it;
this gives the same images as rendering everything at once with the static primitives
first.

Surfaces are seen from outside; a camera inside a box or an ellipsoid sees its inner
surface (a room can be one box), a camera inside a round cone is not supported.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from occupose.synth import _kernels
from occupose.geometry.primitives import BOX, ELLIPSOID, ROUND_CONE, Primitives

#: Share of the albedo a surface shows when lit at grazing incidence (the rest is the
#: headlight's Lambert term).
AMBIENT = 0.35

_PARAMS = 16
_AXES_TOL = 1e-6
_CLIP_Z = 1e-6  # metres: bounding rectangles are built from the part of a primitive beyond this z
_SIGNS = np.array([[sx, sy, sz] for sx in (-1.0, 1.0) for sy in (-1.0, 1.0) for sz in (-1.0, 1.0)])
_EDGES = np.array([(i, i | bit) for bit in (1, 2, 4) for i in range(8) if not i & bit])


@dataclass(frozen=True)
class Rendered:
    """One rendered view.

    depth : (H, W) float32, metres, camera z of the nearest surface; 0 where nothing was hit
    color : (H, W, 3) uint8, shaded RGB; 0 where nothing was hit
    person : (H, W) uint16, the hit primitive's person id (0 = scene or nothing)
    part : (H, W) uint8, the hit primitive's body-part label (:data:`occupose.joints.PARTS`; 0 = none)
    """

    depth: np.ndarray
    color: np.ndarray
    person: np.ndarray
    part: np.ndarray


def render(prims: Primitives, width: int, height: int, fx: float, fy: float, cx: float, cy: float,
           world_from_camera, *, background: Rendered | None = None) -> Rendered:
    """Ray-cast ``prims`` into a ``width`` x ``height`` pinhole view.

    Parameters
    ----------
    prims : Primitives, K solids in world metres (see :mod:`occupose.geometry.primitives`)
    width, height : int, image size in pixels
    fx, fy, cx, cy : float, pinhole intrinsics in pixels
    world_from_camera : (4, 4) float, rigid transform from the camera frame (OpenCV axes) to the world
    background : Rendered or None; when given (a render of other primitives from the same
        view), ``prims`` are drawn over a copy of it with depth testing

    Returns
    -------
    Rendered (new arrays; ``background`` is not modified)
    """
    width, height = _positive_int(width, "width"), _positive_int(height, "height")
    fx, fy = _finite(fx, "fx", positive=True), _finite(fy, "fy", positive=True)
    cx, cy = _finite(cx, "cx"), _finite(cy, "cy")
    camera_from_world = _camera_from_world(world_from_camera)
    _check_primitives(prims)

    if background is None:
        depth = np.zeros((height, width), np.float32)
        color = np.zeros((height, width, 3), np.uint8)
        person = np.zeros((height, width), np.uint16)
        part = np.zeros((height, width), np.uint8)
    else:
        depth, color, person, part = _copy_background(background, width, height)

    if len(prims):
        kinds, params, boxes = _camera_frame_params(prims, camera_from_world)
        rects = _screen_rects(boxes, width, height, fx, fy, cx, cy)
        xs = (np.arange(width) - cx) / fx
        ys = (np.arange(height) - cy) / fy
        _kernels.render_rows(
            kinds, params, rects, prims.color.astype(np.float64),
            prims.person.astype(np.uint16), prims.part.astype(np.uint8), AMBIENT, xs, ys,
            depth, color, person, part,
        )
    return Rendered(depth, color, person, part)


def render_camera(prims: Primitives, camera, background: Rendered | None = None) -> Rendered:
    """:func:`render` with the intrinsics and pose read from ``camera``.

    ``camera`` is any object with attributes width, height, fx, fy, cx, cy and
    world_from_camera (for example :class:`occupose.camera.Camera`).
    """
    try:
        args = [getattr(camera, key) for key in ("width", "height", "fx", "fy", "cx", "cy", "world_from_camera")]
    except AttributeError as error:
        raise ValueError(
            "camera must have attributes width, height, fx, fy, cx, cy and world_from_camera "
            f"({error})"
        ) from None
    return render(prims, *args, background=background)


# --- input checks -------------------------------------------------------------------------

def _positive_int(value, what: str) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value <= 0:
        raise ValueError(f"{what} must be a positive integer, got {value!r}")
    return int(value)


def _finite(value, what: str, *, positive: bool = False) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{what} must be a number, got {value!r}") from None
    if not np.isfinite(number) or (positive and number <= 0.0):
        raise ValueError(f"{what} must be a {'positive ' if positive else ''}finite number, got {value!r}")
    return number


def _camera_from_world(world_from_camera) -> np.ndarray:
    pose = np.asarray(world_from_camera, dtype=np.float64)
    if pose.shape != (4, 4) or not np.all(np.isfinite(pose)):
        raise ValueError(f"world_from_camera must be a finite (4, 4) matrix, got shape {pose.shape}")
    rotation = pose[:3, :3]
    if (np.max(np.abs(rotation.T @ rotation - np.eye(3))) > _AXES_TOL
            or np.max(np.abs(pose[3] - (0.0, 0.0, 0.0, 1.0))) > _AXES_TOL):
        raise ValueError("world_from_camera must be a rigid transform (orthonormal rotation, last row 0 0 0 1)")
    inverse = np.eye(4)
    inverse[:3, :3] = rotation.T
    inverse[:3, 3] = -rotation.T @ pose[:3, 3]
    return inverse


def _check_primitives(prims: Primitives) -> None:
    shapes = {"kind": (), "center": (3,), "axes": (3, 3), "size": (3,), "end": (3,),
              "person": (), "part": (), "color": (3,)}
    try:
        k = len(prims.kind)
        arrays = {name: np.asarray(getattr(prims, name)) for name in shapes}
    except (AttributeError, TypeError):
        raise ValueError(f"prims must be a Primitives batch, got {type(prims).__name__}") from None
    for name, tail in shapes.items():
        if arrays[name].shape != (k, *tail):
            raise ValueError(f"prims.{name} must have shape {(k, *tail)}, got {arrays[name].shape}")
    for name in ("center", "axes", "size", "end"):
        if not np.all(np.isfinite(arrays[name])):
            raise ValueError(f"prims.{name} must be finite")
    kind = arrays["kind"]
    if not np.all(np.isin(kind, (BOX, ELLIPSOID, ROUND_CONE))):
        raise ValueError(f"prims.kind must be BOX ({BOX}), ELLIPSOID ({ELLIPSOID}) or ROUND_CONE "
                         f"({ROUND_CONE}), got {sorted(set(kind.tolist()))}")
    solid = kind != ROUND_CONE
    size = arrays["size"]
    if np.any(size[solid] <= 0.0) or np.any(size[~solid][:, :2] <= 0.0):
        raise ValueError("prims.size must be > 0 (half extents, semi-axes, or the two radii of a round cone)")
    axes = arrays["axes"][solid]
    if len(axes) and np.max(np.abs(np.einsum("kji,kjl->kil", axes, axes) - np.eye(3))) > _AXES_TOL:
        raise ValueError("prims.axes of boxes and ellipsoids must be orthonormal (rotation matrices)")
    if np.any(arrays["person"] < 0) or np.any(arrays["person"] > np.iinfo(np.uint16).max):
        raise ValueError("prims.person must be in 0..65535")
    if np.any(arrays["part"] < 0) or np.any(arrays["part"] > np.iinfo(np.uint8).max):
        raise ValueError("prims.part must be in 0..255")


def _copy_background(background: Rendered, width: int, height: int):
    expected = {"depth": ((height, width), np.float32), "color": ((height, width, 3), np.uint8),
                "person": ((height, width), np.uint16), "part": ((height, width), np.uint8)}
    copies = []
    for name, (shape, dtype) in expected.items():
        array = getattr(background, name, None)
        if not isinstance(array, np.ndarray) or array.shape != shape or array.dtype != dtype:
            got = "missing" if not isinstance(array, np.ndarray) else f"{array.shape} {array.dtype}"
            raise ValueError(f"background.{name} must be a {shape} {np.dtype(dtype)} array "
                             f"(a Rendered of the same view), got {got}")
        copies.append(np.array(array, order="C"))
    return copies


# --- primitives in the camera frame -----------------------------------------------------

def _camera_frame_params(prims: Primitives, camera_from_world: np.ndarray):
    """Kernel parameters and oriented bounding boxes, in the camera frame.

    Returns kinds (K,) int8, params (K, 16) float64 (layout in ``_kernels``), and bounding
    boxes as (centres (K, 3), axes (K, 3, 3) camera_from_local, half extents (K, 3)).
    """
    rotation, shift = camera_from_world[:3, :3], camera_from_world[:3, 3]
    kinds = np.array(prims.kind, dtype=np.int8)
    centers = prims.center @ rotation.T + shift
    axes = np.einsum("ij,kjl->kil", rotation, prims.axes)
    half = np.array(prims.size, dtype=np.float64)
    params = np.zeros((len(kinds), _PARAMS))

    solid = kinds != ROUND_CONE
    local_from_camera = np.transpose(axes, (0, 2, 1)).copy()
    ell = kinds == ELLIPSOID
    local_from_camera[ell] /= half[ell][:, :, None]  # unit-sphere frame
    params[solid, 0:3] = -np.einsum("kij,kj->ki", local_from_camera[solid], centers[solid])
    params[solid, 3:12] = local_from_camera[solid].reshape(-1, 9)
    params[solid, 12:15] = half[solid]

    cone = ~solid
    if np.any(cone):
        a, b = centers[cone], prims.end[cone] @ rotation.T + shift
        ra, rb = half[cone, 0], half[cone, 1]
        params[cone, 0:3], params[cone, 3:6], params[cone, 6], params[cone, 7] = a, b, ra, rb
        lo = np.minimum(a - ra[:, None], b - rb[:, None])
        hi = np.maximum(a + ra[:, None], b + rb[:, None])
        centers[cone], axes[cone], half[cone] = (lo + hi) / 2, np.eye(3), (hi - lo) / 2
        # A round cone whose larger end sphere holds the other one is that sphere.
        sphere = np.linalg.norm(b - a, axis=1) <= np.abs(ra - rb)
        if np.any(sphere):
            index = np.flatnonzero(cone)[sphere]
            big_at_a = (ra >= rb)[sphere]
            c = np.where(big_at_a[:, None], a[sphere], b[sphere])
            r = np.maximum(ra, rb)[sphere]
            kinds[index] = ELLIPSOID
            params[index] = 0.0
            params[index, 0:3] = -c / r[:, None]
            params[index, 3:12] = (np.eye(3)[None] / r[:, None, None]).reshape(-1, 9)
    return kinds, params, (centers, axes, half)


def _screen_rects(boxes, width: int, height: int, fx: float, fy: float, cx: float, cy: float) -> np.ndarray:
    """Inclusive pixel rectangles (K, 4) int64 ``u0, u1, v0, v1`` holding each box's image.

    The box is clipped to z >= _CLIP_Z (its corners in front plus the points where its
    edges cross that plane) and those points are projected; u0 > u1 means off-screen.
    """
    centers, axes, half = boxes
    corners = centers[:, None, :] + np.einsum("knj,kij->kni", _SIGNS[None] * half[:, None, :], axes)
    p0, p1 = corners[:, _EDGES[:, 0]], corners[:, _EDGES[:, 1]]
    z0, z1 = p0[..., 2], p1[..., 2]
    crossing = (z0 - _CLIP_Z) * (z1 - _CLIP_Z) < 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        s = np.where(crossing, (_CLIP_Z - z0) / (z1 - z0), 0.0)
    points = np.concatenate([corners, p0 + s[..., None] * (p1 - p0)], axis=1)
    valid = np.concatenate([corners[..., 2] >= _CLIP_Z, crossing], axis=1)
    z = np.where(valid, points[..., 2], 1.0)
    u = fx * points[..., 0] / z + cx
    v = fy * points[..., 1] / z + cy
    rects = np.empty((len(centers), 4), np.int64)
    for column, (coord, size) in enumerate(((u, width), (v, height))):
        lo = np.floor(np.where(valid, coord, np.inf).min(axis=1))
        hi = np.ceil(np.where(valid, coord, -np.inf).max(axis=1))
        rects[:, 2 * column] = np.clip(lo, -1, size)
        rects[:, 2 * column + 1] = np.clip(hi, -1, size)
    rects[:, [0, 2]] = np.maximum(rects[:, [0, 2]], 0)
    rects[:, 1] = np.minimum(rects[:, 1], width - 1)
    rects[:, 3] = np.minimum(rects[:, 3], height - 1)
    return rects
