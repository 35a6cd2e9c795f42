"""The occlusion state machine on constructed cases (a toy body of 4 parts, 1 DOF each):
0 torso (root) -> 1 thigh -> 2 shin, 0 torso -> 3 arm."""

import numpy as np
import pytest

from occupose.pose.occlusion import HIDDEN_CELL, OcclusionState, hidden_parts, sphere_centres

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
