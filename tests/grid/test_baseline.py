"""The baseline foreground of stage 1: OpenCV background subtraction on depth (an install extra)."""

import sys

import numpy as np
import pytest

from occupose.grid.baseline import DepthBackgroundSubtractor


def test_baseline_needs_opencv_and_finds_a_new_object(monkeypatch):
    subtractor = DepthBackgroundSubtractor("mog2", history=50)
    rng = np.random.default_rng(0)
    wall = np.full((48, 64), 3.0)
    for _ in range(30):
        foreground = subtractor.apply(wall + rng.normal(0, 0.005, wall.shape))
    assert foreground.mean() < 0.01
    scene = wall.copy()
    scene[10:30, 20:40] = 2.0
    scene[0, 0] = 0.0
    foreground = subtractor.apply(scene)
    assert foreground[10:30, 20:40].all() and foreground.sum() == 400
    with pytest.raises(ValueError, match="valid names"):
        DepthBackgroundSubtractor("median")
    monkeypatch.setitem(sys.modules, "cv2", None)
    with pytest.raises(ImportError, match=r"pip install occupose\[baseline\]"):
        DepthBackgroundSubtractor("knn")
