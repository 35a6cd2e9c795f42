"""A tracked person's policies: facing the way walked, carrying out of sight, coming back."""

import numpy as np
import pytest

from occupose.body import body_model, standing_pose
from occupose.camera import camera_preset, look_at
from occupose.config import CarryConfig, TrackerConfig
from occupose.likelihood import View, observation_from_views
from occupose.pose.person import Person

CARRY = CarryConfig()
#: A camera 3 m in front of the origin, seeing 1.5 m to the right of it there, and a
#: frame of it without measurements (which sees through nothing: a carried person walks on).
FRONT = camera_preset("kinect_v1", world_from_camera=look_at((0.0, -3.0, 1.5), (0.0, 0.0, 1.0)), camera_name="front")
NOTHING = {"front": np.zeros((FRONT.height, FRONT.width), np.float32)}


def _person(model, **kw):
    return Person(model, TrackerConfig(), 30.0, np.random.default_rng(0), (FRONT,), **kw)


def _walk(person, path, heights=None):
    """Give ``person`` the pelvis path (list of (2,) x, y) of its last estimates, at the
    pelvis ``heights`` (default: its standing height all along)."""
    person.path = list(path)
    person.heights = [float(person.stance[2])] * len(path) if heights is None else list(heights)


def test_a_person_walking_faces_the_way_it_walks_standing_still_no_prior():
    person = _person(body_model("full"))
    assert person.walking() is None and not person.standing()  # no path yet: neither
    _walk(person, [np.array([0.0, 0.04 * i]) for i in range(CARRY.walk_frames)])  # 1.2 m/s along +y
    direction, weight = person.walking()
    assert direction == pytest.approx(np.pi / 2) and weight == pytest.approx(CARRY.walk_prior)
    assert not person.standing()
    _walk(person, [np.array([-0.02 * i, 0.0]) for i in range(CARRY.walk_frames)])  # 0.6 m/s along -x
    direction, weight = person.walking()
    assert abs(direction) == pytest.approx(np.pi) and weight == pytest.approx(CARRY.walk_prior * (0.6 - CARRY.walk_from) / CARRY.walk_ramp)
    _walk(person, [np.array([0.01 * i, 0.0]) for i in range(CARRY.walk_frames)])  # 0.3 m/s: standing, swaying
    assert person.walking() is None and person.standing()


def test_a_person_run_backwards_faces_the_way_its_path_comes_from():
    """Run back in time (the look-back, occupose.pose.lookback), a person's path goes the way it walked from:
    its walking prior points the other way, and it is turned round when its path goes the
    way it faces."""
    model = body_model("full")
    person = _person(model, backwards=True)
    _walk(person, [np.array([0.0, 0.04 * i]) for i in range(CARRY.walk_frames)])  # +y back in time
    direction, weight = person.walking()
    assert direction == pytest.approx(-np.pi / 2) and weight == pytest.approx(CARRY.walk_prior)
    pose = standing_pose(model, (0.0, 0.0), np.pi / 2)  # facing +y
    person.estimator.initialise(pose, 0.0)
    person.pose, person.estimates, person.since_turn = pose, 10, CARRY.frames
    person.face_the_way_walked()
    assert person.pose[model.dof_names.index("heading")] == pytest.approx(-np.pi / 2)


@pytest.mark.parametrize("speed, estimates, turned", [(1.2, 100, True), (0.5, 100, False), (0.5, 10, True)])
def test_a_person_walking_backwards_is_turned_round_at_the_start_or_when_walking_fast(speed, estimates, turned):
    """The estimate faces +x while the path goes along -x: turned round (heading + pi) at
    a walk above CARRY.walking_speed in the first CARRY.start_check_s seconds, later only above
    CARRY.later_speed (a person turning to sit down still shows the way it came)."""
    assert CARRY.walking_speed < 0.5 < CARRY.later_speed < 1.2 and 10 <= CARRY.start_check_s * 30 < 100
    model = body_model("full")
    person = _person(model)
    pose = standing_pose(model, (0.0, 0.0), 0.0)
    person.estimator.initialise(pose, 0.0)
    person.pose, person.estimates, person.since_turn = pose, estimates, CARRY.frames
    _walk(person, [np.array([-speed / 30.0 * i, 0.0]) for i in range(CARRY.frames)])
    person.face_the_way_walked()
    heading = person.pose[model.dof_names.index("heading")]
    assert abs(abs(heading) - np.pi) < 1e-9 if turned else heading == 0.0


@pytest.mark.parametrize("gains, turned, settled", [
    ([0.05, 0.02, 0.08, -0.01, 0.06, 0.04], True, True),  # t = 3.1
    ([-0.05, -0.02, -0.08, 0.01, -0.06, -0.04], False, True),  # t = -3.1: the estimate is kept
    ([0.1, -0.1, 0.2, -0.05, 0.03], False, False),  # t = 0.67: nothing is settled
    ([0.05, 0.02, 0.08, 0.04], False, False),  # t = 3.8, but too few comparisons
])
def test_the_start_settles_the_way_a_person_faces_on_its_twins_gains(gains, turned, settled):
    """At the end of a new person's first CARRY.start_twin_s seconds (Person.settle_facing), the
    twin's gains in log-likelihood over the estimate (nats), when there are at least
    CARRY.start_twin_count of them, decide by their t statistic: the twin is taken at
    CARRY.start_twin_t or more, the estimate kept at minus that or less; either heading is
    then settled."""
    assert CARRY.start_twin_count == 5 and CARRY.start_twin_t == 2.0
    model = body_model("full")
    person = _person(model)
    pose = standing_pose(model, (0.0, 0.0), 0.3)
    person.estimator.initialise(pose, 0.0)
    person.pose, person.start_twins = pose, list(gains)
    person.estimates = int(CARRY.start_twin_s * 30) + 1
    _walk(person, [np.zeros(2)] * CARRY.frames)  # standing still
    person.settle_facing()
    heading = person.pose[model.dof_names.index("heading")]
    assert person.start_twins is None  # decided once
    assert abs(abs((heading - 0.3 + np.pi) % (2 * np.pi) - np.pi) - (np.pi if turned else 0.0)) < 0.05
    assert person.settled == (heading if settled else None)


@pytest.mark.parametrize("speed, decided", [(0.0, False), (0.2, False), (0.6, True)])
def test_the_start_compares_a_person_with_its_twin_until_it_walks(speed, decided):
    """Within its first CARRY.start_twin_s seconds a person standing or swaying is compared
    with its twin again (one more gain every CARRY.twin_every estimates); one walking faster
    than CARRY.walking_speed is decided on the gains so far (walking says nothing about one
    who walks backwards, and a walk's gains are the walking prior's)."""
    assert CARRY.walking_speed == 0.3 and CARRY.twin_every == 3
    model = body_model("full")
    person = _person(model)
    pose = standing_pose(model, (0.0, 0.0), 0.0)
    person.estimator.initialise(pose, 0.0)
    person.pose, person.start_twins, person.estimates = pose, [0.05, 0.02, 0.08, -0.01, 0.06, 0.04], 21
    depth = np.zeros((FRONT.height, FRONT.width), np.float32)
    depth[100:400, 280:360] = 3.0  # a person-sized patch of points where it stands
    person.problem.set_observation(observation_from_views([View(FRONT, depth, depth > 0)]))
    _walk(person, [np.array([speed / 30.0 * i, 0.0]) for i in range(CARRY.frames)])
    person.settle_facing()
    assert (person.start_twins is None) == decided
    if not decided:
        assert len(person.start_twins) == 7  # one more: its twin's gain now


@pytest.mark.parametrize("settled, kept", [(0.0, True), (0.3, True), (np.pi, False), (None, False)])
def test_a_heading_settled_by_the_limbs_is_kept_against_a_walk_backwards(settled, kept):
    """The estimate faces +x and the path goes along -x at 1.2 m/s. A heading settled by the
    start's twin test (Person.settle_facing) within a quarter turn of the estimate's is kept:
    no turn round and no walking prior (it walks backwards); one a half turn off is dropped
    (the person has turned since), and then, as with none, the walk turns the estimate."""
    model = body_model("full")
    person = _person(model)
    pose = standing_pose(model, (0.0, 0.0), 0.0)
    person.estimator.initialise(pose, 0.0)
    person.pose, person.estimates, person.since_turn, person.settled = pose, 100, CARRY.frames, settled
    _walk(person, [np.array([-1.2 / 30.0 * i, 0.0]) for i in range(CARRY.frames)])
    assert (person.walking() is None) == kept
    person.face_the_way_walked()
    heading = person.pose[model.dof_names.index("heading")]
    assert heading == 0.0 if kept else abs(abs(heading) - np.pi) < 1e-9
    assert (person.settled is not None) == kept


@pytest.mark.parametrize("lowest, moves", [(0.95, True), (0.86, True), (0.84, False), (0.65, False)])
def test_only_an_upright_person_walks(lowest, moves):
    """A person sitting down steps backwards at walking speed (0.3-0.7 m/s on the randomized
    benchmark's procedural sitting) while its pelvis drops: with the pelvis below
    CARRY.upright of its standing height at some estimate of the window, the move is no walk,
    so it neither turns the estimate round to face the seat nor weighs the walking prior."""
    assert CARRY.upright == 0.85
    model = body_model("full")
    person = _person(model)
    pose = standing_pose(model, (0.0, 0.0), 0.0)  # facing +x
    person.estimator.initialise(pose, 0.0)
    person.pose, person.estimates, person.since_turn = pose, 10, CARRY.frames
    standing = float(person.stance[2])
    heights = np.linspace(standing, lowest * standing, CARRY.frames)  # the pelvis drops as it goes
    _walk(person, [np.array([-0.7 / 30.0 * i, 0.0]) for i in range(CARRY.frames)], heights)  # backwards
    assert (person.walking() is not None) == moves
    person.face_the_way_walked()
    heading = person.pose[model.dof_names.index("heading")]
    assert abs(abs(heading) - np.pi) < 1e-9 if moves else heading == 0.0


def test_a_person_back_from_a_gap_walks_on_the_way_it_walked_before():
    model = body_model("full")
    person = _person(model)
    pose = standing_pose(model, (0.0, 0.0), 0.0)
    person.estimator.initialise(pose, 0.0)
    person.pose, person.centroid = pose, np.array([0.0, 0.0, 1.0])
    _walk(person, [np.array([0.04 * i, 0.0]) for i in range(CARRY.walk_frames)])  # 1.2 m/s along +x
    person.lost = True
    person.come_back(np.array([1.0, 1.0, 1.0]))  # back at another blob after a gap
    assert not person.lost
    np.testing.assert_allclose(person.pose[:2], [1.0, 1.0])
    np.testing.assert_allclose(person.estimator.filter.estimate[:2], [1.0, 1.0])
    np.testing.assert_allclose(person.path[-1], [1.0, 1.0])  # the jump is no step: same way, same speed
    direction, weight = person.walking()
    assert direction == pytest.approx(0.0) and weight == pytest.approx(CARRY.walk_prior)
    person.carry(NOTHING)  # hidden again at once: carried on along +x (no camera sees through it)
    np.testing.assert_allclose(person.pose[:2], [1.04, 1.0])


@pytest.mark.parametrize("speed", [1.2, 0.3])
def test_a_person_carried_out_of_sight_at_a_walk_stands_its_legs(speed):
    """Carried at a walker's speed (above CARRY.walk_from), the legs' DOFs, and their occlusion
    memory, take the standing pose's (the middle of a gait cycle), the trunk, head and arms
    kept; coming back, the particles follow. Carried standing, nothing but the root's x, y
    moves."""
    model = body_model("full")
    person = _person(model)
    stride = standing_pose(model, (0.0, 0.0), 0.0)
    for name, angle in (("left_hip_flex", 0.4), ("right_hip_flex", -0.3), ("right_knee", 0.6),
                        ("left_shoulder_flex", -0.3), ("right_elbow", 0.5), ("trunk_lean", 0.1)):
        stride[model.dof(name)] = angle
    person.estimator.initialise(stride, 0.0)
    person.pose, person.centroid = stride.copy(), np.array([0.0, 0.0, 1.0])
    person.occlusion.memory = stride.copy()
    _walk(person, [np.array([speed / 30.0 * i, 0.0]) for i in range(CARRY.frames)])
    person.carry(NOTHING)
    legs = np.array([n.startswith(CARRY.stand_dofs) for n in model.dof_names])
    assert legs.sum() == 8 and person.walked_on == (speed > CARRY.walk_from)
    rest = standing_pose(model) if person.walked_on else stride
    np.testing.assert_allclose(person.pose[legs], rest[legs])
    np.testing.assert_allclose(person.occlusion.memory[legs], rest[legs])
    np.testing.assert_allclose(person.pose[2:][~legs[2:]], stride[2:][~legs[2:]])  # z, heading, trunk, head, arms
    person.come_back(np.array([0.5, 0.0, 1.0]))
    np.testing.assert_allclose(person.estimator.filter.particles[:, legs],
                               np.broadcast_to(rest[legs], (len(person.estimator.filter.particles), 8)), atol=1e-12)
    np.testing.assert_allclose(person.estimator.filter.estimate, person.pose, atol=1e-12)


def test_a_person_walking_behind_a_cabinet_is_carried_at_its_speed_in_full_view():
    """The estimates of a person walking into occlusion stall at the cabinet's edge: the
    carry takes its step from the last estimates with every part in view (while they are
    recent): their mean step or their blob's median velocity (the first frames of the blob
    being cut do not count), whichever is faster; a person suspended on its blob while
    walking comes back where it was carried to, not at its blob's centroid (which stays at
    the edge). The estimates in full view need not follow one another."""
    model = body_model("full")
    person = _person(model)
    pose = standing_pose(model, (0.0, 0.0), 0.0)
    person.estimator.initialise(pose, 0.0)
    person.centroid = np.array([0.0, 0.0, 1.0])
    shin = model.part_names.index("right_shin")
    for i in range(10):  # in full view, the blob at 1.2 m/s along +x (the last two: being cut),
        person.part_visible[shin] = i not in (4, 5)  # but for a shin counted hidden twice; the
        blob = [1.2, 0.0] if i < 8 else [0.7, 0.1]  # estimates lag, at 0.6 m/s
        person.settle(pose + np.eye(model.num_dofs)[0] * 0.02 * i, np.array(blob))
    person.part_visible[shin] = False
    for i in range(5):  # partly hidden: the estimate slows to 0.3 m/s, the blob stalls
        person.settle(pose + np.eye(model.num_dofs)[0] * (0.18 + 0.01 * (i + 1)), np.array([0.2, 0.0]))
    np.testing.assert_allclose(person.step(), [0.04, 0.0])
    person.carry(NOTHING)
    np.testing.assert_allclose(person.pose[:2], [0.27, 0.0])
    assert person.walked_on  # carried at 1.2 m/s: it comes back there, not on its blob
    person.come_back(np.array([0.9, 0.3, 1.0]))
    np.testing.assert_allclose(person.pose[:2], [0.27, 0.0])
    np.testing.assert_allclose(person.estimator.filter.estimate[:2], [0.27, 0.0])
    assert not person.walked_on and not person.lost
    for _ in range(CARRY.frames):  # standing partly hidden for long: its own recent path again
        person.settle(person.pose, np.array([0.3, 0.0]))
    np.testing.assert_allclose(person.step(), [0.0, 0.0], atol=1e-12)
    person.carry(NOTHING)
    assert not person.walked_on  # carried standing: it comes back on its blob
    person.come_back(np.array([0.9, 0.3, 1.0]))
    np.testing.assert_allclose(person.pose[:2], np.array([0.9, 0.3]) + person.anchor)
    person.part_visible[:] = True
    for i in range(3):  # in full view again, 0.6 m/s along -y: the walk before is too old to count
        person.settle(person.pose - np.eye(model.num_dofs)[1] * 0.02, np.array([0.0, -0.6]))
    np.testing.assert_allclose(person.step(), [0.0, -0.02], atol=1e-12)
    for i in range(3):  # speeding up to 0.9 m/s, the blob's velocity lagging at 0.6: the estimates'
        person.settle(person.pose - np.eye(model.num_dofs)[1] * 0.03, np.array([0.0, -0.6]))
    np.testing.assert_allclose(person.step(), [0.0, -0.026], atol=1e-12)  # (2 x 0.02 + 3 x 0.03) / 5


def _shoulder_heading(joints: np.ndarray) -> np.ndarray:
    """(T,) rad: the way a skeleton (T, 15, 3) faces, from its shoulders."""
    from occupose.joints import JOINT_INDEX

    across = joints[:, JOINT_INDEX["left_shoulder"], :2] - joints[:, JOINT_INDEX["right_shoulder"], :2]
    return np.arctan2(-across[:, 0], across[:, 1])


@pytest.fixture(scope="module")
def standing_still():
    """A person standing still 3 m in front of the camera of no_occlusion from the first frame,
    facing away from it or towards it: 75 rendered frames (2.5 s) each."""
    import math
    from dataclasses import replace

    from occupose.body.dims import DEFAULT_DIMS
    from occupose.synth import motion as sm
    from occupose.synth.generate import frames
    from occupose.synth.scenarios import build_scenario

    base = build_scenario("no_occlusion", use_mocap=False)
    scenes = {}
    for way, heading in (("away", math.pi / 2), ("towards", -math.pi / 2)):
        joints = sm.MotionBuilder((0.2, 3.0), heading, DEFAULT_DIMS.scaled(1.75), base.fps).stand(3.0).joints()
        scene = replace(base, people=(replace(base.people[0], joints=joints),))
        scenes[way] = scene, list(frames(scene, seed=0, num_frames=75))
    return scenes


@pytest.mark.parametrize("way", ["away", "towards"])
def test_a_person_standing_still_is_turned_to_the_way_its_limbs_bend(standing_still, way):
    """Nothing walks to say which way a still person faces; the twin test does, over a new
    person's first seconds (carry.start_twin_s, on by default) and all along (carry.twin,
    off by default). Measured on the person facing away: it starts facing the camera, 180 deg
    off, and is turned in frame 49 by the start's test (after its 1.5 s), in frame 42 by the
    test all along (after its first window of 1 s); with neither it faces the camera all
    along. The person facing the camera is never turned."""
    from occupose.run import track_frames
    from occupose.tracker import Tracker

    scene, rendered = standing_still[way]
    truth = _shoulder_heading(np.stack([f.joints[0] for f in rendered]))
    runs = {}
    for name, values in (("neither", {"carry.start_twin_s": 0.0}), ("start", {}),
                         ("all along", {"carry.start_twin_s": 0.0, "carry.twin": True})):
        tracker = Tracker(scene.cameras, scene.fps, TrackerConfig().with_values(values), seed=0)
        joints = track_frames(tracker, rendered, len(rendered)).tracks[1][0]
        tracked = np.isfinite(joints[:, 0, 0])
        off = np.abs((_shoulder_heading(joints[tracked]) - truth[tracked] + np.pi) % (2 * np.pi) - np.pi)
        runs[name] = np.degrees(off)
    if way == "away":
        assert np.median(runs["neither"]) > 150
        for name in ("start", "all along"):
            assert runs[name][0] > 150 and np.all(runs[name][-15:] < 30), name
    else:
        assert all(np.all(off < 30) for off in runs.values())


def test_a_person_carried_into_space_a_camera_sees_through_stays():
    """Carried at a walk, a person walks on behind something (the camera measures a surface
    in front of where its torso goes), but not into space the camera sees through (a
    surface measured beyond it): nobody is there, so the walk out of sight has stopped."""
    camera = FRONT
    model = body_model("full")
    for depth, walks in ((1.0, True), (6.0, False)):  # a cabinet 1 m from the camera; a wall 6 m away
        person = _person(model)
        pose = standing_pose(model, (0.0, 0.0), 0.0)
        person.estimator.initialise(pose, 0.0)
        person.pose, person.centroid = pose.copy(), np.array([0.0, 0.0, 1.0])
        _walk(person, [np.array([0.04 * i, 0.0]) for i in range(CARRY.frames)])  # 1.2 m/s along +x
        image = np.full((camera.height, camera.width), depth, np.float32)
        assert person.carry({"front": image}) == walks and person.lost
        np.testing.assert_allclose(person.pose[:2], [0.04, 0.0] if walks else [0.0, 0.0])
        assert person.walked_on == walks
        holes = np.zeros_like(image)  # no measurement sees through nothing: it walks on
        assert person.carry({"front": holes})


@pytest.mark.parametrize("x, walks", [(0.0, True), (1.4, True), (1.5, False)])
def test_a_person_carried_out_of_every_cameras_image_stays(x, walks):
    """Out of every camera's image is not hidden: a person carried there would walk on
    for ever (an estimate slid off a person standing still was carried out of the room and
    on behind the camera while its blob stayed). FRONT sees 1.52 m to the right at the
    person's distance: a step of 4 cm along +x from x = 1.5 m takes the torso out."""
    model = body_model("full")
    person = _person(model)
    pose = standing_pose(model, (x, 0.0), 0.0)
    person.estimator.initialise(pose, 0.0)
    person.pose, person.centroid = pose.copy(), np.array([x, 0.0, 1.0])
    _walk(person, [np.array([x + 0.04 * i - 0.56, 0.0]) for i in range(CARRY.frames)])  # 1.2 m/s along +x
    assert person.carry(NOTHING) == walks and person.walked_on == walks
    np.testing.assert_allclose(person.pose[:2], [x + 0.04, 0.0] if walks else [x, 0.0])


def test_a_person_is_not_carried_out_of_the_watched_area():
    """Nor out of the floor area the cameras watch (the grid's, beyond which they measure
    nothing of anyone): a walker behind a back wall is not there."""
    model = body_model("full")
    for high, walks in ((1.0, True), (0.02, False)):
        person = _person(model, area=(np.array([-1.0, -1.0]), np.array([high, 1.0])))
        pose = standing_pose(model, (0.0, 0.0), 0.0)
        person.estimator.initialise(pose, 0.0)
        person.pose, person.centroid = pose.copy(), np.array([0.0, 0.0, 1.0])
        _walk(person, [np.array([0.04 * i - 0.56, 0.0]) for i in range(CARRY.frames)])  # 1.2 m/s along +x
        assert person.carry(NOTHING) == walks
        np.testing.assert_allclose(person.pose[:2], [0.04 if walks else 0.0, 0.0])
