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

:func:`depth_std` gives each model's random depth error (one standard deviation) at a
distance, the figure the occupancy grid uses as its measurement tolerance.
"""

from __future__ import annotations

import inspect
from typing import Callable

import numpy as np

#: Kinect v1 raw disparity to depth: 1 / z = OFFSET - STEP * raw (z in metres). The
#: widely used fit of the OpenKinect / ROS drivers; one raw unit is about 1/8 pixel.
KINECT_V1_INVERSE_DEPTH_OFFSET = 3.3309495161
KINECT_V1_INVERSE_DEPTH_STEP = 0.0030711016


def _std_structured_light(z):
    """Nguyen, Izadi & Lovell (2012), Kinect v1 axial noise at moderate surface angles."""
    return 0.0012 + 0.0019 * (z - 0.4) ** 2


def _std_tof(z):
    """Fankhauser et al. (2015), Kinect v2 axial noise at normal incidence (mm -> m).

    Below 5.3 mm over 0.5-4.5 m, within the Azure Kinect's specified random error
    (standard deviation <= 17 mm over its 0.5-3.86 m range).
    """
    return 1e-3 * (1.5 - 0.5 * z + 0.3 * z**2)


def _std_none(z):
    return np.zeros_like(z)


_DEPTH_STD: dict[str, Callable] = {
    "none": _std_none, "structured_light": _std_structured_light, "tof": _std_tof,
}


def depth_std(z, model: str):
    """Random depth error (one standard deviation, metres) of ``model`` at depth ``z``.

    z : float or (...) array, metres. Returns a float for a scalar ``z``, else an array
    of the same shape (float64). For ``"structured_light"`` it includes the disparity
    quantisation; the systematic (bias) errors of real sensors are not modelled.
    """
    if model not in _DEPTH_STD:
        raise ValueError(f"unknown noise model {model!r}; valid names: {sorted(_DEPTH_STD)}")
    values = np.asarray(z, dtype=np.float64)
    std = _DEPTH_STD[model](values)
    return float(std) if std.ndim == 0 else std


def _check_depth(depth) -> np.ndarray:
    array = np.asarray(depth)
    if array.ndim != 2 or array.dtype.kind not in "fiu":
        raise ValueError(f"depth must be a 2-D array of metres, got shape {array.shape} dtype {array.dtype}")
    array = array.astype(np.float64)
    if not np.all(np.isfinite(array)) or np.any(array < 0.0):
        raise ValueError("depth must be finite and >= 0 (0 = no measurement)")
    return array


def _check_rate(value: float, what: str) -> float:
    if not 0.0 <= value <= 1.0:
        raise ValueError(f"{what} must be in [0, 1], got {value!r}")
    return float(value)


def _in_range(z: np.ndarray, min_range: float, max_range: float) -> np.ndarray:
    if not 0.0 <= min_range < max_range:
        raise ValueError(f"need 0 <= min_range < max_range, got {min_range!r}, {max_range!r}")
    return (z >= min_range) & (z <= max_range)


def no_noise(depth, rng: np.random.Generator) -> np.ndarray:
    """The ideal sensor: a float32 copy of ``depth`` (H, W), metres."""
    return _check_depth(depth).astype(np.float32)


def projector_shadows(depth, fx: float, baseline: float = 0.075) -> np.ndarray:
    """Pixels that a structured-light projector beside the camera cannot light.

    depth : (H, W) float, metres, 0 = no surface
    fx : float, focal length in pixels
    baseline : float, metres, the projector's offset along the camera's x axis (positive:
        to the image's right, as on a Kinect v1, which puts the shadows on the left of
        foreground objects; negative: the other side)

    Returns a (H, W) bool mask. A surface point is lit when no nearer surface point of the
    same image row lies on its projector ray, i.e. while its projector coordinate
    ``u - fx * baseline / z`` keeps the camera's left-to-right order. The band is about
    ``fx * |baseline| * (1 / z_near - 1 / z_far)`` pixels wide beside each depth edge.
    """
    z = _check_depth(depth)
    if fx is None or not fx > 0:
        raise ValueError(f"fx must be a positive focal length in pixels, got {fx!r}")
    if baseline < 0:
        return projector_shadows(z[:, ::-1], fx, -baseline)[:, ::-1]
    valid = z > 0
    with np.errstate(divide="ignore"):
        projector_u = np.where(valid, np.arange(z.shape[1]) - fx * baseline / np.where(valid, z, 1.0), np.inf)
    # Smallest projector coordinate strictly to the right of each pixel.
    right_min = np.full_like(projector_u, np.inf)
    right_min[:, :-1] = np.minimum.accumulate(projector_u[:, :0:-1], axis=1)[:, ::-1]
    return valid & (projector_u > right_min)


def structured_light_noise(depth, rng: np.random.Generator, *, fx: float | None = None,
                           baseline: float = 0.075, shadows: bool = True, dropout: float = 0.005,
                           min_range: float = 0.5, max_range: float = 5.0) -> np.ndarray:
    """Kinect v1 style depth: disparity noise and quantisation, projector shadows, dropouts.

    depth : (H, W) float, metres, 0 = no measurement
    rng : np.random.Generator
    fx : float, pixels; required when ``shadows`` is on
    baseline : float, metres, projector offset along the camera x axis (see :func:`projector_shadows`)
    shadows : bool, blank the projector's shadows
    dropout : float in [0, 1], share of pixels randomly lost
    min_range, max_range : float, metres; true depths outside are not measured
        (Kinect v1 returns depth from about 0.5 to 5 m; its nominal range is 0.8-4 m)

    Depth becomes the raw disparity ``(OFFSET - 1/z) / STEP`` (one unit is about 1/8 pixel),
    gets Gaussian noise, is rounded to a whole unit and turned back into depth, so depth is
    quantised in steps of ``STEP * z^2`` (about 0.00307 z^2 m). The Gaussian part is chosen
    so that noise and rounding together have the standard deviation ``depth_std(z,
    "structured_light")``. Returns (H, W) float32.
    """
    z = _check_depth(depth)
    dropout = _check_rate(dropout, "dropout")
    valid = (z > 0) & _in_range(z, min_range, max_range)
    if shadows:
        if fx is None:
            raise ValueError("structured_light noise needs fx (pixels) to place the projector shadows")
        valid &= ~projector_shadows(z, fx, baseline)
    noise = rng.standard_normal(z.shape)
    lost = rng.random(z.shape) < dropout

    zv = np.where(valid, z, 1.0)
    step, offset = KINECT_V1_INVERSE_DEPTH_STEP, KINECT_V1_INVERSE_DEPTH_OFFSET
    raw = (offset - 1.0 / zv) / step
    total = _std_structured_light(zv) / (step * zv**2)  # wanted std in raw units (dz = step z^2 draw)
    gaussian = np.sqrt(np.maximum(total**2 - 1.0 / 12.0, 0.0))  # rounding adds 1/12 unit^2
    inverse = offset - step * np.round(raw + gaussian * noise)
    valid &= ~lost & (inverse > 0.0)
    return np.where(valid, 1.0 / np.where(valid, inverse, 1.0), 0.0).astype(np.float32)


def tof_noise(depth, rng: np.random.Generator, *, flying_fraction: float = 0.5, edge_jump: float = 0.05,
              dropout: float = 0.002, min_range: float = 0.5, max_range: float = 4.5) -> np.ndarray:
    """Time-of-flight depth: Gaussian noise, flying pixels at depth edges, dropouts.

    depth : (H, W) float, metres, 0 = no measurement
    rng : np.random.Generator
    flying_fraction : float in [0, 1], share of edge pixels that become flying pixels
    edge_jump : float, metres; a pixel is on a depth edge when one of its 4 neighbours
        (with a measurement) differs from it by more than this
    dropout : float in [0, 1], share of pixels randomly lost
    min_range, max_range : float, metres; true depths outside are not measured
        (defaults: Kinect v2, 0.5-4.5 m; the Azure Kinect NFOV unbinned mode is 0.5-3.86 m)

    A flying pixel mixes the two surfaces its footprint straddles: its depth moves a
    uniform random share of the way towards the neighbour most different from it. Every
    measured pixel then gets Gaussian noise of ``depth_std(z, "tof")``. Returns (H, W) float32.
    """
    z = _check_depth(depth)
    flying_fraction = _check_rate(flying_fraction, "flying_fraction")
    dropout = _check_rate(dropout, "dropout")
    if not edge_jump > 0:
        raise ValueError(f"edge_jump must be > 0 metres, got {edge_jump!r}")
    valid = (z > 0) & _in_range(z, min_range, max_range)
    noise = rng.standard_normal(z.shape)
    mix = rng.random(z.shape)
    flies = rng.random(z.shape) < flying_fraction
    lost = rng.random(z.shape) < dropout

    # The measured 4-neighbour that differs most from each pixel.
    padded = np.pad(z, 1)
    other = np.zeros_like(z)
    jump = np.zeros_like(z)
    for neighbour in (padded[:-2, 1:-1], padded[2:, 1:-1], padded[1:-1, :-2], padded[1:-1, 2:]):
        larger = (neighbour > 0) & (np.abs(neighbour - z) > jump)
        other = np.where(larger, neighbour, other)
        jump = np.where(larger, np.abs(neighbour - z), jump)
    edge = (z > 0) & (jump > edge_jump)
    mixed = np.where(edge & flies, z + mix * (other - z), z)

    noisy = mixed + _std_tof(mixed) * noise
    valid &= ~lost & (noisy > 0)
    return np.where(valid, noisy, 0.0).astype(np.float32)


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
    if not isinstance(rng, np.random.Generator):
        raise ValueError(f"rng must be a numpy.random.Generator, got {type(rng).__name__}")
    function = NOISE_MODELS[model]
    accepted = [name for name, p in inspect.signature(function).parameters.items()
                if p.kind is inspect.Parameter.KEYWORD_ONLY]
    unknown = sorted(set(options) - set(accepted))
    if unknown:
        raise ValueError(f"noise model {model!r} has no option(s) {unknown}; its options: {accepted}")
    if "fx" in accepted:
        options["fx"] = fx
    return function(depth, rng, **options)
