"""Procedural actions: the gait, turning, standing, sitting, arm motions, keyframes."""

import math

import numpy as np
import pytest

from occupose.body.dims import BodyDims
from occupose.synth.retarget import facing_from_joints as facing
from occupose.joints import JOINT_INDEX as J
from occupose.synth import motion as m

FPS = 30.0


def angle_diff(a, b):
    return np.abs((np.asarray(a) - b + np.pi) % (2 * np.pi) - np.pi)


@pytest.fixture(scope="module")
def straight():
    """Poses and joints of a 6 m walk along +x at 1.3 m/s, start frame included."""
    start = m.stance((0.0, 0.0), 0.0)
    poses = np.vstack([start, m.walk(start, [(6.0, 0.0)], 1.3, fps=FPS)])
    return poses, m.joints_from_procedural(poses)


# ---------------------------------------------------------------------------------------
# walking


def test_walk_moves_along_the_path_at_the_requested_speed(straight):
    poses, j = straight
    pelvis = j[:, J["pelvis"]]
    np.testing.assert_allclose(pelvis[-1, :2], [6.0, 0.0], atol=1e-9)
    assert np.abs(pelvis[:, 1]).max() < 0.03           # sways, stays on the line
    speed = np.linalg.norm(np.diff(pelvis[:, :2], axis=0), axis=1) * FPS
    cruise = speed[45:-45]                             # under way
    assert np.mean(cruise) == pytest.approx(1.3, rel=0.05)
    duration = (len(poses) - 1) / FPS
    assert 6.0 / 1.3 < duration < 6.0 / 1.3 + 1.2      # plus speeding up, braking, closing the feet
    for speed_request in (0.9, 1.6):
        p = m.walk(m.stance(), [(6.0, 0.0)], speed_request)
        v = np.linalg.norm(np.diff(p[:, :2], axis=0), axis=1) * FPS
        assert np.mean(v[45:-45]) == pytest.approx(speed_request, rel=0.05)


def test_walk_cycle_is_human(straight):
    poses, j = straight
    pelvis = j[:, J["pelvis"]]
    under_way = slice(45, -45)
    # steps of about 0.7 m: successive foot plants of alternate feet
    plants = []
    for side in ("left", "right"):
        ankle = j[:, J[f"{side}_ankle"]]
        flat = ankle[:, 2] < 0.0805
        landed = np.flatnonzero(flat[1:] & ~flat[:-1]) + 1
        plants += [(f, ankle[f, 0]) for f in landed]
    xs = np.array([x for _, x in sorted(plants)])
    steps = np.diff(xs)[1:-2]                          # leave out starting and stopping
    assert np.all((steps > 0.6) & (steps < 0.8)), steps
    # knees bend in swing, pelvis bobs a few cm below standing, arms swing in counter-phase
    assert 0.9 < poses[under_way, m.LEFT + m.KNEE].max() < 1.3
    bob = pelvis[under_way, 2]
    assert 0.02 < np.ptp(bob) < 0.07 and bob.max() < poses[0, m.Z]
    left_arm = j[under_way, J["left_wrist"], 0] - pelvis[under_way, 0]
    left_leg = j[under_way, J["left_ankle"], 0] - pelvis[under_way, 0]
    right_arm = j[under_way, J["right_wrist"], 0] - pelvis[under_way, 0]
    assert np.corrcoef(left_arm, left_leg)[0, 1] < -0.7
    assert np.corrcoef(left_arm, right_arm)[0, 1] < -0.9
    assert np.ptp(left_arm) > 0.3


def test_walking_feet_stay_on_the_floor_and_do_not_slide(straight):
    _, j = straight
    for side in ("left", "right"):
        ankle = j[:, J[f"{side}_ankle"]]
        assert ankle[:, 2].min() == pytest.approx(0.08, abs=1e-6)
        assert ankle[:, 2].min() > 0.05
        assert ankle[:, 2].max() < 0.25
        on_floor = (ankle[1:, 2] < 0.0805) & (ankle[:-1, 2] < 0.0805)
        slide = np.linalg.norm(np.diff(ankle[:, :2], axis=0), axis=1)[on_floor]
        assert slide.max() < 0.005                     # metres per frame while planted
    # ends standing, feet side by side under the hips
    np.testing.assert_allclose(j[-1, [J["left_ankle"], J["right_ankle"]], :2],
                               j[-1, [J["left_hip"], J["right_hip"]], :2], atol=1e-6)


def test_heading_follows_the_path():
    start = m.stance((0.0, 0.0), 0.0)
    poses = m.walk(start, [(3.0, 0.0), (3.0, 3.0)], 1.2)
    j = m.joints_from_procedural(poses)
    pelvis = j[:, J["pelvis"], :2]
    assert angle_diff(facing(j[-1]), np.pi / 2) < 1e-6
    velocity = np.gradient(pelvis, axis=0)
    moving = np.linalg.norm(velocity, axis=1) * FPS > 0.8
    travel = np.arctan2(velocity[moving, 1], velocity[moving, 0])
    assert np.max(angle_diff(facing(j[moving]), travel)) < 0.2
    # the corner is rounded: a peak turn rate like recorded walking turns (2.3-3.4 rad/s)
    assert np.abs(np.diff(poses[:, m.HEADING])).max() * FPS < 3.5
    # a walk starting the wrong way turns on the spot first, towards the path
    back = m.walk(start, [(-3.0, 0.0)], 1.2)
    jb = m.joints_from_procedural(back)
    turning = np.flatnonzero(np.linalg.norm(jb[:, J["pelvis"], :2], axis=1) < 1e-9)
    assert len(turning) > 15
    assert angle_diff(facing(jb[turning[-1]]), np.pi) < 1e-6
    assert jb[-1, J["pelvis"], 0] == pytest.approx(-3.0)


def test_walk_rejects_bad_paths_and_speeds():
    start = m.stance()
    with pytest.raises(ValueError, match=r"path_xy must be finite waypoints of shape \(K, 2\)"):
        m.walk(start, [1.0, 2.0])
    with pytest.raises(ValueError, match="lead away from the start"):
        m.walk(start, [(0.01, 0.0)])
    with pytest.raises(ValueError, match="walk, turn, walk"):
        m.walk(start, [(2.0, 0.0), (0.0, 0.1)])
    with pytest.raises(ValueError, match="speed"):
        m.walk(start, [(2.0, 0.0)], speed=4.0)
    seated = m.sit_down(start)[-1]
    with pytest.raises(ValueError, match="call stand_up first"):
        m.walk(seated, [(2.0, 0.0)])


def test_turn_steps_round_without_sliding():
    start = m.stance((1.0, 1.0), 0.5)
    poses = np.vstack([start, m.turn(start, 0.5 - 2.8, fps=FPS)])
    j = m.joints_from_procedural(poses)
    assert angle_diff(facing(j[-1]), 0.5 - 2.8) < 1e-9
    np.testing.assert_allclose(j[:, J["pelvis"], :2], 1.0, atol=1e-12)
    for side in ("left", "right"):
        ankle = j[:, J[f"{side}_ankle"]]
        planted = (ankle[1:, 2] < 0.0801) & (ankle[:-1, 2] < 0.0801)
        assert np.linalg.norm(np.diff(ankle[:, :2], axis=0), axis=1)[planted].max() < 0.002
        assert ankle[:, 2].max() > 0.1                 # the feet step
    np.testing.assert_allclose(j[-1, [J["left_ankle"], J["right_ankle"]], :2],
                               j[-1, [J["left_hip"], J["right_hip"]], :2], atol=1e-9)


# ---------------------------------------------------------------------------------------
# standing and sitting


def test_sitting_down_puts_the_pelvis_on_the_seat():
    dims = BodyDims()
    start = m.stance((0.0, 0.0), heading=math.pi)   # facing -x: the seat is towards +x
    b = m.MotionBuilder(start_pose=start).sit_down(0.45, 1.8).sitting(2.0)
    j = b.joints()
    seated = j[b.segments()[1].start:b.segments()[1].stop]
    back, z = m.pelvis_offset_from_seat(0.45, dims)
    assert z == pytest.approx(0.45 + dims.seat_clearance)
    assert np.abs(seated[:, J["pelvis"], 2] - z).max() < 0.03
    np.testing.assert_allclose(seated[:, J["pelvis"], 0], back, atol=0.03)
    for side in ("left", "right"):
        thigh = seated[:, J[f"{side}_knee"]] - seated[:, J[f"{side}_hip"]]
        assert np.abs(np.degrees(np.arcsin(thigh[:, 2] / dims.thigh))).max() < 15     # near horizontal
        shin = seated[:, J[f"{side}_ankle"]] - seated[:, J[f"{side}_knee"]]
        assert np.abs(shin[:, :2]).max() < 0.02                                     # near vertical
    # the feet never leave their place, hips and knees end near 90 degrees
    ankles = j[:, [J["left_ankle"], J["right_ankle"]]]
    np.testing.assert_allclose(ankles, np.broadcast_to(ankles[0], ankles.shape), atol=1e-9)
    end = b.pose
    assert abs(end[m.LEFT + m.HIP_FLEX] - math.pi / 2) < 0.25 and abs(end[m.LEFT + m.KNEE] - math.pi / 2) < 0.25


def test_standing_up_returns_to_the_standing_pose():
    start = m.stance((2.0, -1.0), heading=0.3)
    b = m.MotionBuilder(start_pose=start).sit_down(0.5).stand_up(1.8)
    np.testing.assert_allclose(b.pose, start, atol=1e-9)
    lean = b.poses()[b.segments()[1].start:, m.TRUNK_LEAN]
    assert lean.max() > 0.5                                   # leans forward to rise


def test_seat_height_and_start_pose_are_checked():
    with pytest.raises(ValueError, match=r"seat_height must be in \["):
        m.sit_down(m.stance(), seat_height=0.9)
    with pytest.raises(ValueError, match="call sit_down first"):
        m.stand_up(m.stance())
    with pytest.raises(ValueError, match="call sit_down first"):
        m.sitting(m.stance(), 1.0)
    with pytest.raises(ValueError, match="call stand_up first"):
        m.sit_down(m.sit_down(m.stance())[-1])


def test_idle_standing_sways_a_little_and_ends_where_it_started():
    start = m.stance()
    poses = m.stand(start, 4.0)
    j = m.joints_from_procedural(poses)
    shift = np.linalg.norm(j[:, J["pelvis"], :2], axis=1)
    assert 0.003 < shift.max() < 0.03
    np.testing.assert_allclose(poses[-1], start, atol=1e-9)
    ankles = j[:, [J["left_ankle"], J["right_ankle"]]]
    np.testing.assert_allclose(ankles, np.broadcast_to(m.joints_from_procedural(start)[[J["left_ankle"], J["right_ankle"]]],
                                                       ankles.shape), atol=1e-6)


# ---------------------------------------------------------------------------------------
# arms


@pytest.mark.parametrize("arm", ["left", "right", "both"])
def test_wave_raises_the_wrist_above_the_shoulder(arm):
    start = m.stance()
    poses = m.wave(start, arm, duration=2.5, cycles=3)
    j = m.joints_from_procedural(poses)
    middle = slice(20, -20)
    sides = ("left", "right") if arm == "both" else (arm,)
    for side in ("left", "right"):
        above = j[middle, J[f"{side}_wrist"], 2] - j[middle, J[f"{side}_shoulder"], 2]
        if side in sides:
            assert above.min() > 0.1
            lateral = j[middle, J[f"{side}_wrist"], 1]
            assert np.ptp(lateral) > 0.1                          # the hand swings side to side
        else:
            assert above.max() < -0.4                             # the other arm stays down
    np.testing.assert_allclose(poses[-1], start, atol=1e-12)
    non_arm = np.r_[0:m.LEFT + m.SHOULDER_FLEX, m.LEFT + m.HIP_FLEX:m.LEFT + m.KNEE + 1,
                    m.RIGHT + m.HIP_FLEX:m.RIGHT + m.KNEE + 1]
    np.testing.assert_array_equal(poses[:, non_arm], np.broadcast_to(start[non_arm], poses[:, non_arm].shape))


def test_gestures():
    start = m.stance()
    j0 = m.joints_from_procedural(start)

    def held(name, arm="right"):
        poses = m.gesture(start, name, arm, duration=2.0)
        np.testing.assert_allclose(poses[-1], start, atol=1e-12)
        return m.joints_from_procedural(poses[len(poses) // 2])

    assert held("raise")[J["right_wrist"], 2] > j0[J["head"], 2] + 0.2
    point = held("point", "left")
    assert point[J["left_wrist"], 0] > 0.5 and abs(point[J["left_wrist"], 2] - point[J["left_shoulder"], 2]) < 0.1
    assert held("side")[J["right_wrist"], 1] < -0.65
    cross = held("cross", "right")                                # always both arms
    assert cross[J["left_wrist"], 1] < 0.0 < cross[J["right_wrist"], 1]
    assert np.all(cross[[J["left_wrist"], J["right_wrist"]], 0] > 0.15)   # in front of the body
    with pytest.raises(ValueError, match="valid names: raise, point, side, reach, cross"):
        m.gesture(start, "salute")
    with pytest.raises(ValueError, match="arm must be one of left, right, both"):
        m.wave(start, "middle")


# ---------------------------------------------------------------------------------------
# keyframes


def test_keyframes_interpolate_smoothly_through_the_keys():
    start = m.stance()
    key1 = m.pose_with(start, right_shoulder_flex=1.2, x=0.2)
    key2 = m.pose_with(start, right_shoulder_flex=0.4, x=0.3)
    for interpolation in m.INTERPOLATIONS:
        poses = m.keyframes(start, [1.0, 2.0], [key1, key2], interpolation, fps=FPS)
        assert poses.shape == (60, m.POSE_SIZE)
        np.testing.assert_allclose(poses[29], key1, atol=1e-12)
        np.testing.assert_allclose(poses[-1], key2, atol=1e-12)
        flex = poses[:, m.RIGHT + m.SHOULDER_FLEX]
        assert flex.max() <= 1.2 + 1e-12                           # no overshoot
    smooth = m.keyframes(start, [1.0], [key1], fps=FPS)
    assert smooth[14, m.X] == pytest.approx(0.1, abs=0.01)        # half way at half time
    with pytest.raises(ValueError, match="strictly increasing"):
        m.keyframes(start, [1.0, 1.0], [key1, key2])
    with pytest.raises(ValueError, match="valid names: smoothstep, pchip"):
        m.keyframes(start, [1.0], [key1], "linear")


def test_frame_rate_sets_the_frame_count():
    for fps in (15.0, 30.0, 60.0):
        assert m.stand(m.stance(), 2.0, fps=fps).shape == (int(2 * fps), m.POSE_SIZE)
    with pytest.raises(ValueError, match="fps must be a positive number"):
        m.MotionBuilder(fps=0)
    with pytest.raises(ValueError, match="duration must be a positive number"):
        m.stand(m.stance(), -1.0)
