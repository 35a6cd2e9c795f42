"""Numba kernel of the occupancy grid (private: use :class:`occupose.grid.occupancy.OccupancyGrid`).

One fused kernel does a whole frame: for every cell (in parallel over x slices, without
the GIL) it projects the cell centre into each camera, reads the depth pixel, evaluates
the observation function, runs one forward step of the cell's three-state HMM, and
writes the MAP state and the cell's visibility.

Conventions shared with the wrapper:

- cells are flat in C order: ``n = (i * ny + j) * nz + k``;
- state index 0 = O (static occupied), 1 = M (moving), 2 = E (empty);
- visibility 0 = unobserved, 1 = visible, 2 = hidden;
- camera ``c``: ``rotations[c]`` (3, 3) and ``translations[c]`` (3,) take world points to the
  camera frame (``p_cam = R p_world + t``); ``intrinsics[c] = (fx, fy, cx, cy)``;
  ``sizes[c] = (width, height)``; its depth image (metres, float32, row-major) starts at
  ``offsets[c]`` in ``depth``; ``sigma_lut[c, m]`` is its depth noise (one standard deviation,
  metres) at depth ``m * lut_step``; ``half_extents[c]`` is half a cell's extent along its
  optical axis (metres).
"""

from __future__ import annotations

import math

import numba
import numpy as np

UNOBSERVED = 0
VISIBLE = 1
HIDDEN = 2


@numba.njit(cache=True, nogil=True, parallel=True, error_model="numpy")
def update_grid(origin, cell, nx, ny, nz, rotations, translations, intrinsics, sizes, offsets, depth,
                sigma_lut, lut_step, half_extents, n_sigmas, p_occ, p_free, transition, flush,
                probabilities, states, visibility):
    """One frame of the grid, in place.

    origin : (3,) float64 metres; cell : float metres; nx, ny, nz : int cell counts
    rotations (C, 3, 3), translations (C, 3), intrinsics (C, 4) float64; sizes (C, 2),
    offsets (C,) int64; depth (sum H*W,) float32 metres (<= 0 or not finite: no measurement)
    sigma_lut (C, L) float64 metres; lut_step float metres; half_extents (C,) float64 metres
    n_sigmas, p_occ, p_free : floats of the observation function
    transition : (3, 3) float64, row = previous state, column = next state
    flush : float, posterior probabilities below it are set to 0 (no subnormal floats)
    probabilities : (N, 3) float32 in/out; states, visibility : (N,) uint8 out
    """
    num_cameras = rotations.shape[0]
    lut_last = sigma_lut.shape[1] - 1
    for i in numba.prange(nx):
        x = origin[0] + cell * (i + 0.5)
        for j in range(ny):
            y = origin[1] + cell * (j + 0.5)
            for k in range(nz):
                z = origin[2] + cell * (k + 0.5)
                n = (i * ny + j) * nz + k
                b_occupied = 1.0
                b_empty = 1.0
                covered = False
                seen = False
                for c in range(num_cameras):
                    depth_l = rotations[c, 2, 0] * x + rotations[c, 2, 1] * y + rotations[c, 2, 2] * z + translations[c, 2]
                    if depth_l <= 0.0:
                        continue
                    xc = rotations[c, 0, 0] * x + rotations[c, 0, 1] * y + rotations[c, 0, 2] * z + translations[c, 0]
                    yc = rotations[c, 1, 0] * x + rotations[c, 1, 1] * y + rotations[c, 1, 2] * z + translations[c, 1]
                    u = math.floor(intrinsics[c, 0] * xc / depth_l + intrinsics[c, 2] + 0.5)
                    v = math.floor(intrinsics[c, 1] * yc / depth_l + intrinsics[c, 3] + 0.5)
                    if u < 0 or u >= sizes[c, 0] or v < 0 or v >= sizes[c, 1]:
                        continue
                    d = depth[offsets[c] + int(v) * sizes[c, 0] + int(u)]
                    if not (d > 0.0 and d < np.inf):
                        continue
                    covered = True
                    m = int(depth_l / lut_step)
                    band = n_sigmas * sigma_lut[c, min(m, lut_last)] + half_extents[c]
                    epsilon = d - depth_l
                    if epsilon > band:
                        f = p_free
                        seen = True
                    elif epsilon >= -band:
                        f = p_occ
                        seen = True
                    else:
                        f = 0.5
                    b_occupied *= f
                    b_empty *= 1.0 - f
                # forward step: Q_t ~ (Q_{t-1}^T A) o B_t
                q_o = probabilities[n, 0]
                q_m = probabilities[n, 1]
                q_e = probabilities[n, 2]
                r_o = (q_o * transition[0, 0] + q_m * transition[1, 0] + q_e * transition[2, 0]) * b_occupied
                r_m = (q_o * transition[0, 1] + q_m * transition[1, 1] + q_e * transition[2, 1]) * b_occupied
                r_e = (q_o * transition[0, 2] + q_m * transition[1, 2] + q_e * transition[2, 2]) * b_empty
                total = r_o + r_m + r_e
                r_o /= total
                r_m /= total
                r_e /= total
                if r_o < flush:
                    r_o = 0.0
                if r_m < flush:
                    r_m = 0.0
                if r_e < flush:
                    r_e = 0.0
                probabilities[n, 0] = r_o
                probabilities[n, 1] = r_m
                probabilities[n, 2] = r_e
                if r_o >= r_m and r_o >= r_e:
                    states[n] = 0
                elif r_m >= r_e:
                    states[n] = 1
                else:
                    states[n] = 2
                if seen:
                    visibility[n] = VISIBLE
                elif covered:
                    visibility[n] = HIDDEN
                else:
                    visibility[n] = UNOBSERVED
