"""Numba kernels of the capsules' camera-facing surface samples (private: use
:class:`occupose.likelihood.FreeSpaceLikelihood` and :class:`occupose.likelihood.ColorLikelihood`):
the samples of each capsule projected into a view, the free-space penalty and the colour
counts of those samples, and the offset depth images they are compared with. The
distance kernels (points, render) are in :mod:`occupose.likelihood._distance_kernels`.

Every kernel takes the particles' capsules as ``a, b`` (P, C, 3) float64 world metres (the
two ends of each round cone) with ``radii`` (C, 2) float64 (radius at a, at b) and, where
parts matter, ``capsule_part`` (C,) int64; runs in parallel over particles (over image rows
for the depth offsets); and adds its result into an output array.

No kernel here calls one of another module: numba's cache is invalidated only by a change
of the file that holds a cached function, not of the files of the functions it calls.
"""

from __future__ import annotations

import math

import numba
import numpy as np


@numba.njit(cache=True, nogil=True, parallel=True, error_model="numpy")
def offset_depths(depth, c0, c1, c2, out):
    """out = depth + c0 + c1 depth + c2 depth^2 where depth > 0, else 0 (float32, metres).

    depth : (H, W) float32, metres; c0, c1, c2 : float (the signed offset's quadratic in
    depth); out : (H, W) float32. float32 throughout, so that the loop vectorises (exact to
    about 1 micrometre at 7.5 m).
    """
    q0, q1, q2 = np.float32(c0), np.float32(1.0 + c1), np.float32(c2)
    for v in numba.prange(depth.shape[0]):
        for u in range(depth.shape[1]):
            d = depth[v, u]
            value = q0 + d * (q1 + d * q2)
            out[v, u] = value if d > 0 else np.float32(0.0)


@numba.njit(cache=True, nogil=True, inline="always", error_model="numpy")
def _camera_samples(a, b, radii, p, c, rotation, shift, along, cos_around, sin_around, samples):
    """Write the camera-facing samples of capsule ``c`` of particle ``p`` into ``samples``
    (3, 2 + T * A), camera-frame metres, x, y, z rows (rotation (3, 3), shift (3,):
    camera_from_world): first the point of each end sphere nearest the camera centre (the
    sphere's centre when the camera is inside it), then for each axis fraction ``along[j]``
    the points at the angles (cos_around, sin_around) about the axis, from the direction
    facing the camera, on the circle of radius lerp(ra, rb, t) about lerp(a, b, t) (that
    direction, square to the axis, is the same all along it). Every sample lies in the
    round cone. Only the two ends are transformed; the samples are built in the camera frame,
    where the camera centre is the origin.
    """
    ra, rb = radii[c, 0], radii[c, 1]
    ax = rotation[0, 0] * a[p, c, 0] + rotation[0, 1] * a[p, c, 1] + rotation[0, 2] * a[p, c, 2] + shift[0]
    ay = rotation[1, 0] * a[p, c, 0] + rotation[1, 1] * a[p, c, 1] + rotation[1, 2] * a[p, c, 2] + shift[1]
    az = rotation[2, 0] * a[p, c, 0] + rotation[2, 1] * a[p, c, 1] + rotation[2, 2] * a[p, c, 2] + shift[2]
    bx = rotation[0, 0] * b[p, c, 0] + rotation[0, 1] * b[p, c, 1] + rotation[0, 2] * b[p, c, 2] + shift[0]
    by = rotation[1, 0] * b[p, c, 0] + rotation[1, 1] * b[p, c, 1] + rotation[1, 2] * b[p, c, 2] + shift[1]
    bz = rotation[2, 0] * b[p, c, 0] + rotation[2, 1] * b[p, c, 1] + rotation[2, 2] * b[p, c, 2] + shift[2]
    for end in range(2):
        x, y, z, r = (ax, ay, az, ra) if end == 0 else (bx, by, bz, rb)
        norm = math.sqrt(x * x + y * y + z * z)
        scale = 1.0 - r / norm if norm > r else 1.0
        samples[0, end] = x * scale
        samples[1, end] = y * scale
        samples[2, end] = z * scale
    dx, dy, dz = bx - ax, by - ay, bz - az
    length = math.sqrt(dx * dx + dy * dy + dz * dz)
    if length > 0.0:
        inverse = 1.0 / length
        ex, ey, ez = dx * inverse, dy * inverse, dz * inverse
    else:  # the world's z axis
        ex, ey, ez = rotation[0, 2], rotation[1, 2], rotation[2, 2]
    # n: towards the camera (-o, o any point of the axis), square to the axis; m = e x n.
    ox, oy, oz = 0.5 * (ax + bx), 0.5 * (ay + by), 0.5 * (az + bz)
    dot = -(ox * ex + oy * ey + oz * ez)
    nx, ny, nz = -ox - dot * ex, -oy - dot * ey, -oz - dot * ez
    norm = math.sqrt(nx * nx + ny * ny + nz * nz)
    if norm < 1e-9:  # camera on the axis: any square direction (the world's x or y axis)
        world_x = rotation[0, 0] * ex + rotation[1, 0] * ey + rotation[2, 0] * ez
        k = 0 if abs(world_x) < 0.9 else 1
        nx, ny, nz = rotation[0, k], rotation[1, k], rotation[2, k]
        dot = nx * ex + ny * ey + nz * ez
        nx, ny, nz = nx - dot * ex, ny - dot * ey, nz - dot * ez
        norm = math.sqrt(nx * nx + ny * ny + nz * nz)
    inverse = 1.0 / norm
    nx, ny, nz = nx * inverse, ny * inverse, nz * inverse
    mx, my, mz = ey * nz - ez * ny, ez * nx - ex * nz, ex * ny - ey * nx
    s = 2
    for j in range(along.shape[0]):
        t = along[j]
        ox, oy, oz = ax + t * dx, ay + t * dy, az + t * dz
        r = ra + t * (rb - ra)
        for i in range(cos_around.shape[0]):
            co, si = r * cos_around[i], r * sin_around[i]
            samples[0, s] = ox + co * nx + si * mx
            samples[1, s] = oy + co * ny + si * my
            samples[2, s] = oz + co * nz + si * mz
            s += 1


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _sample_pixels(samples, fx, fy, cx, cy, height, width, pixel):
    """pixel[s] = v * width + u, the nearest pixel (v, u) of camera-frame sample s of
    ``samples`` (3, S), or -1 when it is behind the camera or outside the height x width
    image; pixel : (S,) int32 (branch-free, vectorised over the samples)."""
    for s in range(samples.shape[1]):
        z = samples[2, s]
        inverse = 1.0 / z
        u = np.floor(fx * samples[0, s] * inverse + cx + 0.5)
        v = np.floor(fy * samples[1, s] * inverse + cy + 0.5)
        inside = (z > 0.0) & (u >= 0.0) & (v >= 0.0) & (u < width) & (v < height)
        pixel[s] = np.int32(v * width + u) if inside else np.int32(-1)


@numba.njit(cache=True, nogil=True, parallel=True, error_model="numpy")
def free_space_penalties(a, b, radii, capsule_part, rotation, shift, fx, fy, cx, cy, free_depth,
                         along, cos_around, sin_around, ramp, out):
    """out[p, k] += sum over part k's surface samples of their free-space penalty in one view.

    rotation (3, 3), shift (3,) : camera_from_world; fx, fy, cx, cy : intrinsics (pixels);
    free_depth : (H, W) float32, metres, the depth beyond which space is seen empty
    (measured depth minus the margin; 0 where nothing was measured, which never
    penalises); along, cos_around, sin_around : the samples of :func:`_camera_samples`;
    ramp : metres. A sample in the image whose pixel's free depth f exceeds its camera
    depth zc costs min((f - zc) / ramp, 1).
    """
    height, width = free_depth.shape
    flat = free_depth.reshape(-1)
    num_samples = 2 + along.shape[0] * cos_around.shape[0]
    inverse_ramp = 1.0 / ramp
    for p in numba.prange(a.shape[0]):
        samples = np.empty((3, num_samples))
        pixel = np.empty(num_samples, np.int32)
        for c in range(a.shape[1]):
            _camera_samples(a, b, radii, p, c, rotation, shift, along, cos_around, sin_around, samples)
            _sample_pixels(samples, fx, fy, cx, cy, height, width, pixel)
            total = 0.0
            for s in range(num_samples):
                q = pixel[s]
                if q >= 0:  # branch-free below: whether a sample is penalised is unpredictable
                    total += min(max(flat[q] - samples[2, s], 0.0) * inverse_ramp, 1.0)
            out[p, capsule_part[c]] += total


@numba.njit(cache=True, nogil=True, parallel=True, error_model="numpy")
def color_counts(a, b, radii, capsule_part, rotation, shift, fx, fy, cx, cy, hidden_depth, cells,
                 along, cos_around, sin_around, counts):
    """counts[p, k, j] += how many of part k's surface samples land on a pixel of colour cell j.

    Arguments as :func:`free_space_penalties`; hidden_depth : (H, W) float32, metres, the
    depth beyond which a sample is hidden by what was measured at its pixel (0 = no
    measurement: never hidden); cells : (H, W) int64, each pixel's colour cell, -1 for
    none; counts : (P, K, B) float64. A sample counts when it is in the image, on a pixel
    with a colour cell, and not hidden (zc <= hidden depth): the pixel shows either the
    part or, where the part is misplaced, whatever lies behind it.
    """
    height, width = cells.shape
    flat_hidden = hidden_depth.reshape(-1)
    flat_cells = cells.reshape(-1)
    num_samples = 2 + along.shape[0] * cos_around.shape[0]
    for p in numba.prange(a.shape[0]):
        samples = np.empty((3, num_samples))
        pixel = np.empty(num_samples, np.int32)
        for c in range(a.shape[1]):
            _camera_samples(a, b, radii, p, c, rotation, shift, along, cos_around, sin_around, samples)
            _sample_pixels(samples, fx, fy, cx, cy, height, width, pixel)
            k = capsule_part[c]
            for s in range(num_samples):
                q = pixel[s]
                if q >= 0 and flat_cells[q] >= 0:
                    hidden = flat_hidden[q]
                    if hidden == 0.0 or samples[2, s] <= hidden:
                        counts[p, k, flat_cells[q]] += 1.0
