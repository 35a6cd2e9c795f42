"""Numba kernel of the floor search (private: use :func:`occupose.geometry.floor.fit_floor`):
how many points lie on each RANSAC plane hypothesis."""

from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True, nogil=True, parallel=True, error_model="numpy")
def plane_inliers(x, y, z, tolerance, normals, offsets, counts):
    """counts[h] = how many points i have |normals[h] . p_i + offsets[h]| < tolerance[i].

    x, y, z : (N,) float64, metres, the points' coordinates; tolerance : (N,) float64, metres;
    normals : (H, 3) float64 unit vectors; offsets : (H,) float64, metres; counts : (H,) int64
    out. Parallel over the hypotheses, the point loop branch-free (vectorised); it reads
    4 N numbers per hypothesis where the matrix of every point's distance to every plane
    would write and read 8 N H bytes several times.
    """
    for h in numba.prange(normals.shape[0]):
        nx, ny, nz, offset = normals[h, 0], normals[h, 1], normals[h, 2], offsets[h]
        count = 0
        for i in range(x.shape[0]):
            count += abs(x[i] * nx + y[i] * ny + z[i] * nz + offset) < tolerance[i]
        counts[h] = count
