"""Tests of occupose.body: model tables, forward kinematics (kernel vs NumPy reference and
hand-computed poses), pose fitting, size estimation and the diffusion motion model."""

import math
from dataclasses import replace

import numpy as np
import pytest

from scipy import stats

from occupose.body.dims import BodyDims, dims_from_joints
from occupose.body import (BODY_MODELS, limb_angles, body_model, capsules_from_poses, diffuse, diffusion_scales,
                           dims_from_observation, joints_from_poses, pose_from_joints, root_drift,
                           standing_pose)
from occupose.body.model import FULL_TORSO_SPREAD
from occupose.body.size import breadth_profile, dims_with_shoulders, neck_and_shoulders, top_height
from occupose.camera import points_from_depth
from occupose.joints import JOINT_INDEX as J
from occupose.synth.generate import frames
from occupose.synth.scenarios import build_scenario
from occupose.synth import motion as sm
from occupose.body.dims import DEFAULT_DIMS

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


# ---------------------------------------------------------------------------------------
# Pose fitting


def _fit_errors(model, joints):
    """Largest joint error (metres) of the fitted pose of each frame (T, 15, 3)."""
    used = model.reported_joints
    out = []
    for frame in joints:
        pose = pose_from_joints(model, frame)
        assert np.all(pose >= model.limits[:, 0]) and np.all(pose <= model.limits[:, 1])
        fitted = joints_from_poses(model, pose[None])[0]
        out.append(np.linalg.norm(fitted[used] - frame[used], axis=-1).max())
    return np.array(out)


@pytest.fixture(scope="module")
def procedural_joints():
    """Walking, turning, waving, folding the arms, raising an arm, sitting and standing up."""
    dims = D.scaled(1.8)
    b = sm.MotionBuilder((0.5, -1.0), 0.3, dims=dims)
    b.walk([(2.0, 0.5), (3.0, 2.0)]).turn(2.0).wave("right").gesture("cross").gesture("raise", "left")
    b.sit_down(0.45).wave("both").stand_up()
    return dims, b.joints()[::12]


@pytest.mark.parametrize("name", ["full", "upper"])
def test_pose_from_joints_reproduces_procedural_motion(name, procedural_joints):
    dims, joints = procedural_joints
    errors = _fit_errors(body_model(name, dims), joints)
    assert len(errors) > 40 and errors.max() < 0.02  # measured: 6 mm (full), 3 mm (upper)


def test_pose_from_joints_recovers_the_pose(rng):
    """Joints of a model pose give back that pose (where the joints determine it)."""
    m = BODY_MODELS["full"]
    pose = standing_pose(m, (1.0, -2.0), 2.5)
    for name, value in (("left_shoulder_flex", 1.2), ("left_shoulder_rot", 0.6), ("left_elbow", 1.1),
                        ("trunk_lean", 0.3), ("trunk_side", -0.1), ("right_hip_flex", 0.7), ("right_knee", 0.9),
                        ("right_hip_rot", 0.3), ("neck_flex", 0.4), ("neck_side", 0.2)):
        pose[m.dof(name)] = value
    fitted = pose_from_joints(m, joints_from_poses(m, pose[None])[0])
    determined = np.array([n != "neck_twist" for n in m.dof_names])
    np.testing.assert_allclose(fitted[determined], pose[determined], atol=1e-4)


@pytest.mark.parametrize("name", ["full", "upper"])
def test_arm_angles_give_back_an_arm_of_a_leaning_turned_body(name):
    """The arm's angles from its own shoulder, elbow and wrist, in a torso turned and
    leaning (and bent sideways, for the full model): the arm of the pose, other DOFs kept."""
    m = BODY_MODELS[name]
    pose = standing_pose(m, (0.5, 1.0), -2.0)
    for dof, value in (("trunk_lean", 0.4), ("trunk_side", 0.2), ("right_shoulder_flex", 0.9),
                       ("right_shoulder_abd", 0.5), ("right_shoulder_rot", -0.4), ("right_elbow", 1.3)):
        if dof in m.dof_names:
            pose[m.dof(dof)] = value
    joints = joints_from_poses(m, pose[None])[0]
    got = limb_angles(m, pose, "right", "arm", *(joints[J[f"right_{j}"]] for j in ("shoulder", "elbow", "wrist")))
    want = [pose[m.dof(f"right_{n}")] for n in ("shoulder_flex", "shoulder_abd", "shoulder_rot", "elbow")]
    np.testing.assert_allclose(got, want, atol=1e-9)


def test_pose_from_joints_wraps_heading_and_checks_input():
    m = BODY_MODELS["upper"]
    pose = standing_pose(m, heading=3.0 + 2.0 * math.pi)
    assert pose[m.dof("heading")] == pytest.approx(3.0, abs=1e-6)
    joints = joints_from_poses(m, pose[None])[0]        # hips, knees, ankles are NaN: ignored
    assert pose_from_joints(m, joints)[m.dof("heading")] == pytest.approx(3.0, abs=1e-6)
    joints[J["left_wrist"]] = np.nan
    with pytest.raises(ValueError, match="left_wrist"):
        pose_from_joints(m, joints)
    with pytest.raises(ValueError, match=r"\(15, 3\)"):
        pose_from_joints(m, np.zeros((14, 3)))


@pytest.mark.parametrize("clip_name, models", [("dataset-1_walk_normal_001", ("full", "upper")),
                                                 ("dataset-2_wave-right-hand_active_001", ("full",))])
def test_pose_from_joints_on_real_mocap(mocap, clip_name, models):
    from occupose.io.mocap import canonical_from_clip, find_clip, load_clip

    joints = canonical_from_clip(load_clip(find_clip(clip_name)))
    dims = dims_from_joints(joints)
    for name in models:
        errors = _fit_errors(body_model(name, dims), joints[::15])
        # measured: walk 1.0 cm (full) / 1.8 cm (upper), wave 3.0 cm (full); a rigid torso
        # cannot shrug one shoulder, and the upper model has no sideways lean
        assert errors.max() < 0.04, name


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


# ---------------------------------------------------------------------------------------
# Size from observation


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


# ---------------------------------------------------------------------------------------
# Motion model


def test_diffusion_scales():
    m = BODY_MODELS["full"]
    s = diffusion_scales(m)
    assert s[m.dof("x")] == 0.02 and s[m.dof("left_elbow")] == 0.10
    s60 = diffusion_scales(m, fps=60.0, shoulder=0.3, left_elbow=0.5)
    assert s60[m.dof("x")] == pytest.approx(0.01)
    assert s60[m.dof("right_shoulder_abd")] == 0.3 and s60[m.dof("left_elbow")] == 0.5
    with pytest.raises(ValueError, match="valid"):
        diffusion_scales(m, elbows=0.1)


def test_diffuse_statistics_and_seed(rng):
    limits = np.array([[-10.0, 10.0], [0.0, 1.0]])
    poses = np.tile([1.0, 0.5], (20000, 1))
    out = diffuse(poses, [0.2, 0.01], limits, np.random.default_rng(3))
    np.testing.assert_allclose(out.mean(axis=0), [1.0, 0.5], atol=0.005)
    np.testing.assert_allclose(out.std(axis=0), [0.2, 0.01], rtol=0.03)
    np.testing.assert_array_equal(out, diffuse(poses, [0.2, 0.01], limits, np.random.default_rng(3)))
    drift = np.array([0.5, 0.0])
    moved = diffuse(poses, [0.0, 0.0], limits, rng, drift=drift)
    np.testing.assert_array_equal(moved, poses + drift)


def test_diffuse_reflects_rejects_clips_and_wraps(rng):
    limits = np.array([[0.0, 1.0], [-math.pi, math.pi]])
    periodic = np.array([False, True])
    poses = np.tile([0.95, 3.0], (20000, 1))
    reflected = diffuse(poses, [0.1, 0.5], limits, rng, periodic=periodic)
    assert reflected[:, 0].max() <= 1.0 and reflected[:, 1].min() >= -math.pi and reflected[:, 1].max() < math.pi
    assert np.mean(reflected[:, 1] < 0) > 0.3           # heading wrapped past pi, not stopped
    one = diffuse(np.array([[0.95, 0.0]]), [0.0, 0.0], limits, rng, drift=[0.35, 0.0])
    assert one[0, 0] == pytest.approx(0.7)              # 1.3 folds back to 0.7
    rejected = diffuse(poses, [0.1, 0.5], limits, rng, periodic=periodic, mode="reject")
    expected = stats.truncnorm((0.0 - 0.95) / 0.1, (1.0 - 0.95) / 0.1, loc=0.95, scale=0.1).mean()
    assert rejected[:, 0].mean() == pytest.approx(expected, abs=0.003)
    clipped = diffuse(poses, [0.1, 0.5], limits, rng, periodic=periodic, mode="clip")
    assert np.mean(clipped[:, 0] == 1.0) == pytest.approx(0.31, abs=0.02)  # P(N > 0.5 sd)
    with pytest.raises(ValueError, match="reflect, reject, clip"):
        diffuse(poses, [0.1, 0.5], limits, rng, mode="bounce")


def test_diffuse_keeps_model_poses_valid(rng):
    m = BODY_MODELS["upper"]
    poses = np.tile(standing_pose(m), (500, 1))
    for _ in range(20):
        poses = diffuse(poses, diffusion_scales(m, scale=3.0), m.limits, rng, periodic=m.periodic)
    assert np.all(poses >= m.limits[:, 0]) and np.all(poses <= m.limits[:, 1])


def test_root_drift():
    m = BODY_MODELS["full"]
    previous = standing_pose(m, (0.0, 0.0))
    current = standing_pose(m, (0.04, -0.02), heading=0.1)
    drift = root_drift(m, previous, current, damping=0.5)
    np.testing.assert_allclose(drift[:4], [0.02, -0.01, 0.0, 0.05], atol=1e-12)
    assert not drift[4:].any()
    # the turn goes the shorter way round, through +-pi
    turned = root_drift(m, standing_pose(m, (0.0, 0.0), heading=3.1), standing_pose(m, (0.0, 0.0), heading=-3.1))
    assert turned[m.dof("heading")] == pytest.approx(2 * np.pi - 6.2)

