"""occupose.body.dynamics: the diffusion motion model (scales, statistics, limits) and the
root drift."""

import math

import numpy as np
import pytest
from scipy import stats

from occupose.body import BODY_MODELS, diffuse, diffusion_scales, root_drift, standing_pose


def test_diffusion_scales():
    m = BODY_MODELS["full"]
    s = diffusion_scales(m)
    assert s[m.dof("x")] == 0.02 and s[m.dof("left_elbow")] == 0.10
    s60 = diffusion_scales(m, fps=60.0, shoulder=0.3, left_elbow=0.5)
    assert s60[m.dof("x")] == pytest.approx(0.01)
    assert s60[m.dof("right_shoulder_abd")] == 0.3 and s60[m.dof("left_elbow")] == 0.5
    with pytest.raises(ValueError, match="valid"):
        diffusion_scales(m, elbows=0.1)


def test_diffuse_statistics_and_seed(rng):
    limits = np.array([[-10.0, 10.0], [0.0, 1.0]])
    poses = np.tile([1.0, 0.5], (20000, 1))
    out = diffuse(poses, [0.2, 0.01], limits, np.random.default_rng(3))
    np.testing.assert_allclose(out.mean(axis=0), [1.0, 0.5], atol=0.005)
    np.testing.assert_allclose(out.std(axis=0), [0.2, 0.01], rtol=0.03)
    np.testing.assert_array_equal(out, diffuse(poses, [0.2, 0.01], limits, np.random.default_rng(3)))
    drift = np.array([0.5, 0.0])
    moved = diffuse(poses, [0.0, 0.0], limits, rng, drift=drift)
    np.testing.assert_array_equal(moved, poses + drift)


def test_diffuse_reflects_rejects_clips_and_wraps(rng):
    limits = np.array([[0.0, 1.0], [-math.pi, math.pi]])
    periodic = np.array([False, True])
    poses = np.tile([0.95, 3.0], (20000, 1))
    reflected = diffuse(poses, [0.1, 0.5], limits, rng, periodic=periodic)
    assert reflected[:, 0].max() <= 1.0 and reflected[:, 1].min() >= -math.pi and reflected[:, 1].max() < math.pi
    assert np.mean(reflected[:, 1] < 0) > 0.3           # heading wrapped past pi, not stopped
    one = diffuse(np.array([[0.95, 0.0]]), [0.0, 0.0], limits, rng, drift=[0.35, 0.0])
    assert one[0, 0] == pytest.approx(0.7)              # 1.3 folds back to 0.7
    rejected = diffuse(poses, [0.1, 0.5], limits, rng, periodic=periodic, mode="reject")
    expected = stats.truncnorm((0.0 - 0.95) / 0.1, (1.0 - 0.95) / 0.1, loc=0.95, scale=0.1).mean()
    assert rejected[:, 0].mean() == pytest.approx(expected, abs=0.003)
    clipped = diffuse(poses, [0.1, 0.5], limits, rng, periodic=periodic, mode="clip")
    assert np.mean(clipped[:, 0] == 1.0) == pytest.approx(0.31, abs=0.02)  # P(N > 0.5 sd)
    with pytest.raises(ValueError, match="reflect, reject, clip"):
        diffuse(poses, [0.1, 0.5], limits, rng, mode="bounce")


def test_diffuse_keeps_model_poses_valid(rng):
    m = BODY_MODELS["upper"]
    poses = np.tile(standing_pose(m), (500, 1))
    for _ in range(20):
        poses = diffuse(poses, diffusion_scales(m, scale=3.0), m.limits, rng, periodic=m.periodic)
    assert np.all(poses >= m.limits[:, 0]) and np.all(poses <= m.limits[:, 1])


def test_root_drift():
    m = BODY_MODELS["full"]
    previous = standing_pose(m, (0.0, 0.0))
    current = standing_pose(m, (0.04, -0.02), heading=0.1)
    drift = root_drift(m, previous, current, damping=0.5)
    np.testing.assert_allclose(drift[:4], [0.02, -0.01, 0.0, 0.05], atol=1e-12)
    assert not drift[4:].any()
    # the turn goes the shorter way round, through +-pi
    turned = root_drift(m, standing_pose(m, (0.0, 0.0), heading=3.1), standing_pose(m, (0.0, 0.0), heading=-3.1))
    assert turned[m.dof("heading")] == pytest.approx(2 * np.pi - 6.2)
