"""occupose.body.size: body size from observed points (stature, girth) and the neck and
shoulders read from a breadth profile, on rendered people and model surfaces."""

import math
from dataclasses import replace

import numpy as np
import pytest

from occupose.body import body_model, capsules_from_poses, dims_from_observation, standing_pose
from occupose.body.dims import DEFAULT_DIMS, BodyDims, dims_from_joints
from occupose.body.size import breadth_profile, dims_with_shoulders, neck_and_shoulders, top_height
from occupose.camera import points_from_depth
from occupose.joints import JOINT_INDEX as J
from occupose.synth.generate import frames
from occupose.synth.scenarios import build_scenario
from occupose.synth import motion as sm


D = DEFAULT_DIMS


def _first_points(seed: int):
    """Points of the first two frames where the no_occlusion person stands upright (still,
    hands below the shoulders): dims_from_observation assumes a standing person."""
    scenario = build_scenario("no_occlusion", seed=seed, use_mocap=False)
    joints = scenario.people[0].joints
    speed = np.linalg.norm(np.diff(joints[:, 2, :2], axis=0), axis=1) * scenario.fps
    hands_low = np.all(joints[1:, [5, 8], 2] < joints[1:, [3, 6], 2], axis=1)
    first = 1 + int(np.flatnonzero((speed < 0.05) & hands_low)[0])
    points = []
    for frame in frames(scenario, seed=0, indices=[first, first + 1]):
        for cam in scenario.cameras:
            depth = np.where(frame.rendered[cam.name].person == 1, frame.depth[cam.name], 0.0).astype(np.float32)
            points.append(points_from_depth(depth, cam)[0])
    return np.concatenate(points), dims_from_joints(scenario.people[0].joints[:30]).height


def test_dims_from_observation_on_rendered_people():
    heights = []
    for seed in (3, 5):  # a 1.88 m and a 1.68 m person
        points, height = _first_points(seed)
        size = dims_from_observation(points)
        assert size.dims.height == pytest.approx(height, abs=0.05)   # measured: -3.2 cm and 0.0 cm
        assert 0.85 <= size.girth <= 1.2
        heights.append(size.dims.height)
    assert heights[0] - heights[1] > 0.12


def test_dims_from_observation_on_a_model_surface(rng):
    """Points on the standing model's cones: stature, floor offset and a girth near 1."""
    m = body_model("full", D.scaled(1.65))
    a, b = capsules_from_poses(m, standing_pose(m)[None])
    t = rng.random((4000, 1))
    k = rng.integers(m.num_capsules, size=4000)
    r = m.capsule_radii[k, 0] + t[:, 0] * (m.capsule_radii[k, 1] - m.capsule_radii[k, 0])
    direction = rng.standard_normal((4000, 3))
    direction /= np.linalg.norm(direction, axis=1, keepdims=True)
    points = a[0, k] + t * (b[0, k] - a[0, k]) + r[:, None] * direction
    top = points[:, 2].max()
    size = dims_from_observation(points + [0, 0, 0.3], floor_z=0.3)
    assert size.dims.height == pytest.approx(top, abs=0.02)
    assert size.girth == pytest.approx(1.0, abs=0.1)
    with pytest.raises(ValueError, match=r"\(N, 3\)"):
        dims_from_observation(np.zeros((5, 3)))


def _walker_profiles(dims: BodyDims):
    """Breadth profiles of a procedural person of ``dims`` walking towards the camera of
    no_occlusion (seen from the front), every third of 30 frames, with each frame's true
    neck depth below the top of its points."""
    from occupose.testing import person_observations

    scenario = build_scenario("no_occlusion", use_mocap=False)
    joints = sm.MotionBuilder((0.3, 3.6), -math.pi / 2, dims, scenario.fps).walk([(0.3, 2.6)]).joints()
    scenario = replace(scenario, people=(replace(scenario.people[0], joints=joints),))
    observations = person_observations(scenario, 30, max_points=20000)
    return [(breadth_profile(o.points), top_height(o.points[:, 2]) - joints[t, J["neck"], 2])
            for t, o in enumerate(observations) if t % 3 == 0]


def test_neck_and_shoulders_of_rendered_walkers():
    """The neck depth and shoulder width measured from the front on an average body and on
    one with the mocap subject's shape (a neck 5 cm lower, shoulders 0.6 as wide)."""
    average = D.scaled(1.75)
    subject = replace(average, spine=0.78 * average.spine, shoulder_width=0.6 * average.shoulder_width,
                      neck_head=average.neck_head + 0.11 * average.spine)
    widths = []
    for dims in (average, subject):
        profiles = _walker_profiles(dims)
        measured = [neck_and_shoulders(profile) for profile, _ in profiles]
        assert sum(m is not None for m in measured) >= 8  # measured: all 10
        depth, breadth = np.median([m for m in measured if m is not None], axis=0)
        truth = np.median([depth for _, depth in profiles])
        assert depth == pytest.approx(truth, abs=0.02)  # measured: 0.6 and 1.1 cm deeper
        fitted = dims_with_shoulders(average, 1.0, depth, breadth)
        # measured: 0.2 cm narrow and 1.8 cm wide (narrow shoulders hide inside the chest's breadth)
        assert fitted.shoulder_width == pytest.approx(dims.shoulder_width, abs=0.025)
        assert fitted.height == pytest.approx(average.height) and fitted.thigh == average.thigh
        assert 2 * fitted.neck_head == pytest.approx(depth)
        widths.append(fitted.shoulder_width)
    assert widths[1] < 0.75 * widths[0]


def test_neck_and_shoulders_refuse_what_they_cannot_read():
    profile = np.full(50, 0.3)
    profile[:20] = 0.16  # a head 20 cm tall
    assert neck_and_shoulders(profile) == pytest.approx((0.20, 0.3))
    raised = profile.copy()
    raised[2:6] = 0.4  # a hand up by the head
    assert neck_and_shoulders(raised) is None
    assert neck_and_shoulders(np.full(50, np.nan)) is None
    assert neck_and_shoulders(np.full(50, 0.2)) is None  # no chest wider than the head
    far = dims_with_shoulders(D, 1.0, 1.0, 2.0)  # clipped to SHAPE_RANGE of the average
    assert 2 * far.neck_head == pytest.approx(1.5 * 2 * D.neck_head)
    assert far.shoulder_width == pytest.approx(1.5 * D.shoulder_width)
    with pytest.raises(ValueError, match=r"\(N, 3\)"):
        breadth_profile(np.zeros((5, 3)))
