"""Per-step overhead of each particle filter, the likelihood excluded.

Problem: 25 DOFs and 10 parts laid out like the first paper's body (torso 6 DOFs, head 3,
upper arm / thigh 3 and forearm / shin 1 each); partitions and weight groups: torso, head,
each arm, each leg (6). The likelihood is a trivial Gaussian around a fixed pose (a few
microseconds), timed by the filter and subtracted: what is left is the filter's own cost
(diffusion, annealing exponents, resampling, the estimate). Budgets of the papers: apf+ps
200 particles x 5 layers per partition, apf 200 x 10, ps 2000 particles.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from occupose.filters import make_filter

TITLE = "Particle filters: time per step without the likelihood, D=25, K=10 (ms)"

_PART_DOFS = [6, 3, 3, 1, 3, 1, 3, 1, 3, 1]  # torso, head, then upper / lower of each limb
_PARTITIONS = [[0], [1], [2, 3], [4, 5], [6, 7], [8, 9]]  # parts of each partition, in order


@dataclass(frozen=True)
class _Group:
    dofs: np.ndarray
    parts: np.ndarray


class _BodyLikeProblem:
    """25 DOFs, 10 parts, 6 partitions; log-likelihood: a Gaussian around a fixed pose per part."""

    def __init__(self):
        bounds = np.cumsum([0] + _PART_DOFS)
        self.num_dofs = int(bounds[-1])
        self.limits = np.tile([-np.pi, np.pi], (self.num_dofs, 1))
        self.limits[:3] = [[-5.0, 5.0], [-5.0, 5.0], [0.0, 2.0]]
        self.angular = np.ones(self.num_dofs, bool)
        self.angular[:3] = False
        self.diffusion = np.full(self.num_dofs, 0.05)
        self.part_of_dof = np.repeat(np.arange(len(_PART_DOFS)), _PART_DOFS)
        self.partitions = [_Group(np.flatnonzero(np.isin(self.part_of_dof, parts)), np.array(parts))
                           for parts in _PARTITIONS]
        self.weight_groups = self.partitions
        self.pose = np.zeros(self.num_dofs)
        self.pose[2] = 1.0
        self.membership = np.eye(len(_PART_DOFS))[self.part_of_dof]  # (D, K)

    def log_likelihood(self, poses: np.ndarray) -> np.ndarray:
        return -0.5 * ((poses - self.pose) / 0.1) ** 2 @ self.membership


CASES = [  # name, filter, particles, options
    ("apf+ps 200x5", "apf+ps", 200, {"num_layers": 5}),
    ("apf 200x10", "apf", 200, {"num_layers": 10}),
    ("ps 2000", "ps", 2000, {}),
    ("sir 1000", "sir", 1000, {}),
    ("part-based 200", "part-based", 200, {}),
    ("part-based 1000", "part-based", 1000, {}),
]


def run(steps: int = 100, warmup: int = 5) -> list[dict]:
    """Time each case. Returns one dict per case: filter, likelihood evaluations and calls per
    step, ms per step without the likelihood (median and min over steps) and the median ms of
    the filter's phases (diffuse, weight: exponents and estimate, resample)."""
    rows = []
    for label, name, particles, options in CASES:
        problem = _BodyLikeProblem()
        pf = make_filter(name, problem, particles, np.random.default_rng(0), **options)
        pf.initialise(problem.pose, 0.1)
        totals, phases = [], {"diffuse": [], "weight": [], "resample": []}
        for i in range(warmup + steps):
            start = time.perf_counter()
            pf.step()
            elapsed = time.perf_counter() - start
            if i >= warmup:
                seconds = pf.diagnostics["seconds"]
                totals.append(elapsed - seconds["likelihood"])
                for phase in phases:
                    phases[phase].append(seconds[phase])
        evaluations = pf.diagnostics["likelihood_evaluations"]
        rows.append({"filter": label, "evaluations": evaluations, "calls": evaluations // particles,
                     "ms_median": 1e3 * float(np.median(totals)), "ms_min": 1e3 * float(np.min(totals)),
                     **{f"ms_{phase}": 1e3 * float(np.median(v)) for phase, v in phases.items()}})
    return rows


if __name__ == "__main__":
    from benchmarks import print_table

    print_table(TITLE, run())
