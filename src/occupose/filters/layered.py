"""SIR, the annealed particle filter, partitioned sampling and their combination.

All four are one loop: for each *stage* (a set of DOFs and the parts that weight them) and
each *layer* of that stage: resample by the current weights, diffuse the stage's DOFs, weight
the particles by the stage's log-likelihood raised to an exponent beta.

======== ============================= ======================== ==========================
filter   stages                        layers per stage         beta
======== ============================= ======================== ==========================
sir      all DOFs, all parts           1                        1
apf      all DOFs, all parts           num_layers               ESS / P = survival target
ps       problem.partitions in order   1                        1
apf+ps   problem.partitions in order   num_layers (per stage)   ESS / P = survival target
======== ============================= ======================== ==========================

SIR is CONDENSATION (Isard & Blake 1998). The annealed filter follows Deutscher & Reid
("Articulated body motion capture by stochastic search", IJCV 2005): in each layer beta is
chosen so that the particle survival rate ESS / P equals a target (0.5 by default), and the
diffusion covariance of the next layer is the current one times the survival rate reached
(standard deviation times its square root). Partitioned sampling follows MacCormick & Isard
(ECCV 2000): the root partition is diffused and weighted by its own parts, resampled, then
its children, so the search of a limb starts from a good torso. ``apf+ps`` runs the
annealing layers inside each partition (the first paper's hierarchical filter, after
Bandouch et al. 2008). The final weights are the last layer's; resampling happens at the
start of the next layer or frame, so ``log_weights`` always weight ``particles``.

A stage none of whose DOFs is active in a step (``step(active=...)``: the legs hidden
behind a table, left out by the occlusion handling) gives its layers to the stages that
are, spread from the first down (:func:`spread_layers`), so every frame costs the same
likelihood evaluations: the first paper's 200 x 5 budget searches the visible body with
all of it instead of dropping the idle stage's share.
"""

from __future__ import annotations

import time
from collections.abc import Sequence

import numpy as np

from occupose.filters import _kernels
from occupose.filters.base import ParticleFilter, Problem, check_groups


def spread_layers(total: int, stages: int) -> tuple[int, ...]:
    """``total`` layers over ``stages`` stages as evenly as it goes, the first ones taking
    the remainder: spread_layers(5, 2) == (3, 2)."""
    return tuple(total // stages + (k < total % stages) for k in range(stages))


class _LayeredFilter(ParticleFilter):
    """The stage x layer loop; subclasses set the stages, the layers and whether to anneal."""

    annealed = False

    def __init__(self, problem: Problem, num_particles: int, rng: np.random.Generator, *,
                 resampling: str = "systematic", stages=None, num_layers: int | Sequence[int] = 1,
                 survival: float = 0.5):
        super().__init__(problem, num_particles, rng, resampling=resampling)
        if stages is None:
            stages = [(np.arange(self.num_dofs), np.empty(0, np.int64))]  # every DOF, every part
        self.stages = stages
        layers = np.atleast_1d(np.asarray(num_layers))
        if layers.ndim != 1 or layers.size not in (1, len(stages)) or not np.issubdtype(layers.dtype, np.integer) \
                or (layers < 1).any():
            raise ValueError(f"num_layers must be an integer >= 1 or one per stage ({len(stages)}), got {num_layers!r}")
        self.num_layers = [int(m) for m in np.broadcast_to(layers, (len(stages),))]
        if not 0.0 < survival < 1.0:
            raise ValueError(f"survival (the target particle survival rate) must be in (0, 1), got {survival!r}")
        self.survival = float(survival)

    def _layers(self, active: np.ndarray) -> list[int]:
        """Layers per stage this step: a stage with no ``active`` (D,) bool DOF (parts hidden
        by furniture, left out) gives its layers to the others, the total spread over them
        from the first down as evenly as it goes ((2, 1, 2) with the last idle: (3, 2, 0)),
        so a frame costs the same likelihood evaluations."""
        live = [k for k, (dofs, _) in enumerate(self.stages) if active[dofs].any()]
        if len(live) in (0, len(self.stages)):
            return self.num_layers
        layers = [0] * len(self.stages)
        for k, count in zip(live, spread_layers(sum(self.num_layers), len(live))):
            layers[k] = count
        return layers

    def _step(self, std: np.ndarray, active: np.ndarray) -> None:
        diagnostics = self.diagnostics
        values = None
        layers = self._layers(active)
        for (dofs, parts), num_layers in zip(self.stages, layers):
            dofs = dofs[active[dofs]]
            if dofs.size == 0:
                continue
            stage_std = std[dofs]
            for _ in range(num_layers):
                indices = self._resample(self.log_weights)
                if indices is not None:
                    self.particles = self.particles[indices]
                self._diffuse(dofs, stage_std)
                values = self._evaluate()
                start = time.perf_counter()
                _, beta, survival = _kernels.layer_weights(values, parts, self.annealed, self.survival,
                                                           self.log_weights)
                stage_std = stage_std * np.sqrt(survival)
                diagnostics["betas"].append(beta)
                diagnostics["layer_survival"].append(survival)
                self._timed("weight", start)
        if values is not None:
            diagnostics["survival"] = self._survival(values)
            diagnostics["ess"] = diagnostics["layer_survival"][-1] * self.num_particles


class SIRFilter(_LayeredFilter):
    """CONDENSATION: resample, diffuse every DOF, weight by the total log-likelihood.

    problem, num_particles, rng : see ParticleFilter
    resampling : a key of RESAMPLING (default systematic)
    """

    name = "sir"

    def __init__(self, problem: Problem, num_particles: int, rng: np.random.Generator, *,
                 resampling: str = "systematic"):
        super().__init__(problem, num_particles, rng, resampling=resampling)


class AnnealedFilter(_LayeredFilter):
    """Annealed particle filter (Deutscher & Reid): ``num_layers`` layers on every DOF.

    problem, num_particles, rng : see ParticleFilter
    num_layers : M >= 1 annealing layers per frame (P x M likelihood evaluations)
    survival : target particle survival rate ESS / P of every layer, in (0, 1)
    resampling : a key of RESAMPLING
    """

    name = "apf"
    annealed = True

    def __init__(self, problem: Problem, num_particles: int, rng: np.random.Generator, *,
                 num_layers: int = 10, survival: float = 0.5, resampling: str = "systematic"):
        super().__init__(problem, num_particles, rng, resampling=resampling, num_layers=num_layers,
                         survival=survival)


class PartitionedFilter(_LayeredFilter):
    """Partitioned sampling (MacCormick & Isard): ``problem.partitions`` one after the other.

    problem, num_particles, rng : see ParticleFilter; needs ``problem.partitions``
    resampling : a key of RESAMPLING
    Each partition costs P likelihood evaluations (its parts' columns weight it).
    """

    name = "ps"

    def __init__(self, problem: Problem, num_particles: int, rng: np.random.Generator, *,
                 resampling: str = "systematic"):
        stages = check_groups(problem.partitions, "partitions", int(problem.num_dofs))
        super().__init__(problem, num_particles, rng, resampling=resampling, stages=stages)
        self._groups.append(("partitions", stages))


class AnnealedPartitionedFilter(_LayeredFilter):
    """Annealing layers inside each partition (the first paper's hierarchical APF + PS).

    problem, num_particles, rng : see ParticleFilter; needs ``problem.partitions``
    num_layers : layers per partition, an int or one per partition (P x sum(layers) evaluations)
    survival : target particle survival rate of every layer, in (0, 1)
    resampling : a key of RESAMPLING
    """

    name = "apf+ps"
    annealed = True

    def __init__(self, problem: Problem, num_particles: int, rng: np.random.Generator, *,
                 num_layers: int | Sequence[int] = 5, survival: float = 0.5, resampling: str = "systematic"):
        stages = check_groups(problem.partitions, "partitions", int(problem.num_dofs))
        super().__init__(problem, num_particles, rng, resampling=resampling, stages=stages,
                         num_layers=num_layers, survival=survival)
        self._groups.append(("partitions", stages))
