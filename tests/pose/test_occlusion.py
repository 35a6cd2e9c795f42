"""The occlusion state machine on constructed cases (a toy body of 4 parts, 1 DOF each):
0 torso (root) -> 1 thigh -> 2 shin, 0 torso -> 3 arm."""

import numpy as np
import pytest

from occupose.body import body_model, capsules_from_poses, joints_from_poses, standing_pose
from occupose.joints import JOINT_INDEX, JOINTS
from occupose.pose.occlusion import (
    HIDDEN_CELL, OcclusionState, hidden_parts, hidden_parts_in_views, joint_parts, part_tree, planted_legs, sphere_centres,
)

PARENTS = [-1, 0, 1, 0]
DOFS = [np.array([0]), np.array([1]), np.array([2]), np.array([3])]


def state(**kw):
    return OcclusionState(PARENTS, DOFS, num_dofs=4, **kw)


def hides(*parts):
    """hidden_fn that reports the given parts hidden whatever the pose."""
    def fn(pose):
        out = np.zeros(4, bool)
        out[list(parts)] = True
        return out
    return fn


def test_spheres_and_hidden_parts_majority_rule():
    a = np.array([[0.0, 0, 0], [2.0, 0, 1.0]])
    b = np.array([[1.0, 0, 0], [2.0, 0, 2.0]])
    centres = sphere_centres(a, b, n=4)
    np.testing.assert_allclose(centres[0, :, 0], [0.125, 0.375, 0.625, 0.875])
    # cells with x < 0.6 are hidden: 2 of capsule 0's 4 spheres (not more than half), none of capsule 1's
    hidden_at = lambda p: np.where(p[:, 0] < 0.6, HIDDEN_CELL, 1)
    assert hidden_parts(a, b, np.array([0, 1]), 2, hidden_at, n=4).tolist() == [False, False]
    hidden_at = lambda p: np.where(p[:, 0] < 0.7, HIDDEN_CELL, 1)  # now 3 of 4
    assert hidden_parts(a, b, np.array([0, 1]), 2, hidden_at, n=4).tolist() == [True, False]
    # a part of two capsules counts all its spheres together
    assert hidden_parts(a, b, np.array([0, 0]), 1, hidden_at, n=4).tolist() == [False]


def test_hidden_part_keeps_its_memory_and_freezes_its_dofs():
    s = state()
    s.update(np.array([0.0, 0.1, 0.2, 0.3]), hides())
    s.remember(np.array([0.0, 0.1, 0.2, 0.3]))
    visible = s.update(np.array([0.5, 0.9, 0.9, 0.9]), hides(2))
    assert visible.tolist() == [True, True, False, True]
    assert s.active_dofs().tolist() == [True, True, False, True]
    np.testing.assert_allclose(s.with_memory(np.array([9.0, 9, 9, 9])), [9, 9, 0.2, 9])


def test_hidden_state_is_inherited_down_the_tree():
    s = state()
    visible = s.update(np.zeros(4), hides(1))  # thigh hidden -> shin hidden too, arm not
    assert visible.tolist() == [True, False, False, True]


def test_hidden_part_is_tested_with_its_memory_configuration():
    s = state()
    s.update(np.array([0.0, 0.0, 0.2, 0.0]), hides())
    seen = []

    def fn(pose):
        seen.append(pose.copy())
        return np.array([False, False, pose[2] > 0.1, False])  # hidden while the shin angle is large

    s.update(np.array([0.0, 0.0, 0.2, 0.0]), fn)
    assert not s.visible[2]
    s.update(np.array([0.0, 0.0, 0.0, 0.0]), fn)  # the current pose would test visible...
    assert seen[-1][2] == pytest.approx(0.2) and not s.visible[2]  # ...but the memory is tested


def test_part_that_reappears_gets_a_wider_search_for_a_few_frames():
    s = state(resume_frames=3, resume_scale=4.0)
    s.update(np.zeros(4), hides(3))
    assert np.all(s.diffusion_scale() == 1.0)
    s.update(np.zeros(4), hides())
    assert s.diffusion_scale().tolist() == [1, 1, 1, 4]
    for _ in range(2):
        s.update(np.zeros(4), hides())
        assert s.diffusion_scale()[3] == 4.0
    s.update(np.zeros(4), hides())
    assert np.all(s.diffusion_scale() == 1.0)


def test_torso_hidden_suspends_the_track_until_visible_again():
    s = state()
    s.update(np.zeros(4), hides())
    assert not s.suspended
    visible = s.update(np.zeros(4), hides(0))
    assert s.suspended and not visible.any() and not s.active_dofs().any()
    s.update(np.zeros(4), hides())
    assert not s.suspended and s.visible.all()
    assert s.diffusion_scale().tolist() == [3, 3, 3, 3]


def test_bad_trees_are_refused():
    with pytest.raises(ValueError, match="parent-first with one root"):
        OcclusionState([-1, 2, 0], [np.array([0])] * 3, 3)
    with pytest.raises(ValueError, match="one entry per part"):
        OcclusionState([-1, 0], [np.array([0])], 1)

def test_part_tree_of_the_full_model():
    model = body_model("full")
    parents, dofs = part_tree(model)
    names = model.part_names
    named = {names[k]: (names[p] if p >= 0 else None) for k, p in enumerate(parents)}
    assert named == {"torso": None, "head": "torso", "left_upper_arm": "torso", "left_forearm": "left_upper_arm",
                     "right_upper_arm": "torso", "right_forearm": "right_upper_arm", "left_thigh": "torso",
                     "left_shin": "left_thigh", "right_thigh": "torso", "right_shin": "right_thigh"}
    assert sorted(np.concatenate(dofs).tolist()) == list(range(model.num_dofs))


def test_joints_are_visible_when_the_parts_placing_them_are():
    model = body_model("full")
    parts = {JOINTS[j]: sorted(model.part_names[k] for k in p) for j, p in enumerate(joint_parts(model))}
    assert parts["pelvis"] == ["torso"] and parts["left_hip"] == ["torso"]
    assert parts["left_knee"] == ["left_thigh", "torso"]
    assert parts["right_ankle"] == ["right_shin", "right_thigh", "torso"]
    assert parts["head"] == ["head", "torso"]
    upper = body_model("upper")
    assert [len(p) for p in joint_parts(upper)][JOINT_INDEX["left_knee"]] == 0  # not reported


def test_hidden_parts_behind_a_surface_that_is_not_the_person(small_camera):
    camera = small_camera
    model = body_model("full")
    pose = standing_pose(model, (0.0, 0.0), np.pi / 2 + np.pi)  # facing the camera at y = -3
    a, b = (x[0] for x in capsules_from_poses(model, pose[None]))
    depth = np.full((camera.height, camera.width), 3.5, np.float32)
    owners = np.zeros(depth.shape, np.int32)
    depth[70:, :] = 2.0  # a table top edge in front of the legs (image rows below the hips)
    args = (a, b, model.capsule_radii, model.capsule_part, model.num_parts, {"cam": depth})
    hidden = hidden_parts_in_views(*args, {"cam": owners}, [camera], track_id=1)
    names = [n for n, h in zip(model.part_names, hidden) if h]
    assert {"left_shin", "right_shin"} <= set(names)
    assert "torso" not in names and "head" not in names
    owners[70:, :] = 1  # the same surface is the person's own: nothing is hidden
    assert not hidden_parts_in_views(*args, {"cam": owners}, [camera], track_id=1).any()
    far = standing_pose(model, (6.0, 0.0), 0.0)  # outside the image: hidden from the only camera
    a, b = (x[0] for x in capsules_from_poses(model, far[None]))
    owners[:] = 0
    assert hidden_parts_in_views(a, b, model.capsule_radii, model.capsule_part, model.num_parts, {"cam": depth},
                                 {"cam": owners}, [camera], track_id=1).all()


def test_planted_legs_keep_the_feet_on_the_floor():
    model = body_model("full")
    pose = standing_pose(model)
    seated = pose.copy()
    seated[2] = 0.5  # pelvis at seat height, legs still straight: they would sink into the floor
    fixed = planted_legs(model, seated, ["left", "right"])
    joints = joints_from_poses(model, fixed[None])[0]
    for side in ("left", "right"):
        assert abs(joints[JOINT_INDEX[f"{side}_ankle"], 2] - model.dims.ankle_height) < 0.03
        assert fixed[model.dof_names.index(f"{side}_knee")] > 1.2  # bent like a seated leg
    standing = planted_legs(model, pose, ["left"])
    assert standing[model.dof_names.index("left_knee")] < 0.15  # a standing leg stays straight
    assert np.array_equal(standing[model.dof_names.index("right_knee")], pose[model.dof_names.index("right_knee")])
    # a seen thigh (seated, forward) over a hidden shin last seen folded back: only the knee moves
    folded = fixed.copy()
    folded[model.dof_names.index("right_knee")] = 2.1
    shin = planted_legs(model, folded, [], ["right"])
    changed = np.flatnonzero(shin != folded)
    assert [model.dof_names[i] for i in changed] == ["right_knee"]
    ankle = joints_from_poses(model, shin[None])[0, JOINT_INDEX["right_ankle"]]
    assert abs(ankle[2] - model.dims.ankle_height) < 0.03


def test_planted_legs_reach_the_feet_that_show():
    """A hidden leg whose foot shows (below a chair's back) reaches it, knee forwards; a
    hidden shin under a seen thigh bends to put its ankle nearest its foot."""
    model = body_model("full")
    pose = standing_pose(model, (0.0, 2.5), -np.pi / 2)  # facing -y
    joints = joints_from_poses(model, pose[None])[0]
    foot = joints[JOINT_INDEX["left_ankle"]] + [0.05, -0.2, 0.0]  # 20 cm forwards, 5 cm out
    pose[2] -= 0.1  # the pelvis 10 cm lower: the leg must bend to reach it
    planted = planted_legs(model, pose, ["left"], feet={"left": foot})
    got = joints_from_poses(model, planted[None])[0]
    assert np.linalg.norm(got[JOINT_INDEX["left_ankle"]] - foot) < 0.01
    hip, knee, ankle = (got[JOINT_INDEX[f"left_{j}"]] for j in ("hip", "knee", "ankle"))
    assert (knee - (hip + ankle) / 2)[1] < -0.05  # the knee bends forwards (-y)
    assert np.array_equal(planted[model.dof_names.index("right_knee")], pose[model.dof_names.index("right_knee")])
    # a seated thigh over a hidden shin: the knee bend whose ankle is nearest the foot
    seated = pose.copy()
    seated[2] = 0.5
    seated[model.dof_names.index("right_hip_flex")] = 1.5
    knee = joints_from_poses(model, seated[None])[0, JOINT_INDEX["right_knee"]]
    tucked = knee + [0.0, 0.25, -(knee[2] - model.dims.ankle_height) * 0.8]  # the foot drawn back under the seat
    shin = planted_legs(model, seated, [], ["right"], feet={"right": tucked})
    ankle = joints_from_poses(model, shin[None])[0, JOINT_INDEX["right_ankle"]]
    plain = joints_from_poses(model, planted_legs(model, seated, [], ["right"])[None])[0, JOINT_INDEX["right_ankle"]]
    assert np.linalg.norm(ankle - tucked) < 0.06 < np.linalg.norm(plain - tucked)
