"""The first paper's term: the model's depth image compared with the observed one.

For each particle the capsules are ray-cast (exact round-cone hits, nearest camera z)
into a pixel grid over each view's person box (every ``stride``-th pixel of the ROI, from
its top-left corner) and compared pixel by pixel with the observed depth inside the
person's mask, after the paper's equation (section III-C.2)::

    sigma = sum over pixels of f^2,  f = min(|d_obs - d_model| / D, 1) on pixels in both
    silhouettes (S-intersection), f = 1 on pixels in only one of them

with the truncation D = ``truncation`` (the paper's 100 mm). The paper weighs a particle by
exp(-sigma) over full-resolution pixels; here sigma is divided by the number of observed
silhouette pixels on the grid, so the figure does not depend on the stride or on how
far the person is, and scaled::

    log L = -scale * sigma / n_obs

Per part: a pixel the model covers counts for the part rendered there; an observed pixel
the model misses counts for the part whose capsule is nearest (in 3D) its back-projected
point, so that a part which drifted away from its pixels pays for them.
"""

from __future__ import annotations

import numba
import numpy as np

from occupose.config import LikelihoodConfig
from occupose.likelihood import _distance_kernels
from occupose.likelihood._capsules import check_capsules, check_positive
from occupose.likelihood._samples import camera_arrays
from occupose.likelihood.observation import Observation

#: Default scale, nats per observed-silhouette share of sigma: a model that misses a tenth
#: of the silhouette (about one limb) and covers as much elsewhere costs 5 x 0.2 = 1 nat.
#: Calibrated as the points scale (occupose.likelihood.points.POINTS_SCALE): an effective
#: sample size of 123 of 200 (scale 10: 40).
RENDER_SCALE = LikelihoodConfig.render_scale
#: The paper's truncation D, metres.
RENDER_TRUNCATION = LikelihoodConfig.render_truncation
#: Default grid stride, pixels.
RENDER_STRIDE = LikelihoodConfig.render_stride


class RenderLikelihood:
    """``render``: log L[p, k] = -scale * (part k's share of sigma) / n_obs.

    observation : Observation (its views' depth, mask and roi are read)
    scale : nats (see the module docstring); truncation : D, metres; stride : pixels
    """

    def __init__(self, observation: Observation, *, scale: float = RENDER_SCALE,
                 truncation: float = RENDER_TRUNCATION, stride: int = RENDER_STRIDE):
        if not isinstance(observation, Observation):
            raise ValueError(f"observation must be an Observation, got {type(observation).__name__}")
        if not observation.views:
            raise ValueError("the render likelihood needs an observation with at least one view")
        self.scale = check_positive(scale, "scale")
        self.truncation = check_positive(truncation, "truncation")
        if isinstance(stride, bool) or not isinstance(stride, (int, np.integer)) or stride < 1:
            raise ValueError(f"stride must be a positive integer (pixels), got {stride!r}")
        self.stride = int(stride)
        self._views = []
        self.num_observed = 0
        for view in observation.views:
            v0, v1, u0, u1 = view.roi
            if v1 <= v0 or u1 <= u0:
                continue
            rows, cols = np.arange(v0, v1, self.stride), np.arange(u0, u1, self.stride)
            observed = np.where(view.mask[np.ix_(rows, cols)], view.depth[np.ix_(rows, cols)], 0.0).astype(np.float64)
            index = np.flatnonzero(observed)
            gv, gu = np.divmod(index, len(cols))
            cam = view.camera
            z = observed.reshape(-1)[index]
            back = [(cols[gu] - cam.cx) / cam.fx * z, (rows[gv] - cam.cy) / cam.fy * z, z]
            self.num_observed += len(index)
            self._views.append((*camera_arrays(cam), cam, u0, v0, np.ascontiguousarray(observed), index,
                                *(np.ascontiguousarray(c, dtype=np.float32) for c in back)))

    def evaluate(self, a, b, radii, capsule_part, num_parts) -> np.ndarray:
        """(P, K) float64 log-likelihoods of particles with capsules a, b (P, C, 3) metres,
        radii (C, 2) metres, capsule_part (C,) int in [0, num_parts)."""
        return self.evaluate_checked(*check_capsules(a, b, radii, capsule_part, num_parts))

    def evaluate_checked(self, a, b, radii, capsule_part, num_parts) -> np.ndarray:
        """:meth:`evaluate` on arguments that passed ``check_capsules``."""
        out = np.zeros((a.shape[0], num_parts))
        for rotation, shift, cam, u0, v0, observed, index, x, y, z in self._views:
            _distance_kernels.render_sigmas(a, b, radii, capsule_part, rotation, shift, cam.fx, cam.fy, cam.cx, cam.cy,
                                            u0, v0, self.stride, observed, index, x, y, z, self.truncation,
                                            min(a.shape[0], 4 * numba.get_num_threads()), out)
        out *= -self.scale / max(self.num_observed, 1)
        return out
