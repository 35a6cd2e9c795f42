"""When a blob may start a person: in full view of some camera, a solid silhouette."""

from dataclasses import replace

import numpy as np
import pytest

from occupose.config import StartConfig
from occupose.grid.pixels import PersonPixels
from occupose.pose.start import silhouette_fill
from occupose.pose.views import at_border

BORDER = StartConfig.border_px


def test_a_person_cut_by_the_image_edge_does_not_start(small_camera):
    """A person not fully in view (pixels at the left, right or top edge) is not started: its
    points would misjudge its size; the bottom edge (feet cut near the camera) is allowed."""
    camera = small_camera

    def observation(rows, cols):
        v, u = np.meshgrid(np.arange(*rows), np.arange(*cols), indexing="ij")
        pixels = np.sort((v * camera.width + u).reshape(-1))
        return PersonPixels(1, {"cam": pixels}, {"cam": np.zeros((pixels.size, 3))})

    assert not at_border(observation((20, 110), (60, 90)), [camera], BORDER)
    assert not at_border(observation((20, 120), (60, 90)), [camera], BORDER)  # feet at the bottom edge
    assert at_border(observation((20, 110), (0, 30)), [camera], BORDER)  # left edge
    assert at_border(observation((20, 110), (140, 160)), [camera], BORDER)  # right edge
    assert at_border(observation((0, 60), (60, 90)), [camera], BORDER)  # top edge


def test_with_two_cameras_one_that_sees_the_whole_person_is_enough_to_start(small_camera):
    front, side = small_camera, replace(small_camera, name="side")

    def pixels(rows, cols):
        v, u = np.meshgrid(np.arange(*rows), np.arange(*cols), indexing="ij")
        return np.sort((v * front.width + u).reshape(-1))

    def observation(front_pixels, side_pixels):
        return PersonPixels(1, {"cam": front_pixels, "side": side_pixels},
                               {"cam": np.zeros((front_pixels.size, 3)), "side": np.zeros((side_pixels.size, 3))})

    whole, cut, none = pixels((20, 110), (60, 90)), pixels((20, 110), (0, 30)), np.zeros(0, np.int64)
    assert not at_border(observation(whole, cut), [front, side], BORDER)
    assert not at_border(observation(cut, whole), [front, side], BORDER)
    assert at_border(observation(cut, cut), [front, side], BORDER)
    assert at_border(observation(cut, none), [front, side], BORDER)  # the only camera that sees it cuts it
    assert at_border(observation(none, none), [front, side], BORDER)


def test_silhouette_fill_of_solid_and_scattered_pixels():
    width = 160
    v, u = np.meshgrid(np.arange(20, 110), np.arange(60, 90), indexing="ij")
    solid = np.sort((v * width + u).reshape(-1))
    assert silhouette_fill(solid, width) == pytest.approx(1.0, abs=0.01)
    scattered = np.sort(np.random.default_rng(0).choice(solid, solid.size // 20, replace=False))
    assert silhouette_fill(scattered, width) == pytest.approx(0.05, abs=0.01)
    assert silhouette_fill(np.zeros(0, np.int64), width) == 0.0

