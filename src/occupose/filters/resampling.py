"""Resampling schemes and the effective sample size, from log-weights.

Weights arrive as log-weights (any additive constant; ``-inf`` = weight 0) and are
normalised with the log-sum-exp trick, so likelihoods far below ``exp(-745)`` still
resample correctly. Every scheme draws ``num`` ancestor indices with
``E[count_i] = num * w_i`` (unbiased); systematic and stratified draws have a lower
variance than multinomial, residual copies ``floor(num * w_i)`` deterministically and
draws the rest multinomially (Douc, Cappe & Moulines 2005, "Comparison of resampling
schemes for particle filtering").
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np


def normalised_weights(log_weights) -> np.ndarray:
    """Weights summing to 1 from log-weights.

    log_weights : (N,) float, natural log, any additive constant; -inf = weight 0
    Returns (N,) float64. All -inf (no particle explains the data) gives uniform weights.
    """
    log_weights = np.asarray(log_weights, dtype=np.float64)
    if log_weights.ndim != 1 or log_weights.size == 0:
        raise ValueError(f"log_weights must be a non-empty (N,) array, got shape {log_weights.shape}")
    top = log_weights.max()
    if np.isnan(top) or np.isnan(log_weights).any():
        raise ValueError("log_weights contain NaN")
    if top == np.inf:
        raise ValueError("log_weights contain +inf")
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


def _search(cumulative: np.ndarray, points: np.ndarray) -> np.ndarray:
    """Indices i with cumulative[i-1] <= point < cumulative[i] (points scaled to the total)."""
    indices = np.searchsorted(cumulative, points * cumulative[-1], side="right")
    return np.minimum(indices, cumulative.size - 1)


def multinomial(weights: np.ndarray, num: int, rng: np.random.Generator) -> np.ndarray:
    """``num`` independent draws from the categorical distribution ``weights``.

    weights : (N,) float64, non-negative, summing to 1
    Returns (num,) int64 ancestor indices (unsorted).
    """
    return _search(np.cumsum(weights), rng.random(_check_num(num)))


def systematic(weights: np.ndarray, num: int, rng: np.random.Generator) -> np.ndarray:
    """One uniform offset u, points ``(u + j) / num``: each count within 1 of ``num * w_i``.

    weights : (N,) float64, non-negative, summing to 1
    Returns (num,) int64 ancestor indices, sorted.
    """
    num = _check_num(num)
    return _search(np.cumsum(weights), (rng.random() + np.arange(num)) / num)


def stratified(weights: np.ndarray, num: int, rng: np.random.Generator) -> np.ndarray:
    """One uniform point in each of the ``num`` strata ``[j / num, (j + 1) / num)``.

    weights : (N,) float64, non-negative, summing to 1
    Returns (num,) int64 ancestor indices, sorted.
    """
    num = _check_num(num)
    return _search(np.cumsum(weights), (rng.random(num) + np.arange(num)) / num)


def residual(weights: np.ndarray, num: int, rng: np.random.Generator) -> np.ndarray:
    """``floor(num * w_i)`` copies of each particle, the remaining draws multinomial on the residuals.

    weights : (N,) float64, non-negative, summing to 1
    Returns (num,) int64 ancestor indices (the deterministic copies first, sorted).
    """
    num = _check_num(num)
    expected = num * np.asarray(weights, dtype=np.float64)
    copies = np.floor(expected).astype(np.int64)
    indices = np.repeat(np.arange(expected.size), copies)
    rest = num - indices.size
    if rest == 0:
        return indices
    leftover = expected - copies
    return np.concatenate([indices, multinomial(leftover / leftover.sum(), rest, rng)])


#: Resampling schemes by name: ``f(weights (N,) summing to 1, num, rng) -> (num,) int64 indices``.
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

    log_weights : (N,) float, natural log, any additive constant; -inf = weight 0
    rng : np.random.Generator
    scheme : a key of RESAMPLING
    num : number of draws (default N)
    Returns (num,) int64 indices into the N particles.
    """
    check_scheme(scheme)
    if not isinstance(rng, np.random.Generator):
        raise ValueError(f"rng must be a np.random.Generator, got {type(rng).__name__}")
    weights = normalised_weights(log_weights)
    return RESAMPLING[scheme](weights, weights.size if num is None else num, rng)
