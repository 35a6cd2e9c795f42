"""occupose.body.fit: poses fitted to joints (procedural motion, model poses, a leaning
arm, real mocap) and limb angles."""

import math

import numpy as np
import pytest

from occupose.body import BODY_MODELS, body_model, joints_from_poses, limb_angles, pose_from_joints, standing_pose
from occupose.body.dims import DEFAULT_DIMS, dims_from_joints
from occupose.joints import JOINT_INDEX as J
from occupose.synth import motion as sm


D = DEFAULT_DIMS


def _fit_errors(model, joints):
    """Largest joint error (metres) of the fitted pose of each frame (T, 15, 3)."""
    used = model.reported_joints
    out = []
    for frame in joints:
        pose = pose_from_joints(model, frame)
        assert np.all(pose >= model.limits[:, 0]) and np.all(pose <= model.limits[:, 1])
        fitted = joints_from_poses(model, pose[None])[0]
        out.append(np.linalg.norm(fitted[used] - frame[used], axis=-1).max())
    return np.array(out)


@pytest.fixture(scope="module")
def procedural_joints():
    """Walking, turning, waving, folding the arms, raising an arm, sitting and standing up."""
    dims = D.scaled(1.8)
    b = sm.MotionBuilder((0.5, -1.0), 0.3, dims=dims)
    b.walk([(2.0, 0.5), (3.0, 2.0)]).turn(2.0).wave("right").gesture("cross").gesture("raise", "left")
    b.sit_down(0.45).wave("both").stand_up()
    return dims, b.joints()[::12]


@pytest.mark.parametrize("name", ["full", "upper"])
def test_pose_from_joints_reproduces_procedural_motion(name, procedural_joints):
    dims, joints = procedural_joints
    errors = _fit_errors(body_model(name, dims), joints)
    assert len(errors) > 40 and errors.max() < 0.02  # measured: 6 mm (full), 3 mm (upper)


def test_pose_from_joints_recovers_the_pose(rng):
    """Joints of a model pose give back that pose (where the joints determine it)."""
    m = BODY_MODELS["full"]
    pose = standing_pose(m, (1.0, -2.0), 2.5)
    for name, value in (("left_shoulder_flex", 1.2), ("left_shoulder_rot", 0.6), ("left_elbow", 1.1),
                        ("trunk_lean", 0.3), ("trunk_side", -0.1), ("right_hip_flex", 0.7), ("right_knee", 0.9),
                        ("right_hip_rot", 0.3), ("neck_flex", 0.4), ("neck_side", 0.2)):
        pose[m.dof(name)] = value
    fitted = pose_from_joints(m, joints_from_poses(m, pose[None])[0])
    determined = np.array([n != "neck_twist" for n in m.dof_names])
    np.testing.assert_allclose(fitted[determined], pose[determined], atol=1e-4)


@pytest.mark.parametrize("name", ["full", "upper"])
def test_arm_angles_give_back_an_arm_of_a_leaning_turned_body(name):
    """The arm's angles from its own shoulder, elbow and wrist, in a torso turned and
    leaning (and bent sideways, for the full model): the arm of the pose, other DOFs kept."""
    m = BODY_MODELS[name]
    pose = standing_pose(m, (0.5, 1.0), -2.0)
    for dof, value in (("trunk_lean", 0.4), ("trunk_side", 0.2), ("right_shoulder_flex", 0.9),
                       ("right_shoulder_abd", 0.5), ("right_shoulder_rot", -0.4), ("right_elbow", 1.3)):
        if dof in m.dof_names:
            pose[m.dof(dof)] = value
    joints = joints_from_poses(m, pose[None])[0]
    got = limb_angles(m, pose, "right", "arm", *(joints[J[f"right_{j}"]] for j in ("shoulder", "elbow", "wrist")))
    want = [pose[m.dof(f"right_{n}")] for n in ("shoulder_flex", "shoulder_abd", "shoulder_rot", "elbow")]
    np.testing.assert_allclose(got, want, atol=1e-9)


def test_pose_from_joints_wraps_heading_and_checks_input():
    m = BODY_MODELS["upper"]
    pose = standing_pose(m, heading=3.0 + 2.0 * math.pi)
    assert pose[m.dof("heading")] == pytest.approx(3.0, abs=1e-6)
    joints = joints_from_poses(m, pose[None])[0]        # hips, knees, ankles are NaN: ignored
    assert pose_from_joints(m, joints)[m.dof("heading")] == pytest.approx(3.0, abs=1e-6)
    joints[J["left_wrist"]] = np.nan
    with pytest.raises(ValueError, match="left_wrist"):
        pose_from_joints(m, joints)
    with pytest.raises(ValueError, match=r"\(15, 3\)"):
        pose_from_joints(m, np.zeros((14, 3)))


@pytest.mark.parametrize("clip_name, models", [("dataset-1_walk_normal_001", ("full", "upper")),
                                                 ("dataset-2_wave-right-hand_active_001", ("full",))])
def test_pose_from_joints_on_real_mocap(mocap, clip_name, models):
    from occupose.io.mocap import canonical_from_clip, find_clip, load_clip

    joints = canonical_from_clip(load_clip(find_clip(clip_name)))
    dims = dims_from_joints(joints)
    for name in models:
        errors = _fit_errors(body_model(name, dims), joints[::15])
        # measured: walk 1.0 cm (full) / 1.8 cm (upper), wave 3.0 cm (full); a rigid torso
        # cannot shrug one shoulder, and the upper model has no sideways lean
        assert errors.max() < 0.04, name


@pytest.mark.parametrize("name", ["full", "upper"])
def test_twin_pose_is_the_skeleton_relabelled_left_for_right_within_the_joint_limits(name):
    """The twin of a pose with one arm held out sideways has the pose's joints with left and
    right swapped, faces the other way, and its twin is the pose again. An elbow bent forward
    has no twin: the twin's elbow would bend backwards, beyond its limit (what lets the
    tracker tell a person's front from its back, Person.face_the_better_way)."""
    from occupose.body import twin_pose
    from occupose.joints import MIRRORED

    model = body_model(name)
    pose = standing_pose(model, (0.4, 2.0), 0.3)
    pose[model.dof("left_shoulder_abd")] = 0.8
    twin = twin_pose(model, pose)
    joints = joints_from_poses(model, pose[None])[0]
    np.testing.assert_allclose(joints_from_poses(model, twin[None])[0], joints[list(MIRRORED)], atol=0.02)  # measured: 1.4 cm at most (the elbows)
    assert abs((twin[model.dof("heading")] - pose[model.dof("heading")]) % (2 * math.pi) - math.pi) < 0.05
    np.testing.assert_allclose(joints_from_poses(model, twin_pose(model, twin)[None])[0], joints, atol=0.02)
    pose[model.dof("left_elbow")] = 1.2
    bent = joints_from_poses(model, pose[None])[0][list(MIRRORED)]
    wrist = J["right_wrist"]
    assert np.linalg.norm(joints_from_poses(model, twin_pose(model, pose)[None])[0][wrist] - bent[wrist]) > 0.07  # measured: 11 cm (full), 10 cm (upper)
