"""The generator's pose vector: skeleton geometry, angle conventions, forward and leg inverse kinematics."""

import math

import numpy as np
import pytest

from occupose.body.dims import BodyDims
from occupose.synth.retarget import facing_from_joints as facing
from occupose.joints import JOINT_INDEX as J
from occupose.synth import motion as m
from occupose.synth.motion.pose import _leg_angles


def angle_diff(a, b):
    return np.abs((np.asarray(a) - b + np.pi) % (2 * np.pi) - np.pi)


def test_left_is_left_of_the_facing_direction():
    j = m.joints_from_procedural(m.stance((1.0, 2.0), heading=math.pi / 2))  # facing +y
    assert j[J["left_hip"], 0] < j[J["right_hip"], 0]
    assert j[J["left_shoulder"], 0] < j[J["right_shoulder"], 0]
    assert j[J["left_ankle"], 0] < j[J["right_ankle"], 0]
    for heading in (0.0, 0.7, -2.5, 3.0):
        assert angle_diff(facing(m.joints_from_procedural(m.stance(heading=heading))), heading) < 1e-9


def test_pose_angle_conventions():
    base = m.stance()
    j0 = m.joints_from_procedural(base)

    def moved(**values):
        return m.joints_from_procedural(m.pose_with(base, **values))

    # facing +x: forward is +x, left is +y, up is +z
    assert moved(right_shoulder_flex=math.pi / 2)[J["right_wrist"], 0] > 0.5   # arm forward
    assert moved(left_shoulder_abd=math.pi / 2)[J["left_wrist"], 1] > 0.7      # arm out to the left
    assert moved(right_shoulder_abd=math.pi / 2)[J["right_wrist"], 1] < -0.7   # arm out to the right
    assert moved(left_shoulder_flex=math.pi)[J["left_wrist"], 2] > 1.9          # arm straight up
    assert moved(trunk_lean=0.5)[J["neck"], 0] > 0.2                             # leaning forward
    assert moved(trunk_side=0.3)[J["neck"], 1] > 0.1                             # leaning left
    assert moved(left_hip_flex=math.pi / 2)[J["left_ankle"], 0] > 0.8            # leg forward
    bent = moved(left_knee=1.0)
    assert bent[J["left_ankle"], 0] < bent[J["left_knee"], 0]                    # shin goes back
    up = moved(left_shoulder_abd=math.pi / 2, left_elbow=math.pi / 2, left_shoulder_rot=math.pi / 2)
    assert up[J["left_wrist"], 2] - up[J["left_elbow"], 2] == pytest.approx(0.25, abs=0.02)  # forearm up
    across = moved(right_elbow=math.pi / 2, right_shoulder_rot=-math.pi / 2)
    assert across[J["right_wrist"], 1] > j0[J["right_elbow"], 1] + 0.2           # forearm across the body
    # the same numbers on both sides mirror the pose about the sagittal plane
    mirror = moved(left_shoulder_flex=0.4, left_shoulder_abd=0.3, left_shoulder_rot=0.5, left_elbow=1.0,
                   right_shoulder_flex=0.4, right_shoulder_abd=0.3, right_shoulder_rot=0.5, right_elbow=1.0)
    np.testing.assert_allclose(mirror[J["left_wrist"]] * [1, -1, 1], mirror[J["right_wrist"]], atol=1e-12)


def test_joints_from_procedural_batches_and_checks_shape():
    poses = np.stack([m.stance(heading=h) for h in (0.0, 1.0, 2.0)])
    batch = m.joints_from_procedural(poses.reshape(3, 1, -1))
    assert batch.shape == (3, 1, 15, 3)
    np.testing.assert_allclose(batch[1, 0], m.joints_from_procedural(poses[1]), atol=1e-12)
    with pytest.raises(ValueError, match=r"\(\.\.\., 22\)"):
        m.joints_from_procedural(np.zeros((4, 21)))
    with pytest.raises(ValueError, match="unknown pose entry 'knee'"):
        m.pose_with(m.stance(), knee=0.3)


def test_leg_inverse_kinematics_round_trip(rng):
    dims = BodyDims()
    n = 200
    poses = np.repeat(m.stance()[None], n, axis=0)
    poses[:, m.HEADING] = rng.uniform(-np.pi, np.pi, n)
    poses[:, m.LEFT + m.HIP_FLEX] = rng.uniform(-0.5, 1.6, n)
    poses[:, m.LEFT + m.HIP_ABD] = rng.uniform(-0.3, 0.5, n)
    poses[:, m.LEFT + m.KNEE] = rng.uniform(0.05, 2.0, n)
    j = m.joints_from_procedural(poses, dims)
    angles = _leg_angles(j[:, J["left_hip"]], j[:, J["left_ankle"]], poses[:, m.HEADING], 1.0, dims)
    np.testing.assert_allclose(angles, poses[:, m.LEFT + m.HIP_FLEX:m.LEFT + m.KNEE + 1], atol=1e-9)
