"""Poses searched for from scratch, without a previous estimate: where a person starts
(:mod:`occupose.pose.start`) and where a lost estimate is searched for again
(:meth:`occupose.pose.person.Person.recheck`).

The candidates are standing and seated poses at a set of headings above the centre of the
person's points; the search scores random perturbations of each and takes the best. The
settings are the fields of :class:`occupose.config.StartConfig` (and, searching again,
:class:`occupose.config.RecoverConfig`).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from occupose.body import BodyModel, seated_pose, standing_pose
from occupose.config import StartConfig
from occupose.pose.problem import PoseProblem


def start_candidates(model: BodyModel, centroid: np.ndarray, headings: np.ndarray,
                     seat_share: float = StartConfig.seat_share) -> np.ndarray:
    """(S, D) start poses for a person whose blob is centred at ``centroid`` (3,) metres:
    standing and (for models with legs) seated on a seat ``seat_share`` of the stature
    high (:mod:`occupose.body.postures`), at every heading of ``headings`` (radians), the
    pelvis above the centroid."""
    postures = [standing_pose(model)]
    if "left_knee" in model.dof_names:
        postures.append(seated_pose(model, seat_share * model.dims.height))
    poses = np.repeat(np.array(postures), len(headings), axis=0)
    poses[:, model.dof("heading")] = np.tile(headings, len(postures))
    poses[:, 0:2] = centroid[:2]  # pelvis above the blob's centre; the filter settles the rest
    return poses


def start_spread(model: BodyModel, config: StartConfig) -> np.ndarray:
    """(D,) spread (std) of a new person's particles around its start: ``spread_position``
    metres on the root's x, y, z, ``spread_heading`` on the heading, ``spread_angle`` on
    every other angle, radians."""
    spread = np.where(model.angular, config.spread_angle, config.spread_position)
    spread[model.dof_names.index("heading")] = config.spread_heading
    return spread


def best_sample(problem: PoseProblem, candidates: np.ndarray, spread: np.ndarray, samples: int,
                rng: np.random.Generator) -> np.ndarray:
    """(D,) the most likely (under ``problem``'s observation) of ``samples`` random
    perturbations (normal, std ``spread`` (D,)) of each of ``candidates`` (S, D), kept
    inside the limits."""
    drawn = np.repeat(candidates, samples, axis=0)
    drawn += rng.standard_normal(drawn.shape) * spread
    drawn = np.clip(drawn, problem.limits[:, 0], problem.limits[:, 1])
    return drawn[int(np.argmax(problem.log_likelihood(drawn).sum(axis=1)))]


def explained_share(distance: Callable[[np.ndarray], np.ndarray], points: np.ndarray, within: float) -> float:
    """Share of ``points`` (N, 3) metres at most ``within`` metres from a body, ``distance``
    giving each point's distance (metres) to its surface; 1.0 for no points."""
    if len(points) == 0:
        return 1.0
    return float(np.mean(distance(points) <= within))
