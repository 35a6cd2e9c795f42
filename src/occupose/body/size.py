"""A person's body size (stature and girth) from the 3D points of their first frames, and
the trunk split and shoulder width from frames seen from the front.

Stature is the height of the top of the points above the floor (the person is assumed to
stand upright in those frames). The top is the ``TOP_RANK``-th highest point, so a few
stray points (flying pixels, a neighbour's hand) do not raise it, plus ``TOP_BIAS`` for
what that rank loses below the true top on a head (measured on the synthetic renders:
a Kinect v1 at 3 m, 1 to 3 frames). The top of the points is the top of the head, which
is what :attr:`BodyDims.height` means, so no head-centre correction is needed; the head
centre is ``neck_head`` below the top's ``2 * neck_head`` above the neck.

Segment lengths are the average adult's proportions (:data:`DEFAULT_DIMS`) scaled to that
stature (anthropometric ratios are near constant across adult statures: Drillis &
Contini's segment fractions of height).

Girth (the scale of the model's radii) is the ratio of the horizontal breadth of the
points in a slice at chest height (``CHEST_SLICE`` of the stature) to the breadth of the
full model, girth 1, standing with the arms at rest, at that stature. Breadth is the extent
along the slice's principal horizontal axis between the ``BREADTH_QUANTILES``. Caveats,
measured on the synthetic renders: with the arms hanging beside the chest the breadth is
mostly shoulder width plus arm thickness, so this ratio follows the frame more than the
flesh (it came out 0.96 .. 1.0 from a front camera and 0.92 .. 0.94 from a ceiling
camera for bodies whose chest radii span 0.7 .. 1.07 of the average); seen only in
profile it measures the chest's depth and comes out low. It is clipped to ``GIRTH_RANGE``
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

#: Rank of the point taken as the top of the head (counted from the highest, 1-based).
TOP_RANK = 10
#: Added to that point's height, metres (its mean loss below the head top on synthetic renders).
TOP_BIAS = 0.004
#: Chest slice: heights between these fractions of the stature.
CHEST_SLICE = (0.70, 0.74)
#: Lower and upper quantiles of the slice's points along its principal horizontal axis.
BREADTH_QUANTILES = (0.003, 0.997)
#: Girth is clipped to this range.
GIRTH_RANGE = (0.85, 1.2)
#: Fewest points in the chest slice for a girth estimate (otherwise girth 1).
MIN_SLICE_POINTS = 30


#: The breadth profile of a person's upper body (:func:`breadth_profile`): slices this
#: thick, metres, down to this depth below the top of the head; a slice with fewer points
#: than MIN_PROFILE_POINTS has no breadth.
PROFILE_SLICE = 0.01
PROFILE_DEPTH = 0.50
MIN_PROFILE_POINTS = 10
#: The head is the widest slice within HEAD_DEPTH of the top, and no wider than HEAD_MAX
#: (else a hand is up by the head); the chest is the median breadth between the depths of
#: CHEST_DEPTH; the shoulders the median breadth SHOULDER_BAND below the neck (metres).
HEAD_DEPTH = 0.14
HEAD_MAX = 0.25
CHEST_DEPTH = (0.30, 0.45)
SHOULDER_BAND = (0.04, 0.12)
#: Measured neck depths and shoulder widths stay within these factors of the average
#: adult's at the person's stature.
SHAPE_RANGE = (0.7, 1.5)


class BodySize(NamedTuple):
    """Estimated body size: segment lengths ``dims`` and ``girth`` (radius scale, 1 = average)."""

    dims: BodyDims
    girth: float


def _along(xy: np.ndarray) -> np.ndarray:
    """(N,) metres: horizontal points (N, 2) along their principal axis (from their mean)."""
    centred = xy - xy.mean(axis=0)
    _, vectors = np.linalg.eigh(centred.T @ centred)
    return centred @ vectors[:, -1]


def _breadth(xy: np.ndarray) -> float:
    """Extent (metres) of horizontal points (N, 2) along their principal axis, between quantiles."""
    lo, hi = np.quantile(_along(xy), BREADTH_QUANTILES)
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


def top_height(heights: np.ndarray) -> float:
    """The top of a person's points: the TOP_RANK-th highest of ``heights`` (N,) metres,
    N >= TOP_RANK (a few stray points do not raise it)."""
    return float(np.partition(heights, heights.shape[0] - TOP_RANK)[heights.shape[0] - TOP_RANK])


def dims_from_observation(points, *, floor_z: float = 0.0) -> BodySize:
    """Body size of a standing person from their observed 3D points.

    points : (N, 3) float, world metres (z up), the person's points pooled over their
        first frames, N >= TOP_RANK
    floor_z : height of the floor, metres
    Returns BodySize(dims, girth): dims are DEFAULT_DIMS scaled to the measured stature
    (clipped to 1.0 .. 2.2 m), girth the radius scale (see the module docstring).
    """
    points = np.asarray(points, dtype=np.float64)
    if points.ndim != 2 or points.shape[1] != 3 or points.shape[0] < TOP_RANK:
        raise ValueError(f"points must have shape (N, 3) with N >= {TOP_RANK}, got {points.shape}")
    points = points[np.all(np.isfinite(points), axis=1)]
    if points.shape[0] < TOP_RANK:
        raise ValueError(f"points must hold at least {TOP_RANK} finite points, got {points.shape[0]}")
    if not math.isfinite(floor_z):
        raise ValueError(f"floor_z must be a finite height in metres, got {floor_z!r}")
    z = points[:, 2] - floor_z
    top = top_height(z) + TOP_BIAS
    stature = float(np.clip(top, 1.0, 2.2))
    dims = DEFAULT_DIMS.scaled(stature)
    in_slice = (z >= CHEST_SLICE[0] * stature) & (z <= CHEST_SLICE[1] * stature)
    if np.count_nonzero(in_slice) < MIN_SLICE_POINTS:
        return BodySize(dims, 1.0)
    observed = _breadth(points[in_slice, :2])
    model = _model_breadth(full_model(dims), 0.5 * (CHEST_SLICE[0] + CHEST_SLICE[1]) * stature)
    return BodySize(dims, float(np.clip(observed / model, *GIRTH_RANGE)))


def breadth_profile(points) -> np.ndarray:
    """The breadth of a person's upper body slice by slice from the top of the head down.

    points : (N, 3) float, world metres (z up), one frame of one person seen by one camera
    Returns (S,) float metres, S = PROFILE_DEPTH / PROFILE_SLICE: slice k holds the points
    between k and k + 1 slices below the top (:func:`top_height`); its breadth is the
    extent of its points along the principal horizontal axis of all the profile's points,
    between BREADTH_QUANTILES; NaN for a slice of fewer than MIN_PROFILE_POINTS points.
    """
    points = np.asarray(points, dtype=np.float64)
    if points.ndim != 2 or points.shape[1] != 3 or points.shape[0] < TOP_RANK:
        raise ValueError(f"points must have shape (N, 3) with N >= {TOP_RANK}, got {points.shape}")
    count = int(round(PROFILE_DEPTH / PROFILE_SLICE))
    depth = top_height(points[:, 2]) - points[:, 2]
    upper = (depth >= 0.0) & (depth < count * PROFILE_SLICE)
    depth = depth[upper]
    along = _along(points[upper, :2])
    slices = np.minimum((depth / PROFILE_SLICE).astype(np.int64), count - 1)
    profile = np.full(count, np.nan)
    for k in np.flatnonzero(np.bincount(slices, minlength=count) >= MIN_PROFILE_POINTS):
        lo, hi = np.quantile(along[slices == k], BREADTH_QUANTILES)
        profile[k] = hi - lo
    return profile


def neck_and_shoulders(profile: np.ndarray) -> tuple[float, float] | None:
    """(neck depth below the top of the head, shoulder breadth), metres, from one frame's
    :func:`breadth_profile` of a person seen from the front or the back; None when the
    profile shows no head above a wider chest (a hand by the head, slices missing).

    The neck is where the breadth first reaches halfway from the head's (its widest slice
    near the top) to the chest's (CHEST_DEPTH) below the head; the shoulders are the median
    breadth SHOULDER_BAND below it: the upper arms hanging from the shoulder joints and the
    chest between them. Measured on the synthetic renders (a Kinect v1 at 3 m, the renderer's
    bodies, frames within 37 degrees of facing the camera or away): neck depth 0.25-0.28 m
    for a true 0.265-0.28 (the mocap subject, whose neck sits 5 cm lower than the average
    adult's) and 0.22 for 0.215 (average bodies); shoulder breadth / 2 - upper arm radius
    0.10-0.11 for shoulder widths of 0.10 and 0.175 for 0.183 (medians of 15 frames).
    Shoulders narrower than the chest read as the chest's breadth (0.128 for 0.110 on a
    procedural body with narrow shoulders).
    """
    head_slices = int(round(HEAD_DEPTH / PROFILE_SLICE))
    chest = profile[int(round(CHEST_DEPTH[0] / PROFILE_SLICE)):int(round(CHEST_DEPTH[1] / PROFILE_SLICE))]
    if np.all(np.isnan(profile[:head_slices])) or np.all(np.isnan(chest)):
        return None
    head = int(np.nanargmax(profile[:head_slices]))
    head_breadth, chest_breadth = profile[head], float(np.nanmedian(chest))
    if head_breadth > HEAD_MAX or chest_breadth <= head_breadth:
        return None
    wide = np.flatnonzero(profile[head:] > 0.5 * (head_breadth + chest_breadth))
    neck = head + int(wide[0])
    band = profile[neck + int(round(SHOULDER_BAND[0] / PROFILE_SLICE)):
                   neck + int(round(SHOULDER_BAND[1] / PROFILE_SLICE))]
    if np.all(np.isnan(band)):
        return None
    return neck * PROFILE_SLICE, float(np.nanmedian(band))


def dims_with_shoulders(dims: BodyDims, girth: float, neck_depth: float, shoulder_breadth: float) -> BodyDims:
    """``dims`` with the neck ``neck_depth`` metres below the top of the head (the trunk
    split between spine and neck_head; stature and legs kept) and the shoulders as wide
    as ``shoulder_breadth`` metres across the upper arms (:func:`neck_and_shoulders`) of
    a model of ``girth``, each kept within SHAPE_RANGE of the average adult's at the stature.
    """
    average = DEFAULT_DIMS.scaled(dims.height)
    depth = float(np.clip(neck_depth, *(f * 2.0 * average.neck_head for f in SHAPE_RANGE)))
    arm = FULL_RADII["upper_arm"][0] * girth
    width = float(np.clip(0.5 * shoulder_breadth - arm, *(f * average.shoulder_width for f in SHAPE_RANGE)))
    return replace(dims, spine=dims.height - dims.hip_height - depth, neck_head=0.5 * depth, shoulder_width=width)
