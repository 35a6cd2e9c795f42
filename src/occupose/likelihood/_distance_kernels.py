"""Numba kernels on round-cone distances (private: use the classes of :mod:`occupose.likelihood`):
the nearest capsule of each observed point (the points term, its blocks of nearby points)
and the render term's ray cast, which takes the nearest capsule of the pixels the model
misses. The kernels of the camera-facing surface samples (free space, colour) are in
:mod:`occupose.likelihood._sample_kernels`.

Every kernel takes the particles' capsules as ``a, b`` (P, C, 3) float64 world metres (the
two ends of each round cone) with ``radii`` (C, 2) float64 (radius at a, at b) and, where
parts matter, ``capsule_part`` (C,) int64; runs in parallel over particles; and adds its
result into an output array, (P, K) float64 (one column per part) for the likelihoods.

Loop order for speed (measured): particles outer (one per thread), then blocks of nearby
points, capsules next (nearest first, skipping those that cannot be the nearest of any
point of the block), the points of the block innermost over separate contiguous x, y, z
float32 arrays, so that the point loop is branch-free and vectorised (8 float32 lanes with
AVX2). Points are stored relative to a per-frame ``origin`` (their centroid) to keep
float32 exact to micrometres.

A round cone whose larger end sphere holds the smaller one (``|b - a| <= |ra - rb|``,
e.g. a sphere given as ``a == b``) is that larger sphere.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from occupose.geometry._raycast import _depth
from occupose.geometry.primitives import ELLIPSOID, ROUND_CONE

# Below this value of |b - a|^2 - (ra - rb)^2 (m^2) a round cone is treated as its larger sphere.
_DEGENERATE = 1e-12


@numba.njit(cache=True, nogil=True, inline="always", error_model="numpy")
def _round_cone_distance(px, py, pz, ax, ay, az, ex, ey, ez, length, k, s, g, r1, r2):
    """Signed distance from point p to a round cone (negative inside), after Inigo Quilez's
    exact round-cone distance, written in the cone's own units with one square root.

    a : end a; e : unit axis a -> b; length = |b - a|; with rr = r1 - r2, l2 = length^2
    and a2 = l2 - rr^2 (> 0): k = rr |rr| / a2, s = a2 / l2, g = rr / length.
    """
    pax = px - ax
    pay = py - ay
    paz = pz - az
    t = pax * ex + pay * ey + paz * ez  # along the axis from a
    rho2 = pax * pax + pay * pay + paz * paz - t * t  # squared distance from the axis
    tb = t - length
    bound = k * rho2
    near_b = tb * abs(tb) > bound  # closest to the sphere at b
    near_a = t * abs(t) < bound  # closest to the sphere at a
    arg = rho2 + tb * tb if near_b else (rho2 + t * t if near_a else rho2 * s)
    offset = -r2 if near_b else (-r1 if near_a else t * g - r1)
    return math.sqrt(arg) + offset


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _capsule_constants(ax, ay, az, bx, by, bz, r1, r2):
    """The arguments of :func:`_round_cone_distance` after the point, as a tuple of 12
    floats, for the round cone from (ax, ay, az) radius r1 to (bx, by, bz) radius r2. A
    degenerate cone comes back as its larger sphere: centre in the ``a`` slot, axis 0,
    length 0, k = 1 (so that ``near_a`` always holds), radius in r1 and r2.
    """
    dx, dy, dz = bx - ax, by - ay, bz - az
    l2 = dx * dx + dy * dy + dz * dz
    rr = r1 - r2
    a2 = l2 - rr * rr
    if a2 <= _DEGENERATE:
        if r2 > r1:
            return bx, by, bz, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, r2, r2
        return ax, ay, az, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, r1, r1
    length = math.sqrt(l2)
    return ax, ay, az, dx / length, dy / length, dz / length, length, rr * abs(rr) / a2, a2 / l2, rr / length, r1, r2


@numba.njit(cache=True, nogil=True)
def _select(points, axis, order, lo, hi, kth):
    """Reorder order[lo:hi] so that order[kth] indexes the point whose coordinate ``axis``
    is the (kth - lo)-th smallest of the range, the entries before it points no larger and
    those after it points no smaller (quickselect, median-of-three pivots). points : (N, 3)
    float64; order : (N,) int64, indices into points, reordered in place; lo <= kth < hi."""
    while hi - lo > 1:
        mid = lo + (hi - lo) // 2
        x, y, z = points[order[lo], axis], points[order[mid], axis], points[order[hi - 1], axis]
        pivot = max(min(x, y), min(max(x, y), z))
        i, j = lo, hi - 1
        while i <= j:
            while points[order[i], axis] < pivot:
                i += 1
            while points[order[j], axis] > pivot:
                j -= 1
            if i <= j:
                order[i], order[j] = order[j], order[i]
                i += 1
                j -= 1
        # now order[lo:j + 1] <= pivot <= order[i:hi], and entries between equal the pivot
        if kth <= j:
            hi = j + 1
        elif kth >= i:
            lo = i
        else:
            return


@numba.njit(cache=True, nogil=True)
def block_order(points, block_size, order):
    """Split (N, 3) float64 points into spatially compact blocks of at most ``block_size``
    points: halve each set at the median of its longest side (the lower half first) until
    it is small enough. order : (N,) int64 out, the points block after block.
    Returns (B + 1,) int64: block b is order[start[b]:start[b + 1]]."""
    n = points.shape[0]
    for i in range(n):
        order[i] = i
    start = [0]
    stack = [(0, n)]
    while len(stack):
        lo, hi = stack.pop()
        if hi - lo <= block_size:
            if hi > lo:
                start.append(hi)
            continue
        axis, widest = 0, -1.0
        for k in range(3):
            low, high = np.inf, -np.inf
            for i in range(lo, hi):
                low = min(low, points[order[i], k])
                high = max(high, points[order[i], k])
            if high - low > widest:
                axis, widest = k, high - low
        half = lo + (hi - lo) // 2
        _select(points, axis, order, lo, hi, half)
        stack.append((half, hi))
        stack.append((lo, half))
    return np.array(start, np.int64)


@numba.njit(cache=True, nogil=True)
def pack_blocks(points, order, leaf_start, pad, slack):
    """The arrays of :class:`occupose.likelihood._capsules.PointBlocks` for (N, 3) float64
    ``points`` split into blocks order[leaf_start[b]:leaf_start[b + 1]] (N >= 1), each
    padded to a multiple of ``pad`` entries with copies of its last point (weight 0);
    block radii get ``slack`` metres more. Returns origin (3,) float64 (the points'
    centroid), px, py, pz (M,) float32 (points minus origin), start (B + 1,) int64, centre
    (3, B) float64 (the middle of each block's bounding box, minus origin), radius (B,)
    float64, weight (M,) float32, position (N,) int64; metres as the points. Allocates its
    outputs: their sizes come from the blocks' padded counts."""
    n, num_blocks = points.shape[0], leaf_start.shape[0] - 1
    origin = np.zeros(3)
    for i in range(n):
        for k in range(3):
            origin[k] += points[i, k]
    origin /= n
    start = np.zeros(num_blocks + 1, np.int64)
    for block in range(num_blocks):
        count = leaf_start[block + 1] - leaf_start[block]
        start[block + 1] = start[block] + (count + pad - 1) // pad * pad
    m = start[num_blocks]
    px, py, pz = np.empty(m, np.float32), np.empty(m, np.float32), np.empty(m, np.float32)
    weight = np.zeros(m, np.float32)
    position = np.empty(n, np.int64)
    centre, radius = np.empty((3, num_blocks)), np.empty(num_blocks)
    for block in range(num_blocks):
        first, last = leaf_start[block], leaf_start[block + 1]
        low, high = np.full(3, np.inf), np.full(3, -np.inf)
        for j in range(start[block], start[block + 1]):
            i = order[min(first + j - start[block], last - 1)]
            x, y, z = points[i, 0] - origin[0], points[i, 1] - origin[1], points[i, 2] - origin[2]
            px[j], py[j], pz[j] = x, y, z
            if j - start[block] < last - first:
                weight[j] = 1.0
                position[i] = j
                low[0], low[1], low[2] = min(low[0], x), min(low[1], y), min(low[2], z)
                high[0], high[1], high[2] = max(high[0], x), max(high[1], y), max(high[2], z)
        for k in range(3):
            centre[k, block] = 0.5 * (low[k] + high[k])
        largest = 0.0
        for i in order[first:last]:
            squared = 0.0
            for k in range(3):
                squared += (points[i, k] - origin[k] - centre[k, block]) ** 2
            largest = max(largest, squared)
        radius[block] = math.sqrt(largest) + slack
    return origin, px, py, pz, start, centre, radius, weight, position


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _particle_bounds(a, b, radii, p, origin, block_centre, block_radius, consts, bounds):
    """The capsules of particle ``p`` for the block search of :func:`_nearest_in_block`:
    consts (C, 12) gets their :func:`_capsule_constants` (minus origin) and bounds (C, B)
    the lower bound |d(block centre)| - block radius of every point of each block's
    distance to each capsule (the distance is 1-Lipschitz)."""
    num_capsules = a.shape[1]
    for c in range(num_capsules):
        values = _capsule_constants(
            a[p, c, 0] - origin[0], a[p, c, 1] - origin[1], a[p, c, 2] - origin[2],
            b[p, c, 0] - origin[0], b[p, c, 1] - origin[1], b[p, c, 2] - origin[2], radii[c, 0], radii[c, 1])
        for j in range(12):
            consts[c, j] = values[j]
    for c in range(num_capsules):  # vectorised over blocks
        ax, ay, az, ex, ey, ez = consts[c, 0], consts[c, 1], consts[c, 2], consts[c, 3], consts[c, 4], consts[c, 5]
        length, k, s, g, r1, r2 = consts[c, 6], consts[c, 7], consts[c, 8], consts[c, 9], consts[c, 10], consts[c, 11]
        for block in range(block_radius.shape[0]):
            bounds[c, block] = abs(_round_cone_distance(block_centre[0, block], block_centre[1, block],
                                                        block_centre[2, block], ax, ay, az, ex, ey, ez, length, k,
                                                        s, g, r1, r2)) - block_radius[block]


@numba.njit(cache=True, nogil=True, inline="always", error_model="numpy")
def _nearest_in_block(consts, bounds, block, px, py, pz, lo, hi, best, arg, bound, order, best_bits, scratch,
                      scratch_bits):
    """For each point i of entries lo..hi - 1 (uint64) of block ``block``: ``best[i]`` = min
    over capsules of |signed distance| (float32, metres) and ``arg[i]`` the capsule that
    attains it. Returns n: the capsules visited are order[:n] (every capsule that attains
    some point's minimum is among them).

    The block visits the capsules in order of their bounds (see :func:`_particle_bounds`)
    and stops at the first whose bound exceeds the block's worst distance so far: the
    result is the exhaustive one (up to float32 rounding on near-ties), in a fraction of
    the time. bound (C,) float64, order (C,) int64: scratch; best_bits, scratch, scratch_bits:
    int32 view of best, a float32 (1,) array and its int32 view.
    """
    num_capsules = consts.shape[0]
    for c in range(num_capsules):  # insertion sort of the capsules by their bound
        value = bounds[c, block]
        j = c
        while j > 0 and bound[j - 1] > value:
            bound[j] = bound[j - 1]
            order[j] = order[j - 1]
            j -= 1
        bound[j] = value
        order[j] = c
    for i in range(lo, hi):
        best[i] = np.inf
        arg[i] = 0
    f = np.float32
    worst = np.inf
    visited = 0
    # Unsigned loop bounds and no array views in the loops: a signed start makes numba guard
    # every index against wraparound, and views cost reference counting, both of which
    # keep the point loop from vectorising or dominate it.
    for j in range(num_capsules):
        if bound[j] >= worst:
            break
        visited += 1
        c = order[j]
        ax, ay, az = f(consts[c, 0]), f(consts[c, 1]), f(consts[c, 2])
        ex, ey, ez = f(consts[c, 3]), f(consts[c, 4]), f(consts[c, 5])
        length, k, s, g = f(consts[c, 6]), f(consts[c, 7]), f(consts[c, 8]), f(consts[c, 9])
        r1, r2 = f(consts[c, 10]), f(consts[c, 11])
        cc = np.int32(c)
        for i in range(lo, hi):
            d = abs(_round_cone_distance(px[i], py[i], pz[i], ax, ay, az, ex, ey, ez, length, k, s, g, r1, r2))
            current = best[i]
            arg[i] = cc if d < current else arg[i]
            best[i] = min(d, current)
        # The block's largest distance: a max over the float32 bit patterns (ordered as the
        # non-negative floats they encode), which vectorises where a float max does not.
        top = np.int32(0)
        for i in range(lo, hi):
            top = max(top, best_bits[i])
        scratch_bits[0] = top
        worst = scratch[0]
    return visited


@numba.njit(cache=True, nogil=True, parallel=True, error_model="numpy")
def nearest_capsules(a, b, radii, origin, px, py, pz, block_start, block_centre, block_radius, distance, capsule):
    """Each point's distance to the nearest capsule surface and that capsule, per particle.

    origin : (3,) float64; px, py, pz : (M,) float32, points minus origin, in blocks
    (block b holds entries block_start[b] to block_start[b + 1] - 1; block_start (B + 1,)
    int64, block_centre (3, B) float64 minus origin, block_radius (B,) float64: a ball
    holding the block; see :func:`_nearest_in_block`); distance : (P, M) float32 out,
    metres; capsule : (P, M) int32 out.
    """
    num_capsules, num_blocks = a.shape[1], block_radius.shape[0]
    for p in numba.prange(a.shape[0]):
        consts = np.empty((num_capsules, 12))
        bounds = np.empty((num_capsules, num_blocks))
        bound = np.empty(num_capsules)
        order = np.empty(num_capsules, np.int64)
        scratch = np.empty(1, np.float32)
        best = distance[p]
        _particle_bounds(a, b, radii, p, origin, block_centre, block_radius, consts, bounds)
        for block in range(num_blocks):
            _nearest_in_block(consts, bounds, block, px, py, pz, np.uint64(block_start[block]),
                              np.uint64(block_start[block + 1]), best, capsule[p], bound, order, best.view(np.int32),
                              scratch, scratch.view(np.int32))


@numba.njit(cache=True, nogil=True, error_model="numpy", fastmath=True)
def _capsule_sum(best, weight, arg, c, lo, hi):
    """sum of weight * best over the entries lo..hi - 1 (uint64) with arg == c (float64;
    fastmath lets the sum vectorise, which is faster than adding each point to its part's
    total in turn)."""
    total = 0.0
    for i in range(lo, hi):
        total += weight[i] * best[i] if arg[i] == c else np.float32(0.0)
    return total


@numba.njit(cache=True, nogil=True, parallel=True, error_model="numpy")
def point_distance_sums(a, b, radii, capsule_part, origin, px, py, pz, block_start, block_centre, block_radius,
                        weight, out):
    """out[p, k] += sum of weight * distance over the points whose nearest capsule belongs to
    part k. Arguments as :func:`nearest_capsules`; weight : (M,) float32 (0 for padding);
    out : (P, K) float64. Each block's sums are taken over the capsules it visited, while
    its points are in cache.
    """
    n = px.shape[0]
    num_capsules, num_blocks = a.shape[1], block_radius.shape[0]
    for p in numba.prange(a.shape[0]):
        consts = np.empty((num_capsules, 12))
        bounds = np.empty((num_capsules, num_blocks))
        bound = np.empty(num_capsules)
        order = np.empty(num_capsules, np.int64)
        scratch = np.empty(1, np.float32)
        best = np.empty(n, np.float32)
        arg = np.empty(n, np.int32)
        best_bits = best.view(np.int32)
        scratch_bits = scratch.view(np.int32)
        _particle_bounds(a, b, radii, p, origin, block_centre, block_radius, consts, bounds)
        for block in range(num_blocks):
            lo, hi = np.uint64(block_start[block]), np.uint64(block_start[block + 1])
            visited = _nearest_in_block(consts, bounds, block, px, py, pz, lo, hi, best, arg, bound, order,
                                        best_bits, scratch, scratch_bits)
            for j in range(visited):
                c = order[j]
                out[p, capsule_part[c]] += _capsule_sum(best, weight, arg, np.int32(c), lo, hi)


@numba.njit(cache=True, nogil=True, inline="always", error_model="numpy")
def _hull_row_span(rect, y):
    """x range (lo, hi) at height y of the convex hull of two axis-aligned rectangles
    rect[e] = (x0, x1, y0, y1), e = 0, 1; lo > hi when the row misses the hull.

    The hull is {(1 - t) p + t q : p in rect 0, q in rect 1, t in [0, 1]}: at height y, t
    must keep y between the lerped bottoms and tops, an interval of t, and x spans the
    lerped left and right sides over that interval (extremes at its ends).
    """
    t_lo, t_hi = 0.0, 1.0
    for side in range(2):  # bottom: y0(t) <= y; top: y1(t) >= y
        start, slope = rect[0, 2 + side], rect[1, 2 + side] - rect[0, 2 + side]
        gap = y - start  # bottom: slope t <= gap; top: slope t >= gap
        if side == 1:
            slope, gap = -slope, -gap
        if slope > 0.0:
            t_hi = min(t_hi, gap / slope)
        elif slope < 0.0:
            t_lo = max(t_lo, gap / slope)
        elif gap < 0.0:
            return np.inf, -np.inf
    if t_lo > t_hi:
        return np.inf, -np.inf
    left_lo = rect[0, 0] + t_lo * (rect[1, 0] - rect[0, 0])
    left_hi = rect[0, 0] + t_hi * (rect[1, 0] - rect[0, 0])
    right_lo = rect[0, 1] + t_lo * (rect[1, 1] - rect[0, 1])
    right_hi = rect[0, 1] + t_hi * (rect[1, 1] - rect[0, 1])
    return min(left_lo, left_hi), max(right_lo, right_hi)


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _nearest_of_few(consts, n, qx, qy, qz, best, arg):
    """``arg[i]`` = the capsule nearest (|signed distance|) point i of the first n points
    qx, qy, qz (float32) among the capsules of ``consts`` (C, 12) (constants of
    :func:`_capsule_constants` in the points' frame); exhaustive, vectorised over points."""
    f = np.float32
    for i in range(n):
        best[i] = np.inf
        arg[i] = 0
    for c in range(consts.shape[0]):
        ax, ay, az = f(consts[c, 0]), f(consts[c, 1]), f(consts[c, 2])
        ex, ey, ez = f(consts[c, 3]), f(consts[c, 4]), f(consts[c, 5])
        length, k, s, g = f(consts[c, 6]), f(consts[c, 7]), f(consts[c, 8]), f(consts[c, 9])
        r1, r2 = f(consts[c, 10]), f(consts[c, 11])
        cc = np.int32(c)
        for i in range(n):
            d = abs(_round_cone_distance(qx[i], qy[i], qz[i], ax, ay, az, ex, ey, ez, length, k, s, g, r1, r2))
            current = best[i]
            arg[i] = cc if d < current else arg[i]
            best[i] = min(d, current)


@numba.njit(cache=True, nogil=True, parallel=True, error_model="numpy")
def render_sigmas(a, b, radii, capsule_part, rotation, shift, fx, fy, cx, cy, u0, v0, stride, observed,
                  observed_index, observed_x, observed_y, observed_z, truncation, num_chunks, out):
    """out[p, k] += the first paper's sigma over a pixel grid of one view, split by part.

    rotation (3, 3), shift (3,) : camera_from_world; fx, fy, cx, cy : intrinsics (pixels);
    the grid's pixel (gv, gu) is image pixel (v0 + stride gv, u0 + stride gu);
    observed : (Gv, Gu) float64, metres, the observed depth where the pixel is in the
    person's silhouette, else 0; observed_index : (M,) int64, the flat grid index
    gv * Gu + gu of each such pixel; observed_x, _y, _z : (M,) float32, metres, their
    back-projected points in the camera frame; truncation : D, metres; num_chunks : the
    particles are run in that many chunks in parallel (a few per thread), so that the grid
    buffers are allocated and cleared once per chunk (then reset only where the model
    touched them).

    Each particle's capsules are ray-cast (exact hits, nearest camera z) into the grid
    pixels of their screen rectangles. A pixel in both silhouettes adds
    min(|d_obs - d_model| / D, 1)^2 to the part rendered there; a pixel of the model only
    adds 1 to the part rendered there; a pixel of the observation only adds 1 to the part
    of the capsule nearest (|signed distance|) its back-projected 3D point.
    """
    num_v, num_u = observed.shape
    num_capsules = a.shape[1]
    num_observed = observed_index.shape[0]
    flat_observed = observed.reshape(-1)
    num_particles = a.shape[0]
    for chunk in numba.prange(num_chunks):
        kinds = np.empty(num_capsules, np.int8)
        params = np.zeros((num_capsules, 16))
        consts = np.empty((num_capsules, 12))
        zbuf = np.full(num_v * num_u, np.inf, np.float32)
        winner = np.full(num_v * num_u, -1, np.int32)
        touched = np.empty(num_v * num_u, np.int32)  # the grid pixels the model covers
        missed_x = np.empty(num_observed, np.float32)
        missed_y = np.empty(num_observed, np.float32)
        missed_z = np.empty(num_observed, np.float32)
        best = np.empty(num_observed, np.float32)
        arg = np.empty(num_observed, np.int32)
        for p in range(chunk * num_particles // num_chunks, (chunk + 1) * num_particles // num_chunks):
            _render_particle(a, b, radii, capsule_part, rotation, shift, fx, fy, cx, cy, u0, v0, stride,
                             flat_observed, num_v, num_u, observed_index, observed_x, observed_y, observed_z,
                             truncation, p, kinds, params, consts, zbuf, winner, touched, missed_x, missed_y,
                             missed_z, best, arg, out)


@numba.njit(cache=True, nogil=True, error_model="numpy")
def _render_particle(a, b, radii, capsule_part, rotation, shift, fx, fy, cx, cy, u0, v0, stride, flat_observed,
                     num_v, num_u, observed_index, observed_x, observed_y, observed_z, truncation, p, kinds, params,
                     consts, zbuf, winner, touched, missed_x, missed_y, missed_z, best, arg, out):
    """One particle of :func:`render_sigmas`; the buffers come in cleared (zbuf inf, winner
    -1) and are left so."""
    num_capsules = a.shape[1]
    num_touched = 0
    rect = np.empty((2, 4))  # per end sphere: x0, x1, y0, y1 of its image
    for c in range(num_capsules):
        # Capsule ends in the camera frame.
        for end in range(2):
            x = a[p, c, 0] if end == 0 else b[p, c, 0]
            y = a[p, c, 1] if end == 0 else b[p, c, 1]
            z = a[p, c, 2] if end == 0 else b[p, c, 2]
            for i in range(3):
                params[c, 3 * end + i] = rotation[i, 0] * x + rotation[i, 1] * y + rotation[i, 2] * z + shift[i]
        params[c, 6], params[c, 7] = radii[c, 0], radii[c, 1]
        values = _capsule_constants(params[c, 0], params[c, 1], params[c, 2], params[c, 3], params[c, 4],
                                    params[c, 5], params[c, 6], params[c, 7])
        for i in range(12):
            consts[c, i] = values[i]
        # Each end sphere's image lies in the rectangle that bounds its bounding box's image
        # (in x/z, y/z); the round cone, the convex hull of the two spheres, images into the
        # convex hull of the two rectangles, scanned row by row below.
        behind = False
        for end in range(2):
            x, y, z = params[c, 3 * end], params[c, 3 * end + 1], params[c, 3 * end + 2]
            r = radii[c, end]
            if z - r <= 1e-6:
                behind = True
                break
            rect[end, 0] = min((x - r) / (z - r), (x - r) / (z + r))
            rect[end, 1] = max((x + r) / (z - r), (x + r) / (z + r))
            rect[end, 2] = min((y - r) / (z - r), (y - r) / (z + r))
            rect[end, 3] = max((y + r) / (z - r), (y + r) / (z + r))
        if behind:
            gv0, gv1 = 0, num_v - 1
        else:
            gv0 = max(int(math.ceil((fy * min(rect[0, 2], rect[1, 2]) + cy - v0) / stride)), 0)
            gv1 = min(int(math.floor((fy * max(rect[0, 3], rect[1, 3]) + cy - v0) / stride)), num_v - 1)
        kinds[c] = ROUND_CONE
        if consts[c, 6] == 0.0:  # degenerate: the larger sphere, cast as a unit-sphere ellipsoid
            kinds[c] = ELLIPSOID
            r = consts[c, 10]
            params[c, 0:3] = -consts[c, 0:3] / r
            params[c, 3:12] = 0.0
            params[c, 3] = params[c, 7] = params[c, 11] = 1.0 / r
        for gv in range(gv0, gv1 + 1):
            ray_y = (v0 + stride * gv - cy) / fy
            if behind:
                gu0, gu1 = 0, num_u - 1
            else:
                lo_x, hi_x = _hull_row_span(rect, ray_y)
                if lo_x > hi_x:
                    continue
                gu0 = max(int(math.ceil((fx * lo_x + cx - u0) / stride)), 0)
                gu1 = min(int(math.floor((fx * hi_x + cx - u0) / stride)), num_u - 1)
            for gu in range(gu0, gu1 + 1):
                depth = np.float32(_depth(kinds[c], params, c, (u0 + stride * gu - cx) / fx, ray_y))
                g = gv * num_u + gu
                if 0.0 < depth < zbuf[g]:
                    if winner[g] < 0:
                        touched[num_touched] = g
                        num_touched += 1
                    zbuf[g] = depth
                    winner[g] = c
    for t in range(num_touched):  # model-only pixels
        g = touched[t]
        if flat_observed[g] == 0.0:
            out[p, capsule_part[winner[g]]] += 1.0
    num_missed = 0
    for m in range(observed_index.shape[0]):  # pixels in both silhouettes, and observation-only ones
        g = observed_index[m]
        c = winner[g]
        if c >= 0:
            f = min(abs(flat_observed[g] - zbuf[g]) / truncation, 1.0)
            out[p, capsule_part[c]] += f * f
        else:
            missed_x[num_missed] = observed_x[m]
            missed_y[num_missed] = observed_y[m]
            missed_z[num_missed] = observed_z[m]
            num_missed += 1
    _nearest_of_few(consts, num_missed, missed_x, missed_y, missed_z, best, arg)
    for i in range(num_missed):
        out[p, capsule_part[arg[i]]] += 1.0
    for t in range(num_touched):
        zbuf[touched[t]] = np.inf
        winner[touched[t]] = -1
