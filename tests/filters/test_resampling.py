"""Resampling schemes: unbiased, the variance of each, deterministic copies, ESS and weights."""

import numpy as np
import pytest

from occupose.filters import RESAMPLING, ess, normalised_weights, resample


def test_resampling_schemes_are_unbiased_and_systematic_stratified_beat_multinomial(rng):
    weights = np.array([0.31, 0.02, 0.17, 0.0, 0.05, 0.25, 0.2])
    n, draws = 20, 3000
    variance = {}
    for scheme in RESAMPLING:
        log_weights = np.log(np.where(weights > 0, weights, 1.0)) - np.where(weights > 0, 0.0, np.inf)
        counts = np.array([np.bincount(resample(log_weights, rng, scheme, n), minlength=weights.size)
                           for _ in range(draws)])
        assert (counts.sum(axis=1) == n).all() and (counts[:, 3] == 0).all()
        # the mean count is n * w within 5 standard errors of the multinomial variance (the largest)
        bound = 5 * np.sqrt(n * weights * (1 - weights) / draws) + 1e-12
        assert np.all(np.abs(counts.mean(axis=0) - n * weights) <= bound), scheme
        variance[scheme] = counts.var(axis=0).sum()
    expected_multinomial = (n * weights * (1 - weights)).sum()
    assert variance["multinomial"] == pytest.approx(expected_multinomial, rel=0.1)
    for scheme in ("systematic", "stratified", "residual"):
        assert variance[scheme] < 0.6 * variance["multinomial"], (scheme, variance)


def test_systematic_and_residual_keep_the_deterministic_copies(rng):
    weights = rng.dirichlet(np.ones(50))
    n = 50
    for _ in range(100):
        systematic = np.bincount(RESAMPLING["systematic"](np.log(weights), n, rng), minlength=50)
        assert np.all((systematic >= np.floor(n * weights)) & (systematic <= np.ceil(n * weights)))
        residual = np.bincount(RESAMPLING["residual"](np.log(weights), n, rng), minlength=50)
        assert np.all(residual >= np.floor(n * weights)) and residual.sum() == n


def test_residual_without_remainder_is_exact(rng):
    indices = RESAMPLING["residual"](np.log([0.5, 0.25, 0.25]), 8, rng)
    assert indices.tolist() == [0, 0, 0, 0, 1, 1, 2, 2]


def test_ess_and_normalised_weights():
    assert ess(np.zeros(40)) == pytest.approx(40)
    assert ess([0.0, -np.inf, -np.inf]) == pytest.approx(1)
    assert ess([np.log(0.5), np.log(0.5), -np.inf, -np.inf]) == pytest.approx(2)
    weights = np.array([0.1, 0.2, 0.7])
    assert ess(np.log(weights) - 5000.0) == pytest.approx(1 / (weights ** 2).sum())  # no underflow
    assert normalised_weights([-1e6, -1e6 + np.log(3)]) == pytest.approx([0.25, 0.75])
    assert normalised_weights([-np.inf, -np.inf]) == pytest.approx([0.5, 0.5])
    with pytest.raises(ValueError, match="NaN"):
        normalised_weights([0.0, np.nan])
    with pytest.raises(ValueError, match="valid names: multinomial, systematic, stratified, residual"):
        resample(np.zeros(3), np.random.default_rng(0), "sytematic")
