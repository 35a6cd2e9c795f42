"""Furniture builders of occupose.synth.scene: the counter and the open shelf."""

import math

import numpy as np
import pytest

from occupose.camera import Camera, look_at
from occupose.synth.render import render_camera
from occupose.synth.scene import counter, shelf


def _top(prims) -> float:
    return float(np.max(prims.center[:, 2] + prims.size[:, 2]))


def test_counter_is_a_base_with_an_overhanging_worktop():
    c = counter((1.0, 2.0), math.pi / 2, width=1.8, depth=0.6, height=0.9, overhang=0.03)
    assert len(c) == 2 and _top(c) == pytest.approx(0.9)
    assert c.size[1, :2] == pytest.approx([0.33, 0.93])       # the worktop overhangs the base
    assert np.max(np.abs(c.center[:, :2] - [1.0, 2.0])) < 1e-12


def test_shelf_without_a_back_is_seen_through():
    camera = Camera("c", 80, 60, 60.0, 60.0, 39.5, 29.5, 0.001, look_at((0.0, -2.0, 0.9), (0.0, 0.0, 0.9)))
    open_shelf = shelf((0.0, 0.0), -math.pi / 2, width=1.0, height=1.8, boards=3)
    closed = shelf((0.0, 0.0), -math.pi / 2, width=1.0, height=1.8, boards=3, back=True)
    assert len(open_shelf) == 2 + 5 and len(closed) == 8 and _top(open_shelf) == pytest.approx(1.8)
    seen_open = np.count_nonzero(render_camera(open_shelf, camera).depth)
    seen_closed = np.count_nonzero(render_camera(closed, camera).depth)
    assert seen_open < 0.5 * seen_closed                       # the openings between the boards
    with pytest.raises(ValueError, match="boards must be >= 0"):
        shelf((0.0, 0.0), boards=-1)
