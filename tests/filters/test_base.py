"""Resampling, the annealing kernel, limits, and every filter on toy problems with known answers."""

from dataclasses import dataclass

import numpy as np
import pytest
from scipy.optimize import brentq

from occupose.filters import (FILTERS, RESAMPLING, ess, filter_options, make_filter, mean_pose, normalised_weights,
                              resample)
from occupose.filters import _kernels
from occupose.filters.base import apply_limits, limit_modes
from occupose.filters.layered import spread_layers


@dataclass
class Group:
    dofs: np.ndarray
    parts: np.ndarray


def groups(*pairs):
    return [Group(np.asarray(d), np.asarray(p)) for d, p in pairs]


class RandomWalk1D:
    """x_t = x_{t-1} + N(0, q^2), y_t = x_t + N(0, r^2): the Kalman filter gives the exact posterior."""

    def __init__(self, q, r):
        self.num_dofs = 1
        self.limits = np.array([[-np.inf, np.inf]])
        self.angular = np.array([False])
        self.diffusion = np.array([q])
        self.partitions = self.weight_groups = groups(([0], [0]))
        self.r = r
        self.y = 0.0

    def log_likelihood(self, poses):
        return -0.5 * ((poses[:, :1] - self.y) / self.r) ** 2


class Separable:
    """G parts of ``width`` DOFs each; part k's log-likelihood depends on its own DOFs only.

    Partitions and weight groups are the parts; ``chain`` makes part k's point the sum of the
    DOF blocks 0..k (a kinematic chain: the child's score depends on its parent's DOFs).
    """

    def __init__(self, num_parts, width, sigma=0.1, step=0.05, chain=False, seed=0):
        d = num_parts * width
        self.num_dofs = d
        self.limits = np.tile([-5.0, 5.0], (d, 1))
        self.angular = np.zeros(d, bool)
        self.diffusion = np.full(d, step)
        blocks = np.arange(d).reshape(num_parts, width)
        self.partitions = self.weight_groups = groups(*[(b, [k]) for k, b in enumerate(blocks)])
        self.blocks, self.sigma, self.chain = blocks, sigma, chain
        self.target = np.random.default_rng(seed).uniform(-1, 1, d)
        self.calls = 0

    def points(self, poses):
        parts = poses[:, self.blocks]  # (P, G, width)
        return np.cumsum(parts, axis=1) if self.chain else parts

    def log_likelihood(self, poses):
        self.calls += 1
        goal = self.points(self.target[None])[0]
        return -0.5 * (((self.points(poses) - goal) / self.sigma) ** 2).sum(axis=2)


def kalman(ys, m, p, q, r):
    """Posterior means and variances of the 1-D random walk."""
    out = []
    for y in ys:
        p = p + q * q
        gain = p / (p + r * r)
        m, p = m + gain * (y - m), (1 - gain) * p
        out.append((m, p))
    return np.array(out)


# ---------------------------------------------------------------------------------- resampling
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


# ------------------------------------------------------------------------------------- kernels
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


def test_apply_limits_by_hand():
    limits = np.array([[0.0, 1.0], [-np.pi, np.pi], [0.0, np.inf]])
    angular = np.array([False, True, False])
    values = np.array([[1.25, np.pi + 0.25, -0.5], [-0.25, -np.pi - 0.5, 3.0], [2.5, 0.0, 0.0]])
    np.testing.assert_allclose(apply_limits(values, limits, angular),
                               [[0.75, -np.pi + 0.25, 0.5], [0.25, np.pi - 0.5, 3.0], [0.5, 0.0, 0.0]])


def test_circular_mean_across_the_seam():
    poses = np.array([[np.pi - 0.1, 1.0], [-np.pi + 0.1, 3.0], [np.pi - 0.2, 2.0]])
    weights = np.array([0.5, 0.3, 0.2])
    angular = np.array([True, False])
    mean = mean_pose(poses, weights, angular)
    offsets = np.array([-0.1, 0.1, -0.2])  # angles measured from pi
    assert abs(abs(mean[0]) - np.pi) < 0.1  # at the seam (the linear mean would be 1.2 rad)
    assert np.angle(np.exp(1j * (mean[0] - np.pi))) == pytest.approx(np.angle(weights @ np.exp(1j * offsets)))
    assert mean[1] == pytest.approx(weights @ poses[:, 1])
    # with limits [0, 2 pi) the mean of 0.1 and 2 pi - 0.1 is 0, not pi
    assert mean_pose(np.array([[0.1], [2 * np.pi - 0.1]]), np.array([0.5, 0.5]), np.array([True]),
                     np.array([[0.0, 2 * np.pi]]))[0] == pytest.approx(0.0, abs=1e-12)


class Heading:
    """One full-turn angle observed through a von Mises likelihood centred near the +-pi seam."""

    num_dofs = 1
    limits = np.array([[-np.pi, np.pi]])
    angular = np.array([True])
    diffusion = np.array([0.2])
    partitions = weight_groups = groups(([0], [0]))
    target = np.pi - 0.05

    def log_likelihood(self, poses):
        return 50.0 * np.cos(poses - self.target)


@pytest.mark.parametrize("name", list(FILTERS))
def test_filters_track_an_angle_across_the_seam(name):
    pf = make_filter(name, Heading(), 500, np.random.default_rng(4))
    pf.initialise([-np.pi + 0.2], 0.1)  # 0.35 rad away, on the other side of the seam
    for _ in range(5):
        estimate = pf.step()[0]
    assert abs(np.angle(np.exp(1j * (estimate - Heading.target)))) < 0.03
    assert (pf.particles >= -np.pi).all() and (pf.particles < np.pi).all()


# ------------------------------------------------------------------------------ known posteriors
def test_sir_converges_to_the_kalman_posterior_mean():
    q, r = 1.0, 1.0
    data = np.random.default_rng(7)
    ys = np.cumsum(data.standard_normal(20) * q) + data.standard_normal(20) * r
    exact = kalman(ys, 0.0, 1.0, q, r)
    rms = {}
    for n in (250, 4000):
        problem = RandomWalk1D(q, r)
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


def test_apf_converges_to_its_annealed_gaussian_limit():
    q, r, y, n = 1.0, 1.0, 2.0, 20000
    problem = RandomWalk1D(q, r)
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


def test_apf_final_weights_keep_the_target_share_of_particles():
    problem = RandomWalk1D(1.0, 1.0)
    problem.y = 1.0
    apf = make_filter("apf", problem, 5000, np.random.default_rng(0), num_layers=1)
    apf.initialise([0.0], [1.0])
    apf.step()
    assert ess(apf.log_weights) / 5000 == pytest.approx(0.5, rel=1e-4)


# ---------------------------------------------------------------------------- partitions, parts
@pytest.mark.parametrize("name, options", [("ps", {}), ("apf+ps", {"num_layers": 3})])
def test_partitioned_filters_find_the_mode_of_a_chain(name, options):
    problem = Separable(num_parts=2, width=2, sigma=0.05, step=0.1, chain=True, seed=4)
    pf = make_filter(name, problem, 300, np.random.default_rng(5), **options)
    pf.initialise(np.zeros(4), 0.3)
    for _ in range(15):
        estimate = pf.step()
    assert np.abs(estimate - problem.target).max() < 0.05
    calls_per_step = 2 * options.get("num_layers", 1)
    assert pf.diagnostics["likelihood_evaluations"] == 300 * calls_per_step
    assert len(pf.diagnostics["betas"]) == calls_per_step


def test_apf_ps_layers_per_partition():
    problem = Separable(num_parts=3, width=1)
    pf = make_filter("apf+ps", problem, 50, np.random.default_rng(0), num_layers=[3, 1, 2])
    pf.initialise(np.zeros(3), 0.1)
    pf.step()
    assert pf.diagnostics["likelihood_evaluations"] == 50 * 6


def test_an_idle_partition_gives_its_layers_to_the_others():
    """Legs hidden behind a table: their stage's 2 layers go to the others, (3, 2) not (2, 1)."""
    assert spread_layers(5, 2) == (3, 2) and spread_layers(5, 3) == (2, 2, 1) and spread_layers(2, 3) == (1, 1, 0)
    problem = Separable(num_parts=3, width=2)
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


def _track(name, problem, n, seed, steps, **options):
    pf = make_filter(name, problem, n, np.random.default_rng(seed), **options)
    pf.initialise(np.zeros(problem.num_dofs), 0.5)
    errors = []
    for _ in range(steps):
        problem.target += np.random.default_rng(len(errors)).normal(0, 0.02, problem.num_dofs)
        errors.append(np.abs(pf.step() - problem.target).mean())
    return np.mean(errors[steps // 2:]), pf


def test_part_based_beats_a_whole_vector_filter_of_the_same_budget():
    """6 parts x 4 DOFs (24, about a body): over 5 seeds part-based 0.013, SIR 0.033-0.05 mean error."""
    results = {}
    for name in ("part-based", "sir"):
        problem = Separable(num_parts=6, width=4, sigma=0.1, step=0.05, seed=1)
        results[name], pf = _track(name, problem, 200, 2, 40)
        assert problem.calls == 40  # the same budget: one likelihood call of 200 particles per step
    assert results["part-based"] < 0.5 * results["sir"], results
    assert pf.log_weights.shape == (200,)


class SharedScore(Separable):
    """Every part gets the same column (the total score): the groups' weights are identical."""

    def log_likelihood(self, poses):
        total = super().log_likelihood(poses).sum(axis=1, keepdims=True)
        return np.repeat(total, len(self.blocks), axis=1)


def test_shuffling_recombines_the_parts():
    """Systematic resampling returns sorted ancestors, so without the permutation of eq. 4 a new
    particle takes every part from ancestors of about the same rank: with equal group weights
    (they differ only by each draw's random offset) 30 % of the new particles are plain copies
    of old ones. With it, almost every new particle is a new combination of parts."""
    novel = {}
    for shuffle in (True, False):
        problem = SharedScore(num_parts=5, width=2, sigma=2.0, seed=3)
        problem.diffusion[:] = 0.0  # only resampling and shuffling change the particles
        pf = make_filter("part-based", problem, 200, np.random.default_rng(8), shuffle=shuffle)
        pf.initialise(np.zeros(10), 0.5)
        pf.step()
        before = {row.tobytes() for row in pf.particles}
        pf.step()
        novel[shuffle] = np.mean([row.tobytes() not in before for row in pf.particles])
        assert pf.log_weights.shape == (200, 5)
        assert pf.diagnostics["group_survival"].shape == (5,)
        assert pf.diagnostics["group_survival"].min() > 0.3
    assert novel[True] > 0.95 and novel[False] < 0.8, novel


# ---------------------------------------------------------------------------- every filter
@pytest.mark.parametrize("name", list(FILTERS))
def test_same_seed_same_run(name):
    runs = []
    for _ in range(2):
        problem = Separable(num_parts=3, width=2, chain=True)
        pf = make_filter(name, problem, 64, np.random.default_rng(11))
        pf.initialise(np.zeros(6), 0.2)
        runs.append(np.array([pf.step() for _ in range(4)]))
    np.testing.assert_array_equal(runs[0], runs[1])


@pytest.mark.parametrize("name", list(FILTERS))
def test_inactive_dofs_are_frozen_and_limits_hold(name):
    problem = Separable(num_parts=3, width=2, chain=True, step=0.5)
    problem.limits[:, :] = [-0.4, 0.6]
    pf = make_filter(name, problem, 80, np.random.default_rng(2))
    pf.initialise(np.full(6, 0.1), 0.3)
    first = pf.step()
    active = np.array([True, True, False, False, True, True])
    for _ in range(3):
        estimate = pf.step(active=active, diffusion_scale=np.array([1, 1, 1, 1, 2, 2.0]))
        assert (pf.particles[:, ~active] == first[~active]).all()
        assert (estimate[~active] == first[~active]).all()
        assert (pf.particles >= -0.4).all() and (pf.particles <= 0.6).all()
    assert not np.allclose(estimate[active], first[active])
    nothing = pf.step(active=np.zeros(6, bool))
    assert (nothing == estimate).all() and pf.diagnostics["likelihood_evaluations"] == 0


@pytest.mark.parametrize("name", list(FILTERS))
def test_diagnostics(name):
    problem = Separable(num_parts=3, width=2)
    pf = make_filter(name, problem, 100, np.random.default_rng(0))
    pf.initialise(np.zeros(6), 0.3)
    pf.step()
    d = pf.diagnostics
    assert 1 <= d["ess"] <= 100
    assert d["survival"].shape == (3,) and ((d["survival"] > 0) & (d["survival"] <= 1)).all()
    assert d["likelihood_evaluations"] == 100 * problem.calls
    assert set(d["seconds"]) == {"diffuse", "likelihood", "weight", "resample"}
    assert all(v >= 0 for v in d["seconds"].values())
    assert len(d["betas"]) == len(d["layer_survival"]) >= 1


def test_diffusion_scale_widens_the_search():
    spreads = []
    for scale in (1.0, 4.0):
        problem = Separable(num_parts=1, width=2, sigma=100.0, step=0.05)  # flat likelihood
        pf = make_filter("sir", problem, 2000, np.random.default_rng(0))
        pf.initialise(np.zeros(2), 0.0)
        pf.step(diffusion_scale=np.array([scale, 1.0]))
        spreads.append(pf.particles.std(axis=0))
    assert spreads[1][0] == pytest.approx(4 * spreads[0][0], rel=0.1)
    assert spreads[1][1] == pytest.approx(spreads[0][1], rel=0.1)


def test_bad_options_and_problems_give_clear_errors():
    problem = Separable(num_parts=2, width=1)
    rng = np.random.default_rng(0)
    with pytest.raises(ValueError, match="valid names: sir, apf, ps, apf\\+ps, part-based"):
        make_filter("condensation", problem, 10, rng)
    with pytest.raises(ValueError, match=r"no option\(s\) \['num_layers'\]; its options: \['resampling'\]"):
        make_filter("sir", problem, 10, rng, num_layers=3)
    assert filter_options("apf+ps") == {"num_layers": 5, "survival": 0.5, "resampling": "systematic"}
    with pytest.raises(ValueError, match="valid names: multinomial"):
        make_filter("apf", problem, 10, rng, resampling="ordered")
    with pytest.raises(ValueError, match="survival"):
        make_filter("apf", problem, 10, rng, survival=1.5)
    with pytest.raises(ValueError, match="num_layers"):
        make_filter("apf+ps", problem, 10, rng, num_layers=[2, 2, 2])
    with pytest.raises(ValueError, match="num_particles"):
        make_filter("sir", problem, 0, rng)
    with pytest.raises(ValueError, match="np.random.Generator"):
        make_filter("sir", problem, 10, 42)
    problem.partitions = groups(([0], [0]))
    with pytest.raises(ValueError, match="every DOF 0..1 exactly once"):
        make_filter("ps", problem, 10, rng)
    problem.partitions = groups(([0], [0]), ([1], [5]))
    pf = make_filter("ps", problem, 10, rng)
    pf.initialise([0.0, 0.0], 0.1)
    with pytest.raises(ValueError, match="names part 5 but log_likelihood gives 2 parts"):
        pf.step()
    pf = make_filter("sir", problem, 10, rng)
    with pytest.raises(RuntimeError, match="initialise"):
        pf.step()
    pf.initialise([0.0, 0.0], 0.1)
    with pytest.raises(ValueError, match="active"):
        pf.step(active=np.ones(3, bool))
    with pytest.raises(ValueError, match="diffusion_scale"):
        pf.step(diffusion_scale=-1.0)
    problem.log_likelihood = lambda poses: np.zeros(len(poses))
    with pytest.raises(ValueError, match=r"must return \(10, K\)"):
        pf.step()
