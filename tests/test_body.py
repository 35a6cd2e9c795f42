"""Tests of occupose.body: model tables, forward kinematics (kernel vs NumPy reference and
hand-computed poses)."""

import math

import numpy as np
import pytest

from occupose.body import BODY_MODELS, body_model, capsules_from_poses, joints_from_poses
from occupose.joints import JOINT_INDEX as J
from occupose.synth import motion as sm
from occupose.synth.motion import DEFAULT_DIMS

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
# Model tables


@pytest.mark.parametrize("name, dofs, parts, capsules", [("full", 25, 10, 10), ("upper", 17, 5, 13)])
def test_model_tables(name, dofs, parts, capsules):
    m = BODY_MODELS[name]
    assert (m.num_dofs, m.num_parts, m.num_capsules) == (dofs, parts, capsules)
    assert m.limits.shape == (dofs, 2) and np.all(m.limits[:, 0] < m.limits[:, 1])
    assert m.angular.sum() == dofs - 3 and not m.angular[:3].any()
    assert m.periodic.sum() == 1 and m.dof_names[np.argmax(m.periodic)] == "heading"
    assert m.capsule_radii.shape == (capsules, 2) and np.all(m.capsule_radii > 0.01)
    assert set(m.capsule_part) == set(range(parts))
    for groups in (m.partitions, m.weight_groups):
        assert sorted(np.concatenate([g.dofs for g in groups])) == list(range(dofs))
    assert [int(g.parts[0]) for g in m.weight_groups] == list(range(parts))
    assert list(m.partitions[0].dofs[:3]) == [0, 1, 2]  # the root comes first


def test_full_model_parts_and_partitions():
    m = BODY_MODELS["full"]
    assert m.part_names == ("torso", "head", "left_upper_arm", "left_forearm", "right_upper_arm",
                            "right_forearm", "left_thigh", "left_shin", "right_thigh", "right_shin")
    names = [[m.dof_names[d] for d in p.dofs] for p in m.partitions]
    assert names[0] == ["x", "y", "z", "heading", "trunk_lean", "trunk_side"]
    assert names[1] == ["neck_flex", "neck_side", "neck_twist"]
    assert names[2] == ["left_shoulder_flex", "left_shoulder_abd", "left_shoulder_rot", "left_elbow"]
    assert names[5] == ["right_hip_flex", "right_hip_abd", "right_hip_rot", "right_knee"]


def test_upper_model_weight_groups_are_table_1():
    m = BODY_MODELS["upper"]
    assert m.part_names == ("head", "shoulders", "torso", "right_arm", "left_arm")
    groups = {m.part_names[g.parts[0]]: [m.dof_names[d] for d in g.dofs] for g in m.weight_groups}
    assert groups["head"] == ["neck_flex", "neck_side"]
    assert groups["shoulders"] == ["x", "y", "z"]
    assert groups["torso"] == ["heading", "trunk_lean"]
    assert groups["right_arm"] == ["right_shoulder_flex", "right_shoulder_abd", "right_shoulder_rot",
                                   "right_elbow", "right_forearm_twist"]


def test_body_model_registry_errors_and_sizes():
    with pytest.raises(ValueError, match="valid names: full, upper"):
        body_model("legs")
    with pytest.raises(ValueError, match="girth"):
        body_model("full", girth=3.0)
    tall = body_model("full", D.scaled(1.9), girth=1.2)
    assert tall.offsets[tall.node_names.index("left_knee"), 2] == pytest.approx(-D.thigh * 1.9 / D.height)
    limbs = np.arange(tall.num_capsules) != tall.part_names.index("head")  # the head follows stature
    assert np.allclose(tall.capsule_radii[limbs], BODY_MODELS["full"].capsule_radii[limbs] * 1.2)


# ---------------------------------------------------------------------------------------
# Forward kinematics


@pytest.mark.parametrize("name", ["full", "upper"])
def test_kernel_matches_numpy_reference(name, rng):
    m = BODY_MODELS[name]
    poses = _random_poses(m, rng, 40)
    a, b = capsules_from_poses(m, poses)
    assert a.shape == b.shape == (40, m.num_capsules, 3) and a.flags.c_contiguous and b.flags.c_contiguous
    np.testing.assert_allclose(a, _points_reference(m, poses, m.capsule_nodes[:, 0], m.capsule_offsets[:, 0]),
                               atol=1e-12)
    np.testing.assert_allclose(b, _points_reference(m, poses, m.capsule_nodes[:, 1], m.capsule_offsets[:, 1]),
                               atol=1e-12)
    joints = joints_from_poses(m, poses)
    np.testing.assert_allclose(joints, _points_reference(m, poses, m.joint_nodes, m.joint_offsets), atol=1e-12)
    assert np.isnan(joints[:, J["left_knee"]]).all() == (name == "upper")


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
    torso = m.part_names.index("torso")
    np.testing.assert_allclose(a[0, torso], [0, 0, 0.9 + 0.12 * D.spine])
    np.testing.assert_allclose(b[0, torso], [0, 0, 0.9 + 0.79 * D.spine])


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
    gen = sm.pose_with(sm.standing_pose(heading=0.7), trunk_lean=0.3, left_shoulder_flex=1.0,
                       left_shoulder_abd=0.4, left_shoulder_rot=0.5, left_elbow=1.2, right_hip_flex=0.8,
                       right_hip_abd=0.2, right_knee=1.0, neck_flex=0.3)
    pose = _pose(m, x=gen[0], y=gen[1], z=gen[2], heading=0.7, trunk_lean=0.3, neck_flex=0.3)
    for side in ("left", "right"):
        for name in ("shoulder_flex", "shoulder_abd", "shoulder_rot", "elbow", "hip_abd", "knee"):
            pose[m.dof(f"{side}_{name}")] = gen[sm.POSE_INDEX[f"{side}_{name}"]]
        pose[m.dof(f"{side}_hip_flex")] = gen[sm.POSE_INDEX[f"{side}_hip_flex"]] + 0.3
    np.testing.assert_allclose(joints_from_poses(m, pose[None])[0], sm.joints_from_pose(gen), atol=1e-12)


def test_poses_are_checked():
    m = BODY_MODELS["upper"]
    with pytest.raises(ValueError, match=r"\(P, 17\)"):
        capsules_from_poses(m, np.zeros((3, 25)))
    with pytest.raises(ValueError, match="BodyModel"):
        joints_from_poses("upper", np.zeros((1, 17)))
