"""occupose.evaluation.pixels on hand-computed cases: the arm error, pixel assignment, foreground scores."""

import math

import numpy as np
import pytest

from occupose.evaluation.pixels import (
    MIN_ARM_POINTS,
    arm_epsilons,
    foreground_scores,
    pixel_assignment_accuracy,
    segment_distances,
)
from occupose.joints import JOINT_INDEX, NUM_JOINTS


# --------------------------------------------------------------------------- arm error


def test_segment_distances_to_the_nearest_segment_its_ends_included():
    starts = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    ends = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])  # a segment and a point
    points = np.array([[0.5, 0.3, 0.4], [-0.3, 0.0, 0.4], [0.0, 0.0, 0.9], [1.6, 0.8, 0.0]])
    np.testing.assert_allclose(segment_distances(points, starts, ends), [0.5, 0.5, 0.1, 1.0])
    with pytest.raises(ValueError, match="shape"):
        segment_distances(points, starts, ends[:1])


def _arm_skeleton():
    """15 joints with both arms hanging straight down from shoulders at z = 1.4 m."""
    joints = np.zeros((NUM_JOINTS, 3))
    for side, x in (("left", 0.2), ("right", -0.2)):
        for joint, z in (("shoulder", 1.4), ("elbow", 1.1), ("wrist", 0.85)):
            joints[JOINT_INDEX[f"{side}_{joint}"]] = (x, 0.0, z)
    return joints


def test_arm_epsilon_is_the_limb_radius_on_the_truth_and_grows_with_a_wrong_arm():
    rng = np.random.default_rng(0)
    skeleton = _arm_skeleton()
    # points on 4 cm cylinders round the two left bones and the right forearm
    z = rng.uniform(0.86, 1.39, 300)
    angle = rng.uniform(0, 2 * np.pi, 300)
    x = np.where(np.arange(300) < 200, 0.2, -0.2)
    z = np.where(np.arange(300) < 200, z, rng.uniform(0.86, 1.09, 300))
    points = np.stack([x + 0.04 * np.cos(angle), 0.04 * np.sin(angle), z], axis=1)
    raised = skeleton.copy()  # the right forearm pointing forward instead of down
    raised[JOINT_INDEX["right_wrist"]] = (-0.2, 0.25, 1.1)
    missing = skeleton.copy()
    missing[JOINT_INDEX["left_elbow"]] = np.nan
    eps = arm_epsilons([points, points, points, points[: MIN_ARM_POINTS - 1]],
                       np.stack([skeleton, raised, missing, skeleton]))
    assert eps[0] == pytest.approx(0.04, abs=1e-9)
    # the right forearm's points are now nearest the raised forearm (at z = 1.1 m, along +y
    # from the elbow) or, behind it (y < 0), the elbow itself
    fore = points[200:]
    across = np.where(fore[:, 1] >= 0, np.abs(fore[:, 0] + 0.2), 0.04)
    expected = (200 * 0.04 + np.hypot(across, 1.1 - fore[:, 2]).sum()) / 300
    assert eps[1] == pytest.approx(expected, rel=1e-9) and eps[1] > 0.065
    assert np.isnan(eps[2]) and np.isnan(eps[3])
    with pytest.raises(ValueError, match="shape"):
        arm_epsilons([points], np.stack([skeleton, skeleton]))


# --------------------------------------------------------------------------- pixels


def test_pixel_assignment_accuracy():
    truth = np.array([[0, 1, 1], [2, 2, 0]])
    assigned = np.array([[0, 1, 2], [2, 1, 0]])
    foreground = truth > 0
    assert pixel_assignment_accuracy(assigned, truth, foreground) == pytest.approx(0.5)
    assert math.isnan(pixel_assignment_accuracy(assigned, truth, np.zeros((2, 3), bool)))
    with pytest.raises(ValueError, match="integer"):
        pixel_assignment_accuracy(assigned.astype(float), truth, foreground)


def test_foreground_scores():
    pred = np.array([[1, 1, 0], [1, 0, 0]], dtype=bool)
    true = np.array([[1, 0, 0], [1, 1, 1]], dtype=bool)
    precision, recall, iou = foreground_scores(pred, true)
    assert (precision, recall, iou) == pytest.approx((2 / 3, 2 / 4, 2 / 5))
    empty = np.zeros((2, 3), dtype=bool)
    assert all(math.isnan(v) for v in foreground_scores(empty, empty))
