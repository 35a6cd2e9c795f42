"""A person's body size (stature and girth) from the 3D points of their first frames.

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
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from occupose.body.kinematics import capsules_from_poses
from occupose.body.model import BodyModel, full_model
from occupose.synth.motion import ARM_REST, DEFAULT_DIMS, BodyDims

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


class BodySize(NamedTuple):
    """Estimated body size: segment lengths ``dims`` and ``girth`` (radius scale, 1 = average)."""

    dims: BodyDims
    girth: float


def _breadth(xy: np.ndarray) -> float:
    """Extent (metres) of horizontal points (N, 2) along their principal axis, between quantiles."""
    centred = xy - xy.mean(axis=0)
    _, vectors = np.linalg.eigh(centred.T @ centred)
    along = centred @ vectors[:, -1]
    lo, hi = np.quantile(along, BREADTH_QUANTILES)
    return float(hi - lo)


def _model_breadth(model: BodyModel, height: float) -> float:
    """Breadth of the standing model at ``height`` metres above the floor (arms at rest), metres."""
    pose = np.zeros(model.num_dofs)
    dims = model.dims
    pose[model.dof("z")] = dims.ankle_height + dims.thigh + dims.shin
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
