"""Free-space term: the model must not fill space that a camera sees as empty.

Points on the camera-facing side of every capsule (fixed per capsule: ``samples_along``
positions along the axis times ``samples_around`` angles about it, plus the point of each
end sphere nearest the camera; all inside the round cone) are projected into each view.
Where the measured depth at a sample's pixel is clearly *behind* the sample, the camera
looked through the place the model occupies, so the pose is penalised; a sample in front
of which something was measured (occluded, e.g. a leg behind a desk), on a pixel without a
measurement (depth 0) or outside the image costs nothing.

"Clearly behind": measured depth d > z + margin(d) with margin(d) = ``margin`` + 3 sigma(d),
sigma the random depth error of the sensor ``noise`` model
(:func:`occupose.sensors.depth_std`). A sample's penalty ramps linearly from 0 to 1
over ``ramp`` metres beyond that, and::

    log L[p, k] = -weight * (mean penalty over part k's samples in all views)

so a part lying wholly in seen-empty space costs ``weight`` nats.
"""

from __future__ import annotations

import numpy as np

from occupose.config import LikelihoodConfig
from occupose.likelihood import _sample_kernels
from occupose.likelihood._capsules import check_capsules, check_positive
from occupose.likelihood._samples import camera_arrays, offset_depths, sample_pattern
from occupose.likelihood.observation import Observation

#: Default weight, nats for a part wholly in seen-empty space. Calibrated as the points
#: scale (occupose.likelihood.points.POINTS_SCALE): the term is -0.03 at the true pose and
#: leaves an effective sample size of 86 of 200 alone, 42 together with ``points``
#: (weight 0.5: 144 and 71).
FREE_WEIGHT = LikelihoodConfig.free_weight
#: Default margin beyond 3 sigma of sensor noise, metres: the capsule model's radius error
#: (a few cm) plus the surface samples' offset from the true surface.
FREE_MARGIN = LikelihoodConfig.free_margin
#: Default ramp, metres, over which a sample's penalty grows from 0 to 1.
FREE_RAMP = LikelihoodConfig.free_ramp


class FreeSpaceLikelihood:
    """``free``: log L[p, k] = -weight * mean free-space penalty of part k's samples.

    observation : Observation (its views' depth images are read)
    weight : nats for a part wholly in seen-empty space
    margin, ramp : metres (see the module docstring)
    noise : sensor noise model name of :func:`occupose.sensors.depth_std`
        ("structured_light", "tof" or "none")
    samples_along, samples_around : samples per capsule along and about its axis; the
        angles about it span -45..45 degrees from the direction facing the camera.
    """

    def __init__(self, observation: Observation, *, weight: float = FREE_WEIGHT, margin: float = FREE_MARGIN,
                 ramp: float = FREE_RAMP, noise: str = LikelihoodConfig.free_noise, samples_along: int = 5,
                 samples_around: int = 5):
        if not isinstance(observation, Observation):
            raise ValueError(f"observation must be an Observation, got {type(observation).__name__}")
        if not observation.views:
            raise ValueError("the free-space likelihood needs an observation with at least one view")
        self.weight = check_positive(weight, "weight")
        self.ramp = check_positive(ramp, "ramp")
        self._along, self._cos, self._sin, self.samples_per_capsule = sample_pattern(samples_along, samples_around)
        self._views = []
        for view in observation.views:
            free = offset_depths(view.depth, margin, noise, -1.0)
            self._views.append((*camera_arrays(view.camera), view.camera, free))

    def evaluate(self, a, b, radii, capsule_part, num_parts) -> np.ndarray:
        """(P, K) float64 log-likelihoods of particles with capsules a, b (P, C, 3) metres,
        radii (C, 2) metres, capsule_part (C,) int in [0, num_parts)."""
        return self.evaluate_checked(*check_capsules(a, b, radii, capsule_part, num_parts))

    def evaluate_checked(self, a, b, radii, capsule_part, num_parts) -> np.ndarray:
        """:meth:`evaluate` on arguments that passed ``check_capsules``."""
        out = np.zeros((a.shape[0], num_parts))
        for rotation, shift, cam, free in self._views:
            _sample_kernels.free_space_penalties(a, b, radii, capsule_part, rotation, shift, cam.fx, cam.fy, cam.cx,
                                                 cam.cy, free, self._along, self._cos, self._sin, self.ramp, out)
        samples = np.bincount(capsule_part, minlength=num_parts) * self.samples_per_capsule * len(self._views)
        out *= -self.weight / np.maximum(samples, 1)
        return out
