"""occupose.body.postures: the tracker's own standing and seated poses, checked on the joints
they give (forward kinematics), for the average body, a tall one and one whose thighs are
longer than its shins, facing several ways."""

import math
from dataclasses import replace

import numpy as np
import pytest

from occupose.body import ARM_REST, body_model, joints_from_pose, seated_pose, standing_pose
from occupose.body.dims import DEFAULT_DIMS
from occupose.body.postures import STAND_KNEE
from occupose.joints import JOINT_INDEX as J

BODIES = [DEFAULT_DIMS, DEFAULT_DIMS.scaled(1.9), replace(DEFAULT_DIMS, thigh=0.46, shin=0.40)]
BODY_IDS = ["average", "tall", "long_thighs"]
PLACES = [((0.0, 0.0), 0.0), ((1.2, -0.7), 2.5), ((-2.0, 3.0), -1.9)]
ARM = ("shoulder_flex", "shoulder_abd", "shoulder_rot", "elbow")


def _forward(heading):
    return np.array([math.cos(heading), math.sin(heading)])


def _knee_angle(joints, side):
    """The bend at the knee (radians): the angle between hip -> knee and knee -> ankle."""
    thigh = joints[J[f"{side}_knee"]] - joints[J[f"{side}_hip"]]
    shin = joints[J[f"{side}_ankle"]] - joints[J[f"{side}_knee"]]
    return math.acos(thigh @ shin / np.linalg.norm(thigh) / np.linalg.norm(shin))


@pytest.mark.parametrize("dims", BODIES, ids=BODY_IDS)
@pytest.mark.parametrize("xy, heading", PLACES)
def test_standing_full_model_stands_on_its_ankles(dims, xy, heading):
    model = body_model("full", dims)
    pose = standing_pose(model, xy, heading)
    joints = joints_from_pose(model, pose)
    assert pose[model.dof("x")] == xy[0] and pose[model.dof("y")] == xy[1]
    assert pose[model.dof("heading")] == pytest.approx(heading, abs=1e-12)
    np.testing.assert_allclose(joints[J["pelvis"], :2], xy, atol=1e-12)
    for side in ("left", "right"):
        hip, ankle = joints[J[f"{side}_hip"]], joints[J[f"{side}_ankle"]]
        assert ankle[2] == pytest.approx(dims.ankle_height, abs=1e-9)
        assert np.linalg.norm(ankle[:2] - hip[:2]) < 1e-3  # the ankle under the hip, within 1 mm
        assert pose[model.dof(f"{side}_knee")] == STAND_KNEE
        assert _knee_angle(joints, side) == pytest.approx(STAND_KNEE, abs=1e-9)
        knee = joints[J[f"{side}_knee"]]
        assert (knee[:2] - hip[:2]) @ _forward(heading) > 0.005  # the knee a little forward, not back
        np.testing.assert_array_equal([pose[model.dof(f"{side}_{name}")] for name in ARM], ARM_REST)
    # the left hip is to the left of the way the body faces
    left = joints[J["left_hip"], :2] - joints[J["right_hip"], :2]
    assert left @ _forward(heading + math.pi / 2) == pytest.approx(dims.pelvis_width, abs=1e-9)
    # a straight-legged stance would put the hips 0.4 mm (average body) higher
    assert 0.0 < dims.hip_height - joints[J["pelvis"], 2] < 0.001


@pytest.mark.parametrize("dims", BODIES, ids=BODY_IDS)
def test_standing_upper_model_has_its_pelvis_at_the_same_height(dims):
    full, upper = body_model("full", dims), body_model("upper", dims)
    for xy, heading in PLACES:
        pose = standing_pose(upper, xy, heading)
        joints = joints_from_pose(upper, pose)
        standing = joints_from_pose(full, standing_pose(full, xy, heading))
        assert np.isnan(joints[J["left_ankle"]]).all()  # no legs to stand on
        np.testing.assert_allclose(joints[J["pelvis"]], standing[J["pelvis"]], atol=1e-12)
        assert pose[upper.dof("heading")] == pytest.approx(heading, abs=1e-12)
        np.testing.assert_allclose(joints[J["pelvis"], :2], xy, atol=1e-12)
        for side in ("left", "right"):
            np.testing.assert_array_equal([pose[upper.dof(f"{side}_{name}")] for name in ARM], ARM_REST)


def test_standing_heading_wraps_into_minus_pi_pi():
    model = body_model("full")
    pose = standing_pose(model, (0.0, 0.0), 2.5 + 2 * math.pi)
    assert pose[model.dof("heading")] == pytest.approx(2.5, abs=1e-12)
    with pytest.raises(ValueError, match="xy must be two finite numbers"):
        standing_pose(model, (0.0, np.nan))


@pytest.mark.parametrize("dims", BODIES, ids=BODY_IDS)
@pytest.mark.parametrize("seat", [0.38, 0.45, 0.6])
def test_seated_full_model_sits_on_the_seat_with_vertical_shins(dims, seat):
    model = body_model("full", dims)
    for xy, heading in PLACES:
        pose = seated_pose(model, seat, xy, heading)
        joints = joints_from_pose(model, pose)
        assert joints[J["pelvis"], 2] == pytest.approx(seat + dims.seat_clearance, abs=1e-9)
        np.testing.assert_allclose(joints[J["pelvis"], :2], xy, atol=1e-12)
        assert pose[model.dof("heading")] == pytest.approx(heading, abs=1e-12)
        for side in ("left", "right"):
            hip, knee, ankle = (joints[J[f"{side}_{name}"]] for name in ("hip", "knee", "ankle"))
            assert np.linalg.norm(knee[:2] - ankle[:2]) < 1e-3  # the shin vertical: knee above ankle
            assert knee[2] - ankle[2] == pytest.approx(dims.shin, abs=1e-9)
            assert ankle[2] == pytest.approx(dims.ankle_height, abs=1e-9)
            assert np.linalg.norm(hip - knee) == pytest.approx(dims.thigh, abs=1e-9)
            assert (knee[:2] - hip[:2]) @ _forward(heading) > 0.2  # the thighs reach forward to the knees
            np.testing.assert_array_equal([pose[model.dof(f"{side}_{name}")] for name in ARM], ARM_REST)


def test_seated_upper_model_has_its_pelvis_on_the_seat():
    dims = DEFAULT_DIMS.scaled(1.9)
    joints = joints_from_pose(body_model("upper", dims), seated_pose(body_model("upper", dims), 0.5, (0.3, 0.2), 1.0))
    np.testing.assert_allclose(joints[J["pelvis"]], [0.3, 0.2, 0.5 + dims.seat_clearance], atol=1e-12)


def test_seated_pose_refuses_a_seat_out_of_reach_or_not_a_number():
    model = body_model("full")  # knees 0.50 m high, thighs 0.42 m: hips 0.08 .. 0.92 m up
    seated_pose(model, 0.0)  # a seat on the floor: still within reach
    for seat in (1.2, 0.85, -0.2):
        with pytest.raises(ValueError, match="out of a 0.42 m thigh's reach"):
            seated_pose(model, seat)
    for seat in ("0.45", None, np.nan, math.inf, [0.45]):
        with pytest.raises(ValueError, match="seat_height must be a number of metres"):
            seated_pose(model, seat)
