"""Numba kernel of the annealed filters (private: use the filters of :mod:`occupose.filters`)."""

from __future__ import annotations

import math

import numba
import numpy as np

#: Largest annealing exponent, relative to the spread of the log-likelihoods.
MAX_RELATIVE_BETA = 1e6


@numba.njit(cache=True)
def _log_survival(u, b):
    """log(ESS / N) of the weights exp(b * u) (u <= 0, max 0) and its derivative in b."""
    s1 = 0.0
    s2 = 0.0
    t1 = 0.0
    t2 = 0.0
    for i in range(u.size):
        if u[i] > -np.inf:
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
    at beta -> inf; the root is found by Newton's method kept inside a shrinking bracket.
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
    lo = 0.0  # g(lo) > 0 (weights flatter than the target)
    hi = 1.0
    g, slope = _log_survival(u, hi)
    while g - goal > 0.0 and hi < MAX_RELATIVE_BETA:
        lo = hi
        hi *= 4.0
        g, slope = _log_survival(u, hi)
    if g - goal > 0.0:
        return hi / spread, math.exp(g)
    b = hi
    for _ in range(100):
        if abs(g - goal) < 1e-6:
            break
        if g - goal > 0.0:
            lo = b
        else:
            hi = b
        step = b - (g - goal) / slope if slope < 0.0 else -1.0
        b = step if lo < step < hi else 0.5 * (lo + hi)
        if hi - lo < 1e-12 * hi:
            break
        g, slope = _log_survival(u, b)
    return b / spread, math.exp(g)


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
            if m == REFLECT:
                width = upper[d] - lo
                if width > 0.0:
                    t = (x - lo) % (2.0 * width)
                    x = lo + (t if t <= width else 2.0 * width - t)
                else:
                    x = lo
            elif m == WRAP:
                x = lo + (x - lo) % two_pi
            elif m == LOWER:
                x = lo + abs(x - lo)
            elif m == UPPER:
                x = upper[d] - abs(upper[d] - x)
            particles[i, d] = x
