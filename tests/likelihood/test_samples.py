"""The camera-facing samples of a capsule and the offset depths the free-space and colour
terms compare them with."""

import numpy as np
import pytest

from occupose.camera import Camera, look_at
from occupose.likelihood import FreeSpaceLikelihood, Observation, View


def test_offset_depths_match_reference(rng):
    from occupose.likelihood._samples import offset_depths
    from occupose.sensors import depth_std

    depth = rng.uniform(0.4, 7.5, (30, 40)).astype(np.float32)
    depth[rng.random((30, 40)) < 0.2] = 0.0
    for noise, margin, sign in (("structured_light", 0.03, -1.0), ("tof", 0.1, 1.0), ("none", 0.0, -1.0)):
        want = np.where(depth > 0, depth + sign * (margin + 3 * depth_std(depth.astype(np.float64), noise)), 0.0)
        got = offset_depths(depth, margin, noise, sign)
        assert got.dtype == np.float32 and got.shape == depth.shape
        np.testing.assert_allclose(got, want, atol=1e-6)
    with pytest.raises(ValueError, match="margin"):
        offset_depths(depth, -0.1, "tof", 1.0)
    with pytest.raises(ValueError, match="noise"):
        offset_depths(depth, 0.1, "sonar", 1.0)


def test_camera_samples_of_a_capsule_on_the_cameras_axis():
    """A ceiling camera straight above a vertical limb (a standing person's forearm from
    above): no direction towards the camera is square to the axis, so the samples' ring
    turns from a world axis instead; they must still lie on the capsule, the end samples
    on the end spheres' points nearest the camera, and a limb in seen-empty space cost
    its whole weight."""
    from occupose.likelihood import _sample_kernels
    from occupose.likelihood._samples import camera_arrays, sample_pattern

    camera = Camera("top", 80, 60, 60.0, 60.0, 39.5, 29.5, world_from_camera=look_at((0, 0, 3.0), (0, 0, 0)))
    a, b = np.array([[[0.0, 0.0, 1.0]]]), np.array([[[0.0, 0.0, 0.5]]])
    radii = np.array([[0.06, 0.04]])
    along, cos_around, sin_around, count = sample_pattern(3, 4)
    rotation, shift = camera_arrays(camera)
    samples = np.empty((3, count))
    _sample_kernels._camera_samples(a, b, radii, 0, 0, rotation, shift, along, cos_around, sin_around, samples)
    world = (samples.T - shift) @ rotation  # camera -> world (rotation is orthonormal)
    assert np.isfinite(world).all()
    np.testing.assert_allclose(world[:2], [[0, 0, 1.06], [0, 0, 0.54]], atol=1e-9)  # nearest the camera
    ring = world[2:].reshape(3, 4, 3)
    t = (np.arange(3) + 0.5) / 3
    np.testing.assert_allclose(ring[..., 2], np.repeat(1.0 - 0.5 * t, 4).reshape(3, 4), atol=1e-9)
    np.testing.assert_allclose(np.hypot(ring[..., 0], ring[..., 1]), np.repeat(0.06 - 0.02 * t, 4).reshape(3, 4),
                               atol=1e-9)
    assert np.ptp(np.arctan2(ring[..., 1], ring[..., 0])) == pytest.approx(np.pi / 2)  # -45 .. 45 degrees
    far = View(camera, np.full((60, 80), 3.0, np.float32), np.zeros((60, 80), bool))  # the floor, far behind
    near = View(camera, np.full((60, 80), 1.5, np.float32), np.zeros((60, 80), bool))  # something above it
    for view, cost in ((far, -1.0), (near, 0.0)):
        got = FreeSpaceLikelihood(Observation(np.zeros((1, 3)), (view,)), samples_along=3,
                                  samples_around=4).evaluate(a, b, radii, np.array([0]), 1)
        assert got[0, 0] == pytest.approx(cost)
