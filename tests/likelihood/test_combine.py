"""The registry and sums of terms, and the true pose scoring best over body shapes for the
points, points+free and render likelihoods."""

import numpy as np
import pytest

from occupose.body import BODY_MODELS, pose_from_joints
from occupose.likelihood import LIKELIHOODS, FreeSpaceLikelihood, PointsLikelihood, make_likelihood, sum_of
from occupose.synth import motion as pm

FULL = BODY_MODELS["full"]


def test_true_pose_scores_best_over_body_shapes(frame, room, perturbed, model_capsules, full_dofs, arms_out):
    """Six random body shapes and noise draws, each DOF moved by 0.25 rad / 5 cm either way:
    ``points+free`` and ``render`` rank the true pose first on all six; ``points`` alone on
    five (on the sixth a thigh 0.25 rad forward, nearer the camera, fits the front of the
    thicker rendered thigh better: the points term sees only the near surface, and the
    free-space term is what vetoes the model leg in front of it)."""
    joints = pm.joints_from_procedural(pm.pose_with(pm.stance(), **arms_out))
    pose = pose_from_joints(FULL, joints)
    capsules = model_capsules(FULL, perturbed(FULL, pose, full_dofs))
    wins = {"points": 0, "points+free": 0, "render": 0}
    for seed in range(6):
        obs = frame(joints, static=room, seed=seed)
        for name in wins:
            total = make_likelihood(name, obs).evaluate(*capsules).sum(axis=1)
            wins[name] += bool(np.all(total[1:] < total[0]))
    assert wins == {"points": 5, "points+free": 6, "render": 6}


def test_registry_and_sums(front, perturbed, model_capsules):
    obs, pose = front
    assert {"points", "free", "points+free", "render", "color", "points+color"} <= set(LIKELIHOODS)
    with pytest.raises(ValueError, match="valid names"):
        make_likelihood("nope", obs)
    capsules = model_capsules(FULL, perturbed(FULL, pose, ("x",)))
    both = make_likelihood("points+free", obs, points={"scale": 0.02}, free={"weight": 3.0})
    want = (PointsLikelihood(obs, scale=0.02).evaluate(*capsules)
            + FreeSpaceLikelihood(obs, weight=3.0).evaluate(*capsules))
    np.testing.assert_allclose(both.evaluate(*capsules), want)
    with pytest.raises(ValueError, match="as a dict under its name"):
        make_likelihood("points+free", obs, scale=0.02)
    with pytest.raises(ValueError, match="two or more"):
        sum_of("points", "nope")
    assert np.all(make_likelihood("color", obs).evaluate(*capsules) == 0.0)  # no reference yet
