"""Numba kernels of the filters: annealing exponents and layer weights, ancestor search,
diffusion within limits (private: use :mod:`occupose.filters` and its resampling module)."""

from __future__ import annotations

import math

import numba
import numpy as np

#: Largest annealing exponent, relative to the spread of the log-likelihoods.
MAX_RELATIVE_BETA = 1e6
#: Relative log-weights below this count as 0 (their squares would be denormal numbers,
#: which are slow, and below 1e-150 of the largest weight they change no sum).
NEGLIGIBLE = -345.0


@numba.njit(cache=True)
def _log_survival(u, b):
    """log(ESS / N) of the weights exp(b * u) (u <= 0, max 0) and its derivative in b."""
    s1 = 0.0
    s2 = 0.0
    t1 = 0.0
    t2 = 0.0
    for i in range(u.size):
        if b * u[i] > NEGLIGIBLE:
            e = math.exp(b * u[i])
            e2 = e * e
            s1 += e
            s2 += e2
            t1 += u[i] * e
            t2 += u[i] * e2
    value = 2.0 * math.log(s1) - math.log(s2) - math.log(u.size)
    return value, 2.0 * (t1 / s1 - t2 / s2)


@numba.njit(cache=True)
def annealing_exponent(values, target):
    """The exponent beta > 0 for which the weights exp(beta * values) have ESS / N = target.

    values : (N,) float64 log-likelihoods (-inf allowed); target : survival rate in (0, 1).
    ESS / N falls monotonically from (finite count) / N at beta -> 0 to (ties at the maximum) / N
    at beta -> inf; the root is found by Newton's method from a log-normal guess, kept inside
    a shrinking bracket (bisection when a Newton step leaves it).
    Returns (beta, survival reached). Equal values give (1, their share); a target out of
    reach gives the nearest end (the smallest or the largest exponent tried).
    """
    n = values.size
    top = -np.inf
    bottom = np.inf
    count = 0
    for v in values:
        if v > -np.inf:
            top = max(top, v)
            bottom = min(bottom, v)
            count += 1
    if count == 0:
        return 1.0, 1.0
    if top == bottom:
        return 1.0, count / n
    spread = top - bottom
    if count <= target * n:
        return 1.0 / (MAX_RELATIVE_BETA * spread), count / n
    u = (values - top) / spread  # in [-1, 0], -inf kept
    goal = math.log(target)
    # first guess: log-normal weights have log(ESS / N) = -b^2 var(u)
    mean = 0.0
    for v in u:
        if v > -np.inf:
            mean += v
    mean /= count
    var = 0.0
    for v in u:
        if v > -np.inf:
            var += (v - mean) ** 2
    var /= count
    b = min(max(math.sqrt(-goal / max(var, 1e-300)), 1e-6), MAX_RELATIVE_BETA)
    lo = 0.0  # weights flatter than the target
    hi = np.inf  # weights sharper than the target
    g, slope = _log_survival(u, b)
    for _ in range(200):
        if abs(g - goal) < 1e-6:
            break
        if g > goal:
            lo = b
        else:
            hi = b
        if hi - lo < 1e-12 * hi:
            break
        newton = b - (g - goal) / slope if slope < 0.0 else -1.0
        if lo < newton < hi:
            b = newton
        elif hi == np.inf:
            b *= 4.0
        else:
            b = 0.5 * (lo + hi)
        if b >= MAX_RELATIVE_BETA:
            b = MAX_RELATIVE_BETA
            g, slope = _log_survival(u, b)
            break
        g, slope = _log_survival(u, b)
    return b / spread, math.exp(g)


@numba.njit(cache=True)
def layer_weights(values, parts, anneal, target, out):
    """Log-weights of one layer from per-part log-likelihoods.

    values : (P, K) float64 (-inf allowed, no NaN / +inf)
    parts : (k,) int64 columns to sum (empty: every column)
    anneal : choose beta by annealing_exponent(total, target); otherwise beta = 1
    out : (P,) float64, receives the log-weights beta * total
    Returns (out, beta, survival ESS / P of those weights).
    """
    n = values.shape[0]
    total = out
    for i in range(n):
        total[i] = 0.0
        if parts.size == 0:
            for k in range(values.shape[1]):
                total[i] += values[i, k]
        else:
            for k in parts:
                total[i] += values[i, k]
    if anneal:
        beta, survival = annealing_exponent(total, target)
    else:
        beta = 1.0
        top = total.max()
        if top == -np.inf:
            survival = 1.0
        else:
            s1 = 0.0
            s2 = 0.0
            for v in total:
                if v - top > NEGLIGIBLE:
                    e = math.exp(v - top)
                    s1 += e
                    s2 += e * e
            survival = s1 * s1 / s2 / n
    if beta != 1.0:
        for i in range(n):
            out[i] *= beta
    return out, beta, survival


@numba.njit(cache=True)
def ancestors_from_points(log_weights, points, out):
    """Indices i with C[i-1] <= point * C[N-1] < C[i], C the cumulative sum of exp(log_weights - max).

    log_weights : (N,) float64 (-inf allowed; all -inf = equal weights); points : (n,) in [0, 1)
    out : (n,) int64, receives the indices
    Returns out (binary search per point, so any order of points works). Weights below
    exp(NEGLIGIBLE) of the largest count as 0.
    """
    n = log_weights.size
    top = log_weights.max()
    cumulative = np.empty(n)
    running = 0.0
    for i in range(n):
        if top == -np.inf:
            running += 1.0
        elif log_weights[i] - top > NEGLIGIBLE:
            running += math.exp(log_weights[i] - top)
        cumulative[i] = running
    for j in range(points.size):
        value = points[j] * running
        lo = 0
        hi = n
        while lo < hi:  # first index with cumulative > value (searchsorted side="right")
            mid = (lo + hi) // 2
            if cumulative[mid] <= value:
                lo = mid + 1
            else:
                hi = mid
        out[j] = min(lo, n - 1)
    return out


#: How each DOF is kept inside its limits (see limit_modes).
FREE, REFLECT, WRAP, LOWER, UPPER = 0, 1, 2, 3, 4


@numba.njit(cache=True)
def diffuse_within_limits(particles, dofs, noise, std, lower, upper, mode):
    """particles[:, dofs] += noise * std, each DOF then brought back inside its limits, in place.

    particles : (P, D) float64; dofs : (d,) int64; noise : (P, d) standard normal; std : (d,)
    lower, upper, mode : (D,) per DOF (mode FREE, REFLECT between lower and upper, WRAP into
    [lower, lower + 2 pi), LOWER / UPPER reflect at that one bound).
    """
    two_pi = 2.0 * math.pi
    for i in range(particles.shape[0]):
        for j in range(dofs.size):
            d = dofs[j]
            x = particles[i, d] + noise[i, j] * std[j]
            m = mode[d]
            lo = lower[d]
            if m == WRAP:
                if not lo <= x < lo + two_pi:
                    x = lo + (x - lo) % two_pi
            elif m != FREE and not lo <= x <= upper[d]:
                if m == REFLECT:
                    width = upper[d] - lo
                    if width > 0.0:
                        t = (x - lo) % (2.0 * width)
                        x = lo + (t if t <= width else 2.0 * width - t)
                    else:
                        x = lo
                elif m == LOWER:
                    x = lo + abs(x - lo)
                else:  # UPPER
                    x = upper[d] - abs(upper[d] - x)
            particles[i, d] = x
