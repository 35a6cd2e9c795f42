"""Ray casting of solid primitives: the first hit of a camera ray on a box, an ellipsoid or
a round cone (private numba kernels, shared by the synthetic renderer and the rendered
likelihood).

Rays are in the camera frame (OpenCV axes, the camera centre at the origin): the ray through
pixel ``(u, v)`` is ``t * (x, y, 1)`` with ``x = (u - cx) / fx`` and ``y = (v - cy) / fy``, so
the ray parameter ``t`` of a hit *is* its depth (camera z).

Per-primitive parameters, one row of ``params`` (K, 16) float64 each:

- BOX: ``[0:3]`` ray origin in the box frame ``o = R^T (-c)``; ``[3:12]`` the 3x3
  box_from_camera rotation ``M = R^T`` (row-major); ``[12:15]`` half extents.
- ELLIPSOID: ``[0:3]`` ray origin in the unit-sphere frame ``o = S^-1 R^T (-c)``;
  ``[3:12]`` ``M = S^-1 R^T`` (camera to unit-sphere frame); the rest unused.
- ROUND_CONE: ``[0:3]`` end a, ``[3:6]`` end b, ``[6]`` radius at a, ``[7]`` radius at b;
  neither sphere may contain the other (callers turn that case into a sphere).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from occupose.geometry.primitives import BOX, ELLIPSOID, ROUND_CONE

_MISS = -1.0


@numba.njit(cache=True, inline="always", error_model="numpy")
def _depth_box(params, k, x, y):
    """Camera z of the ray's first hit on box ``k`` (slab test in the box frame); -1 on a miss.

    A camera inside the box sees the inside of the face the ray leaves through (so a room
    can be one box).
    """
    t_enter = -np.inf
    t_exit = np.inf
    for i in range(3):
        o = params[k, i]
        d = params[k, 3 + 3 * i] * x + params[k, 4 + 3 * i] * y + params[k, 5 + 3 * i]
        h = params[k, 12 + i]
        if d == 0.0:
            if o < -h or o > h:
                return _MISS
            continue
        inv = 1.0 / d
        t1 = (-h - o) * inv
        t2 = (h - o) * inv
        t_enter = max(t_enter, min(t1, t2))
        t_exit = min(t_exit, max(t1, t2))
    if t_enter > t_exit or t_exit <= 0.0:
        return _MISS
    return t_enter if t_enter > 0.0 else t_exit


@numba.njit(cache=True, inline="always", error_model="numpy")
def _normal_box(params, k, x, y, z):
    """Camera-frame normal (not unit, sign free) of box ``k`` at its hit ``z * (x, y, 1)``."""
    best = -1.0
    axis = 0
    for i in range(3):
        q = params[k, i] + z * (params[k, 3 + 3 * i] * x + params[k, 4 + 3 * i] * y + params[k, 5 + 3 * i])
        r = abs(q) / params[k, 12 + i]
        if r > best:
            best = r
            axis = i
    # The box's local axis in the camera frame is row `axis` of M = R^T.
    return params[k, 3 + 3 * axis], params[k, 4 + 3 * axis], params[k, 5 + 3 * axis]


@numba.njit(cache=True, inline="always", error_model="numpy")
def _depth_ellipsoid(params, k, x, y):
    """As :func:`_depth_box` for ellipsoid ``k``, mapped to the unit sphere by ``M``."""
    ox, oy, oz = params[k, 0], params[k, 1], params[k, 2]
    dx = params[k, 3] * x + params[k, 4] * y + params[k, 5]
    dy = params[k, 6] * x + params[k, 7] * y + params[k, 8]
    dz = params[k, 9] * x + params[k, 10] * y + params[k, 11]
    a = dx * dx + dy * dy + dz * dz
    b = ox * dx + oy * dy + oz * dz
    c = ox * ox + oy * oy + oz * oz - 1.0
    disc = b * b - a * c
    if disc < 0.0:
        return _MISS
    root = math.sqrt(disc)
    t = (-b - root) / a
    if t > 0.0:
        return t
    t = (-b + root) / a
    return t if t > 0.0 else _MISS


@numba.njit(cache=True, inline="always", error_model="numpy")
def _normal_ellipsoid(params, k, x, y, z):
    """As :func:`_normal_box`: the gradient M^T q of |q|^2, q the unit-sphere point."""
    qx = params[k, 0] + z * (params[k, 3] * x + params[k, 4] * y + params[k, 5])
    qy = params[k, 1] + z * (params[k, 6] * x + params[k, 7] * y + params[k, 8])
    qz = params[k, 2] + z * (params[k, 9] * x + params[k, 10] * y + params[k, 11])
    return (params[k, 3] * qx + params[k, 6] * qy + params[k, 9] * qz,
            params[k, 4] * qx + params[k, 7] * qy + params[k, 10] * qz,
            params[k, 5] * qx + params[k, 8] * qy + params[k, 11] * qz)


@numba.njit(cache=True, inline="always", error_model="numpy")
def _depth_round_cone(params, k, x, y):
    """As :func:`_depth_box` for round cone ``k`` (analytic, after Inigo Quilez's rounded
    cone intersection). The camera must be outside the round cone.
    """
    inv_len = 1.0 / math.sqrt(x * x + y * y + 1.0)
    rx, ry, rz = x * inv_len, y * inv_len, inv_len  # unit ray direction
    ax, ay, az = params[k, 0], params[k, 1], params[k, 2]
    bx, by, bz = params[k, 3], params[k, 4], params[k, 5]
    ra, rb = params[k, 6], params[k, 7]
    bax, bay, baz = bx - ax, by - ay, bz - az
    rr = ra - rb
    m0 = bax * bax + bay * bay + baz * baz
    m1 = -(bax * ax + bay * ay + baz * az)   # ba . (origin - a)
    m2 = bax * rx + bay * ry + baz * rz
    m3 = -(rx * ax + ry * ay + rz * az)      # rd . (origin - a)
    m5 = ax * ax + ay * ay + az * az
    m6 = -(rx * bx + ry * by + rz * bz)      # rd . (origin - b)
    m7 = bx * bx + by * by + bz * bz
    d2 = m0 - rr * rr
    k2 = d2 - m2 * m2
    k1 = d2 * m3 - m1 * m2 + m2 * rr * ra
    k0 = d2 * m5 - m1 * m1 + 2.0 * m1 * rr * ra - m0 * ra * ra
    h = k1 * k1 - k0 * k2
    if h < 0.0:
        return _MISS
    t = (-math.sqrt(h) - k1) / k2
    w = m1 - ra * rr + t * m2
    if 0.0 < w < d2:
        # The lateral surface between the two tangent circles.
        return t * inv_len if t > 0.0 else _MISS
    # One of the two end spheres.
    t = np.inf
    h1 = m3 * m3 - m5 + ra * ra
    h2 = m6 * m6 - m7 + rb * rb
    if h1 > 0.0:
        t = -m3 - math.sqrt(h1)
    if h2 > 0.0:
        t = min(t, -m6 - math.sqrt(h2))
    if t <= 0.0 or t == np.inf:
        return _MISS
    return t * inv_len


@numba.njit(cache=True, inline="always", error_model="numpy")
def _normal_round_cone(params, k, x, y, z):
    """As :func:`_normal_box`: from the axis point whose sphere touches the hit point."""
    px, py, pz = z * x - params[k, 0], z * y - params[k, 1], z - params[k, 2]  # hit - a
    bax, bay, baz = params[k, 3] - params[k, 0], params[k, 4] - params[k, 1], params[k, 5] - params[k, 2]
    rr = params[k, 6] - params[k, 7]
    d2 = bax * bax + bay * bay + baz * baz - rr * rr
    w = bax * px + bay * py + baz * pz - params[k, 6] * rr
    if w <= 0.0:
        return px, py, pz
    if w >= d2:
        return px - bax, py - bay, pz - baz
    return d2 * px - bax * w, d2 * py - bay * w, d2 * pz - baz * w


@numba.njit(cache=True, inline="always", error_model="numpy")
def _depth(kind, params, k, x, y):
    """Camera z of the first hit of the ray ``(x, y, 1)`` on primitive ``k``; -1 on a miss."""
    if kind == BOX:
        return _depth_box(params, k, x, y)
    if kind == ELLIPSOID:
        return _depth_ellipsoid(params, k, x, y)
    if kind == ROUND_CONE:
        return _depth_round_cone(params, k, x, y)
    return _MISS


@numba.njit(cache=True, inline="always", error_model="numpy")
def _normal(kind, params, k, x, y, z):
    """Camera-frame surface normal (not unit, sign free) of primitive ``k`` at depth ``z``."""
    if kind == BOX:
        return _normal_box(params, k, x, y, z)
    if kind == ELLIPSOID:
        return _normal_ellipsoid(params, k, x, y, z)
    return _normal_round_cone(params, k, x, y, z)
