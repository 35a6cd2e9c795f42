"""The second paper's depth term: mean 3D distance from the observed points to the model.

Each observed point is matched to the nearest capsule surface (the absolute distance to
the round cone, so points inside a capsule count as far as they are from its surface)
and belongs to that capsule's part, as in the second paper's Fig. 3 ("each pixel of the
ROI is associated with the nearest part of the model"). The likelihood is
exp(-mean distance / scale), split over parts so that the parts add up to it::

    log L[p, k] = -(sum of the distances of the points matched to part k) / (N * scale)
"""

from __future__ import annotations

import numpy as np

from occupose.config import LikelihoodConfig
from occupose.likelihood import _distance_kernels
from occupose.likelihood._capsules import blocked_points, check_capsules, check_positive
from occupose.likelihood.observation import Observation

#: Default distance scale, metres: each centimetre of mean point-to-model distance costs
#: one nat (the paper's exp(-d) with d in centimetres). Every term's default is set so
#: that, alone, it keeps about half of the particles effective in one calibration: the
#: ``full`` model at the fitted true pose of a synthetic frame (a person facing a Kinect v1
#: 2.5 m away, with its depth noise, as ``front`` in tests/likelihood/conftest.py) and 200 particles
#: diffused by 0.1 rad / 3 cm per DOF. There the mean distance is 1.9 cm at the true pose
#: and the effective sample size 104 of 200 (scale 0.05 m: 190, nearly flat; 0.005 m: 46).
#: Annealed filters rescale it anyway.
POINTS_SCALE = LikelihoodConfig.points_scale


def point_distances(a, b, radii, points, *, sort: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """Distance from each point to the nearest capsule surface, per particle.

    a, b : (P, C, 3) float, metres, world: round-cone ends; radii : (C, 2) float, metres
    points : (N, 3) float, metres, world, or an Observation (whose blocks of points are
        reused)
    sort : for an (N, 3) array, whether to sort the points into compact blocks first
        (:func:`blocked_points`); False for points in image order and few particles
    Returns distance (P, N) float32, metres (absolute distance to the round cone's
    surface; float32, exact to about a micrometre) and capsule (P, N) int32, the index of
    the nearest capsule (the first one on ties).
    """
    a, b, radii, _, _ = check_capsules(a, b, radii, np.zeros(np.shape(radii)[0], np.int64), 1)
    if isinstance(points, Observation):
        blocks = points.blocks
    else:
        points = np.asarray(points, dtype=np.float64)
        if points.ndim != 2 or points.shape[1] != 3 or not np.all(np.isfinite(points)):
            raise ValueError(f"points must be a finite (N, 3) array, got shape {points.shape}")
        blocks = blocked_points(points, sort=sort)
    blocked_distance = np.empty((a.shape[0], len(blocks.px)), np.float32)
    blocked_capsule = np.empty((a.shape[0], len(blocks.px)), np.int32)
    _distance_kernels.nearest_capsules(a, b, radii, *blocks.kernel_args, blocked_distance, blocked_capsule)
    return blocked_distance[:, blocks.position], blocked_capsule[:, blocks.position]


class PointsLikelihood:
    """``points``: log L[p, k] = -(sum of part k's point distances) / (N * scale).

    observation : Observation with at least one point
    scale : metres (default :data:`POINTS_SCALE`)
    """

    def __init__(self, observation: Observation, *, scale: float = POINTS_SCALE):
        if not isinstance(observation, Observation):
            raise ValueError(f"observation must be an Observation, got {type(observation).__name__}")
        if len(observation.points) == 0:
            raise ValueError("the points likelihood needs an observation with at least one point, got none")
        self.scale = check_positive(scale, "scale")
        self.num_points = len(observation.points)
        self._blocks = observation.blocks

    def evaluate(self, a, b, radii, capsule_part, num_parts) -> np.ndarray:
        """(P, K) float64 log-likelihoods of particles with capsules a, b (P, C, 3) metres,
        radii (C, 2) metres, capsule_part (C,) int in [0, num_parts)."""
        return self.evaluate_checked(*check_capsules(a, b, radii, capsule_part, num_parts))

    def evaluate_checked(self, a, b, radii, capsule_part, num_parts) -> np.ndarray:
        """:meth:`evaluate` on arguments that passed ``check_capsules``."""
        out = np.zeros((a.shape[0], num_parts))
        _distance_kernels.point_distance_sums(a, b, radii, capsule_part, *self._blocks.kernel_args, self._blocks.weight,
                                              out)
        out *= -1.0 / (self.num_points * self.scale)
        return out
