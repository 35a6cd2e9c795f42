"""Resampling schemes and the effective sample size, from log-weights.

Weights arrive as log-weights (any additive constant; ``-inf`` = weight 0) and are
normalised with the log-sum-exp trick, so likelihoods far below ``exp(-745)`` still
resample correctly. Each scheme draws its points in [0, 1) from the Generator and a numba
kernel finds their ancestors in the cumulative weights. Every scheme draws ``num`` ancestor indices with
``E[count_i] = num * w_i`` (unbiased); systematic and stratified draws have a lower
variance than multinomial, residual copies ``floor(num * w_i)`` deterministically and
draws the rest multinomially (Douc, Cappe & Moulines 2005, "Comparison of resampling
schemes for particle filtering").
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from occupose.filters import _kernels


def _checked(log_weights) -> np.ndarray:
    """(N,) float64 log-weights, with a clear error for a wrong shape, NaN or +inf."""
    log_weights = np.asarray(log_weights, dtype=np.float64)
    if log_weights.ndim != 1 or log_weights.size == 0:
        raise ValueError(f"log_weights must be a non-empty (N,) array, got shape {log_weights.shape}")
    top = log_weights.max()  # NaN anywhere propagates
    if np.isnan(top):
        raise ValueError("log_weights contain NaN")
    if top == np.inf:
        raise ValueError("log_weights contain +inf")
    return log_weights


def normalised_weights(log_weights) -> np.ndarray:
    """Weights summing to 1 from log-weights.

    log_weights : (N,) float, natural log, any additive constant; -inf = weight 0
    Returns (N,) float64. All -inf (no particle explains the data) gives uniform weights.
    """
    log_weights = _checked(log_weights)
    top = log_weights.max()
    if top == -np.inf:
        return np.full(log_weights.size, 1.0 / log_weights.size)
    weights = np.exp(log_weights - top)
    return weights / weights.sum()


def ess(log_weights) -> float:
    """Effective sample size ``1 / sum(w_i^2)`` of normalised weights, in [1, N].

    log_weights : (N,) float, natural log, any additive constant
    """
    weights = normalised_weights(log_weights)
    return float(1.0 / np.dot(weights, weights))


def _check_num(num) -> int:
    if int(num) != num or num < 1:
        raise ValueError(f"num must be a positive integer, got {num!r}")
    return int(num)


def multinomial(log_weights: np.ndarray, num: int, rng: np.random.Generator) -> np.ndarray:
    """``num`` independent draws from the categorical distribution of the weights.

    log_weights : (N,) float64, checked (no NaN / +inf)
    Returns (num,) int64 ancestor indices (unsorted).
    """
    points = rng.random(_check_num(num))
    return _kernels.ancestors_from_points(log_weights, points, np.empty(points.size, np.int64))


def systematic(log_weights: np.ndarray, num: int, rng: np.random.Generator) -> np.ndarray:
    """One uniform offset u, points ``(u + j) / num``: each count within 1 of ``num * w_i``.

    log_weights : (N,) float64, checked (no NaN / +inf)
    Returns (num,) int64 ancestor indices, sorted.
    """
    num = _check_num(num)
    points = (rng.random() + np.arange(num)) / num
    return _kernels.ancestors_from_points(log_weights, points, np.empty(num, np.int64))


def stratified(log_weights: np.ndarray, num: int, rng: np.random.Generator) -> np.ndarray:
    """One uniform point in each of the ``num`` strata ``[j / num, (j + 1) / num)``.

    log_weights : (N,) float64, checked (no NaN / +inf)
    Returns (num,) int64 ancestor indices, sorted.
    """
    num = _check_num(num)
    points = (rng.random(num) + np.arange(num)) / num
    return _kernels.ancestors_from_points(log_weights, points, np.empty(num, np.int64))


def residual(log_weights: np.ndarray, num: int, rng: np.random.Generator) -> np.ndarray:
    """``floor(num * w_i)`` copies of each particle, the remaining draws multinomial on the residuals.

    log_weights : (N,) float64, checked (no NaN / +inf)
    Returns (num,) int64 ancestor indices (the deterministic copies first, sorted).
    """
    num = _check_num(num)
    expected = num * normalised_weights(log_weights)
    copies = np.floor(expected).astype(np.int64)
    indices = np.repeat(np.arange(expected.size), copies)
    rest = num - indices.size
    if rest == 0:
        return indices
    with np.errstate(divide="ignore"):
        leftover = np.log(expected - copies)
    return np.concatenate([indices, multinomial(leftover, rest, rng)])


#: Resampling schemes by name: ``f(log_weights (N,), num, rng) -> (num,) int64 ancestor indices``.
RESAMPLING: dict[str, Callable[[np.ndarray, int, np.random.Generator], np.ndarray]] = {
    "multinomial": multinomial, "systematic": systematic, "stratified": stratified, "residual": residual,
}


def check_scheme(scheme: str) -> str:
    """``scheme`` if it is a key of RESAMPLING; ValueError listing the valid names otherwise."""
    if scheme not in RESAMPLING:
        raise ValueError(f"unknown resampling scheme {scheme!r}; valid names: {', '.join(RESAMPLING)}")
    return scheme


def resample(log_weights, rng: np.random.Generator, scheme: str = "systematic", num: int | None = None) -> np.ndarray:
    """Ancestor indices drawn from log-weights with the scheme registered as ``scheme``.

    log_weights : (N,) float, natural log, any additive constant; -inf = weight 0 (all -inf: equal)
    rng : np.random.Generator
    scheme : a key of RESAMPLING
    num : number of draws (default N)
    Returns (num,) int64 indices into the N particles.
    """
    check_scheme(scheme)
    if not isinstance(rng, np.random.Generator):
        raise ValueError(f"rng must be a np.random.Generator, got {type(rng).__name__}")
    log_weights = _checked(log_weights)
    return RESAMPLING[scheme](log_weights, log_weights.size if num is None else num, rng)
