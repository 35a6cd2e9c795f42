"""What every filter shares: the problem it runs on, joint limits, diffusion, the weighted mean pose.

A filter knows nothing about bodies. It sees a ``problem`` (see :class:`Problem`): the number
of DOFs, their limits, which are angles, the diffusion per frame, the partitions and weight
groups of DOFs, and ``log_likelihood(poses) -> (P, K)`` per-part log-likelihoods of the
current observation. A 1-D toy problem works as well as a 25-DOF body.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from typing import Protocol

import numpy as np

from occupose.filters import _kernels
from occupose.filters.resampling import RESAMPLING, check_scheme, normalised_weights

TWO_PI = 2.0 * np.pi


class Group(Protocol):
    """A set of DOFs and the parts whose likelihood weights them (``occupose.body.Partition``)."""

    dofs: np.ndarray  # (d,) int, indices into the pose vector
    parts: np.ndarray  # (k,) int, columns of the (P, K) log-likelihood


class Problem(Protocol):
    """What a filter needs to know about the state space and the current observation.

    num_dofs : D
    limits : (D, 2) float64 lower and upper bound per DOF (radians or metres; +-inf = none)
    angular : (D,) bool, True for angles (averaged on the circle; wrapped when the
        limits span a full turn, reflected otherwise)
    diffusion : (D,) float64 standard deviation of the random walk per frame (read every step)
    partitions : Groups in partitioned-sampling order, every DOF in exactly one (ps, apf+ps)
    weight_groups : Groups, one per weighting part, every DOF in exactly one (part-based)
    log_likelihood(poses (P, D)) -> (P, K) float64 per-part log-likelihoods of the current
        observation (the sum over parts is a pose's total; hidden parts should give 0)
    """

    num_dofs: int
    limits: np.ndarray
    angular: np.ndarray
    diffusion: np.ndarray
    partitions: Sequence[Group]
    weight_groups: Sequence[Group]

    def log_likelihood(self, poses: np.ndarray) -> np.ndarray: ...


def limit_modes(limits: np.ndarray, angular: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """How each DOF is kept inside its limits.

    limits : (d, 2) float64 lower, upper (+-inf = unbounded on that side); angular : (d,) bool
    Returns mode (d,) int64 (_kernels.FREE, REFLECT, WRAP, LOWER or UPPER), lower (d,) and
    upper (d,) float64. An angle whose limits span a full turn or more (or are open) wraps
    into [lower, lower + 2 pi) (into [-pi, pi) without a lower bound); any other bounded
    side reflects.
    """
    lo, hi = limits[:, 0], limits[:, 1]
    with np.errstate(invalid="ignore"):
        wrap = angular & ~(hi - lo < TWO_PI - 1e-9)
    mode = np.full(lo.size, _kernels.FREE, dtype=np.int64)
    mode[np.isfinite(lo) & np.isfinite(hi)] = _kernels.REFLECT
    mode[np.isfinite(lo) & ~np.isfinite(hi)] = _kernels.LOWER
    mode[~np.isfinite(lo) & np.isfinite(hi)] = _kernels.UPPER
    mode[wrap] = _kernels.WRAP
    lower = np.where(wrap & ~np.isfinite(lo), -np.pi, lo).astype(np.float64)
    return mode, lower, np.asarray(hi, dtype=np.float64).copy()


def apply_limits(values: np.ndarray, limits: np.ndarray, angular: np.ndarray) -> np.ndarray:
    """Values brought inside their limits: reflected at the bounds, wrapped for full-turn angles.

    values : (P, d) float64, one column per DOF
    limits : (d, 2) float64 lower, upper (+-inf = unbounded on that side)
    angular : (d,) bool (see limit_modes for which angles wrap)
    Returns (P, d) float64, a new array.
    """
    out = np.array(values, dtype=np.float64, copy=True)
    mode, lo, hi = limit_modes(np.asarray(limits, dtype=np.float64), np.asarray(angular, dtype=bool))
    wrap = mode == _kernels.WRAP
    out[:, wrap] = lo[wrap] + np.mod(out[:, wrap] - lo[wrap], TWO_PI)
    both = mode == _kernels.REFLECT
    width = hi[both] - lo[both]
    period = np.where(width > 0, 2.0 * width, 1.0)
    t = np.mod(out[:, both] - lo[both], period)
    out[:, both] = lo[both] + np.where(width > 0, np.where(t > width, period - t, t), 0.0)
    low = mode == _kernels.LOWER
    out[:, low] = lo[low] + np.abs(out[:, low] - lo[low])
    high = mode == _kernels.UPPER
    out[:, high] = hi[high] - np.abs(hi[high] - out[:, high])
    return out


def mean_pose(poses: np.ndarray, weights: np.ndarray, angular: np.ndarray,
              limits: np.ndarray | None = None) -> np.ndarray:
    """Weighted mean of poses, angles averaged on the circle.

    poses : (P, D) float64; weights : (P,) float64 non-negative, summing to 1
    angular : (D,) bool, True for angles in radians: mean = atan2(sum w sin, sum w cos)
    limits : optional (D, 2); an angle's mean is given in the turn centred on its limits'
        middle (in (-pi, pi] when unbounded), so it lies in range whenever it can
    Returns (D,) float64.
    """
    mean = weights @ poses
    if angular.any():
        angles = poses[:, angular]
        circular = np.arctan2(weights @ np.sin(angles), weights @ np.cos(angles))
        if limits is not None:
            middle = limits[angular].mean(axis=1)
            middle = np.where(np.isfinite(middle), middle, 0.0)
            circular = middle + np.mod(circular - middle + np.pi, TWO_PI) - np.pi
        mean[angular] = circular
    return mean


def check_groups(groups, name: str, num_dofs: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """(dofs, parts) int arrays of each group; every DOF must be in exactly one group."""
    if groups is None or len(groups) == 0:
        raise ValueError(f"problem.{name} must list at least one group of DOFs, got {groups!r}")
    out = []
    for group in groups:
        dofs = np.asarray(group.dofs, dtype=np.int64).reshape(-1)
        parts = np.asarray(group.parts, dtype=np.int64).reshape(-1)
        if dofs.size == 0 or parts.size == 0:
            raise ValueError(f"every entry of problem.{name} needs DOFs and parts, got dofs={dofs}, parts={parts}")
        if (parts < 0).any():
            raise ValueError(f"problem.{name} has a negative part index: {parts}")
        out.append((dofs, parts))
    every = np.concatenate([dofs for dofs, _ in out])
    if not np.array_equal(np.sort(every), np.arange(num_dofs)):
        raise ValueError(f"problem.{name} must hold every DOF 0..{num_dofs - 1} exactly once, "
                         f"got {sorted(every.tolist())}")
    return out


class ParticleFilter:
    """State shared by the filters: particles, log-weights, the last estimate, diagnostics.

    problem : see :class:`Problem`
    num_particles : P >= 1
    rng : np.random.Generator (the same seed gives the same run)
    resampling : a key of occupose.filters.resampling.RESAMPLING

    After ``initialise`` and each ``step``: ``particles`` (P, D), ``log_weights`` (P,),
    ``estimate`` (D,) and ``diagnostics`` (dict; see ``step``).
    """

    name = "base"

    def __init__(self, problem: Problem, num_particles: int, rng: np.random.Generator, *,
                 resampling: str = "systematic"):
        if not isinstance(rng, np.random.Generator):
            raise ValueError(f"rng must be a np.random.Generator, got {type(rng).__name__}")
        if int(num_particles) != num_particles or num_particles < 1:
            raise ValueError(f"num_particles must be a positive integer, got {num_particles!r}")
        self.problem = problem
        self.num_particles = int(num_particles)
        self.rng = rng
        self.resampling = check_scheme(resampling)
        d = int(problem.num_dofs)
        if d < 1:
            raise ValueError(f"problem.num_dofs must be >= 1, got {problem.num_dofs!r}")
        self.num_dofs = d
        self.limits = np.asarray(problem.limits, dtype=np.float64)
        if self.limits.shape != (d, 2) or np.isnan(self.limits).any() or (self.limits[:, 0] > self.limits[:, 1]).any():
            raise ValueError(f"problem.limits must be ({d}, 2) with lower <= upper, got {np.asarray(problem.limits)!r}")
        self.angular = np.asarray(problem.angular, dtype=bool).reshape(-1)
        if self.angular.shape != (d,):
            raise ValueError(f"problem.angular must be ({d},) bool, got shape {self.angular.shape}")
        self._diffusion()  # checked now, read again every step
        self._mode, self._lower, self._upper = limit_modes(self.limits, self.angular)
        self.particles: np.ndarray | None = None
        self.log_weights: np.ndarray | None = None
        self.estimate: np.ndarray | None = None
        self.diagnostics: dict = {}
        self._num_parts: int | None = None
        self._groups: list[tuple[str, list[tuple[np.ndarray, np.ndarray]]]] = []  # checked once K is known

    # -- set-up ---------------------------------------------------------------------------
    def initialise(self, pose, spread) -> None:
        """Particles drawn around a pose, equally weighted.

        pose : (D,) float64 the starting pose (brought inside the limits)
        spread : (D,) float64 >= 0 standard deviation of the Gaussian around it (or a scalar)
        """
        pose = np.asarray(pose, dtype=np.float64).reshape(-1)
        spread = np.asarray(spread, dtype=np.float64)
        if spread.ndim == 0:
            spread = np.full(self.num_dofs, float(spread))
        if pose.shape != (self.num_dofs,) or not np.isfinite(pose).all():
            raise ValueError(f"pose must be ({self.num_dofs},) finite, got shape {pose.shape}")
        if spread.shape != (self.num_dofs,) or not (np.isfinite(spread).all() and (spread >= 0).all()):
            raise ValueError(f"spread must be ({self.num_dofs},) finite and >= 0, got {spread!r}")
        noise = self.rng.standard_normal((self.num_particles, self.num_dofs)) * spread
        self.particles = np.ascontiguousarray(apply_limits(pose + noise, self.limits, self.angular))
        self.log_weights = self._initial_log_weights()
        self.estimate = apply_limits(pose[None], self.limits, self.angular)[0]
        self.diagnostics = {}

    def _initial_log_weights(self) -> np.ndarray:
        return np.zeros(self.num_particles)

    # -- one frame --------------------------------------------------------------------------
    def step(self, *, diffusion_scale=None, active=None) -> np.ndarray:
        """Advance one frame on the problem's current observation; returns the estimate (D,).

        diffusion_scale : scalar or (D,) float64 >= 0 multiplier of ``problem.diffusion`` for
            this step (e.g. > 1 to widen the search for a part that reappears); default 1
        active : (D,) bool, the DOFs to estimate; inactive DOFs are frozen at the last
            estimate in every particle (neither diffused nor estimated); default all

        Afterwards ``diagnostics`` holds: ``ess`` (float, of the final weights; part-based:
        the smallest over groups), ``survival`` (K,) ESS / P of each part's own
        log-likelihood at the step's last evaluation, ``betas`` and ``layer_survival``
        (per layer, in order), ``likelihood_evaluations`` (particles x calls) and
        ``seconds`` (dict: diffuse, likelihood, weight, resample).
        """
        if self.particles is None:
            raise RuntimeError("call initialise(pose, spread) before step()")
        std = self._diffusion()
        if diffusion_scale is not None:
            scale = np.asarray(diffusion_scale, dtype=np.float64)
            if scale.ndim == 0:
                scale = np.full(self.num_dofs, float(scale))
            if scale.shape != (self.num_dofs,) or not (np.isfinite(scale).all() and (scale >= 0).all()):
                raise ValueError(f"diffusion_scale must be a scalar or ({self.num_dofs},) finite and >= 0, "
                                 f"got {diffusion_scale!r}")
            std = std * scale
        if active is None:
            active = np.ones(self.num_dofs, bool)
        else:
            active = np.asarray(active)
            if active.shape != (self.num_dofs,) or active.dtype != bool:
                raise ValueError(f"active must be a ({self.num_dofs},) bool array, got {active.dtype} {active.shape}")
        self.particles[:, ~active] = self.estimate[~active]
        self.diagnostics = {"ess": float(self.num_particles), "survival": None, "betas": [], "layer_survival": [],
                            "likelihood_evaluations": 0,
                            "seconds": {"diffuse": 0.0, "likelihood": 0.0, "weight": 0.0, "resample": 0.0}}
        self._step(std, active)
        start = time.perf_counter()
        estimate = self._estimate_all()
        self.estimate = np.where(active, estimate, self.estimate)
        self._timed("weight", start)
        return self.estimate.copy()

    def _step(self, std: np.ndarray, active: np.ndarray) -> None:
        raise NotImplementedError

    def _estimate_all(self) -> np.ndarray:
        return mean_pose(self.particles, normalised_weights(self.log_weights), self.angular, self.limits)

    # -- the phases -----------------------------------------------------------------------------
    def _diffusion(self) -> np.ndarray:
        std = np.asarray(self.problem.diffusion, dtype=np.float64).reshape(-1)
        if std.shape != (self.num_dofs,) or not (np.isfinite(std).all() and (std >= 0).all()):
            raise ValueError(f"problem.diffusion must be ({self.num_dofs},) finite and >= 0, got {std!r}")
        return std

    def _timed(self, phase: str, start: float) -> None:
        self.diagnostics["seconds"][phase] += time.perf_counter() - start

    def _diffuse(self, dofs: np.ndarray, std: np.ndarray) -> None:
        """Gaussian random walk on the columns ``dofs`` with standard deviations ``std`` (d,), then limits."""
        start = time.perf_counter()
        noise = self.rng.standard_normal((self.num_particles, dofs.size))
        _kernels.diffuse_within_limits(self.particles, dofs, noise, std, self._lower, self._upper, self._mode)
        self._timed("diffuse", start)

    def _evaluate(self) -> np.ndarray:
        """(P, K) per-part log-likelihoods of the current particles, checked."""
        start = time.perf_counter()
        values = np.asarray(self.problem.log_likelihood(self.particles), dtype=np.float64)
        self._timed("likelihood", start)
        p = self.num_particles
        if values.ndim != 2 or values.shape[0] != p or values.shape[1] < 1:
            raise ValueError(f"problem.log_likelihood must return ({p}, K) per-part values, got shape {values.shape}")
        if self._num_parts is None:
            for name, groups in self._groups:
                top = max(parts.max() for _, parts in groups)
                if top >= values.shape[1]:
                    raise ValueError(f"problem.{name} names part {top} but log_likelihood gives "
                                     f"{values.shape[1]} parts")
            self._num_parts = values.shape[1]
        elif values.shape[1] != self._num_parts:
            raise ValueError(f"problem.log_likelihood returned {values.shape[1]} parts, earlier {self._num_parts}")
        if not values.max() < np.inf:  # NaN anywhere propagates to the maximum
            raise ValueError("problem.log_likelihood returned NaN or +inf")
        self.diagnostics["likelihood_evaluations"] += p
        return values

    def _resample(self, log_weights: np.ndarray) -> np.ndarray | None:
        """Ancestor indices (P,) from checked log-weights; None for equal weights (nothing to do)."""
        start = time.perf_counter()
        indices = None
        if log_weights.max() != log_weights.min():
            indices = RESAMPLING[self.resampling](log_weights, self.num_particles, self.rng)
        self._timed("resample", start)
        return indices

    def _survival(self, values: np.ndarray) -> np.ndarray:
        """(K,) ESS / P of each column of a (P, K) log-likelihood."""
        top = values.max(axis=0)
        weights = np.exp(values - np.where(np.isfinite(top), top, 0.0))
        total = weights.sum(axis=0)
        with np.errstate(invalid="ignore", divide="ignore"):
            rate = total ** 2 / (weights ** 2).sum(axis=0) / self.num_particles
        return np.where(total > 0, rate, 1.0)

