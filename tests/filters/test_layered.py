"""The layered filters (SIR, APF, PS, APF+PS) on problems with known answers: the Kalman
posterior, the annealed Gaussian limit, the mode of a chain, layers per partition."""

import numpy as np
import pytest
from scipy.optimize import brentq

from occupose.filters import ess, make_filter
from occupose.filters.layered import spread_layers


def kalman(ys, m, p, q, r):
    """Posterior means and variances of the 1-D random walk."""
    out = []
    for y in ys:
        p = p + q * q
        gain = p / (p + r * r)
        m, p = m + gain * (y - m), (1 - gain) * p
        out.append((m, p))
    return np.array(out)


def test_sir_converges_to_the_kalman_posterior_mean(random_walk):
    q, r = 1.0, 1.0
    data = np.random.default_rng(7)
    ys = np.cumsum(data.standard_normal(20) * q) + data.standard_normal(20) * r
    exact = kalman(ys, 0.0, 1.0, q, r)
    rms = {}
    for n in (250, 4000):
        problem = random_walk(q, r)
        sir = make_filter("sir", problem, n, np.random.default_rng(1))
        sir.initialise([0.0], [1.0])
        estimates = []
        for y in ys:
            problem.y = y
            estimates.append(sir.step()[0])
        errors = np.array(estimates) - exact[:, 0]
        # in units of the posterior standard deviation / sqrt(n), Monte-Carlo runs of this
        # set-up (30 seeds, 250 to 4000 particles) have a standard deviation of 1.3
        assert np.sqrt(np.mean(errors ** 2 / (exact[:, 1] / n))) < 2.5
        rms[n] = np.sqrt(np.mean(errors ** 2))
    assert rms[4000] < 0.03 and rms[4000] < rms[250] / 2  # 1 / sqrt(n): a factor 4 expected


def _annealed_gaussian_limit(m, v, y, q, r, layers, alpha):
    """Mean, variance and betas of the annealed filter with infinitely many particles (1-D Gaussian).

    Each layer adds the diffusion variance (shrunk by alpha per layer), then weights N(m, v)
    by N(y; x, r^2)^beta with the beta whose ESS / N = E[w]^2 / E[w^2] equals alpha.
    """
    betas, s2 = [], q * q
    for _ in range(layers):
        v, d = v + s2, m - y

        def log_rate(beta):
            a, b = r * r + beta * v, r * r + 2 * beta * v
            return np.log(r * r / a) - 0.5 * np.log(r * r / b) - beta * d * d / a + beta * d * d / b - np.log(alpha)

        beta = brentq(log_rate, 1e-12, 1e12)
        betas.append(beta)
        precision = 1 / v + beta / (r * r)
        m, v = (m / v + beta * y / (r * r)) / precision, 1 / precision
        s2 *= alpha
    return m, v, betas


def test_apf_converges_to_its_annealed_gaussian_limit(random_walk):
    q, r, y, n = 1.0, 1.0, 2.0, 20000
    problem = random_walk(q, r)
    problem.y = y
    apf = make_filter("apf", problem, n, np.random.default_rng(3), num_layers=4, survival=0.5)
    apf.initialise([0.0], [1.0])
    estimate = apf.step()[0]
    m, v, betas = _annealed_gaussian_limit(0.0, 1.0, y, q, r, 4, 0.5)
    # Monte-Carlo spread over 20 seeds: estimate sd 0.9 sqrt(v / n), betas 1-2.5 % (relative)
    assert abs(estimate - m) < 5 * np.sqrt(v / n)
    np.testing.assert_allclose(apf.diagnostics["betas"], betas, rtol=0.1)
    np.testing.assert_allclose(apf.diagnostics["layer_survival"], 0.5, rtol=1e-4)
    assert apf.diagnostics["likelihood_evaluations"] == 4 * n
    # a mode seeker: it ends near the observation, sharper than the Kalman posterior (mean 4/3)
    assert m > 1.9 and v < 0.05


def test_apf_final_weights_keep_the_target_share_of_particles(random_walk):
    problem = random_walk(1.0, 1.0)
    problem.y = 1.0
    apf = make_filter("apf", problem, 5000, np.random.default_rng(0), num_layers=1)
    apf.initialise([0.0], [1.0])
    apf.step()
    assert ess(apf.log_weights) / 5000 == pytest.approx(0.5, rel=1e-4)


@pytest.mark.parametrize("name, options", [("ps", {}), ("apf+ps", {"num_layers": 3})])
def test_partitioned_filters_find_the_mode_of_a_chain(name, options, separable):
    problem = separable(num_parts=2, width=2, sigma=0.05, step=0.1, chain=True, seed=4)
    pf = make_filter(name, problem, 300, np.random.default_rng(5), **options)
    pf.initialise(np.zeros(4), 0.3)
    for _ in range(15):
        estimate = pf.step()
    assert np.abs(estimate - problem.target).max() < 0.05
    calls_per_step = 2 * options.get("num_layers", 1)
    assert pf.diagnostics["likelihood_evaluations"] == 300 * calls_per_step
    assert len(pf.diagnostics["betas"]) == calls_per_step


def test_apf_ps_layers_per_partition(separable):
    problem = separable(num_parts=3, width=1)
    pf = make_filter("apf+ps", problem, 50, np.random.default_rng(0), num_layers=[3, 1, 2])
    pf.initialise(np.zeros(3), 0.1)
    pf.step()
    assert pf.diagnostics["likelihood_evaluations"] == 50 * 6


def test_an_idle_partition_gives_its_layers_to_the_others(separable):
    """Legs hidden behind a table: their stage's 2 layers go to the others, (3, 2) not (2, 1)."""
    assert spread_layers(5, 2) == (3, 2) and spread_layers(5, 3) == (2, 2, 1) and spread_layers(2, 3) == (1, 1, 0)
    problem = separable(num_parts=3, width=2)
    pf = make_filter("apf+ps", problem, 50, np.random.default_rng(0), num_layers=[2, 1, 2])
    pf.initialise(np.zeros(6), 0.1)
    active = np.array([True, True, True, True, False, False])
    pf.step(active=active)
    assert pf.diagnostics["likelihood_evaluations"] == 50 * 5  # as with every part in view
    assert len(pf.diagnostics["betas"]) == 5
    pf.step(active=np.array([False, False, True, True, False, False]))
    assert pf.diagnostics["likelihood_evaluations"] == 50 * 5  # one stage left: all 5 layers
    pf.step()
    assert pf.diagnostics["likelihood_evaluations"] == 50 * 5 and pf.num_layers == [2, 1, 2]
