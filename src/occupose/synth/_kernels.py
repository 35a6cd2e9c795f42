"""Numba kernels of the synthetic renderer and the sensor noise models (private: use
:mod:`occupose.synth.render` and :mod:`occupose.synth.noise`).

The renderer casts rays in the camera frame with :mod:`occupose.geometry._raycast` (its
docstring gives the ray and the per-primitive parameter layout).
"""

from __future__ import annotations

import math

import numba
import numpy as np

from occupose.geometry._raycast import _depth, _normal

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
