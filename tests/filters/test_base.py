"""What every filter shares (occupose.filters.base and the registry): limits and the circular
mean, the +-pi seam, seeds, frozen DOFs, diagnostics, diffusion scales and clear errors."""

import numpy as np
import pytest

from occupose.filters import FILTERS, filter_options, make_filter, mean_pose
from occupose.filters.base import apply_limits


# ----------------------------------------------------------------------- limits, the mean
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


@pytest.mark.parametrize("name", list(FILTERS))
def test_filters_track_an_angle_across_the_seam(name, heading):
    pf = make_filter(name, heading(), 500, np.random.default_rng(4))
    pf.initialise([-np.pi + 0.2], 0.1)  # 0.35 rad away, on the other side of the seam
    for _ in range(5):
        estimate = pf.step()[0]
    assert abs(np.angle(np.exp(1j * (estimate - heading.target)))) < 0.03
    assert (pf.particles >= -np.pi).all() and (pf.particles < np.pi).all()


# ---------------------------------------------------------------------------- every filter
@pytest.mark.parametrize("name", list(FILTERS))
def test_same_seed_same_run(name, separable):
    runs = []
    for _ in range(2):
        problem = separable(num_parts=3, width=2, chain=True)
        pf = make_filter(name, problem, 64, np.random.default_rng(11))
        pf.initialise(np.zeros(6), 0.2)
        runs.append(np.array([pf.step() for _ in range(4)]))
    np.testing.assert_array_equal(runs[0], runs[1])


@pytest.mark.parametrize("name", list(FILTERS))
def test_inactive_dofs_are_frozen_and_limits_hold(name, separable):
    problem = separable(num_parts=3, width=2, chain=True, step=0.5)
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
def test_diagnostics(name, separable):
    problem = separable(num_parts=3, width=2)
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


def test_diffusion_scale_widens_the_search(separable):
    spreads = []
    for scale in (1.0, 4.0):
        problem = separable(num_parts=1, width=2, sigma=100.0, step=0.05)  # flat likelihood
        pf = make_filter("sir", problem, 2000, np.random.default_rng(0))
        pf.initialise(np.zeros(2), 0.0)
        pf.step(diffusion_scale=np.array([scale, 1.0]))
        spreads.append(pf.particles.std(axis=0))
    assert spreads[1][0] == pytest.approx(4 * spreads[0][0], rel=0.1)
    assert spreads[1][1] == pytest.approx(spreads[0][1], rel=0.1)


def test_bad_options_and_problems_give_clear_errors(separable, groups):
    problem = separable(num_parts=2, width=1)
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
