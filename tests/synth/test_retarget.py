"""Tests of occupose.synth.retarget: retiming, facing and placing canonical sequences (synthetic arrays)."""

import math

import numpy as np
import pytest

from occupose.io.mocap import ANKLE_HEIGHT, bone_lengths
from occupose.joints import JOINT_INDEX as J
from occupose.synth import retarget as rt


def _rotz(points, angle):
    c, s = math.cos(angle), math.sin(angle)
    return points @ np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]]).T


def test_facing_from_joints_follows_rotation_about_z(standing_skeleton):
    body = standing_skeleton
    assert rt.facing_from_joints(body) == pytest.approx(math.pi / 2)
    angles = np.array([0.3, -2.0, 3.0])
    bodies = np.stack([_rotz(body, a) for a in angles])
    expected = np.angle(np.exp(1j * (math.pi / 2 + angles)))
    np.testing.assert_allclose(rt.facing_from_joints(bodies), expected, atol=1e-12)


def test_place_puts_pelvis_heading_and_ankles(rng, standing_skeleton):
    base = _rotz(standing_skeleton, 1.1) + [4.0, -3.0, 0.37]
    walk = np.linspace(0, 1, 45)[:, None, None] * [0.5, 0.2, 0.0]
    sway = np.zeros((45, 15, 3))
    sway[:, J["left_ankle"], 2] = 0.05 * np.sin(np.arange(45) / 3.0) ** 2
    joints = base + walk + sway
    out = rt.place(joints, start_xy=(2.0, -1.0), heading=math.pi, fps=30.0)
    assert out.shape == joints.shape
    np.testing.assert_allclose(out[0, J["pelvis"], :2], [2.0, -1.0], atol=1e-12)
    assert abs(np.angle(np.exp(1j * (rt.facing_from_joints(out[0]) - math.pi)))) < 1e-9
    ankles = out[:30, [J["left_ankle"], J["right_ankle"]], 2]
    assert ankles.min() == pytest.approx(ANKLE_HEIGHT)
    np.testing.assert_allclose(bone_lengths(out), bone_lengths(joints), atol=1e-12)
    with pytest.raises(ValueError, match="start_xy"):
        rt.place(joints, start_xy=(1.0, 2.0, 3.0))


def test_resample_is_exact_on_linear_motion(rng):
    v = rng.normal(size=(15, 3))
    joints = np.arange(121)[:, None, None] / 120.0 * v + rng.normal(size=(15, 3))  # 1 s at 120 fps
    down = rt.resample(joints, 120.0, 30.0)
    assert down.shape == (31, 15, 3)
    np.testing.assert_allclose(down, joints[::4], atol=1e-12)
    up = rt.resample(down, 30.0, 45.0)
    assert up.shape == (46, 15, 3)
    np.testing.assert_allclose(up, np.arange(46)[:, None, None] / 45.0 * v + joints[0], atol=1e-12)
    with pytest.raises(ValueError, match="positive"):
        rt.resample(joints, 0.0, 30.0)


def test_retarget_lengths_gives_the_new_bones_and_keeps_their_directions():
    from occupose.joints import BONES

    rng = np.random.default_rng(0)
    t = np.linspace(0, 1, 40)
    skeleton = np.array([[0, 0, 1.62], [0, 0, 1.5], [0, 0, 0.92], [0.18, 0, 1.44], [0.2, 0.05, 1.15], [0.22, 0.1, 0.9],
                         [-0.18, 0, 1.44], [-0.2, 0.05, 1.15], [-0.22, 0.1, 0.9], [0.095, 0, 0.92], [0.1, 0.02, 0.5],
                         [0.1, 0, 0.08], [-0.095, 0, 0.92], [-0.1, 0.02, 0.5], [-0.1, 0, 0.08]])
    joints = skeleton[None] + 0.02 * rng.standard_normal((40, 15, 3))
    joints[:, :, 0] += 1.2 * t[:, None]                                  # walks 1.2 m along x
    target = rng.uniform(0.1, 0.5, len(BONES))
    out = rt.retarget_lengths(joints, target)
    assert np.allclose(bone_lengths(out), target[None])
    for a, b in BONES:
        old, new = joints[:, b] - joints[:, a], out[:, b] - out[:, a]
        cos = np.sum(old * new, axis=-1) / np.linalg.norm(old, axis=-1) / np.linalg.norm(new, axis=-1)
        assert np.all(cos > 1 - 1e-9)
    legs = [i for i, (a, b) in enumerate(BONES) if {a, b} & {J["left_knee"], J["right_knee"]}]
    ratio = target[legs].sum() / np.median(bone_lengths(joints)[:, legs], axis=0).sum()
    travel = out[-1, J["pelvis"], 0] - out[0, J["pelvis"], 0]
    assert travel == pytest.approx(ratio * (joints[-1, J["pelvis"], 0] - joints[0, J["pelvis"], 0]))
    assert out[:30, [J["left_ankle"], J["right_ankle"]], 2].min() == pytest.approx(ANKLE_HEIGHT)
    with pytest.raises(ValueError, match="bone_lengths must be 14 positive"):
        rt.retarget_lengths(joints, target[:5])
