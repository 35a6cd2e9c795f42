"""The colour (Bhattacharyya) term: histograms against their NumPy reference, and the true pose
scoring best on a synthetic frame."""

import numpy as np

from occupose.body import BODY_MODELS, pose_from_joints
from occupose.likelihood import ColorLikelihood, Observation
from occupose.synth import motion as pm

FULL = BODY_MODELS["full"]


def test_color_matches_reference(rng, color_reference, random_view, random_part_capsules):
    from occupose.sensors import depth_std

    view = random_view(rng, color=True)
    a, b, radii, part = random_part_capsules(rng)
    obs = Observation(np.zeros((1, 3)), (view,))
    like = ColorLikelihood(obs, bins=3, scale=2.0, margin=0.1, noise="tof", samples_along=4, samples_around=3)
    hist = like.histograms(a, b, radii, part, 3)
    want = color_reference(a, b, radii, part, 3, view, lambda d: 0.1 + 3 * depth_std(d, "tof"), 3, 4, 3)
    np.testing.assert_allclose(hist, want, atol=1e-12)
    assert np.all(hist[:, 2] == 0.0) and np.all(hist[:, :2].sum(axis=2) > 0.99)

    reference = rng.random((3, 27))
    reference[1] = 0.0  # part 1 has no reference: scores 0
    like.set_reference(reference)
    got = like.evaluate(a, b, radii, part, 3)
    r = reference / np.maximum(reference.sum(axis=1, keepdims=True), 1e-300)
    want_d = np.sqrt(np.clip(1 - np.sum(np.sqrt(want * r[None]), axis=2), 0, None))
    want_d[want.sum(axis=2) == 0] = 1.0  # part 2 has no capsule: distance 1
    np.testing.assert_allclose(got, -2.0 * want_d * [1, 0, 1], atol=1e-9)
    like.set_reference(hist[1])  # particle 1's own histograms: distance 0 for its parts
    np.testing.assert_allclose(like.evaluate(a[1:2], b[1:2], radii, part, 3)[0, :2], 0.0, atol=1e-6)


def test_color_true_pose_scores_best(frame, room, perturbed, model_capsules, full_dofs):
    """Reference histograms from the estimate of the frame before; flashy clothes (one colour per part)."""
    joints = pm.joints_from_procedural(np.array([pm.pose_with(pm.stance(), right_shoulder_flex=f, left_elbow=e)
                                           for f, e in ((0.5, 0.6), (0.6, 0.8))]))
    before = frame(joints[0], room, clothing="flashy", seed=2)
    now = frame(joints[1], room, clothing="flashy", seed=2)
    like = ColorLikelihood(now)
    like.set_reference(ColorLikelihood(before).histograms(*model_capsules(FULL, pose_from_joints(FULL, joints[0])))[0])
    poses = perturbed(FULL, pose_from_joints(FULL, joints[1]), full_dofs, delta_angle=0.4, delta_metres=0.1)
    total = like.evaluate(*model_capsules(FULL, poses)).sum(axis=1)
    # colour is blind to moves within a uniformly coloured region, so ties are allowed
    assert total[0] >= total.max() - 1e-9
    assert total[0] > np.median(total) + 0.5
