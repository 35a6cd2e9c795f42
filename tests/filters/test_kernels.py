"""The filters' numba kernels against NumPy: the annealing exponent, ancestor search, layer
weights and diffusion within limits."""

import numpy as np
import pytest
from scipy.optimize import brentq

from occupose.filters import ess, normalised_weights
from occupose.filters import _kernels
from occupose.filters.base import apply_limits, limit_modes


def _annealing_reference(values, target):
    """Bisection on beta with NumPy ESS (the slow reference of annealing_exponent)."""
    def survival(beta):
        finite = values[np.isfinite(values)]
        return ess(beta * (finite - finite.max())) / values.size
    return brentq(lambda beta: survival(beta) - target, 1e-9, 1e9, xtol=1e-14, rtol=1e-12)


def test_annealing_exponent_matches_numpy_bisection(rng):
    for case in range(20):
        values = rng.standard_normal(200) * 10 ** rng.uniform(-2, 3) - rng.uniform(0, 1e4)
        if case % 4 == 1:
            values[rng.random(200) < 0.3] = -np.inf
        target = rng.uniform(0.1, 0.6 if case % 4 == 1 else 0.9)  # at most ~70 % finite when 30 % are -inf
        beta, survival = _kernels.annealing_exponent(values, target)
        assert survival == pytest.approx(target, rel=1e-5)
        assert beta == pytest.approx(_annealing_reference(values, target), rel=1e-4)


def test_ancestor_search_matches_numpy_searchsorted(rng):
    for case in range(10):
        log_weights = rng.standard_normal(300) * 20 - 1e3
        log_weights[rng.random(300) < 0.2 * (case % 2)] = -np.inf
        points = np.sort(rng.random(500)) if case % 3 else rng.random(500)
        expected = np.searchsorted(np.cumsum(normalised_weights(log_weights)), points, side="right")
        found = _kernels.ancestors_from_points(log_weights, points, np.empty(500, np.int64))
        np.testing.assert_array_equal(found, np.minimum(expected, 299))
    equal = _kernels.ancestors_from_points(np.full(4, -np.inf), np.array([0.1, 0.3, 0.6, 0.9]), np.empty(4, np.int64))
    assert equal.tolist() == [0, 1, 2, 3]


def test_layer_weights_match_numpy(rng):
    values = rng.standard_normal((100, 6)) * 3
    values[5, 2] = -np.inf
    parts = np.array([0, 2, 5])
    total = values[:, parts].sum(axis=1)
    log_weights, beta, survival = _kernels.layer_weights(values, parts, False, 0.5, np.empty(100))
    assert beta == 1.0 and survival == pytest.approx(ess(total) / 100)
    np.testing.assert_array_equal(log_weights, total)
    log_weights, beta, survival = _kernels.layer_weights(values, parts, True, 0.3, np.empty(100))
    assert beta == pytest.approx(_annealing_reference(total, 0.3), rel=1e-4)
    assert survival == pytest.approx(ess(log_weights) / 100) and survival == pytest.approx(0.3, rel=1e-5)
    np.testing.assert_allclose(log_weights, beta * total)


def test_annealing_exponent_out_of_reach_targets():
    assert _kernels.annealing_exponent(np.full(10, -3.0), 0.5) == (1.0, 1.0)
    values = np.array([0.0] * 6 + [-1.0] * 4)  # 6 tied at the top: ESS / N >= 0.6 for any beta
    beta, survival = _kernels.annealing_exponent(values, 0.5)
    assert survival == pytest.approx(0.6) and beta >= 1e5
    values = np.array([0.0, -1.0] + [-np.inf] * 8)  # at most 2 of 10 survive
    beta, survival = _kernels.annealing_exponent(values, 0.5)
    assert survival == pytest.approx(0.2) and beta < 1e-5


def test_diffusion_kernel_matches_numpy_limits(rng):
    limits = np.array([[-1.0, 2.0], [0.0, np.inf], [-np.inf, 0.5], [-np.inf, np.inf],
                       [-np.pi, np.pi], [0.0, 4 * np.pi], [-np.inf, np.inf], [-0.5, 1.0], [0.3, 0.3]])
    angular = np.array([False, False, False, False, True, True, True, True, False])
    mode, lower, upper = limit_modes(limits, angular)
    particles = rng.uniform(-1, 1, (500, 9))
    dofs = np.array([0, 1, 2, 3, 4, 5, 6, 7, 8])
    noise = rng.standard_normal((500, 9))
    std = np.array([3.0, 2.0, 2.0, 1.0, 9.0, 20.0, 9.0, 4.0, 1.0])
    expected = apply_limits(particles + noise * std, limits, angular)
    _kernels.diffuse_within_limits(particles, dofs, noise, std, lower, upper, mode)
    np.testing.assert_allclose(particles, expected, atol=1e-12)
    inside = (particles >= np.minimum(lower, limits[:, 0]) - 1e-12) & (particles <= upper + 1e-12)
    assert inside[:, [0, 1, 2, 4, 7, 8]].all()
    assert (particles[:, 6] >= -np.pi).all() and (particles[:, 6] < np.pi).all()  # open angle wraps
    assert (particles[:, 5] >= 0).all() and (particles[:, 5] < 2 * np.pi).all()  # full turn or more wraps
