"""Body widths fitted to a person's frames (occupose.proportions), on rendered procedural bodies."""

import math
from dataclasses import replace

import numpy as np
import pytest

from occupose.body import body_model, joints_from_poses, pose_from_joints
from occupose.joints import JOINT_INDEX
from occupose.proportions import FittedProportions, fit_proportions
from occupose.synth import motion as pm
from occupose.synth.generate import person_observations
from occupose.synth.scenarios import build_scenario

AVERAGE = pm.DEFAULT_DIMS.scaled(1.75)
FRAMES = range(0, 60, 6)


def _frames(dims: pm.BodyDims):
    """(joints (T, 15, 3), observations of FRAMES) of a person of ``dims`` who walks towards
    the camera of no_occlusion and waves (procedural motion)."""
    scenario = build_scenario("no_occlusion", use_mocap=False)
    joints = pm.MotionBuilder((0.3, 3.6), -math.pi / 2, dims, scenario.fps).walk([(0.3, 2.6)]).wave("right", 1.0)
    joints = joints.joints()
    scenario = replace(scenario, people=(replace(scenario.people[0], joints=joints),))
    observations = person_observations(scenario, FRAMES[-1] + 1)
    return joints, [observations[k] for k in FRAMES]


def _fit_three_times(dims: pm.BodyDims) -> tuple[list[FittedProportions], np.ndarray]:
    """Three fits as the tracker runs them, each from poses of the last fit's model (here
    fitted to the true joints in place of the tracker's estimates), and the joints (15, 3)
    of the last frame's pose given to the last fit."""
    joints, observations = _frames(dims)
    model, fits = body_model("full", AVERAGE), []
    for _ in range(3):
        poses = np.array([pose_from_joints(model, joints[k]) for k in FRAMES])
        fits.append(fit_proportions(model, poses, observations))
        given = joints_from_poses(model, poses[-1:])[0]
        model = body_model("full", fits[-1].dims)
    return fits, given


def test_narrow_shoulders_are_found_and_an_average_body_stays_average():
    narrow = replace(AVERAGE, shoulder_width=0.7 * AVERAGE.shoulder_width, shoulder_drop=0.7 * AVERAGE.shoulder_drop)
    fits, given = _fit_three_times(narrow)
    width = [f.dims.shoulder_width / AVERAGE.shoulder_width for f in fits]
    assert width[0] < 0.95 and width[-1] < 0.82  # measured 0.90, 0.81, 0.77 (truth 0.7)
    assert all(f.gain > 0.3 for f in fits)  # nats over 10 frames: measured 1.6, 0.9, 0.7
    last = fits[-1].dims
    assert last.shoulder_drop / last.shoulder_width == pytest.approx(AVERAGE.shoulder_drop / AVERAGE.shoulder_width)
    # only the widths change: the lengths (and so the stature) stay
    assert replace(last, shoulder_width=AVERAGE.shoulder_width, shoulder_drop=AVERAGE.shoulder_drop,
                   pelvis_width=AVERAGE.pelvis_width) == AVERAGE
    # the pose handed back keeps the last frame's joints, but for the shoulders and hips
    returned = joints_from_poses(body_model("full", last), fits[-1].pose[None])[0]
    kept = [JOINT_INDEX[name] for name in ("neck", "pelvis", "left_elbow", "right_wrist", "left_knee", "right_ankle")]
    assert np.linalg.norm(returned[kept] - given[kept], axis=1).max() < 0.05

    average, _ = _fit_three_times(AVERAGE)
    assert all(f.dims == AVERAGE and f.gain == 0.0 for f in average)


def test_fit_proportions_bad_input():
    model = body_model("full", AVERAGE)
    _, observations = _frames(AVERAGE)
    with pytest.raises(ValueError, match="poses must have shape"):
        fit_proportions(model, np.zeros((2, 3)), observations[:2])
    with pytest.raises(ValueError, match="observations must be 2 Observations"):
        fit_proportions(model, np.zeros((2, model.num_dofs)), observations[:3])
