"""Motion model of the body's particles: Gaussian diffusion per DOF within the joint limits.

The prediction of a particle filter moves each pose by independent Gaussian noise per DOF
(standard deviations ``scales``, per frame) plus an optional deterministic ``drift`` (a
constant-velocity term for the root's position and heading, :func:`root_drift`). Limits
are kept by one of :data:`BOUNDARY_MODES`:

- ``reflect``: a value past a limit is folded back inside (mirror at the limits; several
  folds for a very large step), which keeps the density continuous at the limit;
- ``reject``: the noise of every DOF that left its range is drawn again (up to
  ``max_tries`` times; what is still outside is then reflected). Limits are a box, so this
  equals sampling each DOF from its Gaussian truncated to the range;
- ``clip``: values past a limit are set to it (mass piles up at the limits; for comparison).

Periodic DOFs (the heading) are wrapped to [-pi, pi) in every mode.

Default scales (:data:`DIFFUSION_30FPS`, by DOF kind, the defaults of
:class:`occupose.config.DiffusionConfig`) are per frame at 30 frames/s, the
typical displacement in a frame of ordinary motion (walking at 1.3 m/s moves the root
4 cm a frame; an arm swing turns the shoulder 0.05 .. 0.1 rad a frame). Being per frame
displacements of smooth motion, they scale with the frame interval (30 / fps), not its
square root.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping

import numpy as np

from occupose.body.model import TRANSLATION, BodyModel
from occupose.config import DiffusionConfig
from occupose.geometry.angles import wrap_angle

#: Diffusion standard deviation per frame at 30 frames/s by DOF kind, metres or radians.
DIFFUSION_30FPS: dict[str, float] = dataclasses.asdict(DiffusionConfig())

BOUNDARY_MODES = ("reflect", "reject", "clip")


def diffusion_scales(model: BodyModel, fps: float = 30.0, scale: float = 1.0, *,
                     per_kind: Mapping[str, float] | None = None, **overrides: float) -> np.ndarray:
    """Diffusion standard deviations per frame for ``model``'s DOFs, (D,) float64.

    fps : frame rate, frames/s (the 30 fps values are multiplied by 30 / fps)
    scale : multiplies every value
    per_kind : the values at 30 fps by DOF kind (every kind of :data:`DIFFUSION_30FPS`);
        default DIFFUSION_30FPS
    overrides : per DOF kind (``root_xy``, ``shoulder``, ... see :data:`DIFFUSION_30FPS`)
        or per DOF name (``left_elbow=0.2``), per frame at ``fps``, not scaled; names win
        over kinds.
    """
    if not isinstance(model, BodyModel):
        raise ValueError(f"model must be a BodyModel, got {type(model).__name__}")
    for name, value in (("fps", fps), ("scale", scale)):
        if not (isinstance(value, (int, float, np.integer, np.floating)) and math.isfinite(value) and value > 0):
            raise ValueError(f"{name} must be a positive number, got {value!r}")
    valid = set(DIFFUSION_30FPS) | set(model.dof_names)
    for key, value in overrides.items():
        if key not in valid:
            raise ValueError(f"unknown DOF kind or name {key!r}; valid: {', '.join(sorted(valid))}")
        if not (math.isfinite(value) and value >= 0):
            raise ValueError(f"diffusion scale {key}={value!r} must be a finite number >= 0")
    per_kind = DIFFUSION_30FPS if per_kind is None else per_kind
    if set(per_kind) != set(DIFFUSION_30FPS):
        raise ValueError(f"per_kind must give every DOF kind {sorted(DIFFUSION_30FPS)}, got {sorted(per_kind)}")
    out = np.array([per_kind[kind] for kind in model.kinds]) * scale * 30.0 / fps
    for i, (name, kind) in enumerate(zip(model.dof_names, model.kinds)):
        if name in overrides:
            out[i] = overrides[name]
        elif kind in overrides:
            out[i] = overrides[kind]
    return out


def _reflect(values: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Fold values (P, D) into [lo, hi] (D,) by mirroring at the limits."""
    width = hi - lo
    folded = np.mod(values - lo, 2.0 * width)
    return lo + np.where(folded > width, 2.0 * width - folded, folded)


def _outside(values, lo, hi, periodic):
    return ((values < lo) | (values > hi)) & ~periodic


def diffuse(poses, scales, limits, rng: np.random.Generator, *, periodic=None, mode: str = "reflect",
            drift=None, max_tries: int = 20) -> np.ndarray:
    """Predicted poses: ``poses + drift + N(0, scales^2)`` per DOF, kept within the limits.

    poses : (P, D) float, current poses (inside the limits)
    scales : (D,) float >= 0, standard deviations per frame (metres or radians)
    limits : (D, 2) float, lower and upper limit of each DOF
    rng : np.random.Generator, the only source of randomness
    periodic : (D,) bool or None, DOFs wrapped to [-pi, pi) instead of limited
    mode : one of :data:`BOUNDARY_MODES`
    drift : (D,) or (P, D) float or None, deterministic displacement added before the noise
    max_tries : redraws per DOF in ``reject`` mode
    Returns (P, D) float64, a new array.
    """
    poses = np.asarray(poses, dtype=np.float64)
    if poses.ndim != 2:
        raise ValueError(f"poses must have shape (P, D), got {poses.shape}")
    num_dofs = poses.shape[1]
    scales = np.asarray(scales, dtype=np.float64)
    limits = np.asarray(limits, dtype=np.float64)
    if scales.shape != (num_dofs,) or not np.all(np.isfinite(scales)) or np.any(scales < 0):
        raise ValueError(f"scales must be {num_dofs} finite numbers >= 0, got shape {scales.shape}")
    if limits.shape != (num_dofs, 2) or not np.all(np.isfinite(limits)) or np.any(limits[:, 0] >= limits[:, 1]):
        raise ValueError(f"limits must be a finite ({num_dofs}, 2) array with lower < upper, got shape {limits.shape}")
    periodic = np.zeros(num_dofs, bool) if periodic is None else np.asarray(periodic, dtype=bool)
    if periodic.shape != (num_dofs,):
        raise ValueError(f"periodic must have shape ({num_dofs},), got {periodic.shape}")
    if mode not in BOUNDARY_MODES:
        raise ValueError(f"unknown boundary mode {mode!r}; valid modes: {', '.join(BOUNDARY_MODES)}")
    if not isinstance(rng, np.random.Generator):
        raise ValueError(f"rng must be a numpy.random.Generator, got {type(rng).__name__}")
    mean = poses.copy()
    if drift is not None:
        drift = np.asarray(drift, dtype=np.float64)
        if drift.shape not in ((num_dofs,), poses.shape):
            raise ValueError(f"drift must have shape ({num_dofs},) or {poses.shape}, got {drift.shape}")
        mean += drift
    lo, hi = limits[:, 0], limits[:, 1]
    out = mean + rng.standard_normal(poses.shape) * scales
    if mode == "reject":
        for _ in range(max_tries):
            bad = _outside(out, lo, hi, periodic)
            if not bad.any():
                break
            rows, cols = np.nonzero(bad)
            out[rows, cols] = mean[rows, cols] + rng.standard_normal(rows.shape[0]) * scales[cols]
    if mode == "clip":
        out = np.where(periodic, out, np.clip(out, lo, hi))
    else:
        out = np.where(periodic, out, _reflect(out, lo, hi))
    out[:, periodic] = wrap_angle(out[:, periodic])
    return out


def root_drift(model: BodyModel, previous, current, damping: float = 1.0) -> np.ndarray:
    """Constant-velocity drift (D,) for :func:`diffuse`: the root's translation and turn
    (its periodic DOFs: the heading, the shorter way round) between the two last estimates
    ``previous`` and ``current`` (D,), times ``damping`` in [0, 1]; zero for every other
    DOF. The turn carries a person turning on the spot on through the half turn where
    the body, seen side-on, fits as well turning back (enter_exit_occlusion: the estimate
    fell 90 degrees behind and then turned back the other way)."""
    previous = np.asarray(previous, dtype=np.float64)
    current = np.asarray(current, dtype=np.float64)
    if previous.shape != (model.num_dofs,) or current.shape != (model.num_dofs,):
        raise ValueError(f"previous and current must be poses of shape ({model.num_dofs},), "
                         f"got {previous.shape} and {current.shape}")
    if not (math.isfinite(damping) and 0.0 <= damping <= 1.0):
        raise ValueError(f"damping must be in [0, 1], got {damping!r}")
    drift = np.zeros(model.num_dofs)
    root = model.dof_type == TRANSLATION
    drift[root] = damping * (current[root] - previous[root])
    turn = model.periodic
    drift[turn] = damping * wrap_angle(current[turn] - previous[turn])
    return drift
