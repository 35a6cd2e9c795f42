"""The render term (the first paper's sigma) against the synthetic renderer."""

import numpy as np

from occupose.camera import Camera, look_at
from occupose.likelihood import Observation, RenderLikelihood, View


def test_render_matches_reference(rng, render_reference):
    camera = Camera("c", 120, 100, 100.0, 100.0, 59.5, 49.5, world_from_camera=look_at((3, 0.3, 1.0), (0, 0, 1)))
    a = rng.normal(size=(8, 4, 3)) * [0.15, 0.15, 0.3] + [0.0, 0.0, 1.0]
    b = a + rng.normal(size=a.shape) * 0.2
    radii = rng.uniform(0.05, 0.12, (4, 2))
    b[0, 0] = a[0, 0]  # a sphere
    part = np.array([0, 1, 1, 2])
    depth = rng.uniform(2.5, 3.3, (100, 120)).astype(np.float32)
    mask = np.zeros((100, 120), bool)
    mask[20:80, 40:75] = True
    view = View(camera, depth, mask, roi=(5, 97, 10, 110))
    like = RenderLikelihood(Observation(np.zeros((1, 3)), (view,)), scale=3.0, truncation=0.2, stride=3)
    got = like.evaluate(a, b, radii, part, 3)
    want, num_observed = render_reference(a, b, radii, part, 3, view, 3, 0.2)
    assert like.num_observed == num_observed > 0
    np.testing.assert_allclose(got, -3.0 * want / num_observed, rtol=1e-5, atol=1e-9)
    assert np.all(want.sum(axis=1) > 0)
