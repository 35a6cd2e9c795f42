"""A person's body widths (shoulders, hips) fitted to their first frames of tracking.

:func:`occupose.body.size.dims_from_observation` measures a person's stature and girth on
their first frames; the segment lengths are then the average adult's proportions scaled to
that stature. People differ from the average: the mocap subject of the shared clips has
shoulders 0.6 and hips 0.71 times as wide as the average at their stature (and a spine 0.78
times as long).

:func:`fit_proportions` adjusts the widths, in groups (:data:`GROUPS`), to frames in which
the person was tracked with every part in view: a coordinate search on the frames' summed
likelihood (the tracker's own, with the floor term). Each group in turn tries its size
times each of :data:`STEPS`, each frame's pose re-fitted to keep the estimated joints
(:func:`occupose.body.pose_from_joints`, analytic), and the best is kept; :data:`SWEEPS`
rounds; sizes stay within :data:`RANGE` times the average at the person's stature. A fit
of 10 frames takes about 0.1 to 0.3 s. The tracker runs it when ``Method.proportions`` is
set (off by default; measured there).

Measured on synthetic bodies (``tests/test_proportions.py``): from poses fitted to the true
joints, shoulders 0.7 of the average are found at 0.77 after three fits, and an average body
stays average; wider than average shoulders and narrower hips were not found (1.0 for 1.2
and 0.8). Tried and left out: lengths along the body, with the poses' angles kept instead
of their joints. The legs came out about 10 % long (our model has no feet, and the points of
the feet pull the shins down); the spine and arms were found from true poses (spine 0.81
for 0.78) but drifted by 10 to 25 % on the tracker's own estimates of average bodies; and
the widths stayed where they started, because the estimated angles had already made up
for the wrong widths (arms turned in to reach the points). With the joints kept, the
spine did not move from the average even for the mocap subject.
"""

from __future__ import annotations

from dataclasses import replace
from typing import NamedTuple

import numpy as np

from occupose.body import BodyModel, body_model, capsules_from_poses, joints_from_poses, pose_from_joints
from occupose.likelihood import Observation, make_likelihood
from occupose.pose import add_floor_term
from occupose.synth.motion import DEFAULT_DIMS, BodyDims

#: Groups of BodyDims fields scaled together.
GROUPS: dict[str, tuple[str, ...]] = {
    "shoulders": ("shoulder_width", "shoulder_drop"),
    "pelvis": ("pelvis_width",),
}
#: The groups each built-in model has (the upper body has no hips).
MODEL_GROUPS: dict[str, tuple[str, ...]] = {
    "full": ("shoulders", "pelvis"),
    "upper": ("shoulders",),
}
#: Factors a group's size is tried at in each sweep.
STEPS = (0.9, 0.95, 1.0, 1.05, 1.1)
#: Coordinate-search rounds over all groups.
SWEEPS = 3
#: A group's size stays within these factors of the average at the person's stature.
RANGE = (0.6, 1.6)


class FittedProportions(NamedTuple):
    """dims : the fitted body dimensions; pose : (D,) the last frame's pose for them (its
    joints kept); gain : nats the fit added to the frames' summed log-likelihood."""

    dims: BodyDims
    pose: np.ndarray
    gain: float


def fit_proportions(model: BodyModel, poses, observations, *, likelihood: str = "points+free",
                    floor: float | None = 0.0) -> FittedProportions:
    """Fit the widths of ``model`` (:data:`MODEL_GROUPS`) to frames of one person.

    model : the person's current model (its dims are the start, its girth is kept)
    poses : (K, D) the estimated poses of K frames with every part in view
    observations : K Observations of those frames (the person's points and views)
    likelihood : the likelihood the person is tracked with; floor : the floor's height,
        metres (None: no floor term)
    """
    poses = np.asarray(poses, np.float64)
    observations = list(observations)
    if poses.ndim != 2 or poses.shape[1] != model.num_dofs or poses.shape[0] < 1:
        raise ValueError(f"poses must have shape (K, {model.num_dofs}) with K >= 1, got {poses.shape}")
    if len(observations) != len(poses) or not all(isinstance(o, Observation) for o in observations):
        raise ValueError(f"observations must be {len(poses)} Observations, one per pose")
    if model.name not in MODEL_GROUPS:
        raise ValueError(f"no proportion groups for model {model.name!r}; valid names: {', '.join(MODEL_GROUPS)}")
    terms = [make_likelihood(likelihood, o) for o in observations]
    joints = joints_from_poses(model, poses)
    average = DEFAULT_DIMS.scaled(model.dims.height)

    def refitted(dims: BodyDims) -> tuple[BodyModel, np.ndarray]:
        """The model of ``dims`` and the frames' poses (K, D) that keep their joints."""
        candidate = body_model(model.name, dims, model.girth)
        return candidate, np.array([pose_from_joints(candidate, j, refine=False) for j in joints])

    def scores(candidates: list[BodyDims]) -> np.ndarray:
        """(len(candidates),) the frames' summed log-likelihoods for each candidate."""
        ends = [capsules_from_poses(*refitted(dims)) for dims in candidates]
        out = np.zeros(len(candidates))
        for k, term in enumerate(terms):
            a = np.stack([e[0][k] for e in ends])
            b = np.stack([e[1][k] for e in ends])
            values = term.evaluate(a, b, model.capsule_radii, model.capsule_part, model.num_parts)
            if floor is not None:
                add_floor_term(model, a, b, floor, values)
            out += values.sum(axis=1)
        return out

    dims = model.dims
    start = best = scores([dims])[0]
    for _ in range(SWEEPS):
        for group in MODEL_GROUPS[model.name]:
            candidates = [_scaled(dims, average, GROUPS[group], factor) for factor in STEPS]
            values = scores(candidates)
            dims, best = candidates[int(np.argmax(values))], float(np.max(values))
    return FittedProportions(dims, refitted(dims)[1][-1], best - start)


def _scaled(dims: BodyDims, average: BodyDims, names: tuple[str, ...], factor: float) -> BodyDims:
    """``dims`` with the fields ``names`` times ``factor``, each kept within RANGE of ``average``."""
    return replace(dims, **{n: float(np.clip(getattr(dims, n) * factor, RANGE[0] * getattr(average, n),
                                             RANGE[1] * getattr(average, n))) for n in names})
