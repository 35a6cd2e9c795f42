"""Particle filters on a generic ``problem``: SIR, annealed, partitioned, both, part-based.

Build one by name with :func:`make_filter` (or ``FILTERS[name](problem, num_particles, rng,
**options)``), call ``initialise(pose, spread)`` once, then ``step()`` once per frame; the
problem's ``log_likelihood`` scores the current observation. See
:class:`occupose.filters.base.Problem` for what a problem provides.
"""

from __future__ import annotations

import inspect

import numpy as np

from occupose.filters.base import ParticleFilter, Problem, apply_limits, mean_pose
from occupose.filters.layered import AnnealedFilter, AnnealedPartitionedFilter, PartitionedFilter, SIRFilter
from occupose.filters.part_based import PartBasedFilter
from occupose.filters.resampling import RESAMPLING, ess, normalised_weights, resample

#: Filters by name: ``cls(problem, num_particles, rng, **options)``.
FILTERS: dict[str, type[ParticleFilter]] = {
    "sir": SIRFilter, "apf": AnnealedFilter, "ps": PartitionedFilter,
    "apf+ps": AnnealedPartitionedFilter, "part-based": PartBasedFilter,
}


def filter_options(name: str) -> dict:
    """The options (keyword -> default) of the filter registered as ``name``."""
    if name not in FILTERS:
        raise ValueError(f"unknown filter {name!r}; valid names: {', '.join(FILTERS)}")
    parameters = inspect.signature(FILTERS[name].__init__).parameters.values()
    return {p.name: p.default for p in parameters if p.kind is inspect.Parameter.KEYWORD_ONLY}


def make_filter(name: str, problem: Problem, num_particles: int, rng: np.random.Generator,
                **options) -> ParticleFilter:
    """The filter registered as ``name``, built on ``problem``.

    name : a key of FILTERS
    num_particles : P
    rng : np.random.Generator
    options : the filter's keyword options (``filter_options(name)`` lists them)
    ValueError naming the valid names or options otherwise.
    """
    accepted = filter_options(name)
    unknown = sorted(set(options) - set(accepted))
    if unknown:
        raise ValueError(f"filter {name!r} has no option(s) {unknown}; its options: {list(accepted)}")
    return FILTERS[name](problem, num_particles, rng, **options)


__all__ = [
    "FILTERS", "RESAMPLING", "ParticleFilter", "Problem", "SIRFilter", "AnnealedFilter", "PartitionedFilter",
    "AnnealedPartitionedFilter", "PartBasedFilter", "make_filter", "filter_options", "resample", "ess",
    "normalised_weights", "apply_limits", "mean_pose",
]
