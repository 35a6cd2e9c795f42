"""Fitting the body to one depth frame (occupose.pose.single): people found and separated,
fitted from that frame alone, with and without a background image, a pose or a floor."""

import dataclasses

import numpy as np
import pytest

from occupose import fit_frame
from occupose.config import as_config
from occupose.joints import UPPER_JOINTS
from occupose.pose.single import foreground, groups_of_points, people_of_points
from occupose.synth.generate import frames
from occupose.synth.render import render_camera
from occupose.synth.scenarios import build_scenario


@pytest.fixture(scope="module")
def standing():
    """Frame 100 of no_occlusion (procedural): one person in full view, and the empty scene."""
    scenario = build_scenario("no_occlusion", use_mocap=False)
    camera = scenario.cameras[0]
    frame = next(frames(scenario, 0, indices=[100]))
    return camera, frame, render_camera(scenario.static, camera).depth


@pytest.fixture(scope="module")
def crossing():
    """Frame 20 of two_people_crossing (procedural): two people apart, both in view."""
    scenario = build_scenario("two_people_crossing", use_mocap=False)
    camera = scenario.cameras[0]
    return camera, next(frames(scenario, 0, indices=[20])), render_camera(scenario.static, camera).depth


def _error(joints, truth, visible) -> float:
    """Mean distance (m) of the joints both have and the ground truth shows."""
    known = visible & np.isfinite(joints).all(axis=1)
    return float(np.linalg.norm(joints[known] - truth[known], axis=1).mean())


def _removed(frame, camera):
    """The frame with every pixel that is not a person's set to 0 (a background-removed export)."""
    return np.where(frame.rendered[camera.name].person > 0, frame.depth[camera.name], 0).astype(np.float32)


def test_a_person_in_full_view_is_fitted_with_the_full_model_given_the_pose_and_background(standing):
    camera, frame, background = standing
    fit = fit_frame(frame.depth[camera.name], camera, world=True, background=background)
    assert fit.frame == "world" and fit.floor is None and len(fit.people) == 1
    person = fit.people[0]
    assert person.model == "full" and person.joints.shape == (15, 3) and np.isfinite(person.joints).all()
    assert 1.6 < person.stature < 1.85  # measured from the points: 1.74 m
    assert _error(person.joints, frame.joints[0], frame.visible[0]) < 0.05  # 2.0 cm measured
    assert person.visible.sum() >= 12


def test_without_the_pose_the_floor_of_the_background_places_the_camera(standing):
    camera, frame, background = standing
    fit = fit_frame(frame.depth[camera.name], camera, background=background)
    height = camera.world_from_camera[2, 3]
    assert fit.frame == "camera" and fit.floor is not None and fit.floor[0] == pytest.approx(height, abs=0.03)
    truth = frame.joints[0] @ camera.camera_from_world[:3, :3].T + camera.camera_from_world[:3, 3]
    assert fit.people[0].model == "full" and _error(fit.people[0].joints, truth, frame.visible[0]) < 0.05


def test_a_background_removed_frame_with_no_floor_gets_the_upper_model_in_the_camera_frame(standing):
    """No floor, no pose: the camera taken as level, the upper body fitted; its legs NaN."""
    camera, frame, _ = standing
    fit = fit_frame(_removed(frame, camera), camera)
    assert fit.frame == "camera" and fit.floor is None and len(fit.people) == 1
    person = fit.people[0]
    upper = len(UPPER_JOINTS)
    assert person.model == "upper" and np.isfinite(person.joints[:upper]).all()
    assert np.isnan(person.joints[upper:]).all() and not person.visible[upper:].any()
    truth = frame.joints[0] @ camera.camera_from_world[:3, :3].T + camera.camera_from_world[:3, 3]
    assert _error(person.joints, truth, frame.visible[0]) < 0.06  # 2.6 cm measured
    assert person.stature == pytest.approx(as_config("ours").fit.stature)  # taken, not measured


def test_two_people_apart_are_two_fits_each_on_its_own_person(crossing):
    camera, frame, background = crossing
    fit = fit_frame(frame.depth[camera.name], camera, world=True, background=background)
    assert len(fit.people) == 2
    errors = np.array([[_error(p.joints, frame.joints[j], frame.visible[j]) for j in range(2)] for p in fit.people])
    matched = errors.argmin(axis=1)
    assert sorted(matched) == [0, 1]  # one fit per person
    assert errors.min(axis=1).max() < 0.08  # 4.9 and 3.8 cm measured
    assert not set(fit.people[0].pixels) & set(fit.people[1].pixels)
    centres = [np.mean(p.pixels % camera.width) for p in fit.people]
    assert centres == sorted(centres)  # left to right in the image


def test_the_same_seed_gives_the_same_fit_and_another_seed_a_close_one(standing):
    camera, frame, background = standing
    depth = frame.depth[camera.name]
    first, again = (fit_frame(depth, camera, world=True, background=background, seed=3) for _ in range(2))
    np.testing.assert_array_equal(first.people[0].joints, again.people[0].joints)
    other = fit_frame(depth, camera, world=True, background=background, seed=4)
    assert not np.array_equal(other.people[0].joints, first.people[0].joints)
    assert _error(other.people[0].joints, frame.joints[0], frame.visible[0]) < 0.05


def test_the_model_asked_for_is_the_model_fitted(standing):
    camera, frame, background = standing
    fit = fit_frame(frame.depth[camera.name], camera, world=True, background=background, model="upper")
    assert fit.people[0].model == "upper" and np.isnan(fit.people[0].joints[len(UPPER_JOINTS):]).all()


def test_an_empty_frame_has_nobody(standing):
    camera, _, background = standing
    assert fit_frame(background.astype(np.float32), camera, world=True, background=background).people == []
    assert fit_frame(np.zeros((camera.height, camera.width), np.float32), camera).people == []


def test_foreground_keeps_blocks_nearer_than_the_background_not_scattered_noise():
    background = np.full((40, 40), 3.0, np.float32)
    depth = background.copy()
    depth[10:20, 10:20] = 2.0  # a body
    depth[30, 5] = depth[5, 30] = 2.5  # two noisy pixels
    depth[35, 35] = 0.0  # no measurement
    mask = foreground(depth, background, 0.05)
    assert mask[10:20, 10:20].all() and mask.sum() == 100
    assert foreground(depth, None, 0.05).sum() == 40 * 40 - 1  # no background: every measured pixel


def test_groups_and_people_of_points():
    """A tall group is a person; a hand apart from them within reach joins them; a
    person-sized group too low (a table top) and a far small group are nobody's."""
    rng = np.random.default_rng(0)
    body = np.column_stack([rng.uniform(-0.2, 0.2, 3000), rng.uniform(0, 0.05, 3000), rng.uniform(0.1, 1.7, 3000)])
    hand = np.column_stack([rng.uniform(0.5, 0.6, 200), rng.uniform(-0.4, -0.3, 200), rng.uniform(1.2, 1.3, 200)])
    table = np.column_stack([rng.uniform(2, 3, 3000), rng.uniform(0, 1, 3000), rng.uniform(0.7, 0.72, 3000)])
    far = np.column_stack([rng.uniform(5, 5.1, 200), rng.uniform(0, 0.1, 200), rng.uniform(1, 1.1, 200)])
    points = np.concatenate([body, hand, table, far])
    config = as_config("ours")
    groups = groups_of_points(points, config.fit.join_m)
    assert len(np.unique(groups)) == 4 and len(np.unique(groups[:3000])) == 1
    people = people_of_points(points, groups, config)
    assert (people[:3200] == 0).all() and (people[3200:] == -1).all()
    apart = people_of_points(points, groups, config.with_values({"fit.reach_m": 0.1}))
    assert (apart[:3000] == 0).all() and (apart[3000:] == -1).all()


def test_bad_inputs_are_refused_with_what_was_expected(standing):
    camera, frame, background = standing
    depth = frame.depth[camera.name]
    with pytest.raises(ValueError, match="unknown model 'legs'"):
        fit_frame(depth, camera, model="legs")
    with pytest.raises(ValueError, match=r"\(480, 640\) float array of metres"):
        fit_frame(depth[:100], camera)
    with pytest.raises(ValueError, match="float array of metres"):
        fit_frame((depth * 1000).astype(np.uint16), camera)
    with pytest.raises(ValueError, match="background must be"):
        fit_frame(depth, camera, background=background[:, :10])
    small = dataclasses.replace(camera, width=320, height=240)
    with pytest.raises(ValueError, match=r"\(240, 320\) float array of metres for camera 'front', got float32 \(480, 640\)"):
        fit_frame(depth, small)
