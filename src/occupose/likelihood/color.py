"""The second paper's colour term: per-part colour histograms, Bhattacharyya distance.

A part's colour histogram for a particle is made of the pixels its capsules cover: the
camera-facing surface samples of each capsule (as in the free-space term) are projected
into every view with a colour image, and each sample that is not hidden by something
measured in front of it (measured depth d with z > d + margin + 3 sigma(d)) adds the colour
cell of its pixel (``bins``^3 RGB cells). A well-placed part shows its own colours; a
misplaced one shows the background or another part. The histogram is compared with the
part's reference (the previous estimate's, :meth:`ColorLikelihood.set_reference`) by the
Bhattacharyya distance d = sqrt(1 - sum sqrt(h r)) (Nummiaro et al. 2002)::

    log L[p, k] = -scale * d[p, k]

A part without any counted sample has d = 1; a part whose reference is empty (not seen in
the previous frame), and every part before a reference is set, scores 0.
"""

from __future__ import annotations

import numpy as np

from occupose.config import LikelihoodConfig
from occupose.likelihood import _sample_kernels
from occupose.likelihood._capsules import check_capsules, check_positive
from occupose.likelihood._samples import camera_arrays, offset_depths, sample_pattern
from occupose.likelihood.observation import Observation

#: Default scale, nats for a part whose colours share nothing with its reference (d = 1).
#: Calibrated as the points scale (occupose.likelihood.points.POINTS_SCALE), with the
#: reference taken from a slightly different pose of the frame before: an effective sample
#: size of 88 of 200 (scale 2: 38).
COLOR_SCALE = LikelihoodConfig.color_scale
#: Default histogram cells per RGB channel (4 -> 64 cells; 8 -> 512 is too sparse for the
#: few dozen samples of a limb).
COLOR_BINS = LikelihoodConfig.color_bins
#: Default margin beyond 3 sigma of sensor noise, metres, before a sample counts as hidden.
COLOR_MARGIN = LikelihoodConfig.color_margin


def color_cells(color: np.ndarray, bins: int = COLOR_BINS) -> np.ndarray:
    """(H, W) int64 colour cell of each pixel of an (H, W, 3) uint8 RGB image:
    ((r * bins // 256) * bins + g * bins // 256) * bins + b * bins // 256, in [0, bins^3)."""
    color = np.asarray(color)
    if color.ndim != 3 or color.shape[2] != 3 or color.dtype != np.uint8:
        raise ValueError(f"color must be an (H, W, 3) uint8 image, got {color.dtype} {color.shape}")
    rgb = color.astype(np.int64) * bins // 256
    return np.ascontiguousarray((rgb[..., 0] * bins + rgb[..., 1]) * bins + rgb[..., 2])


class ColorLikelihood:
    """``color``: log L[p, k] = -scale * Bhattacharyya distance of part k to its reference.

    observation : Observation; views without a colour image are skipped
    scale : nats; bins : cells per RGB channel
    margin : metres, and noise : sensor model name (:func:`occupose.sensors.depth_std`),
        the tolerance before a sample counts as hidden
    samples_along, samples_around : surface samples per capsule (angles -45..45 degrees)
    reference : (K, bins^3) histograms (rows are normalised here; an all-zero row means
        "no reference" for that part), or None until :meth:`set_reference`
    """

    def __init__(self, observation: Observation, *, scale: float = COLOR_SCALE, bins: int = COLOR_BINS,
                 margin: float = COLOR_MARGIN, noise: str = "structured_light", samples_along: int = 6,
                 samples_around: int = 5, reference=None):
        if not isinstance(observation, Observation):
            raise ValueError(f"observation must be an Observation, got {type(observation).__name__}")
        self.scale = check_positive(scale, "scale")
        if isinstance(bins, bool) or not isinstance(bins, (int, np.integer)) or not 1 <= bins <= 256:
            raise ValueError(f"bins must be an integer in 1..256 (cells per RGB channel), got {bins!r}")
        self.bins = int(bins)
        self.num_bins = self.bins ** 3
        self._along, self._cos, self._sin, _ = sample_pattern(samples_along, samples_around)
        self._views = []
        for view in observation.views:
            if view.color is None:
                continue
            hidden = offset_depths(view.depth, margin, noise, 1.0)
            self._views.append((*camera_arrays(view.camera), view.camera, hidden,
                                color_cells(view.color, self.bins)))
        if not self._views:
            raise ValueError("the color likelihood needs an observation with at least one colour image")
        self._sqrt_reference = None
        if reference is not None:
            self.set_reference(reference)

    def histograms(self, a, b, radii, capsule_part, num_parts) -> np.ndarray:
        """(P, K, bins^3) float64 normalised colour histograms of each particle's parts
        (all-zero for a part without a counted sample); arguments as :meth:`evaluate`.
        The estimate's histograms are the next frame's reference."""
        return self._histograms(*check_capsules(a, b, radii, capsule_part, num_parts))

    def _histograms(self, a, b, radii, capsule_part, num_parts) -> np.ndarray:
        counts = np.zeros((a.shape[0], num_parts, self.num_bins))
        for rotation, shift, cam, hidden, cells in self._views:
            _sample_kernels.color_counts(a, b, radii, capsule_part, rotation, shift, cam.fx, cam.fy, cam.cx, cam.cy,
                                         hidden, cells, self._along, self._cos, self._sin, counts)
        total = counts.sum(axis=2, keepdims=True)
        return np.divide(counts, total, out=counts, where=total > 0)

    def set_reference(self, reference) -> None:
        """Set the reference histograms (K, bins^3), e.g. ``histograms(estimate...)[0]`` of the
        previous frame; rows are normalised, an all-zero row switches that part off."""
        reference = np.asarray(reference, dtype=np.float64)
        if reference.ndim != 2 or reference.shape[1] != self.num_bins or not np.all(np.isfinite(reference)) \
                or np.any(reference < 0):
            raise ValueError(f"reference must be a (K, {self.num_bins}) array of non-negative histogram counts "
                             f"(bins={self.bins}), got shape {reference.shape}")
        total = reference.sum(axis=1, keepdims=True)
        self._sqrt_reference = np.sqrt(np.divide(reference, total, out=np.zeros_like(reference), where=total > 0))

    def evaluate(self, a, b, radii, capsule_part, num_parts) -> np.ndarray:
        """(P, K) float64 log-likelihoods of particles with capsules a, b (P, C, 3) metres,
        radii (C, 2) metres, capsule_part (C,) int in [0, num_parts). Zero before a
        reference is set; the reference must have K rows."""
        return self.evaluate_checked(*check_capsules(a, b, radii, capsule_part, num_parts))

    def evaluate_checked(self, a, b, radii, capsule_part, num_parts) -> np.ndarray:
        """:meth:`evaluate` on arguments that passed ``check_capsules``."""
        if self._sqrt_reference is None:
            return np.zeros((a.shape[0], num_parts))
        if self._sqrt_reference.shape[0] != num_parts:
            raise ValueError(f"the colour reference has {self._sqrt_reference.shape[0]} parts, "
                             f"evaluate was given num_parts={num_parts}")
        hist = self._histograms(a, b, radii, capsule_part, num_parts)
        coefficient = np.einsum("pkj,kj->pk", np.sqrt(hist), self._sqrt_reference)
        distance = np.sqrt(np.clip(1.0 - coefficient, 0.0, None))
        distance[hist.sum(axis=2) == 0] = 1.0
        return -self.scale * distance * (self._sqrt_reference.sum(axis=1) > 0)
