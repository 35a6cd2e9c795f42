"""Views (depth, mask, colour, region of interest) and the observation made from them."""

import numpy as np
import pytest

from occupose.camera import Camera
from occupose.likelihood import Observation, View, observation_from_views, roi_from_mask


def test_views_and_observations():
    camera = Camera("c", 8, 6, 5.0, 5.0, 3.5, 2.5)
    mask = np.zeros((6, 8), bool)
    mask[2:4, 3:7] = True
    assert roi_from_mask(mask, margin=0.0) == (2, 4, 3, 7)
    assert roi_from_mask(mask, margin=0.5) == (1, 5, 1, 8)
    assert roi_from_mask(np.zeros((6, 8), bool)) == (0, 0, 0, 0)
    raw = np.full((6, 8), 2000, np.uint16)
    raw[2, 3] = 0
    view = View(camera, raw, mask)
    assert view.depth.dtype == np.float32 and view.depth[0, 0] == pytest.approx(2.0)
    assert view.roi == roi_from_mask(mask)
    obs = observation_from_views([view, view])
    assert obs.points.shape == (14, 3)  # 7 measured mask pixels per view
    np.testing.assert_array_equal(obs.points[:7], view.points)  # the view's points, made once
    assert view.points is view.points and not view.points.flags.writeable
    np.testing.assert_allclose(view.points[:, 2], 2.0)  # camera at the origin looking along +z
    assert observation_from_views([view], max_points=3).points.shape == (3, 3)
    with pytest.raises(ValueError, match="mask"):
        View(camera, raw, mask[:, :4])
    with pytest.raises(ValueError, match="depth"):
        View(camera, np.zeros((6, 8), np.int32), mask)
    with pytest.raises(ValueError, match="color"):
        View(camera, raw, mask, color=np.zeros((6, 8, 3), np.float32))
    with pytest.raises(ValueError, match="roi"):
        View(camera, raw, mask, roi=(0, 7, 0, 8))
    with pytest.raises(ValueError, match="max_points"):
        observation_from_views([view], max_points=0)
    with pytest.raises(ValueError, match=r"\(N, 3\)"):
        Observation(np.zeros((4, 2)), ())
