"""One person's pose as a particle-filter problem: a body model, a likelihood and the priors.

:class:`PoseProblem` is the filter's view of one person (see
:class:`occupose.filters.base.Problem`): the model's state space and the log-likelihood of
poses under the current observation, with the prior terms (floor, reach, feet, hanging arm,
walking) added per part. :class:`occupose.pose.estimator.PoseEstimator` holds a person's
filter across frames.
"""

from __future__ import annotations

import functools

import numpy as np

from occupose.body import BodyModel, capsules_from_poses, diffusion_scales
from occupose.config import PriorConfig
from occupose.likelihood import Observation, make_likelihood, point_distances


class PoseProblem:
    """One person's pose as a particle-filter problem.

    model : the body model; likelihood : a name of occupose.likelihood.LIKELIHOODS
    diffusion : (D,) random-walk std per frame (default: the model's defaults at ``fps``)
    likelihood_options : passed to the likelihood class every frame
    stages : the partitioned-sampling order as groups of the model's partitions (indices
        into ``model.partitions``), each group sampled as one partition; default: the root,
        then head and arms, then legs (the model's own partitions when it has no legs)
    part_weights : how the part-based filter weights each of ``model.weight_groups``, a
        key of :data:`PART_WEIGHTS` (see :func:`chain_weight_groups`)
    floor : height of the floor, world metres (DESIGN: z = 0), below which a part costs
        (:func:`add_floor_term`), and above which a hip cannot be higher than its leg
        reaches, nor a head without legs higher than the stature once it is known
        (:func:`add_reach_term`, :attr:`stature_known`), nor an ankle too high
        (:func:`add_feet_term`); None for no floor
    priors : the costs and slacks of those terms and of the hanging-arm term
        (:class:`occupose.config.PriorConfig`; default its defaults)
    """

    def __init__(self, model: BodyModel, likelihood: str = "points+free", *, fps: float = 30.0,
                 diffusion: np.ndarray | None = None, likelihood_options: dict | None = None,
                 stages: list[list[int]] | None = None, part_weights: str = "chain",
                 floor: float | None = 0.0, priors: PriorConfig | None = None):
        if part_weights not in PART_WEIGHTS:
            raise ValueError(f"unknown part_weights {part_weights!r}; valid names: {', '.join(PART_WEIGHTS)}")
        if floor is not None and not np.isfinite(floor):
            raise ValueError(f"floor must be a finite height in metres or None, got {floor!r}")
        self.floor = floor
        self.priors = PriorConfig() if priors is None else priors
        self.model = model
        self.likelihood_name = likelihood
        self.likelihood_options = dict(likelihood_options or {})
        self.num_dofs = model.num_dofs
        self.limits = model.limits
        self.angular = model.angular
        self.diffusion = diffusion_scales(model, fps) if diffusion is None else np.asarray(diffusion, float)
        # Each partition is weighted by the whole model's likelihood: the other partitions'
        # DOFs are fixed while it is sampled, so this is its conditional likelihood. With
        # points assigned to their nearest part, a part's own column alone rewards a limb
        # moved into empty space (no points left to explain), which makes limbs drift.
        everything = np.arange(len(model.part_names))
        stages = default_stages(model) if stages is None else stages
        self.partitions = [type(model.partitions[0])(np.concatenate([model.partitions[i].dofs for i in group]),
                                                     everything) for group in stages]
        self.weight_groups = PART_WEIGHTS[part_weights](model)
        self.hidden_parts = np.zeros(len(model.part_names), bool)
        #: (direction, weight): the way the person walks (radians, world) and the nats that
        #: facing the opposite way costs, weight (1 - cos(heading - direction)) / 2 on the
        #: heading's part (people walk forwards); None for none. Set per frame by the tracker.
        self.walking: tuple[float, float] | None = None
        #: Whether the person stands (feet on the floor: their points say where the legs
        #: go, see :func:`occupose.pose.proposals.feet`); set per frame by the tracker.
        self.standing = False
        #: Whether ``model.dims.height`` is the person's stature measured well: only then
        #: does a model without legs cost a head above it (the reach term). True by default;
        #: the tracker clears it until it has measured the stature again over the person's
        #: first second upright (the start's may fall short of the head under a ceiling camera).
        self.stature_known = True
        #: (A,) int64: the upper arms' capsules under the hanging-arm term this frame
        #: (:func:`add_rest_term`); set per frame by PoseEstimator (:func:`unseen_arms`).
        self.resting = np.zeros(0, np.int64)
        #: The index of the model's heading DOF, or None for a model without one.
        self.heading_dof = model.dof_names.index("heading") if "heading" in model.dof_names else None
        self._heading_part = next((int(g.parts[0]) for g in model.weight_groups if self.heading_dof in g.dofs), None)
        self._likelihood = None
        self._observed = None  # the observation self._likelihood was built on

    def resize(self, model: BodyModel) -> None:
        """Go on with ``model``: the same model with other body dimensions (its DOFs,
        parts and limits must be this one's)."""
        if (model.name, model.dof_names, model.part_names) != (self.model.name, self.model.dof_names,
                                                               self.model.part_names) \
                or not np.array_equal(model.limits, self.model.limits):
            raise ValueError(f"resize needs the same model ({self.model.name!r}) with other dimensions, "
                             f"got {model.name!r}")
        self.model = model

    def set_observation(self, observation: Observation) -> None:
        """Use this frame's observation for the following likelihood calls. The likelihood
        is built once per observation (an Observation is immutable): the filter steps on one
        frame set the same one again, and building the free-space term reads its whole images."""
        if observation is not self._observed:
            self._likelihood = make_likelihood(self.likelihood_name, observation, **self.likelihood_options)
            self._observed = observation

    def log_likelihood(self, poses: np.ndarray) -> np.ndarray:
        """(P, K) per-part log-likelihoods of poses (P, D); hidden parts give 0."""
        if self._likelihood is None:
            raise ValueError("set_observation() must be called before evaluating poses")
        a, b = capsules_from_poses(self.model, poses)
        out = self._likelihood.evaluate(a, b, self.model.capsule_radii, self.model.capsule_part,
                                        len(self.model.part_names))
        priors = self.priors
        if self.floor is not None:
            add_floor_term(self.model, a, b, self.floor, out, priors.floor_slack, priors.floor_cost)
            add_reach_term(self.model, a, b, self.floor, out, priors.reach_slack, priors.reach_cost,
                           stature_known=self.stature_known)
            add_feet_term(self.model, b, self.floor, out, priors.foot_reach, priors.foot_cost)
        add_rest_term(self.model, a, b, self.resting, out, priors.rest_cost)
        if self.walking is not None and self._heading_part is not None:
            direction, weight = self.walking
            out[:, self._heading_part] -= 0.5 * weight * (1.0 - np.cos(poses[:, self.heading_dof] - direction))
        out[:, self.hidden_parts] = 0.0
        return out


def add_floor_term(model: BodyModel, a: np.ndarray, b: np.ndarray, floor: float, out: np.ndarray,
                   slack: float = PriorConfig.floor_slack, cost: float = PriorConfig.floor_cost) -> None:
    """Add the floor term to per-part log-likelihoods ``out`` (P, K), in place: each capsule
    of ``model`` (ends a, b (P, C, 3) world metres) whose surface reaches more than ``slack``
    metres below ``floor`` (metres) costs its part ``cost`` nats per metre beyond. The camera
    sees the floor, so a limb pushed through it is "hidden behind the floor" and the depth
    terms do not object (docs/notes: the floor term)."""
    lowest = np.minimum(a[..., 2] - model.capsule_radii[:, 0], b[..., 2] - model.capsule_radii[:, 1])
    sunk = np.maximum(floor - slack - lowest, 0.0)
    out -= cost * (sunk @ _part_matrix(model))


def add_feet_term(model: BodyModel, b: np.ndarray, floor: float, out: np.ndarray,
                  reach: float = PriorConfig.foot_reach, cost: float = PriorConfig.foot_cost) -> None:
    """Add the feet term to per-part log-likelihoods ``out`` (P, K), in place, from the
    capsules' ends b (P, C, 3), world metres (a shin's end b is its ankle): each shin of
    ``model`` whose ankle is more than ``reach`` metres above ``floor`` (metres) costs its
    part ``cost`` nats per metre beyond (a model without shins: nothing). People walk, stand
    and sit with their feet near the floor (docs/notes: the feet term)."""
    shins, parts = _shins(model)
    if len(shins):
        raised = np.maximum(b[:, shins, 2] - floor - reach, 0.0)
        out -= cost * (raised @ parts)


def add_rest_term(model: BodyModel, a: np.ndarray, b: np.ndarray, capsules: np.ndarray, out: np.ndarray,
                  cost: float = PriorConfig.rest_cost) -> None:
    """Add the hanging-arm term to per-part log-likelihoods ``out`` (P, K), in place: each
    capsule of ``capsules`` (upper arms, indices into the model's capsules; ends a, b
    (P, C, 3), world metres) costs its part ``cost`` * (1 + cos) / 2 nats, the cosine of
    its axis (a to b) with the vertical pointing up: 0 hanging, ``cost`` raised. An arm the
    camera does not see costs nothing in the depth terms anywhere behind the body and
    drifts there (docs/notes: the hanging-arm term)."""
    for c in capsules:
        axis = b[:, c] - a[:, c]
        up = axis[:, 2] / np.maximum(np.linalg.norm(axis, axis=1), 1e-9)
        out[:, model.capsule_part[c]] -= cost * 0.5 * (1.0 + up)


def unseen_arms(model: BodyModel, pose: np.ndarray, observation: Observation,
                min_points: int = PriorConfig.rest_points) -> np.ndarray:
    """(A,) int64: the upper-arm capsules of ``model``'s arms (upper arm and forearm) that
    fewer than ``min_points`` of ``observation``'s points are nearest to under ``pose``
    (D,); none for a model without legs or arms."""
    arms = _arms(model)
    if not len(arms):
        return np.zeros(0, np.int64)
    a, b = capsules_from_poses(model, np.asarray(pose, float)[None])
    _, nearest = point_distances(a, b, model.capsule_radii, observation)
    counts = np.bincount(model.capsule_part[nearest[0]], minlength=len(model.part_names))
    return np.array([upper for upper, parts in arms if counts[parts].sum() < min_points], np.int64)


@functools.lru_cache(maxsize=64)
def _arms(model: BodyModel) -> tuple[tuple[int, np.ndarray], ...]:
    """((the upper arm's capsule, its arm's parts (2,) int64), ...) per arm of a model with
    legs (cached); empty for a model without legs or arms."""
    names = model.part_names
    if "left_thigh" not in names or "left_upper_arm" not in names:
        return ()
    arms = []
    for side in ("left", "right"):
        parts = np.array([names.index(f"{side}_upper_arm"), names.index(f"{side}_forearm")], np.int64)
        parts.setflags(write=False)
        arms.append((int(np.flatnonzero(model.capsule_part == parts[0])[0]), parts))
    return tuple(arms)


@functools.lru_cache(maxsize=64)
def _shins(model: BodyModel) -> tuple[np.ndarray, np.ndarray]:
    """(the capsules of ``model``'s shin parts (S,) int64, their rows of :func:`_part_matrix`
    (S, K) float64), read-only (cached: the likelihood is evaluated many times a frame)."""
    shins = np.array([c for c, k in enumerate(model.capsule_part) if model.part_names[k].endswith("shin")], np.int64)
    parts = _part_matrix(model)[shins]
    for array in (shins, parts):
        array.setflags(write=False)
    return shins, parts


@functools.lru_cache(maxsize=64)
def _part_matrix(model: BodyModel) -> np.ndarray:
    """(C, K) float64: 1 where capsule c belongs to part k (sums capsules into parts)."""
    return (model.capsule_part[:, None] == np.arange(len(model.part_names))).astype(np.float64)


def add_reach_term(model: BodyModel, a: np.ndarray, b: np.ndarray, floor: float, out: np.ndarray,
                   slack: float = PriorConfig.reach_slack, cost: float = PriorConfig.reach_cost, *,
                   stature_known: bool = True) -> None:
    """Add the reach term to per-part log-likelihoods ``out`` (P, K), in place, from the
    capsule ends a, b (P, C, 3), world metres: the root's part costs ``cost`` nats per
    metre that the body reaches higher above ``floor`` than it can standing, plus
    ``slack`` metres. Feet stand on the floor: a leg hidden behind furniture holds nothing
    down (docs/notes: the reach term). With legs that is the lower hip (the thighs' top ends) above a straight
    leg's reach (thigh + shin + the shin's bottom radius); without legs (the upper body,
    seen from above) the head's top above the stature (``model.dims.height``), when
    ``stature_known`` (else, or without a head either, nothing)."""
    thighs, heads, reach, root_part = _reach(model)
    if not len(thighs) and not (stature_known and len(heads)):
        return
    if len(thighs):
        top = a[:, thighs, 2].min(axis=1)
    else:
        radii = model.capsule_radii[heads]
        top = np.maximum(a[:, heads, 2] + radii[:, 0], b[:, heads, 2] + radii[:, 1]).max(axis=1)
    out[:, root_part] -= cost * np.maximum(top - floor - reach - slack, 0.0)


@functools.lru_cache(maxsize=64)
def _reach(model: BodyModel) -> tuple[np.ndarray, np.ndarray, float, int]:
    """(the thighs' capsules, the head's capsules, how high they reach standing in metres,
    the root's part) of ``model`` (cached: the likelihood is evaluated many times a frame).
    Without legs, the reach is the head's top: the stature."""
    part = [model.part_names[k] for k in model.capsule_part]
    thighs = np.array([c for c, name in enumerate(part) if name.endswith("thigh")], np.int64)
    heads = np.array([c for c, name in enumerate(part) if name == "head"], np.int64)
    shin = next((c for c, name in enumerate(part) if name.endswith("shin")), None)
    if len(thighs) and shin is not None:
        reach = model.dims.thigh + model.dims.shin + float(model.capsule_radii[shin, 1])
    else:
        thighs, reach = thighs[:0], model.dims.height
    return thighs, heads, reach, int(model.capsule_part[np.flatnonzero(model.capsule_nodes[0] == 0)[0]])


def _moved_parts(model: BodyModel, dofs: np.ndarray) -> np.ndarray:
    """(K,) bool, the parts with a capsule end on a node that one of ``dofs`` moves (the
    DOFs' nodes and their descendants)."""
    moved = np.zeros(len(model.node_names), bool)
    moved[model.dof_node[dofs]] = True
    for j in range(len(moved)):  # parent-first order: a node moves with its parent
        if model.parents[j] >= 0 and moved[model.parents[j]]:
            moved[j] = True
    capsules = moved[model.capsule_nodes[0]] | moved[model.capsule_nodes[1]]
    return np.bincount(model.capsule_part[capsules], minlength=len(model.part_names)) > 0


def own_weight_groups(model: BodyModel) -> list:
    """The model's weight groups as they are: each group weighted by its own parts (the
    second paper's Table 1). With points given to their nearest part this rewards a part
    for leaving its points to another part: the root group of the upper model, weighted
    by the shoulders alone, drifts away from the person."""
    return list(model.weight_groups)


def chain_weight_groups(model: BodyModel) -> list:
    """The model's weight groups, each weighted by the parts its DOFs move and the own
    parts of every group that moves it (its chain to the root).

    A limb's points that it leaves go to the trunk, whose columns are then in its weight,
    so leaving costs; sibling limbs stay out of each other's weights, which is what the
    part-based filter's separate resampling and shuffling need. A group that moves the
    whole body (the root) is weighted by every part.
    """
    groups = list(model.weight_groups)
    moves = [_moved_parts(model, g.dofs) for g in groups]
    out = []
    for g, group in enumerate(groups):
        parts = moves[g].copy()
        parts[group.parts] = True
        for h, other in enumerate(groups):
            if h != g and moves[h][group.parts].all():  # h moves all of g's parts: an ancestor
                parts[other.parts] = True
        out.append(type(group)(group.dofs, np.flatnonzero(parts)))
    return out


#: How the part-based filter weights the model's weight groups, by name.
PART_WEIGHTS = {"chain": chain_weight_groups, "own": own_weight_groups}


def default_stages(model: BodyModel) -> list[list[int]]:
    """Partitioned-sampling stages: the root partition, then the head and arms together,
    then the legs together (a model without legs: root, then everything else)."""
    legs = [i for i, p in enumerate(model.partitions)
            if any("thigh" in model.part_names[k] or "shin" in model.part_names[k] for k in p.parts) and i > 0]
    rest = [i for i in range(1, len(model.partitions)) if i not in legs]
    return [group for group in ([0], rest, legs) if group]
