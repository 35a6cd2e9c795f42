"""What the likelihood sees of one person: its pixels per camera, gated and cut, as views."""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence

import numpy as np

from occupose.body import BodyModel
from occupose.camera import Camera
from occupose.config import PoseConfig
from occupose.grid.pixels import PersonPixels
from occupose.likelihood import View


def views_from_pixels(pixels: PersonPixels, depths: Mapping[str, np.ndarray], cameras: Sequence[Camera],
                      model: BodyModel, pose: PoseConfig,
                      near: Callable[[np.ndarray], np.ndarray] | None = None) -> list[View]:
    """The likelihood's views of a person: its pixels in each camera.

    pixels : the person's pixels and points (:func:`occupose.grid.pixels.pixels_from_depth`)
    depths : camera name -> (H, W) float32 metres; cameras : the cameras, in order
    model : the person's body model; for the upper-body model only the pixels whose points
        are above ``pose.upper_cut`` of its stature (as the second paper thresholds its
        top-view images: the model has no legs, and leg points pull its hanging arms down)
    near : f(points (N, 3) metres) -> (N,) metres to the person's predicted body, or None
        (a new person); given, only the pixels whose points are within ``pose.gate_m`` of it
        (a validation gate: what a person carries is not its body), all of a camera's when
        that leaves fewer than ``pose.gate_keep`` of them (the prediction itself is off)
    """
    views = []
    for camera in cameras:
        own, points = pixels.pixels[camera.name], pixels.camera_points[camera.name]
        keep = np.ones(len(own), bool)
        if near is not None and len(own):
            gated = near(points) < pose.gate_m
            keep = gated if gated.mean() >= pose.gate_keep else keep
        keep &= modelled(points, model, pose)
        mask = np.zeros(camera.height * camera.width, bool)
        mask[own[keep]] = True
        views.append(View(camera, depths[camera.name], mask.reshape(camera.height, camera.width)))
    return views


def modelled(points: np.ndarray, model: BodyModel, pose: PoseConfig) -> np.ndarray:
    """(N,) bool: which of a person's points (N, 3) world metres ``model`` is meant to
    explain: all for the full body; for the upper body those above ``pose.upper_cut`` of
    its stature."""
    if model.name == "upper":
        return points[:, 2] >= pose.upper_cut * model.dims.height
    return np.ones(len(points), bool)


def at_border(pixels: PersonPixels, cameras: Sequence[Camera], border_px: int, border_count: int = 1) -> bool:
    """Whether at least ``border_count`` of the person's pixels come within ``border_px`` of
    the left, right or top edge of every camera's image that sees them: not fully in view of
    any camera, so its points would misjudge its size. (The bottom edge is allowed: a camera
    may cut the feet of a person who is near it. With several cameras, one that sees the
    whole person is enough: the pooled points hold the whole body. A body cut by the edge
    has a strip of hundreds of pixels there; a few stray ones, a noisy floor reading given
    to the person, are no cut.)"""
    cut = []
    for camera in cameras:
        own = pixels.pixels[camera.name]
        if len(own) == 0:
            continue
        v, u = np.divmod(own, camera.width)
        near = (u < border_px) | (u >= camera.width - border_px) | (v < border_px)
        cut.append(int(np.count_nonzero(near)) >= border_count)
    return all(cut)
