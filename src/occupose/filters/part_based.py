"""The part-based particle filter of the second paper (sections 2.2 and 2.4).

Each weighting part p (``problem.weight_groups``: its DOFs and the likelihood parts that
weight them) carries its own weights w^{i,p}. A step resamples every group's DOFs by that
group's weights, then shuffles them with an independent random permutation f^p (eq. 4), so
the recombined particles mix the good arms of some particles with the good heads of others
instead of keeping the ancestors' pairings; then diffuses every DOF, evaluates the
likelihood once and gives each group the sum of its parts' columns as new log-weights.
The estimate of each DOF is the mean weighted by its own group's weights.
"""

from __future__ import annotations

import time

import numpy as np

from occupose.filters.base import ParticleFilter, Problem, check_groups, mean_pose
from occupose.filters.resampling import normalised_weights


class PartBasedFilter(ParticleFilter):
    """Per-part weights, per-part resampling and shuffling (eq. 3 and 4 of the second paper).

    problem, num_particles, rng : see ParticleFilter; needs ``problem.weight_groups``
    resampling : a key of RESAMPLING
    shuffle : apply the random permutation f^p of eq. 4 after each group's resampling

    ``log_weights`` is (P, G), one column per weight group (G = len(problem.weight_groups)).
    One likelihood call (P evaluations) per step.
    """

    name = "part-based"

    def __init__(self, problem: Problem, num_particles: int, rng: np.random.Generator, *,
                 resampling: str = "systematic", shuffle: bool = True):
        super().__init__(problem, num_particles, rng, resampling=resampling)
        self.groups = check_groups(problem.weight_groups, "weight_groups", self.num_dofs)
        self._groups.append(("weight_groups", self.groups))
        self.shuffle = bool(shuffle)

    def _initial_log_weights(self) -> np.ndarray:
        return np.zeros((self.num_particles, len(self.groups)))

    def _step(self, std: np.ndarray, active: np.ndarray) -> None:
        old = self.particles
        self.particles = old.copy()
        for g, (dofs, _) in enumerate(self.groups):
            dofs = dofs[active[dofs]]
            if dofs.size == 0:
                continue
            indices = self._resample(self.log_weights[:, g])
            if indices is None:
                indices = np.arange(self.num_particles)
            if self.shuffle:
                start = time.perf_counter()
                indices = indices[self.rng.permutation(self.num_particles)]
                self._timed("resample", start)
            self.particles[:, dofs] = old[indices[:, None], dofs]
            self.log_weights[:, g] = 0.0
        moving = np.flatnonzero(active)
        if moving.size == 0:
            return
        self._diffuse(moving, std[moving])
        values = self._evaluate()
        start = time.perf_counter()
        for g, (dofs, parts) in enumerate(self.groups):
            if active[dofs].any():
                self.log_weights[:, g] = values[:, parts].sum(axis=1)
        survival = self._survival(self.log_weights)
        self.diagnostics["survival"] = self._survival(values)
        self.diagnostics["group_survival"] = survival
        self.diagnostics["layer_survival"].append(float(survival.min()))
        self.diagnostics["betas"].append(1.0)
        self.diagnostics["ess"] = float(survival.min()) * self.num_particles
        self._timed("weight", start)

    def _estimate_all(self) -> np.ndarray:
        estimate = np.empty(self.num_dofs)
        for g, (dofs, _) in enumerate(self.groups):
            weights = normalised_weights(self.log_weights[:, g])
            estimate[dofs] = mean_pose(self.particles[:, dofs], weights, self.angular[dofs], self.limits[dofs])
        return estimate
