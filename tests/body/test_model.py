"""occupose.body.model: the body models' tables (DOFs, parts, partitions, weight groups),
the registry and sizing, and cones sized like the rendered people."""

import numpy as np
import pytest

from occupose.body import BODY_MODELS, body_model, capsules_from_poses, pose_from_joints
from occupose.body.dims import DEFAULT_DIMS, dims_from_joints
from occupose.body.model import FULL_TORSO_SPREAD
from occupose.camera import points_from_depth
from occupose.joints import JOINT_INDEX as J
from occupose.synth.generate import frames
from occupose.synth.scenarios import build_scenario


D = DEFAULT_DIMS


@pytest.mark.parametrize("name, dofs, parts, capsules", [("full", 25, 10, 11), ("upper", 17, 5, 13)])
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
    limbs = tall.capsule_part != tall.part_names.index("head")  # the head follows stature
    assert np.allclose(tall.capsule_radii[limbs], BODY_MODELS["full"].capsule_radii[limbs] * 1.2)
    torso = tall.capsule_part == tall.part_names.index("torso")  # its two cones: spaced by girth too
    hips, chest = FULL_TORSO_SPREAD
    assert np.allclose(tall.capsule_offsets[:, torso, 1], [[1.2 * hips, -1.2 * hips], [1.2 * chest, -1.2 * chest]])


def _signed_distance_round_cone(p, a, b, ra, rb):
    """Exact signed distance (N,) of points p (N, 3) to a round cone a-b with radii ra, rb."""
    ba = b - a
    l2 = ba @ ba
    rr = ra - rb
    a2 = l2 - rr * rr
    pa = p - a
    y = pa @ ba
    z = y - l2
    x2 = np.sum((pa * l2 - np.outer(y, ba)) ** 2, axis=1)
    y2, z2 = y * y * l2, z * z * l2
    k = np.sign(rr) * rr * rr * x2
    out = (np.sqrt(x2 * a2 / l2) + y * rr) / l2 - ra
    near_a = np.sign(y) * a2 * y2 < k
    near_b = np.sign(z) * a2 * z2 > k
    out[near_a] = np.sqrt(x2[near_a] + y2[near_a]) / l2 - ra
    out[near_b] = np.sqrt(x2[near_b] + z2[near_b]) / l2 - rb
    return out


def test_model_fitted_to_ground_truth_explains_the_rendered_person():
    """The cones are sized like the synthetic bodies: the rendered person's points lie on
    the surface of the model fitted to the true joints (median signed distance ~ 0)."""
    scenario = build_scenario("no_occlusion", seed=0, use_mocap=False)
    frame = next(frames(scenario, seed=0, indices=[60]))
    cam = scenario.cameras[0]
    rendered = frame.rendered[cam.name]
    points = points_from_depth(np.where(rendered.person == 1, rendered.depth, 0.0).astype(np.float32), cam)[0]
    dims = dims_from_joints(scenario.people[0].joints)
    for name, keep in (("full", points[:, 2] > 0.15), ("upper", points[:, 2] > frame.joints[0, J["pelvis"], 2])):
        m = body_model(name, dims)
        a, b = capsules_from_poses(m, pose_from_joints(m, frame.joints[0])[None])
        d = np.min([_signed_distance_round_cone(points[keep], a[0, c], b[0, c], *m.capsule_radii[c])
                    for c in range(m.num_capsules)], axis=0)
        # measured: mean |d| 1.2 cm (full, feet excluded) and 0.8 cm (upper), median -1.5 mm
        assert np.mean(np.abs(d)) < 0.025 and abs(np.median(d)) < 0.01, name
