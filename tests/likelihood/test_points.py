"""The points term: distances to the capsules and the likelihood against brute force, the
blocked kernels exact on a body, and the true pose (heading, arms) scoring best on synthetic
frames."""

import numpy as np

from occupose.body import BODY_MODELS, pose_from_joints
from occupose.camera import camera_preset, look_at
from occupose.likelihood import Observation, PointsLikelihood, make_likelihood, point_distances
from occupose.synth import motion as pm
from occupose.synth import scene

FULL = BODY_MODELS["full"]
UPPER = BODY_MODELS["upper"]


# --- NumPy references ----------------------------------------------------------------------


def _random_capsules(rng, num_particles=3, num_capsules=5):
    a = rng.normal(size=(num_particles, num_capsules, 3)) * 0.4 + [0.0, 0.0, 1.0]
    b = a + rng.normal(size=a.shape) * 0.25
    radii = rng.uniform(0.03, 0.12, (num_capsules, 2))
    b[0, 0] = a[0, 0]  # a sphere given as a == b
    b[1, 1] = a[1, 1] + [0.01, 0.0, 0.0]  # end b inside the sphere at a: that sphere
    radii[1] = (0.10, 0.05)
    return a, b, radii


# --- kernels against NumPy references ------------------------------------------------------

def test_point_distances_match_brute_force(rng, capsule_distances):
    a, b, radii = _random_capsules(rng)
    points = rng.normal(size=(300, 3)) * 0.5 + [0.0, 0.0, 1.0]
    points[:20] = a[0, 2] + rng.normal(size=(20, 3)) * 0.03  # some inside a capsule
    distance, capsule = point_distances(a, b, radii, points)
    every = capsule_distances(points, a, b, radii)
    assert distance.dtype == np.float32 and capsule.shape == (3, 300)
    np.testing.assert_allclose(distance, every.min(axis=2), atol=2e-6)
    assert np.mean(capsule == every.argmin(axis=2)) > 0.99  # near-ties within float32 may differ
    chosen = np.take_along_axis(every, capsule[..., None].astype(int), axis=2)[..., 0]
    np.testing.assert_allclose(chosen, every.min(axis=2), atol=2e-6)


def test_block_pruning_is_exact_on_a_body(front, rng, model_capsules):
    """The blocked kernel (capsules skipped per block of nearby points) against one block
    holding every point (every capsule visited), on a person's points and diffused poses."""
    from occupose.likelihood import _distance_kernels
    from occupose.likelihood._capsules import blocked_points

    obs, pose = front
    poses = pose + rng.normal(size=(20, FULL.num_dofs)) * np.where(FULL.angular, 0.2, 0.05)
    a, b, radii, _, _ = model_capsules(FULL, poses)
    distance, capsule = point_distances(a, b, radii, obs.points)
    whole = blocked_points(obs.points, block_size=len(obs.points))
    want_distance = np.empty((20, len(whole.px)), np.float32)
    want_capsule = np.empty((20, len(whole.px)), np.int32)
    _distance_kernels.nearest_capsules(a, b, radii, *whole.kernel_args, want_distance, want_capsule)
    np.testing.assert_allclose(distance, want_distance[:, whole.position], atol=1e-6)
    assert np.mean(capsule == want_capsule[:, whole.position]) > 0.999


def test_unsorted_blocks_give_the_same_distances(front, rng, model_capsules):
    """sort=False (the gate's: image-order runs, no median splits) changes the blocks, not
    the distances."""
    from occupose.likelihood._capsules import blocked_points

    obs, pose = front
    a, b, radii, _, _ = model_capsules(FULL, pose[None] + rng.normal(size=(3, FULL.num_dofs)) * 0.05)
    runs = blocked_points(obs.points, block_size=50, sort=False)
    assert np.array_equal(runs.block_start[:-1] // 64, np.arange(len(runs.block_start) - 1))  # 50 padded to 64
    np.testing.assert_array_equal(runs.position[:50], np.arange(50))
    np.testing.assert_allclose(point_distances(a, b, radii, obs.points, sort=False)[0],
                               point_distances(a, b, radii, obs.points)[0], atol=1e-6)


def test_points_likelihood_matches_reference(rng, nearest_reference):
    a, b, radii = _random_capsules(rng)
    part = np.array([0, 2, 1, 2, 0])
    points = rng.normal(size=(250, 3)) * 0.5 + [0.0, 0.0, 1.0]
    obs = Observation(points, ())
    got = PointsLikelihood(obs, scale=0.05).evaluate(a, b, radii, part, 4)
    distance, capsule = nearest_reference(points, a, b, radii)
    want = np.zeros((3, 4))
    for p in range(3):
        np.add.at(want[p], part[capsule[p]], distance[p])
    want *= -1.0 / (250 * 0.05)
    np.testing.assert_allclose(got, want, atol=1e-6)
    np.testing.assert_allclose(got.sum(axis=1), -distance.mean(axis=1) / 0.05, atol=1e-6)
    assert np.all(got[:, 3] == 0.0)  # no capsule in part 3


# --- the likelihoods on synthetic frames ------------------------------------------------------


def test_full_torso_shows_the_heading(front, model_capsules):
    """The full model's torso (two cones side by side) alone, on the torso's own points (those
    nearest it in the true pose), ranks the true heading first among turns of up to 60
    degrees either way: a standing person's heading no longer rests on the shoulders and
    hips only (a round torso scored every turn the same)."""
    obs, pose = front
    poses = np.repeat(pose[None], 9, axis=0)
    poses[:, FULL.dof("heading")] += np.radians(np.linspace(-60.0, 60.0, 9))
    a, b, radii, part, num_parts = model_capsules(FULL, poses)
    torso = part == FULL.part_names.index("torso")
    assert torso.sum() == 2
    _, nearest = point_distances(a[:1], b[:1], radii, obs.points)
    own = Observation(obs.points[torso[nearest[0]]], obs.views)
    assert len(own.points) > 300
    log_lik = PointsLikelihood(own).evaluate(a[:, torso], b[:, torso], radii[torso], np.zeros(2, np.int64), 1)[:, 0]
    assert np.argmax(log_lik) == 4
    assert np.all(np.diff(log_lik[:5]) > 0) and np.all(np.diff(log_lik[4:]) < 0)


def test_points_true_pose_scores_best_from_above(frame, perturbed, model_capsules):
    """The upper-body model under a ceiling camera (the second paper's setting)."""
    camera = camera_preset("kinect_v1", world_from_camera=look_at((0.0, 0.0, 3.2), (0.0, 0.0, 0.0)))
    joints = pm.joints_from_procedural(pm.pose_with(pm.stance(), right_shoulder_flex=1.2, left_shoulder_abd=0.6))
    obs = frame(joints, scene.room(walls=()), camera=camera)
    pose = pose_from_joints(UPPER, joints)
    dofs = ("x", "y", "heading", "trunk_lean", "left_shoulder_flex", "left_shoulder_abd", "right_shoulder_flex",
            "right_shoulder_abd", "right_elbow")
    poses = perturbed(UPPER, pose, dofs)
    log_lik = make_likelihood("points", obs).evaluate(*model_capsules(UPPER, poses))
    assert log_lik.shape == (len(poses), 5)
    assert np.argmax(log_lik.sum(axis=1)) == 0
