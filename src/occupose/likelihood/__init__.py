"""Observation models: how well a body pose explains one person's depth (and colour) data.

Every likelihood is built once per frame from an :class:`Observation` and evaluated many
times on particles given as capsules (round cones: truncated cones capped by spheres)::

    likelihood = make_likelihood("points+free", observation)
    log_lik = likelihood.evaluate(a, b, radii, capsule_part, num_parts)   # (P, K)

a, b : (P, C, 3) float64, metres, world, the capsule ends of each particle (e.g.
:func:`occupose.body.capsules_from_poses`); radii : (C, 2) metres; capsule_part : (C,) int,
the body part of each capsule; num_parts : K. The result holds per-particle, per-part
LOG-likelihoods; a particle's total is the sum over its parts.

Registered names (:data:`LIKELIHOODS`):

- ``points``: the second paper's exp(-mean point-to-model distance / scale);
- ``free``: the free-space term alone (model inside space a camera sees as empty);
- ``points+free``: both;
- ``render``: the first paper's rendered-depth comparison with truncation D;
- ``color``: the second paper's per-part colour histograms against a reference;
- ``points+color``, ``points+free+color``, ``render+color``: sums (:func:`sum_of` makes others).
"""

from __future__ import annotations

from occupose.likelihood.color import ColorLikelihood, color_cells
from occupose.likelihood.combine import TERMS, Sum, sum_of
from occupose.likelihood.free import FreeSpaceLikelihood
from occupose.likelihood.observation import Observation, View, observation_from_views, roi_from_mask
from occupose.likelihood.points import PointsLikelihood, point_distances
from occupose.likelihood.render import RenderLikelihood

#: Likelihood classes by name; each is called as ``cls(observation, **options)``.
LIKELIHOODS: dict[str, type] = {
    **TERMS,
    "points+free": sum_of("points", "free"),
    "points+color": sum_of("points", "color"),
    "points+free+color": sum_of("points", "free", "color"),
    "render+color": sum_of("render", "color"),
}


def make_likelihood(name: str, observation: Observation, **options):
    """Build the likelihood registered as ``name`` on ``observation``; ValueError listing
    the valid names otherwise. ``options`` go to its class (for sums: one dict per term)."""
    try:
        cls = LIKELIHOODS[name]
    except (KeyError, TypeError):
        raise ValueError(f"unknown likelihood {name!r}; valid names: {sorted(LIKELIHOODS)}") from None
    return cls(observation, **options)


__all__ = [
    "LIKELIHOODS", "TERMS", "ColorLikelihood", "FreeSpaceLikelihood", "Observation", "PointsLikelihood",
    "RenderLikelihood", "Sum", "View", "color_cells", "make_likelihood", "observation_from_views",
    "point_distances", "roi_from_mask", "sum_of",
]
