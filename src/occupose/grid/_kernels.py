"""Numba kernels of the occupancy grid (private: use :class:`occupose.grid.occupancy.OccupancyGrid`).

The cameras do not move, so where a cell centre falls in each image is found once, when
the grid is made (:func:`pixels_from_cells`: each cell's pixel and its depth along the
optical axis, per camera). Then one fused kernel does a whole frame (:func:`update_grid`):
for every cell (in parallel over x slices, without the GIL) it reads the depth pixel of
the cell centre in each camera, evaluates the observation function, runs one forward step
of the cell's three-state HMM, and writes the MAP state and the cell's visibility.

Conventions shared with the wrapper:

- cells are flat in C order: ``n = (i * ny + j) * nz + k``;
- state index 0 = O (static occupied), 1 = M (moving), 2 = E (empty);
- visibility 0 = unobserved, 1 = visible, 2 = hidden;
- camera ``c``: ``rotations[c]`` (3, 3) and ``translations[c]`` (3,) take world points to the
  camera frame (``p_cam = R p_world + t``); ``intrinsics[c] = (fx, fy, cx, cy)``;
  ``sizes[c] = (width, height)``; its depth image (metres, float32, row-major) starts at
  ``offsets[c]`` in ``depth``, pixel ``(u, v)`` at ``offsets[c] + v * width + u``;
  ``sigma_lut[c, m]`` is its depth noise (one standard deviation, metres) at depth
  ``m * lut_step``; ``half_extents[c]`` is half a cell's extent along its optical axis
  (metres);
- ``hold`` is an (N,) bool array over the flat cells, or an empty array for none: a held
  cell takes its forward step with ``held`` instead of ``transition``, and when its MAP
  state before the step is M, its O share first moves to M (the tracker's hold on the
  cells of the people it follows, see ``OccupancyGrid.update``). A per-cell mask
  costs one byte load per cell in the parallel loop; a list of indices would need a
  scatter into such a mask first;
- a cell whose MAP state is O and that no camera sees (hidden or unobserved from all)
  steps with ``alpha = 0`` (the O row ``(1, 0, 0)``): a static object is not removed
  while nobody can see it.
"""

from __future__ import annotations

import math

import numba
import numpy as np

UNOBSERVED = 0
VISIBLE = 1
HIDDEN = 2
#: The observation function's Gaussian tails stop at this many tail widths.
TAIL_CUT = 3.0
#: Classes of one camera's observation of a cell: no measurement, the three values the
#: observation function takes exactly (p_free, p_occ, 0.5), no return within range (the
#: cell is in front of a pixel that measured nothing, nearer than the camera's far range),
#: and the observation function's tails.
UNCOVERED, SEEN_THROUGH, ON_SURFACE, BEHIND, NO_RETURN, TAIL = 0, 1, 2, 3, 4, 5
#: Observation classes of a quiet code's base (all but TAIL).
QUIET_BASE = 5
#: Cameras whose observation classes fit a cell's ``quiet`` code (5 ** 6 < 2 ** 16).
QUIET_CAMERAS = 6


@numba.njit(cache=True, nogil=True, inline="always", error_model="numpy")
def observation(epsilon, half_extent, width, p_occ, p_free):
    """The observation function f(epsilon) (see occupose.grid.occupancy.observation_function)
    and its class: SEEN_THROUGH (f = p_free exactly), ON_SURFACE (p_occ), BEHIND (0.5) or
    TAIL (a value in between, depending on epsilon)."""
    if epsilon > half_extent:
        excess = epsilon - half_extent
        if excess > TAIL_CUT * width:
            return p_free, SEEN_THROUGH
        return p_free + (p_occ - p_free) * math.exp(-0.5 * (excess / width) ** 2), TAIL
    if epsilon < -half_extent:
        excess = -epsilon - half_extent
        if excess > TAIL_CUT * width:
            return 0.5, BEHIND
        return 0.5 + (p_occ - 0.5) * math.exp(-0.5 * (excess / width) ** 2), TAIL
    return p_occ, ON_SURFACE


@numba.njit(cache=True, nogil=True, parallel=True, error_model="numpy", fastmath={"contract", "arcp", "nsz"})
def pixels_from_cells(origin, cell, nx, ny, nz, rotations, translations, intrinsics, sizes, pixels, depths_l):
    """Where every cell centre falls in every camera's image, in place (once per grid: the
    cameras do not move).

    origin : (3,) float64 metres; cell : float metres; nx, ny, nz : int cell counts
    rotations (C, 3, 3), translations (C, 3), intrinsics (C, 4) float64; sizes (C, 2) int64
    pixels : (N, C) int32 out, the flat pixel index ``v * width + u`` of cell n's centre in
        camera c's image, -1 where the centre is behind the camera or outside the image
    depths_l : (N, C) float64 out, metres, the centre's depth along the optical axis
        (``column + k * cell * rotation`` from the centre of cell (i, j, 0): update_grid's
        results depend on these exact values)
    """
    num_cameras = rotations.shape[0]
    for i in numba.prange(nx):
        x = origin[0] + cell * (i + 0.5)
        column = np.empty((num_cameras, 3))  # camera-frame centre of cell (i, j, k)
        for j in range(ny):
            y = origin[1] + cell * (j + 0.5)
            z0 = origin[2] + 0.5 * cell
            for c in range(num_cameras):
                for r in range(3):
                    column[c, r] = (rotations[c, r, 0] * x + rotations[c, r, 1] * y + rotations[c, r, 2] * z0
                                    + translations[c, r])
            for k in range(nz):
                n = (i * ny + j) * nz + k
                for c in range(num_cameras):
                    xc = column[c, 0] + k * cell * rotations[c, 0, 2]
                    yc = column[c, 1] + k * cell * rotations[c, 1, 2]
                    depth_l = column[c, 2] + k * cell * rotations[c, 2, 2]
                    depths_l[n, c] = depth_l
                    pixels[n, c] = -1
                    if depth_l <= 0.0:
                        continue
                    inverse = 1.0 / depth_l
                    u = math.floor(intrinsics[c, 0] * xc * inverse + intrinsics[c, 2] + 0.5)
                    v = math.floor(intrinsics[c, 1] * yc * inverse + intrinsics[c, 3] + 0.5)
                    if u < 0 or u >= sizes[c, 0] or v < 0 or v >= sizes[c, 1]:
                        continue
                    pixels[n, c] = int(v) * sizes[c, 0] + int(u)


@numba.njit(cache=True, nogil=True, inline="always", error_model="numpy")
def tail_width_at(depth_l, sigma_lut, c, lut_scale, tail_width):
    """The observation function's tail width (metres) for camera ``c`` at depth ``depth_l``
    (metres): ``tail_width`` times the noise tabulated in ``sigma_lut`` ((C, L) metres) at
    ``int(depth_l * lut_scale)`` (the last entry beyond). One multiplication on each side of
    the look-up: found where it is needed, it is the same number every time (a table of
    it cost 8 bytes per cell and camera to read every frame)."""
    return tail_width * sigma_lut[c, min(int(depth_l * lut_scale), sigma_lut.shape[1] - 1)]


@numba.njit(cache=True, nogil=True, error_model="numpy")
def count_missing(depth, run, after, returnless):
    """One frame of each pixel's run of frames without a reading, in place.

    depth (P,) float32 metres (<= 0 or not finite: no measurement); run (P,) uint16 in/out,
    frames in a row without a reading, at most ``after`` (int >= 1); returnless (P,) bool
    out: the pixels whose run has reached ``after``. One pass, where the same in NumPy took
    four over the images (about 1.7 ms a frame for one 640x480 camera).
    """
    for p in range(depth.shape[0]):
        d = depth[p]
        if d > 0.0 and d < np.inf:
            run[p] = 0
        elif run[p] < after:
            run[p] += 1
        returnless[p] = run[p] >= after


@numba.njit(cache=True, nogil=True, parallel=True, error_model="numpy", fastmath={"contract", "arcp", "nsz"})
def update_grid(nx, pixels, depths_l, sigma_lut, lut_step, tail_width, offsets, depth, returnless, half_extents, fars,
                p_occ, p_free, no_return, transition, held, hold, flush, probabilities, states, visibility, quiet):
    """One frame of the grid, in place; returns the number of cells whose HMM step ran.

    nx : int, the grid's x slices (run in parallel; the N cells are nx slices of N / nx)
    pixels (N, C) int32, depths_l (N, C) float64 metres: each cell centre's pixel in each
        camera's image (-1: none) and depth along its optical axis, from :func:`pixels_from_cells`
    sigma_lut (C, L) float64 metres, each camera's depth noise at depth ``m * lut_step``;
        lut_step : float metres; tail_width : float, noise stds: the observation function's
        tail width at a cell (:func:`tail_width_at`)
    offsets (C,) int64; depth (sum H*W,) float32 metres (<= 0 or not finite: no measurement)
    returnless (sum H*W,) bool: pixels that have measured nothing for long enough to count as
        no return (:meth:`occupose.grid.occupancy.OccupancyGrid.update`)
    half_extents (C,) float64 metres; fars (C,) float64 metres, each camera's far range
    p_occ, p_free : floats of the observation function
    no_return : float in (0, 1], the factor on O's likelihood per camera whose pixel is
        returnless while the cell is nearer than its far range (a static surface there would
        have returned; M and E are alike, so a person's dropouts cut no holes): class
        NO_RETURN. A cell whose MAP state is O before the step takes no factor: as for a
        static cell no camera sees, a missing reading does not remove it
    transition : (3, 3) float64, row = previous state, column = next state
    held : (3, 3) float64, the transition matrix of held cells (only its M row may differ from
        ``transition``); hold : (N,) bool or (0,) bool
    flush : float, posterior probabilities below it are set to 0 (no subnormal floats)
    probabilities : (N, 3) float32 in/out; states, visibility : (N,) uint8 out
    quiet : (N,) uint16 in/out, 0 or ``1 + sum_c class_c 5^c`` over the cameras' observation
        classes (UNCOVERED, SEEN_THROUGH, ON_SURFACE, BEHIND, NO_RETURN) of the cell's last step when
        that step was unheld and left its float32 probabilities bit for bit as they were. The
        step is a function of the probabilities, the classes and the hold alone, so an
        unheld cell whose code matches this frame's classes would give the same result
        again: it is skipped (nothing is written; states and visibility are those of the
        last step). A class TAIL, a held cell or more than QUIET_CAMERAS cameras give code 0.
        An unheld cell of code > 0 whose probabilities equal those of the last such cell
        stepped in its x slice with the same code (cells never seen, which share their
        history) takes that step's result without computing it.
    """
    num_cameras = pixels.shape[1]
    slice_cells = pixels.shape[0] // nx
    lut_scale = 1.0 / lut_step
    use_hold = hold.size > 0
    use_quiet = num_cameras <= QUIET_CAMERAS
    t_oo, t_om, t_oe = transition[0, 0], transition[0, 1], transition[0, 2]
    t_mo, t_mm, t_me = transition[1, 0], transition[1, 1], transition[1, 2]
    t_eo, t_em, t_ee = transition[2, 0], transition[2, 1], transition[2, 2]
    h_mo, h_mm, h_me = held[1, 0], held[1, 1], held[1, 2]
    stepped = 0
    for i in numba.prange(nx):
        last_code = 0  # the last unheld step of code > 0 in this slice: its input and output
        last_in = np.zeros(3, np.float32)
        last_out = np.zeros(3, np.float32)
        last_state = 0
        last_quiet = 0
        for n in range(i * slice_cells, (i + 1) * slice_cells):
            b_occupied = 1.0
            b_empty = 1.0
            b_static = 1.0  # O's likelihood relative to M's (NO_RETURN)
            covered = False
            seen = False
            code = 1 if use_quiet else 0
            power = 1
            for c in range(num_cameras):
                pixel = pixels[n, c]
                power_c = power
                power *= QUIET_BASE
                if pixel < 0:
                    continue
                d = depth[offsets[c] + pixel]
                if not (d > 0.0 and d < np.inf):
                    if no_return < 1.0 and returnless[offsets[c] + pixel] and depths_l[n, c] <= fars[c]:
                        b_static *= no_return
                        if code > 0:
                            code += NO_RETURN * power_c
                    continue
                covered = True
                depth_l = depths_l[n, c]
                f, kind = observation(d - depth_l, half_extents[c], tail_width_at(depth_l, sigma_lut, c, lut_scale,
                                                                                   tail_width), p_occ, p_free)
                if kind != BEHIND:
                    seen = True
                if kind == TAIL:
                    code = 0
                elif code > 0:
                    code += kind * power_c
                b_occupied *= f
                b_empty *= 1.0 - f
            held_here = use_hold and hold[n]
            if code > 0 and not held_here and quiet[n] == code:
                continue  # the step would change nothing
            q_o = probabilities[n, 0]
            q_m = probabilities[n, 1]
            q_e = probabilities[n, 2]
            if (code > 0 and not held_here and code == last_code and q_o == last_in[0] and q_m == last_in[1]
                    and q_e == last_in[2]):  # the same step as the last one (cells never seen): its result
                probabilities[n, 0] = last_out[0]
                probabilities[n, 1] = last_out[1]
                probabilities[n, 2] = last_out[2]
                states[n] = last_state
                visibility[n] = VISIBLE if seen else (HIDDEN if covered else UNOBSERVED)
                quiet[n] = last_quiet
                continue
            stepped += 1
            # forward step: Q_t ~ (Q_{t-1}^T A) o B_t
            o_o, o_e = t_oo, t_oe
            if not seen and q_o >= q_m and q_o >= q_e:  # static and unseen: it stays
                o_o, o_e = 1.0, 0.0
            m_o, m_m, m_e = t_mo, t_mm, t_me  # the M row: the only one a hold changes
            if held_here:
                m_o, m_m, m_e = h_mo, h_mm, h_me
                if q_m > q_o and q_m >= q_e:  # MAP M: taken as moving, its O share moves to M
                    q_m += q_o
                    q_o = 0.0
            if q_o >= q_m and q_o >= q_e:  # static: a missing reading does not remove it (as unseen)
                b_static = 1.0
            r_o = (q_o * o_o + q_m * m_o + q_e * t_eo) * b_occupied * b_static
            r_m = (q_o * t_om + q_m * m_m + q_e * t_em) * b_occupied
            r_e = (q_o * o_e + q_m * m_e + q_e * t_ee) * b_empty
            scale = 1.0 / (r_o + r_m + r_e)
            r_o *= scale
            r_m *= scale
            r_e *= scale
            if r_o < flush:
                r_o = 0.0
            if r_m < flush:
                r_m = 0.0
            if r_e < flush:
                r_e = 0.0
            s_o, s_m, s_e = np.float32(r_o), np.float32(r_m), np.float32(r_e)
            unchanged = s_o == probabilities[n, 0] and s_m == probabilities[n, 1] and s_e == probabilities[n, 2]
            quiet[n] = code if unchanged and not held_here else 0
            probabilities[n, 0] = s_o
            probabilities[n, 1] = s_m
            probabilities[n, 2] = s_e
            if r_o >= r_m and r_o >= r_e:
                states[n] = 0
            elif r_m >= r_e:
                states[n] = 1
            else:
                states[n] = 2
            visibility[n] = VISIBLE if seen else (HIDDEN if covered else UNOBSERVED)
            if code > 0 and not held_here:
                last_code = code
                last_in[0], last_in[1], last_in[2] = q_o, q_m, q_e
                last_out[0], last_out[1], last_out[2] = s_o, s_m, s_e
                last_state = states[n]
                last_quiet = quiet[n]
    return stepped


@numba.njit(cache=True, nogil=True, parallel=True, error_model="numpy")
def cells_from_pixels(depth, fx, fy, cx, cy, rotation, translation, origin, cell, nx, ny, nz, bounds, states, labels,
                      claims, out):
    """Flat cell index of every pixel's back-projected point, in place.

    depth : (H, W) float32 metres (<= 0 or not finite: no measurement)
    fx, fy, cx, cy : floats, pixels; rotation (3, 3), translation (3,) float64: world_from_camera
    origin : (3,) float64 metres; cell : float metres; nx, ny, nz : int cell counts
    bounds : (2, 3) int64, the lowest and highest (i, j, k) of the cells looked at: a point
        whose own cell is outside gets -1 (``[[0, 0, 0], [nx - 1, ny - 1, nz - 1]]`` for all)
    states : (N,) uint8 cell states, or an empty array; when given, a point in an E cell (2)
        moves to the O or M cell among the 26 around it whose centre is nearest (first in
        (di, dj, dk) lexicographic order on ties), if any
    labels : (N,) int32 label of each cell, and claims : (L,) int64, nonzero for the labels
        wanted, or both empty arrays; when given, a point whose (moved) cell's label is not
        claimed gets -1 (one pass where a gather of labels and claims per pixel took two
        more over the image)
    out : (H * W,) int64, -1 where there is no measurement, the point is outside the grid
        or its cell is not claimed
    """
    height, width = depth.shape
    use_states = states.size > 0
    use_claims = claims.size > 0
    for v in numba.prange(height):
        for u in range(width):
            p = v * width + u
            out[p] = -1
            d = depth[v, u]
            if not (d > 0.0 and d < np.inf):
                continue
            xc = (u - cx) * d / fx
            yc = (v - cy) * d / fy
            px = rotation[0, 0] * xc + rotation[0, 1] * yc + rotation[0, 2] * d + translation[0]
            py = rotation[1, 0] * xc + rotation[1, 1] * yc + rotation[1, 2] * d + translation[1]
            pz = rotation[2, 0] * xc + rotation[2, 1] * yc + rotation[2, 2] * d + translation[2]
            i = int(math.floor((px - origin[0]) / cell))
            j = int(math.floor((py - origin[1]) / cell))
            k = int(math.floor((pz - origin[2]) / cell))
            if (i < bounds[0, 0] or i > bounds[1, 0] or j < bounds[0, 1] or j > bounds[1, 1] or k < bounds[0, 2]
                    or k > bounds[1, 2]):
                continue
            n = (i * ny + j) * nz + k
            if use_states and states[n] == 2:
                best = np.inf
                for di in range(-1, 2):
                    for dj in range(-1, 2):
                        for dk in range(-1, 2):
                            a, b, c = i + di, j + dj, k + dk
                            if a < 0 or a >= nx or b < 0 or b >= ny or c < 0 or c >= nz:
                                continue
                            m = (a * ny + b) * nz + c
                            if states[m] == 2:
                                continue
                            ex = origin[0] + cell * (a + 0.5) - px
                            ey = origin[1] + cell * (b + 0.5) - py
                            ez = origin[2] + cell * (c + 0.5) - pz
                            dist = ex * ex + ey * ey + ez * ez
                            if dist < best:
                                best = dist
                                n = m
            if use_claims and claims[labels[n]] == 0:
                continue
            out[p] = n


@numba.njit(cache=True, nogil=True, error_model="numpy")
def mark_capsules(origin, cell, nx, ny, nz, a, b, radii, margin, out):
    """Mark the cells whose centre lies within a capsule's radius plus ``margin``, in place.

    origin : (3,) float64 metres; cell : float metres; nx, ny, nz : int cell counts
    a, b : (C, 3) float64 world metres, the capsules' ends; radii : (C, 2) float64 metres at
    a and at b; margin : float metres
    out : (nx, ny, nz) bool, set True (never cleared) where the distance from the cell centre
    to the segment ab, at the segment point nearest it (parameter t in [0, 1]), is at most
    ``(1 - t) radii[c, 0] + t radii[c, 1] + margin``. Only the box of cells around each
    capsule is visited.
    """
    for c in range(a.shape[0]):
        reach = max(radii[c, 0], radii[c, 1]) + margin
        low = np.empty(3, np.int64)
        high = np.empty(3, np.int64)
        counts = (nx, ny, nz)
        for r in range(3):
            low[r] = max(int(math.floor((min(a[c, r], b[c, r]) - reach - origin[r]) / cell)), 0)
            high[r] = min(int(math.floor((max(a[c, r], b[c, r]) + reach - origin[r]) / cell)), counts[r] - 1)
        ax, ay, az = a[c, 0], a[c, 1], a[c, 2]
        dx, dy, dz = b[c, 0] - ax, b[c, 1] - ay, b[c, 2] - az
        length2 = dx * dx + dy * dy + dz * dz
        inverse = 1.0 / length2 if length2 > 0.0 else 0.0
        for i in range(low[0], high[0] + 1):
            px = origin[0] + cell * (i + 0.5) - ax
            for j in range(low[1], high[1] + 1):
                py = origin[1] + cell * (j + 0.5) - ay
                for k in range(low[2], high[2] + 1):
                    pz = origin[2] + cell * (k + 0.5) - az
                    t = min(max((px * dx + py * dy + pz * dz) * inverse, 0.0), 1.0)
                    ex, ey, ez = px - t * dx, py - t * dy, pz - t * dz
                    limit = (1.0 - t) * radii[c, 0] + t * radii[c, 1] + margin
                    if ex * ex + ey * ey + ez * ez <= limit * limit:
                        out[i, j, k] = True
