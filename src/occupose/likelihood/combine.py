"""Sums of likelihood terms (independent evidence: log-likelihoods add)."""

from __future__ import annotations

import numpy as np

from occupose.likelihood._capsules import check_capsules
from occupose.likelihood.color import ColorLikelihood
from occupose.likelihood.free import FreeSpaceLikelihood
from occupose.likelihood.observation import Observation
from occupose.likelihood.points import PointsLikelihood
from occupose.likelihood.render import RenderLikelihood

#: The single terms, by name.
TERMS: dict[str, type] = {
    "points": PointsLikelihood,
    "free": FreeSpaceLikelihood,
    "render": RenderLikelihood,
    "color": ColorLikelihood,
}


class Sum:
    """The sum of several terms, each built from the same observation.

    Subclasses made by :func:`sum_of` fix ``names``. Options go per term, as dicts keyed
    by term name: ``sum_of("points", "color")(obs, points={"scale": 0.02}, color={"bins": 8})``.
    ``terms`` maps each name to its built instance (e.g. ``terms["color"].set_reference(...)``).
    """

    names: tuple[str, ...] = ()

    def __init__(self, observation: Observation, **options):
        unknown = sorted(set(options) - set(self.names))
        if unknown:
            raise ValueError(f"unknown option(s) {unknown} for {'+'.join(self.names)!r}; give each term's "
                             f"options as a dict under its name: {list(self.names)}")
        self.terms = {}
        for name in self.names:
            term_options = options.get(name, {})
            if not isinstance(term_options, dict):
                raise ValueError(f"options of term {name!r} must be a dict, got {type(term_options).__name__}")
            self.terms[name] = TERMS[name](observation, **term_options)

    def evaluate(self, a, b, radii, capsule_part, num_parts) -> np.ndarray:
        """(P, K) float64: the sum of the terms' log-likelihoods (see the terms' evaluate).
        The capsules are checked once, here, not by every term."""
        checked = check_capsules(a, b, radii, capsule_part, num_parts)
        total = None
        for term in self.terms.values():
            values = term.evaluate_checked(*checked)
            total = values if total is None else total + values
        return total


def sum_of(*names: str) -> type:
    """A :class:`Sum` subclass of the named terms (names from :data:`TERMS`, at least two)."""
    if len(names) < 2 or len(set(names)) != len(names) or not all(name in TERMS for name in names):
        raise ValueError(f"sum_of needs two or more different term names from {sorted(TERMS)}, got {list(names)}")
    return type("Sum_" + "_".join(names), (Sum,), {"names": tuple(names), "__doc__": f"``{'+'.join(names)}``: "
                                                     f"the sum of the {', '.join(names)} terms (see Sum)."})
