"""The free-space term: against its NumPy reference, and on synthetic frames (an arm in seen
empty space, legs hidden behind a desk)."""

import numpy as np

from occupose.body import BODY_MODELS, pose_from_joints
from occupose.geometry.primitives import concat
from occupose.likelihood import FreeSpaceLikelihood, Observation, make_likelihood
from occupose.synth import motion as pm
from occupose.synth import scene

FULL = BODY_MODELS["full"]


def test_free_space_matches_reference(rng, free_reference, random_view, random_part_capsules):
    from occupose.sensors import depth_std

    view = random_view(rng)
    a, b, radii, part = random_part_capsules(rng)
    got = FreeSpaceLikelihood(Observation(np.zeros((1, 3)), (view,)), weight=2.0, margin=0.02, ramp=0.1,
                              noise="tof", samples_along=3, samples_around=4).evaluate(a, b, radii, part, 3)
    want = free_reference(a, b, radii, part, 3, view, lambda d: 0.02 + 3 * depth_std(d, "tof"), 0.1, 3, 4)
    np.testing.assert_allclose(got, -2.0 * want, atol=1e-6)
    assert np.any(want > 0.05) and np.all(got[:, 2] == 0.0)


def test_free_space_penalises_an_arm_in_seen_empty_space(front, model_capsules):
    obs, pose = front
    out = pose.copy()
    out[FULL.dof("left_shoulder_abd")] = 1.4  # the left arm raised sideways, the wall seen behind it
    like = make_likelihood("points+free", obs)
    log_lik = {name: term.evaluate(*model_capsules(FULL, np.array([pose, out])))
               for name, term in like.terms.items()}
    arm = [FULL.part_names.index("left_upper_arm"), FULL.part_names.index("left_forearm")]
    assert np.all(log_lik["free"][0] > -0.05)  # the true pose sits in occupied space
    assert np.all(log_lik["free"][1, arm] < -0.5)  # most of the raised arm's samples see the wall behind
    total = like.evaluate(*model_capsules(FULL, np.array([pose, out]))).sum(axis=1)
    assert total[0] > total[1] + 1.0


def test_free_space_does_not_penalise_legs_behind_a_desk(frame, room, model_capsules):
    """Legs hidden by a desk's front panel (all but the tops of the thighs): the desk is in
    front of the leg samples, at the true pose and with the legs spread behind it."""
    joints = pm.joints_from_procedural(pm.stance(xy=(-0.1, 0.0)))
    desk = scene.table((0.45, 0.0), size=(1.2, 0.5), panel=True)
    obs = frame(joints, concat([room, desk]))
    pose = pose_from_joints(FULL, joints)
    spread = pose.copy()
    spread[[FULL.dof("left_hip_abd"), FULL.dof("right_hip_abd")]] += 0.3
    spread[FULL.dof("left_knee")] += 0.4
    capsules = model_capsules(FULL, np.array([pose, spread]))
    free = make_likelihood("free", obs).evaluate(*capsules)
    legs = [FULL.part_names.index(n) for n in ("left_thigh", "left_shin", "right_thigh", "right_shin")]
    shins = legs[1::2]
    np.testing.assert_array_equal(free[0, legs], 0.0)
    np.testing.assert_array_equal(free[1, shins], 0.0)
    # without the desk the spread shins are seen to be wrong: the wall shows through them
    open_free = make_likelihood("free", frame(joints, room)).evaluate(*capsules)
    assert np.all(open_free[0, legs] > -0.05) and np.all(open_free[1, shins] < -0.3)
    # the render term, which has no notion of occlusion, does charge the hidden legs
    render_legs = make_likelihood("render", obs).evaluate(*model_capsules(FULL, pose))[0, legs]
    assert render_legs.sum() < -0.5
