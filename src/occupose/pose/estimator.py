"""A particle filter on one person's pose, stepped frame by frame (:class:`PoseEstimator`)."""

from __future__ import annotations

import numpy as np

from occupose.body import root_drift
from occupose.config import ProposalConfig
from occupose.filters import apply_limits, make_filter
from occupose.likelihood import Observation
from occupose.pose.problem import PoseProblem, unseen_arms
from occupose.pose.proposals import limb_proposals, mirrored_legs


class PoseEstimator:
    """A particle filter on one person's pose, stepped frame by frame.

    filter : a name of occupose.filters.FILTERS; particles : number of particles;
    rng : np.random.Generator; velocity_damping : share of the root's last translation
    added to every particle before a step (constant-velocity prediction; 0 = none);
    proposals : share of the particles whose arm or leg tries where the points unexplained
    by the last estimate suggest, per limb (:func:`occupose.pose.proposals.limb_proposals`), and
    whose leg tries the other leg's angles for a still person with bent legs
    (:func:`occupose.pose.proposals.mirrored_legs`; 0 = none); before each step the arms with
    no points of their own under the last estimate are put under the hanging-arm term
    (:func:`occupose.pose.problem.unseen_arms` with the problem's ``priors.rest_points``,
    :attr:`PoseProblem.resting`); proposal_config : the proposals' settings
    (:class:`occupose.config.ProposalConfig`; default its defaults);
    filter_options : e.g. ``num_layers``
    """

    def __init__(self, problem: PoseProblem, filter: str, particles: int, rng: np.random.Generator,
                 velocity_damping: float = 0.8, proposals: float = 0.1, *,
                 proposal_config: ProposalConfig | None = None, **filter_options):
        if not 0.0 <= proposals < 1.0:
            raise ValueError(f"proposals (a share of the particles) must be in [0, 1), got {proposals!r}")
        self.problem = problem
        self.filter = make_filter(filter, problem, particles, rng, **filter_options)
        self.velocity_damping = velocity_damping
        self.proposals = proposals
        self.proposal_config = ProposalConfig() if proposal_config is None else proposal_config
        self._has_arms = "left_shoulder_flex" in problem.model.dof_names
        self._previous = None

    def initialise(self, pose: np.ndarray, spread: float | np.ndarray = 0.0) -> None:
        """Start from ``pose`` (D,), particles spread by ``spread`` std (scalar or (D,))."""
        self.filter.initialise(np.asarray(pose, float), spread)
        self._previous = np.asarray(pose, float).copy()

    def state(self) -> tuple[np.ndarray, ...]:
        """A copy of the filter's particles, weights and estimate and the velocity memory,
        for :meth:`restore` (a search tried and not taken)."""
        f = self.filter
        return tuple(np.array(x, copy=True) for x in (f.particles, f.log_weights, f.estimate, self._previous))

    def restore(self, state: tuple[np.ndarray, ...]) -> None:
        """Go back to a :meth:`state`."""
        f = self.filter
        f.particles, f.log_weights, f.estimate, self._previous = (np.array(x, copy=True) for x in state)

    def shift(self, offset: np.ndarray) -> None:
        """Move every particle, the estimate and the velocity memory by ``offset`` (D,), e.g.
        the root's x, y to where a person reappeared (no velocity is inferred from the jump),
        then bring them inside the limits (a heading turned by pi wraps)."""
        offset = np.asarray(offset, float)
        if offset.shape != (self.problem.num_dofs,):
            raise ValueError(f"offset must have shape ({self.problem.num_dofs},), got {offset.shape}")
        limits, angular = self.problem.limits, self.problem.angular
        self.filter.particles = apply_limits(self.filter.particles + offset, limits, angular)
        self.filter.estimate = apply_limits((self.filter.estimate + offset)[None], limits, angular)[0]
        self._previous = self.filter.estimate.copy()

    def step(self, observation: Observation, *, active: np.ndarray | None = None,
             diffusion_scale: np.ndarray | None = None) -> np.ndarray:
        """Estimate this frame's pose (D,) from ``observation``; ``active`` (D,) bool freezes
        the other DOFs, ``diffusion_scale`` (D,) widens the search per DOF."""
        if active is not None:
            active = np.asarray(active)
            if active.shape != (self.problem.num_dofs,) or active.dtype != bool:
                raise ValueError(f"active must be a ({self.problem.num_dofs},) bool array, got "
                                 f"{active.dtype} {active.shape}")
        self.problem.set_observation(observation)
        current = self.filter.estimate
        if self.velocity_damping > 0 and current is not None:
            drift = root_drift(self.problem.model, self._previous, current, self.velocity_damping)
            if active is not None:
                drift[~active] = 0.0
            self.filter.particles = self.filter.particles + drift
            self._previous = current.copy()
        if current is not None:
            self.problem.resting = unseen_arms(self.problem.model, current, observation,
                                               self.problem.priors.rest_points)
        if self.proposals > 0 and current is not None:
            self._propose(current, observation, active)
        return self.filter.step(active=active, diffusion_scale=diffusion_scale)

    def _propose(self, current: np.ndarray, observation: Observation, active: np.ndarray | None) -> None:
        """Set the DOFs of a random share of the particles to each limb proposal (models with
        arms) and to the heading of the way walked, where every DOF set is active, and, for
        a still person seated or crouching, each leg's active DOFs to the other leg's
        (:func:`mirrored_legs`)."""
        model = self.problem.model
        proposals = limb_proposals(model, current, observation, legs=self.problem.standing,
                                   floor=self.problem.floor, config=self.proposal_config) if self._has_arms else []
        if self.problem.walking is not None and self.problem.heading_dof is not None:
            proposals.append((np.array([self.problem.heading_dof]), np.array([self.problem.walking[0]])))
        proposals = [(dofs, values) for dofs, values in proposals if active is None or active[dofs].all()]
        if self.problem.standing:
            proposals += mirrored_legs(model, current, active, self.problem.floor, config=self.proposal_config)
        if not proposals:
            return
        count = int(round(self.proposals * self.filter.num_particles))
        particles = self.filter.particles.copy()
        for dofs, values in proposals:
            chosen = self.filter.rng.choice(len(particles), count, replace=False)
            particles[np.ix_(chosen, dofs)] = values
        self.filter.particles = particles
