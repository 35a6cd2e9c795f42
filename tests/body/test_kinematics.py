"""occupose.body.kinematics: forward kinematics, the kernels against a slow NumPy reference
and hand-computed poses, and the generator's joints from the same angles."""

import math

import numpy as np
import pytest

from occupose.body import BODY_MODELS, capsules_from_poses, joints_from_poses
from occupose.body.dims import DEFAULT_DIMS
from occupose.body.model import FULL_TORSO_SPREAD
from occupose.joints import JOINT_INDEX as J
from occupose.synth import motion as sm


D = DEFAULT_DIMS


# ---------------------------------------------------------------------------------------
# Slow NumPy reference of the forward kinematics (general rotation matrices, one pose at a time)


def _rotation(axis: int, angle: float) -> np.ndarray:
    k = np.eye(3)[axis]
    kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + math.sin(angle) * kx + (1 - math.cos(angle)) * kx @ kx


def _frames_reference(model, pose):
    rot, pos = [], []
    for j, parent in enumerate(model.parents):
        r = np.eye(3) if parent < 0 else rot[parent].copy()
        p = model.offsets[j].copy() if parent < 0 else pos[parent] + rot[parent] @ model.offsets[j]
        for d in np.flatnonzero(model.dof_node == j):
            value = pose[d] * model.dof_sign[d]
            if model.dof_type[d] == 0:
                p = p + (np.eye(3) if parent < 0 else rot[parent])[:, model.dof_axis[d]] * value
            else:
                r = r @ _rotation(model.dof_axis[d], value)
        rot.append(r)
        pos.append(p)
    return rot, pos


def _points_reference(model, poses, nodes, offsets):
    out = np.full((len(poses), len(nodes), 3), np.nan)
    for i, pose in enumerate(poses):
        rot, pos = _frames_reference(model, pose)
        for m, (n, off) in enumerate(zip(nodes, offsets)):
            if n >= 0:
                out[i, m] = pos[n] + rot[n] @ off
    return out


def _random_poses(model, rng, count):
    return rng.uniform(model.limits[:, 0], model.limits[:, 1], size=(count, model.num_dofs)) * np.where(
        np.arange(model.num_dofs) < 2, 0.05, 1.0)


# ---------------------------------------------------------------------------------------
# Forward kinematics


@pytest.mark.parametrize("name", ["full", "upper"])
def test_kernel_matches_numpy_reference(name, rng):
    m = BODY_MODELS[name]
    poses = _random_poses(m, rng, 40)
    a, b = capsules_from_poses(m, poses)
    assert a.shape == b.shape == (40, m.num_capsules, 3) and a.flags.c_contiguous and b.flags.c_contiguous
    np.testing.assert_allclose(a, _points_reference(m, poses, m.capsule_nodes[0], m.capsule_offsets[0]),
                               atol=1e-12)
    np.testing.assert_allclose(b, _points_reference(m, poses, m.capsule_nodes[1], m.capsule_offsets[1]),
                               atol=1e-12)
    joints = joints_from_poses(m, poses)
    np.testing.assert_allclose(joints, _points_reference(m, poses, m.joint_nodes, m.joint_offsets), atol=1e-12)
    assert np.isnan(joints[:, J["left_knee"]]).all() == (name == "upper")


def test_serial_and_parallel_kernels_agree(rng):
    from occupose.body import _kernels
    from occupose.body.kinematics import _tree

    m = BODY_MODELS["full"]
    poses = _random_poses(m, rng, _kernels.SERIAL_POSES + 37)  # more than the serial kernel takes
    a, b = capsules_from_poses(m, poses)
    serial = np.empty_like(a), np.empty_like(b)
    _kernels.points_from_poses_serial(poses, *_tree(m), m.capsule_nodes[0], m.capsule_offsets[0], serial[0],
                                      m.capsule_nodes[1], m.capsule_offsets[1], serial[1])
    np.testing.assert_array_equal(a, serial[0])
    np.testing.assert_array_equal(b, serial[1])
    np.testing.assert_allclose(a[-3:], _points_reference(m, poses[-3:], m.capsule_nodes[0], m.capsule_offsets[0]),
                               atol=1e-12)


def test_kernel_sincos_matches_libm(rng):
    from occupose.body._kernels import sincos

    x = np.concatenate([rng.uniform(-60.0, 60.0, 3000), np.arange(-8, 9) * math.pi / 4, [0.0, -0.0]])
    got = np.array([sincos(v) for v in x])
    np.testing.assert_allclose(got[:, 0], np.sin(x), rtol=0, atol=3e-16)
    np.testing.assert_allclose(got[:, 1], np.cos(x), rtol=0, atol=3e-16)


def _pose(m, **values):
    pose = np.zeros(m.num_dofs)
    for key, value in values.items():
        pose[m.dof(key)] = value
    return pose


def test_zero_pose_stands_upright():
    m = BODY_MODELS["full"]
    j = joints_from_poses(m, _pose(m, x=1.0, y=2.0, z=0.9)[None])[0]
    sh_z = 0.9 + D.spine - D.shoulder_drop
    np.testing.assert_allclose(j[J["pelvis"]], [1.0, 2.0, 0.9])
    np.testing.assert_allclose(j[J["head"]], [1.0, 2.0, 0.9 + D.spine + D.neck_head])
    np.testing.assert_allclose(j[J["left_wrist"]], [1.0, 2.0 + D.shoulder_width, sh_z - D.upper_arm - D.forearm])
    np.testing.assert_allclose(j[J["right_ankle"]], [1.0, 2.0 - D.pelvis_width / 2, 0.9 - D.thigh - D.shin])
    a, b = capsules_from_poses(m, _pose(m, z=0.9)[None])
    torso = m.capsule_part == m.part_names.index("torso")  # two cones, left and right
    hips, chest = FULL_TORSO_SPREAD
    np.testing.assert_allclose(a[0, torso], [[0, hips, 0.9 + 0.12 * D.spine], [0, -hips, 0.9 + 0.12 * D.spine]])
    np.testing.assert_allclose(b[0, torso], [[0, chest, 0.9 + 0.79 * D.spine], [0, -chest, 0.9 + 0.79 * D.spine]])


def test_arm_raised_forward_and_turned():
    m = BODY_MODELS["full"]
    # facing +y (heading 90 deg), left arm raised 90 deg forward: the wrist points along +y
    pose = _pose(m, z=1.0, heading=math.pi / 2, left_shoulder_flex=math.pi / 2)
    j = joints_from_poses(m, pose[None])[0]
    shoulder = [-D.shoulder_width, 0.0, 1.0 + D.spine - D.shoulder_drop]  # left of a +y facing body is -x
    np.testing.assert_allclose(j[J["left_shoulder"]], shoulder, atol=1e-12)
    np.testing.assert_allclose(j[J["left_wrist"]], np.add(shoulder, [0, D.upper_arm + D.forearm, 0]), atol=1e-12)
    # abducted 90 deg instead: the arm points out to the left (-x), and the elbow bent 90 deg
    # turns the forearm forward (+y)
    pose = _pose(m, z=1.0, heading=math.pi / 2, left_shoulder_abd=math.pi / 2, left_elbow=math.pi / 2)
    j = joints_from_poses(m, pose[None])[0]
    elbow = np.add(shoulder, [-D.upper_arm, 0, 0])
    np.testing.assert_allclose(j[J["left_elbow"]], elbow, atol=1e-12)
    np.testing.assert_allclose(j[J["left_wrist"]], elbow + [0, D.forearm, 0], atol=1e-12)


def test_trunk_lean_and_knee():
    m = BODY_MODELS["full"]
    pose = _pose(m, z=1.0, trunk_lean=math.pi / 2, right_knee=math.pi / 2, right_hip_flex=math.pi / 2)
    j = joints_from_poses(m, pose[None])[0]
    np.testing.assert_allclose(j[J["neck"]], [D.spine, 0, 1.0], atol=1e-12)       # bent forward flat
    # the hips turn with the torso: a thigh flexed 90 deg from a flat torso points down,
    # and the shin bent 90 deg at the knee points backwards
    np.testing.assert_allclose(j[J["right_knee"]], [0, -D.pelvis_width / 2, 1.0 - D.thigh], atol=1e-12)
    np.testing.assert_allclose(j[J["right_ankle"]], [-D.shin, -D.pelvis_width / 2, 1.0 - D.thigh], atol=1e-12)


def test_full_model_reproduces_the_generator_arms_and_legs():
    """Same angles as occupose.synth.motion give the same joints (trunk lean only)."""
    m = BODY_MODELS["full"]
    gen = sm.pose_with(sm.stance(heading=0.7), trunk_lean=0.3, left_shoulder_flex=1.0,
                       left_shoulder_abd=0.4, left_shoulder_rot=0.5, left_elbow=1.2, right_hip_flex=0.8,
                       right_hip_abd=0.2, right_knee=1.0, neck_flex=0.3)
    pose = _pose(m, x=gen[0], y=gen[1], z=gen[2], heading=0.7, trunk_lean=0.3, neck_flex=0.3)
    for side in ("left", "right"):
        for name in ("shoulder_flex", "shoulder_abd", "shoulder_rot", "elbow", "hip_abd", "knee"):
            pose[m.dof(f"{side}_{name}")] = gen[sm.POSE_INDEX[f"{side}_{name}"]]
        pose[m.dof(f"{side}_hip_flex")] = gen[sm.POSE_INDEX[f"{side}_hip_flex"]] + 0.3
    np.testing.assert_allclose(joints_from_poses(m, pose[None])[0], sm.joints_from_procedural(gen), atol=1e-12)


def test_poses_are_checked():
    m = BODY_MODELS["upper"]
    with pytest.raises(ValueError, match=r"\(P, 17\)"):
        capsules_from_poses(m, np.zeros((3, 25)))
    with pytest.raises(ValueError, match="BodyModel"):
        joints_from_poses("upper", np.zeros((1, 17)))
