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

Any model's entry may add :func:`sensor_errors` (extra random noise, a systematic bias,
patchy dropouts on people in clothes of low reflectivity): the randomized scenes draw
them from nominal up to a sensor's specified worst case.

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


def sensor_errors(depth, rng: np.random.Generator, person=None, *, extra_std: float = 0.0, bias: float = 0.0,
                  bias_scale: float = 0.0, body_dropout: float = 0.0, dark_people=(), patch: int = 6) -> np.ndarray:
    """Errors beyond a sensor model's nominal ones, on an already noisy depth image.

    depth : (H, W) float, metres, 0 = no measurement
    rng : np.random.Generator (not used when every option is at its default)
    person : (H, W) int person-id image of the same view (0 = scene); needed for ``body_dropout``
    extra_std : metres, standard deviation of extra Gaussian noise on every measured pixel
        (a sensor worse than its nominal model, up to its specified worst case)
    bias, bias_scale : systematic depth error: every measured depth becomes
        ``z + bias + bias_scale * z`` (metres, and a share of the depth); the same in every
        frame of a camera, as a real sensor's calibration error is
    body_dropout : share in [0, 1] of the pixels of ``dark_people`` lost, in patches:
        clothes of low reflectivity return too little light for a time-of-flight or
        structured-light measurement
    dark_people : person ids wearing such clothes
    patch : pixels, the size of the cells of the random field whose lowest values are dropped

    Returns (H, W) float32 metres; pixels that were 0 stay 0.
    """
    z = _check_depth(depth)
    _check_rng(rng)
    body_dropout = _check_rate(body_dropout, "body_dropout")
    if not (np.isfinite(extra_std) and extra_std >= 0.0):
        raise ValueError(f"extra_std must be >= 0 metres, got {extra_std!r}")
    if not (np.isfinite(bias) and np.isfinite(bias_scale) and abs(bias_scale) < 1.0):
        raise ValueError(f"bias must be finite metres and |bias_scale| < 1, got {bias!r}, {bias_scale!r}")
    measured = z > 0.0
    if extra_std > 0.0:
        z = np.where(measured, z + rng.normal(0.0, extra_std, z.shape), 0.0)
    if bias or bias_scale:
        z = np.where(measured, z + bias + bias_scale * z, 0.0)
    if body_dropout > 0.0 and len(dark_people):
        if person is None or np.shape(person) != z.shape:
            raise ValueError(f"body_dropout needs the person image of the view, shape {z.shape}")
        if not int(patch) >= 1:
            raise ValueError(f"patch must be >= 1 pixel, got {patch!r}")
        body = np.isin(person, list(dark_people)) & measured
        if np.any(body):
            field = _patch_field(z.shape, int(patch), rng)
            z = np.where(body & (field <= np.quantile(field[body], body_dropout)), 0.0, z)
    return np.maximum(z, 0.0).astype(np.float32)


def _patch_field(shape: tuple[int, int], patch: int, rng: np.random.Generator) -> np.ndarray:
    """(H, W) smooth random field: uniform values on a grid of ``patch``-pixel cells,
    interpolated bilinearly."""
    height, width = shape
    grid = rng.random((height // patch + 2, width // patch + 2))
    v, u = np.arange(height) / patch, np.arange(width) / patch
    v0, u0 = v.astype(np.int64), u.astype(np.int64)
    fv, fu = (v - v0)[:, None], (u - u0)[None, :]
    top = grid[v0][:, u0] * (1 - fu) + grid[v0][:, u0 + 1] * fu
    bottom = grid[v0 + 1][:, u0] * (1 - fu) + grid[v0 + 1][:, u0 + 1] * fu
    return top * (1 - fv) + bottom * fv


#: Options of every noise entry besides the model's own: :func:`sensor_errors`'s.
SENSOR_ERROR_OPTIONS = ("extra_std", "bias", "bias_scale", "body_dropout", "dark_people", "patch")

#: Noise models by name: each is ``f(depth, rng, **options) -> depth``.
NOISE_MODELS: dict[str, Callable[..., np.ndarray]] = {
    "none": no_noise, "structured_light": structured_light_noise, "tof": tof_noise,
}


def apply_noise(depth, model: str, rng: np.random.Generator, *, fx: float | None = None,
                person=None, **options) -> np.ndarray:
    """Apply the noise model registered as ``model`` to a depth image.

    depth : (H, W) float, metres, 0 = no measurement
    model : a key of NOISE_MODELS
    rng : np.random.Generator (the same seed gives the same image)
    fx : float, focal length in pixels, passed to the models that use it (structured light)
    person : (H, W) person-id image of the view, for the ``body_dropout`` option
    options : the model's own keyword options (see its function) and those of
        :data:`SENSOR_ERROR_OPTIONS` (:func:`sensor_errors`, applied after the model when given)

    Returns (H, W) float32 metres, 0 = no measurement.
    """
    if model not in NOISE_MODELS:
        raise ValueError(f"unknown noise model {model!r}; valid names: {sorted(NOISE_MODELS)}")
    errors = {name: options.pop(name) for name in SENSOR_ERROR_OPTIONS if name in options}
    function = NOISE_MODELS[model]
    accepted = [name for name, p in inspect.signature(function).parameters.items()
                if p.kind is inspect.Parameter.KEYWORD_ONLY]
    unknown = sorted(set(options) - set(accepted))
    if unknown:
        raise ValueError(f"noise model {model!r} has no option(s) {unknown}; its options: {accepted}")
    if "fx" in accepted:
        options["fx"] = fx
    out = function(depth, rng, **options)
    return sensor_errors(out, rng, person, **errors) if errors else out
