"""Depth-sensor noise models applied to ideal rendered depth images.

Every model takes a depth image ``(H, W)`` of camera z in metres (0 = no measurement) and
returns a new float32 image of the same shape where 0 still means "no measurement":
pixels that were 0 stay 0, and a model may add invalid pixels of its own.

- ``"none"``: the ideal sensor (a float32 copy).
- ``"structured_light"`` (Kinect v1): Gaussian noise on the raw disparity, rounded to whole
  raw disparity units, so depth is quantised in steps of about 0.00307 z^2 m; projector
  shadows beside depth edges; random dropouts; a working range.
- ``"tof"`` (time of flight, Kinect v2 / Azure Kinect): Gaussian depth noise, flying pixels
  at depth edges, random dropouts, a working range.

The random depth error of each model (one standard deviation at a distance) is
:func:`occupose.sensors.depth_std`, the figure the occupancy grid uses as its tolerance.
"""

from __future__ import annotations

import inspect
import math
from typing import Callable

import numpy as np

from occupose.sensors import depth_std_coefficients
from occupose.synth import _kernels

#: Kinect v1 raw disparity to depth: 1 / z = OFFSET - STEP * raw (z in metres). The
#: widely used fit of the OpenKinect / ROS drivers; one raw unit is about 1/8 pixel.
KINECT_V1_INVERSE_DEPTH_OFFSET = 3.3309495161
KINECT_V1_INVERSE_DEPTH_STEP = 0.0030711016


def _check_depth(depth) -> np.ndarray:
    array = np.asarray(depth)
    if array.ndim != 2 or array.dtype.kind not in "fiu":
        raise ValueError(f"depth must be a 2-D array of metres, got shape {array.shape} dtype {array.dtype}")
    array = np.ascontiguousarray(array, dtype=np.float64)
    if not np.all(np.isfinite(array)) or np.any(array < 0.0):
        raise ValueError("depth must be finite and >= 0 (0 = no measurement)")
    return array


def _check_rng(rng) -> None:
    if not isinstance(rng, np.random.Generator):
        raise ValueError(f"rng must be a numpy.random.Generator, got {type(rng).__name__}")


def _check_rate(value: float, what: str) -> float:
    if not 0.0 <= value <= 1.0:
        raise ValueError(f"{what} must be in [0, 1], got {value!r}")
    return float(value)


def _check_range(min_range: float, max_range: float) -> None:
    if not 0.0 <= min_range < max_range:
        raise ValueError(f"need 0 <= min_range < max_range, got {min_range!r}, {max_range!r}")


def _drop(depth: np.ndarray, rng: np.random.Generator, rate: float) -> np.ndarray:
    """Zero each pixel with probability ``rate`` (in place; returns ``depth``)."""
    count = rng.binomial(depth.size, rate)
    depth.reshape(-1)[rng.choice(depth.size, size=count, replace=False)] = 0.0
    return depth


def no_noise(depth, rng: np.random.Generator) -> np.ndarray:
    """The ideal sensor: a float32 copy of ``depth`` (H, W), metres (``rng`` is not used)."""
    _check_rng(rng)
    return _check_depth(depth).astype(np.float32)


def structured_light_noise(depth, rng: np.random.Generator, *, fx: float | None = None,
                           baseline: float = 0.075, shadows: bool = True, dropout: float = 0.005,
                           min_range: float = 0.5, max_range: float = 5.0) -> np.ndarray:
    """Kinect v1 style depth: disparity noise and quantisation, projector shadows, dropouts.

    depth : (H, W) float, metres, 0 = no measurement
    rng : np.random.Generator
    fx : float, pixels; required when ``shadows`` is on
    baseline : float, metres, the projector's offset along the camera's x axis (positive:
        to the image's right, as on a Kinect v1, which puts the shadows on the left of
        foreground objects; negative: the other side)
    shadows : bool, blank the pixels the projector cannot light
    dropout : float in [0, 1], share of pixels randomly lost
    min_range, max_range : float, metres; true depths outside are not measured
        (Kinect v1 returns depth from about 0.5 to 5 m; its nominal range is 0.8-4 m)

    Shadows: a surface point is lit when no nearer point of the same image row lies on its
    projector ray, i.e. while its projector coordinate ``u - fx * baseline / z`` keeps the
    camera's order; the band beside a depth edge is about ``fx * |baseline| * (1 / z_near -
    1 / z_far)`` pixels wide. Noise: depth becomes the raw disparity ``(OFFSET - 1/z) /
    STEP`` (one unit is about 1/8 pixel), gets Gaussian noise, is rounded to a whole unit
    and turned back into depth, so depth is quantised in steps of ``STEP * z^2`` (about
    0.00307 z^2 m); the Gaussian part is chosen so that noise and rounding together have
    the standard deviation ``occupose.sensors.depth_std(z, "structured_light")``. Returns (H, W) float32.
    """
    z = _check_depth(depth)
    _check_rng(rng)
    dropout = _check_rate(dropout, "dropout")
    _check_range(min_range, max_range)
    if shadows and (fx is None or not fx > 0):
        raise ValueError(f"structured_light noise needs fx > 0 (pixels) to place the projector shadows, got {fx!r}")
    out = np.empty(z.shape, np.float32)
    _kernels.structured_light_pixels(
        z, rng, float(fx or 0.0) * float(baseline), bool(shadows), float(min_range), float(max_range),
        depth_std_coefficients("structured_light"), KINECT_V1_INVERSE_DEPTH_OFFSET, KINECT_V1_INVERSE_DEPTH_STEP, out,
    )
    return _drop(out, rng, dropout)


def tof_noise(depth, rng: np.random.Generator, *, flying_fraction: float = 0.5, edge_jump: float = 0.05,
              dropout: float = 0.002, min_range: float = 0.5, max_range: float = 4.5,
              std_scale: float = 1.0) -> np.ndarray:
    """Time-of-flight depth: Gaussian noise, flying pixels at depth edges, dropouts.

    depth : (H, W) float, metres, 0 = no measurement
    rng : np.random.Generator
    flying_fraction : float in [0, 1], share of edge pixels that become flying pixels
    edge_jump : float, metres; a pixel is on a depth edge when one of its 4 neighbours
        (with a measurement) differs from it by more than this
    dropout : float in [0, 1], share of pixels randomly lost
    min_range, max_range : float, metres; true depths outside are not measured
        (defaults: Kinect v2, 0.5-4.5 m; the Azure Kinect NFOV unbinned mode is 0.5-3.86 m)
    std_scale : float > 0, the random depth error as a multiple of the nominal one (real
        ToF cameras on dark or slanted surfaces are several times noisier)

    A flying pixel mixes the two surfaces its footprint straddles: its depth moves a
    uniform random share of the way towards the neighbour most different from it. Every
    measured pixel then gets Gaussian noise of ``std_scale * occupose.sensors.depth_std(z, "tof")``.
    Returns (H, W) float32.
    """
    z = _check_depth(depth)
    _check_rng(rng)
    flying_fraction = _check_rate(flying_fraction, "flying_fraction")
    dropout = _check_rate(dropout, "dropout")
    _check_range(min_range, max_range)
    if not edge_jump > 0:
        raise ValueError(f"edge_jump must be > 0 metres, got {edge_jump!r}")
    if not (math.isfinite(std_scale) and std_scale > 0):
        raise ValueError(f"std_scale must be a finite number > 0, got {std_scale!r}")
    out = np.empty(z.shape, np.float32)
    _kernels.tof_pixels(z, rng, flying_fraction, float(edge_jump), float(min_range), float(max_range),
                        float(std_scale) * depth_std_coefficients("tof"), out)
    return _drop(out, rng, dropout)


#: Noise models by name: each is ``f(depth, rng, **options) -> depth``.
NOISE_MODELS: dict[str, Callable[..., np.ndarray]] = {
    "none": no_noise, "structured_light": structured_light_noise, "tof": tof_noise,
}


def apply_noise(depth, model: str, rng: np.random.Generator, *, fx: float | None = None,
                **options) -> np.ndarray:
    """Apply the noise model registered as ``model`` to a depth image.

    depth : (H, W) float, metres, 0 = no measurement
    model : a key of NOISE_MODELS
    rng : np.random.Generator (the same seed gives the same image)
    fx : float, focal length in pixels, passed to the models that use it (structured light)
    options : the model's own keyword options (see its function)

    Returns (H, W) float32 metres, 0 = no measurement.
    """
    if model not in NOISE_MODELS:
        raise ValueError(f"unknown noise model {model!r}; valid names: {sorted(NOISE_MODELS)}")
    function = NOISE_MODELS[model]
    accepted = [name for name, p in inspect.signature(function).parameters.items()
                if p.kind is inspect.Parameter.KEYWORD_ONLY]
    unknown = sorted(set(options) - set(accepted))
    if unknown:
        raise ValueError(f"noise model {model!r} has no option(s) {unknown}; its options: {accepted}")
    if "fx" in accepted:
        options["fx"] = fx
    return function(depth, rng, **options)
