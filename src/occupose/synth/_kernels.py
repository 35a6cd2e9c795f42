"""Numba kernels of the synthetic renderer and the sensor noise models (private: use
:mod:`occupose.synth.render` and :mod:`occupose.synth.noise`).

The renderer's kernels work in the camera frame (OpenCV axes, the camera centre at the origin).
The ray through pixel ``(u, v)`` is ``t * (xs[u], ys[v], 1)``, so the ray parameter ``t``
of a hit *is* its depth (camera z).

Per-primitive parameters, one row of ``params`` (K, 16) float64 each:

- BOX: ``[0:3]`` ray origin in the box frame ``o = R^T (-c)``; ``[3:12]`` the 3x3
  box_from_camera rotation ``M = R^T`` (row-major); ``[12:15]`` half extents.
- ELLIPSOID: ``[0:3]`` ray origin in the unit-sphere frame ``o = S^-1 R^T (-c)``;
  ``[3:12]`` ``M = S^-1 R^T`` (camera to unit-sphere frame); the rest unused.
- ROUND_CONE: ``[0:3]`` end a, ``[3:6]`` end b, ``[6]`` radius at a, ``[7]`` radius at b;
  neither sphere may contain the other (the wrapper turns that case into a sphere).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from occupose.synth.primitives import BOX, ELLIPSOID, ROUND_CONE

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


@numba.njit(cache=True, parallel=True, error_model="numpy")
def render_rows(kinds, params, rects, albedo, person_ids, part_ids, ambient, xs, ys,
                depth, color, person, part):
    """Cast every primitive into the pixels of its screen rectangle, nearest z wins.

    kinds : (K,) int8; params : (K, 16) float64 (module docstring); rects : (K, 4) int64
    inclusive pixel bounds ``u0, u1, v0, v1`` (empty when u0 > u1); albedo : (K, 3) float64;
    person_ids : (K,) uint16; part_ids : (K,) uint8; ambient : float in [0, 1];
    xs : (W,) float64 = (u - cx) / fx; ys : (H,) float64 = (v - cy) / fy.
    depth (H, W) float32 (0 = empty), color (H, W, 3) uint8, person (H, W) uint16,
    part (H, W) uint8 are updated in place; a hit replaces a pixel only when its float32
    depth is strictly smaller, so equal depths keep the earlier primitive.
    Shading: albedo * (ambient + (1 - ambient) * |cos|), cos between normal and ray.
    """
    height, width = depth.shape
    for v in numba.prange(height):
        y = ys[v]
        winner = np.full(width, -1, np.int32)
        z_winner = np.empty(width)
        u_min, u_max = width, -1
        # Depth pass: the nearest primitive of each pixel.
        for k in range(kinds.shape[0]):
            if v < rects[k, 2] or v > rects[k, 3]:
                continue
            kind = kinds[k]
            u_min = min(u_min, rects[k, 0])
            u_max = max(u_max, rects[k, 1])
            for u in range(rects[k, 0], rects[k, 1] + 1):
                z = _depth(kind, params, k, xs[u], y)
                if z <= 0.0:
                    continue
                z32 = np.float32(z)
                current = depth[v, u]
                if current == 0.0 or z32 < current:
                    depth[v, u] = z32
                    winner[u] = k
                    z_winner[u] = z
        # Shading pass: once per pixel that one of these primitives won.
        for u in range(u_min, u_max + 1):
            k = winner[u]
            if k < 0:
                continue
            x = xs[u]
            nx, ny, nz = _normal(kinds[k], params, k, x, y, z_winner[u])
            norm = math.sqrt((nx * nx + ny * ny + nz * nz) * (x * x + y * y + 1.0))
            cos = abs(nx * x + ny * y + nz) / norm if norm > 0.0 else 1.0
            shade = ambient + (1.0 - ambient) * cos
            for c in range(3):
                value = albedo[k, c] * shade + 0.5
                color[v, u, c] = 255 if value >= 255.0 else np.uint8(value)
            person[v, u] = person_ids[k]
            part[v, u] = part_ids[k]


# --- sensor noise ------------------------------------------------------------------------
# Random numbers come from the Generator passed in, drawn in a fixed documented order, so
# a NumPy reference with an identically seeded Generator draws the same values.

@numba.njit(cache=True, error_model="numpy")
def structured_light_pixels(depth, rng, fx_baseline, shadows, min_range, max_range,
                            std_coeffs, offset, step, out):
    """Structured-light depth of every pixel, written into ``out`` (H, W) float32.

    depth : (H, W) float64, metres, 0 = none; rng : np.random.Generator;
    fx_baseline : fx * baseline (pixel metres; its sign is the projector's side);
    shadows : bool; min_range, max_range : metres; std_coeffs : (3,) float64, the wanted
    depth std c0 + c1 z + c2 z^2 (metres); offset, step : 1 / z = offset - step * raw.

    A pixel is measured when z > 0, min_range <= z <= max_range and (with ``shadows``) its
    projector coordinate u - fx_baseline / z keeps the camera's order along the row (for a
    projector at +x: no pixel to its right has a smaller one). Each measured pixel, in
    row-major order, draws one ``rng.standard_normal()`` n; its raw disparity
    (offset - 1/z) / step gets g * n with g = sqrt(max(s^2 - 1/12, 0)), s the wanted std in
    raw units (std / (step z^2)), and is rounded (floor(x + 0.5)); depth is 1 / (offset -
    step * raw), or 0 where that is not positive.
    """
    height, width = depth.shape
    lit = np.empty(width, np.bool_)
    for v in range(height):
        # Projector shadows: scan away from the projector, tracking the extreme coordinate.
        extreme = np.inf if fx_baseline >= 0 else -np.inf
        for i in range(width):
            u = width - 1 - i if fx_baseline >= 0 else i
            z = depth[v, u]
            lit[u] = z > 0.0
            if not lit[u]:
                continue
            projector_u = u - fx_baseline / z
            if fx_baseline >= 0:
                lit[u] = not (shadows and projector_u > extreme)
                extreme = min(extreme, projector_u)
            else:
                lit[u] = not (shadows and projector_u < extreme)
                extreme = max(extreme, projector_u)
        for u in range(width):
            z = depth[v, u]
            out[v, u] = 0.0
            if not lit[u] or z < min_range or z > max_range:
                continue
            noise = rng.standard_normal()
            std_raw = (std_coeffs[0] + std_coeffs[1] * z + std_coeffs[2] * z * z) / (step * z * z)
            gaussian = math.sqrt(max(std_raw * std_raw - 1.0 / 12.0, 0.0))
            raw = math.floor((offset - 1.0 / z) / step + gaussian * noise + 0.5)
            inverse = offset - step * raw
            if inverse > 0.0:
                out[v, u] = 1.0 / inverse


@numba.njit(cache=True, error_model="numpy")
def tof_pixels(depth, rng, flying_fraction, edge_jump, min_range, max_range, std_coeffs, out):
    """Time-of-flight depth of every pixel, written into ``out`` (H, W) float32.

    depth : (H, W) float64, metres, 0 = none; rng : np.random.Generator; flying_fraction
    in [0, 1]; edge_jump, min_range, max_range : metres; std_coeffs : (3,) float64, the
    depth std c0 + c1 z + c2 z^2 (metres).

    Pass 1, row-major: a pixel with z > 0 whose measured 4-neighbours (up, down, left,
    right; the first of equal jumps wins) differ from it by more than ``edge_jump`` draws
    two ``rng.random()`` values a, b; when a < flying_fraction its depth moves b of the way
    to the most different neighbour. Pass 2, row-major: each pixel with min_range <= z <=
    max_range (true depth) draws one ``rng.standard_normal()`` n and reads
    mixed + std(mixed) * n, or 0 where that is not positive. Other pixels read 0.
    """
    height, width = depth.shape
    mixed = np.empty((height, width))
    for v in range(height):
        for u in range(width):
            z = depth[v, u]
            mixed[v, u] = z
            if z <= 0.0:
                continue
            jump = 0.0
            other = z
            for dv, du in ((-1, 0), (1, 0), (0, -1), (0, 1)):
                vv, uu = v + dv, u + du
                if vv < 0 or vv >= height or uu < 0 or uu >= width:
                    continue
                n = depth[vv, uu]
                if n > 0.0 and abs(n - z) > jump:
                    jump = abs(n - z)
                    other = n
            if jump > edge_jump:
                a = rng.random()
                b = rng.random()
                if a < flying_fraction:
                    mixed[v, u] = z + b * (other - z)
    for v in range(height):
        for u in range(width):
            z = depth[v, u]
            out[v, u] = 0.0
            if z <= 0.0 or z < min_range or z > max_range:
                continue
            m = mixed[v, u]
            value = m + (std_coeffs[0] + std_coeffs[1] * m + std_coeffs[2] * m * m) * rng.standard_normal()
            if value > 0.0:
                out[v, u] = value
