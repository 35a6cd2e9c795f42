"""Chaining actions with MotionBuilder: continuity, segments, determinism, constant bones."""

import math

import numpy as np
import pytest

from occupose.body.dims import BodyDims, bone_lengths_from_dims
from occupose.io.mocap import bone_lengths
from occupose.joints import JOINT_INDEX as J
from occupose.synth import motion as m

FPS = 30.0


@pytest.fixture(scope="module")
def script():
    """A chained scene: walk round a corner, sit, gesture, stand, wave, walk back."""
    b = m.MotionBuilder((0.0, 0.0), heading=0.0, fps=FPS)
    b.walk([(3.0, 0.0), (3.0, 2.0)], speed=1.3).turn(-math.pi / 2).sit_down(0.45, 1.8).sitting(1.0)
    b.gesture("cross", duration=2.0).wave("left", 2.0, 2).stand_up(1.8).stand(1.0).walk([(0.0, 0.0)], 1.0)
    return b


def test_bone_lengths_are_constant_and_equal_dims(script):
    for dims in (BodyDims(), BodyDims().scaled(1.58)):
        b = m.MotionBuilder((0.0, 0.0), dims=dims).walk([(2.0, 1.0)]).sit_down(0.42).wave("both").stand_up()
        lengths = bone_lengths(b.joints())
        np.testing.assert_allclose(lengths, np.broadcast_to(bone_lengths_from_dims(dims), lengths.shape),
                                   atol=1e-6)
    lengths = bone_lengths(script.joints())
    assert np.ptp(lengths, axis=0).max() < 1e-6


def test_chained_actions_have_no_jumps(script):
    j = script.joints()
    assert j.shape == (script.num_frames, 15, 3) and j.dtype == np.float64
    step = np.linalg.norm(np.diff(j, axis=0), axis=2)
    assert step.max() < 0.15                                     # < 4.5 m/s at 30 fps
    # poses stay continuous across the boundaries between actions
    for seg in script.segments()[1:]:
        assert step[seg.start - 1].max() < 0.1
    assert j[..., 2].min() > 0.05 - 1e-9                         # nothing under the floor but feet above 5 cm


def test_segments_cover_all_frames(script):
    segments = script.segments()
    assert [s.name for s in segments] == ["walk", "turn", "sit_down", "sitting", "gesture:cross", "wave",
                                          "stand_up", "stand", "walk"]
    assert segments[0].start == 0 and segments[-1].stop == script.num_frames
    assert all(a.stop == b.start for a, b in zip(segments, segments[1:]))
    sitting = segments[3]
    pelvis = script.joints()[sitting.start:sitting.stop, J["pelvis"], 2]
    assert np.all(pelvis < 0.6)
    assert script.poses().shape == (script.num_frames, m.POSE_SIZE)


def test_motion_is_deterministic(script):
    again = m.MotionBuilder((0.0, 0.0), heading=0.0, fps=FPS)
    again.walk([(3.0, 0.0), (3.0, 2.0)], speed=1.3).turn(-math.pi / 2).sit_down(0.45, 1.8).sitting(1.0)
    again.gesture("cross", duration=2.0).wave("left", 2.0, 2).stand_up(1.8).stand(1.0).walk([(0.0, 0.0)], 1.0)
    np.testing.assert_array_equal(again.joints(), script.joints())
