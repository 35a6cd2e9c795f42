"""A person's body size (stature and girth) from the 3D points of their first frames, and
the trunk split and shoulder width from frames seen from the front.

Stature is the height of the top of the points above the floor (the person is assumed to
stand upright in those frames). The top is the ``top_rank``-th highest point, so a few
stray points (flying pixels, a neighbour's hand) do not raise it, plus ``top_bias`` for
what that rank loses below the true top on a head (measured on the synthetic renders:
a Kinect v1 at 3 m, 1 to 3 frames). The top of the points is the top of the head, which
is what :attr:`BodyDims.height` means, so no head-centre correction is needed; the head
centre is ``neck_head`` below the top's ``2 * neck_head`` above the neck.

Segment lengths are the average adult's proportions (:data:`DEFAULT_DIMS`) scaled to that
stature (anthropometric ratios are near constant across adult statures: Drillis &
Contini's segment fractions of height).

Girth (the scale of the model's radii) is the ratio of the horizontal breadth of the
points in a slice at chest height (``chest_slice`` of the stature) to the breadth of the
full model, girth 1, standing with the arms at rest, at that stature. Breadth is the extent
along the slice's principal horizontal axis between the ``breadth_quantiles``. Caveats,
measured on the synthetic renders: with the arms hanging beside the chest the breadth is
mostly shoulder width plus arm thickness, so this ratio follows the frame more than the
flesh (it came out 0.96 .. 1.0 from a front camera and 0.92 .. 0.94 from a ceiling
camera for bodies whose chest radii span 0.7 .. 1.07 of the average); seen only in
profile it measures the chest's depth and comes out low. It is clipped to ``girth_range``
and is a starting value, not a measurement.

People differ from the average proportions: the mocap subject of the shared clips has its
neck 5 cm lower than the average adult at its stature (a spine 0.78 times as long) and
shoulders 0.6 times as wide, and given its true segment lengths the tracker is 1-2.5 cm
better in most scenes. :func:`breadth_profile` and :func:`neck_and_shoulders` read the
neck's depth below the top of the head and the shoulders' breadth from one frame of a
person seen from the front or the back, :func:`dims_with_shoulders` puts them into the
dimensions (the tracker measures a few frames and resizes the model once).
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import NamedTuple

import numpy as np

from occupose.body.kinematics import capsules_from_poses
from occupose.body.model import FULL_RADII, BodyModel, full_model
from occupose.body.dims import DEFAULT_DIMS, BodyDims
from occupose.body.postures import ARM_REST
from occupose.config import SizeConfig

class BodySize(NamedTuple):
    """Estimated body size: segment lengths ``dims`` and ``girth`` (radius scale, 1 = average)."""

    dims: BodyDims
    girth: float


def _along(xy: np.ndarray) -> np.ndarray:
    """(N,) metres: horizontal points (N, 2) along their principal axis (from their mean)."""
    centred = xy - xy.mean(axis=0)
    _, vectors = np.linalg.eigh(centred.T @ centred)
    return centred @ vectors[:, -1]


def _breadth(xy: np.ndarray, quantiles: tuple[float, float]) -> float:
    """Extent (metres) of horizontal points (N, 2) along their principal axis, between quantiles."""
    lo, hi = np.quantile(_along(xy), quantiles)
    return float(hi - lo)


def _model_breadth(model: BodyModel, height: float) -> float:
    """Breadth of the standing model at ``height`` metres above the floor (arms at rest), metres."""
    pose = np.zeros(model.num_dofs)
    dims = model.dims
    pose[model.dof("z")] = dims.hip_height
    for side in ("left", "right"):
        for name, value in zip(("shoulder_flex", "shoulder_abd", "shoulder_rot", "elbow"), ARM_REST):
            pose[model.dof(f"{side}_{name}")] = value
    a, b = capsules_from_poses(model, pose[None])
    a, b, radii = a[0], b[0], model.capsule_radii
    # each capsule's horizontal section at `height`: the axis point and radius there
    # (the end spheres where the height is beyond an end)
    t = np.clip((height - a[:, 2]) / np.where(np.abs(b[:, 2] - a[:, 2]) > 1e-9, b[:, 2] - a[:, 2], 1e-9), 0.0, 1.0)
    centre = a + t[:, None] * (b - a)
    r = radii[:, 0] + t * (radii[:, 1] - radii[:, 0])
    half = np.sqrt(np.maximum(r**2 - (height - centre[:, 2]) ** 2, 0.0))
    cut = half > 0.0
    return float(np.max(centre[cut, 1] + half[cut]) - np.min(centre[cut, 1] - half[cut]))


def top_height(heights: np.ndarray, rank: int = SizeConfig.top_rank) -> float:
    """The top of a person's points: the ``rank``-th highest of ``heights`` (N,) metres,
    N >= rank (a few stray points do not raise it)."""
    return float(np.partition(heights, heights.shape[0] - rank)[heights.shape[0] - rank])


def dims_from_observation(points, *, floor_z: float = 0.0, size: SizeConfig | None = None) -> BodySize:
    """Body size of a standing person from their observed 3D points.

    points : (N, 3) float, world metres (z up), the person's points pooled over their
        first frames, N >= ``top_rank``
    floor_z : height of the floor, metres
    size : the measurement's settings (default :class:`occupose.config.SizeConfig`'s)
    Returns BodySize(dims, girth): dims are DEFAULT_DIMS scaled to the measured stature
    (clipped to 1.0 .. 2.2 m), girth the radius scale (see the module docstring).
    """
    size = SizeConfig() if size is None else size
    points = np.asarray(points, dtype=np.float64)
    if points.ndim != 2 or points.shape[1] != 3 or points.shape[0] < size.top_rank:
        raise ValueError(f"points must have shape (N, 3) with N >= {size.top_rank}, got {points.shape}")
    points = points[np.all(np.isfinite(points), axis=1)]
    if points.shape[0] < size.top_rank:
        raise ValueError(f"points must hold at least {size.top_rank} finite points, got {points.shape[0]}")
    if not math.isfinite(floor_z):
        raise ValueError(f"floor_z must be a finite height in metres, got {floor_z!r}")
    z = points[:, 2] - floor_z
    top = top_height(z, size.top_rank) + size.top_bias
    stature = float(np.clip(top, 1.0, 2.2))
    dims = DEFAULT_DIMS.scaled(stature)
    in_slice = (z >= size.chest_slice[0] * stature) & (z <= size.chest_slice[1] * stature)
    if np.count_nonzero(in_slice) < size.min_slice_points:
        return BodySize(dims, 1.0)
    observed = _breadth(points[in_slice, :2], size.breadth_quantiles)
    model = _model_breadth(full_model(dims), 0.5 * (size.chest_slice[0] + size.chest_slice[1]) * stature)
    return BodySize(dims, float(np.clip(observed / model, *size.girth_range)))


def breadth_profile(points, size: SizeConfig | None = None) -> np.ndarray:
    """The breadth of a person's upper body slice by slice from the top of the head down.

    points : (N, 3) float, world metres (z up), one frame of one person seen by one camera
    Returns (S,) float metres, S = ``profile_depth`` / ``profile_slice``: slice k holds the points
    between k and k + 1 slices below the top (:func:`top_height`); its breadth is the
    extent of its points along the principal horizontal axis of all the profile's points,
    between ``breadth_quantiles``; NaN for a slice of fewer than ``min_profile_points`` points.
    """
    size = SizeConfig() if size is None else size
    points = np.asarray(points, dtype=np.float64)
    if points.ndim != 2 or points.shape[1] != 3 or points.shape[0] < size.top_rank:
        raise ValueError(f"points must have shape (N, 3) with N >= {size.top_rank}, got {points.shape}")
    count = int(round(size.profile_depth / size.profile_slice))
    depth = top_height(points[:, 2], size.top_rank) - points[:, 2]
    upper = (depth >= 0.0) & (depth < count * size.profile_slice)
    depth = depth[upper]
    along = _along(points[upper, :2])
    slices = np.minimum((depth / size.profile_slice).astype(np.int64), count - 1)
    profile = np.full(count, np.nan)
    for k in np.flatnonzero(np.bincount(slices, minlength=count) >= size.min_profile_points):
        lo, hi = np.quantile(along[slices == k], size.breadth_quantiles)
        profile[k] = hi - lo
    return profile


def neck_and_shoulders(profile: np.ndarray, size: SizeConfig | None = None) -> tuple[float, float] | None:
    """(neck depth below the top of the head, shoulder breadth), metres, from one frame's
    :func:`breadth_profile` of a person seen from the front or the back; None when the
    profile shows no head above a wider chest (a hand by the head, slices missing).

    The neck is where the breadth first reaches halfway from the head's (its widest slice
    near the top) to the chest's (``chest_depth``) below the head; the shoulders are the median
    breadth ``shoulder_band`` below it: the upper arms hanging from the shoulder joints and the
    chest between them. Measured on the synthetic renders (a Kinect v1 at 3 m, the renderer's
    bodies, frames within 37 degrees of facing the camera or away): neck depth 0.25-0.28 m
    for a true 0.265-0.28 (the mocap subject, whose neck sits 5 cm lower than the average
    adult's) and 0.22 for 0.215 (average bodies); shoulder breadth / 2 - upper arm radius
    0.10-0.11 for shoulder widths of 0.10 and 0.175 for 0.183 (medians of 15 frames).
    Shoulders narrower than the chest read as the chest's breadth (0.128 for 0.110 on a
    procedural body with narrow shoulders).
    """
    size = SizeConfig() if size is None else size
    head_slices = int(round(size.head_depth / size.profile_slice))
    chest = profile[int(round(size.chest_depth[0] / size.profile_slice)):int(round(size.chest_depth[1] / size.profile_slice))]
    if np.all(np.isnan(profile[:head_slices])) or np.all(np.isnan(chest)):
        return None
    head = int(np.nanargmax(profile[:head_slices]))
    head_breadth, chest_breadth = profile[head], float(np.nanmedian(chest))
    if head_breadth > size.head_max or chest_breadth <= head_breadth:
        return None
    wide = np.flatnonzero(profile[head:] > 0.5 * (head_breadth + chest_breadth))
    neck = head + int(wide[0])
    band = profile[neck + int(round(size.shoulder_band[0] / size.profile_slice)):
                   neck + int(round(size.shoulder_band[1] / size.profile_slice))]
    if np.all(np.isnan(band)):
        return None
    return neck * size.profile_slice, float(np.nanmedian(band))


def dims_with_shoulders(dims: BodyDims, girth: float, neck_depth: float, shoulder_breadth: float,
                        size: SizeConfig | None = None) -> BodyDims:
    """``dims`` with the neck ``neck_depth`` metres below the top of the head (the trunk
    split between spine and neck_head; stature and legs kept) and the shoulders as wide
    as ``shoulder_breadth`` metres across the upper arms (:func:`neck_and_shoulders`) of
    a model of ``girth``, each kept within ``shape_range`` of the average adult's at the stature.
    """
    size = SizeConfig() if size is None else size
    average = DEFAULT_DIMS.scaled(dims.height)
    depth = float(np.clip(neck_depth, *(f * 2.0 * average.neck_head for f in size.shape_range)))
    arm = FULL_RADII["upper_arm"][0] * girth
    width = float(np.clip(0.5 * shoulder_breadth - arm, *(f * average.shoulder_width for f in size.shape_range)))
    return replace(dims, spine=dims.height - dims.hip_height - depth, neck_head=0.5 * depth, shoulder_width=width)
