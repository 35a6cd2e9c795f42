"""Depth-sensor noise: the random depth error of each sensor model at a distance.

Two models of real depth cameras and the ideal sensor:

- ``"structured_light"`` (Kinect v1): 0.0012 + 0.0019 (z - 0.4)^2 metres (Nguyen, Izadi &
  Lovell 2012), the disparity quantisation included;
- ``"tof"`` (time of flight, Kinect v2 / Azure Kinect): (1.5 - 0.5 z + 0.3 z^2) mm
  (Fankhauser et al. 2015);
- ``"none"``: 0.

The occupancy grid takes its measurement tolerance from :func:`depth_std`, the likelihood
its margins; the scene generator's noise (:mod:`occupose.synth.noise`) draws from the same
figures.

Real sensors are often noisier than these nominal figures (ToF on dark or slanted
surfaces, a worn unit), so :func:`estimate_depth_noise` measures a camera's random depth
error from its own frames: the temporal spread of the pixels that stay put, per depth,
fitted to the same quadratic form (:class:`NoiseEstimate`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from occupose.config import GridConfig

#: Random depth error of each model as a quadratic c0 + c1 z + c2 z^2 (metres, z in metres).
_STD_COEFFS: dict[str, np.ndarray] = {
    "none": np.zeros(3),
    # Nguyen, Izadi & Lovell (2012), Kinect v1 axial noise at moderate surface angles:
    # 0.0012 + 0.0019 (z - 0.4)^2, expanded.
    "structured_light": np.array([0.0012 + 0.0019 * 0.16, -0.0019 * 0.8, 0.0019]),
    # Fankhauser et al. (2015), Kinect v2 axial noise at normal incidence:
    # 1.5 - 0.5 z + 0.3 z^2 mm. Below 5.3 mm over 0.5-4.5 m, within the Azure Kinect's
    # specified random error (standard deviation <= 17 mm over its 0.5-3.86 m range).
    "tof": np.array([1.5e-3, -0.5e-3, 0.3e-3]),
}


def depth_std(z, model: str):
    """Random depth error (one standard deviation, metres) of ``model`` at depth ``z``.

    z : float or (...) array, metres. Returns a float for a scalar ``z``, else an array
    of the same shape (float64). ``"structured_light"``: 0.0012 + 0.0019 (z - 0.4)^2
    (Nguyen et al. 2012), including the disparity quantisation; ``"tof"``: (1.5 - 0.5 z +
    0.3 z^2) mm (Fankhauser et al. 2015); ``"none"``: 0. Systematic (bias) errors of real
    sensors are not modelled.
    """
    return std_from_coefficients(z, depth_std_coefficients(model))


def std_from_coefficients(z, coefficients) -> float | np.ndarray:
    """c0 + c1 z + c2 z^2 for ``coefficients`` (3,) (metres; z float or (...) array, metres):
    a float for a scalar ``z``, else a float64 array of its shape."""
    c0, c1, c2 = coefficients
    values = np.asarray(z, dtype=np.float64)
    std = c0 + c1 * values + c2 * values**2
    return float(std) if std.ndim == 0 else std


def depth_std_coefficients(model: str) -> np.ndarray:
    """(3,) float64 c0, c1, c2: :func:`depth_std` of ``model`` is c0 + c1 z + c2 z^2 metres."""
    if model not in _STD_COEFFS:
        raise ValueError(f"unknown noise model {model!r}; valid names: {sorted(_STD_COEFFS)}")
    return _STD_COEFFS[model].copy()


#: Fewest frames :func:`estimate_depth_noise` takes (a temporal std of 2 readings is too coarse).
MIN_NOISE_FRAMES = 3
#: Residuals beyond this many robust (MAD) standard deviations are left out of a bin's std:
#: flying pixels and the odd outlier, not the Gaussian tail (0.00006 % of it lies beyond).
_TRIM = 5.0
#: Depth bins needed to fit all three coefficients; with fewer, c1 = 0 (see :func:`_fit`).
_FULL_FIT_BINS = 4
#: A bin whose std is this factor off the fit of the others is dropped (see :func:`estimate_depth_noise`).
_BIN_OUTLIER = 1.5
#: Percentile of the valid depths taken as the farthest depth a camera measures.
_FAR_PERCENTILE = 99.9
#: MAD to standard deviation for a Gaussian.
_MAD_TO_STD = 1.4826


@dataclass(frozen=True, eq=False)
class NoiseEstimate:
    """One camera's random depth error measured from its frames (:func:`estimate_depth_noise`).

    coefficients : (3,) float64 c0, c1, c2: the std is c0 + c1 z + c2 z^2 metres (z metres),
        the form of the named models (:func:`depth_std`)
    pixels : int, the static pixels the estimate rests on; frames : int, the frames
    depth_range : (near, far) metres, the depths of the bins that were fitted; outside it
        the fitted form is extrapolated (it has c2 >= 0 and is positive for z >= 0, so it
        grows on past ``far``)
    bin_depths, bin_stds : (B,) float64 metres, each bin's median depth and measured std;
    bin_pixels : (B,) int64, static pixels per bin
    far : float, metres, the farthest depth the camera measured (99.9th percentile of its
        valid readings)
    """

    coefficients: np.ndarray
    pixels: int
    frames: int
    depth_range: tuple[float, float]
    bin_depths: np.ndarray
    bin_stds: np.ndarray
    bin_pixels: np.ndarray
    far: float

    def std(self, z) -> float | np.ndarray:
        """The estimated std (metres) at depth ``z`` (float or (...) array, metres)."""
        return std_from_coefficients(z, self.coefficients)

    def to_dict(self) -> dict:
        """Plain data for ``summary.json``: coefficients, pixels, frames, depth range, far, bins."""
        return {"coefficients": [float(c) for c in self.coefficients], "pixels": self.pixels, "frames": self.frames,
                "depth_range": [round(v, 4) for v in self.depth_range], "far": round(self.far, 4),
                "bins": {"depth": [round(float(v), 4) for v in self.bin_depths],
                         "std": [round(float(v), 6) for v in self.bin_stds],
                         "pixels": [int(v) for v in self.bin_pixels]}}


def estimate_depth_noise(depths, *, bin_width: float = GridConfig.noise_bin,
                         static_cut: float = GridConfig.noise_static_cut,
                         min_pixels: int = GridConfig.noise_min_pixels) -> NoiseEstimate:
    """A camera's random depth error from the temporal spread of its static pixels.

    depths : (T, H, W) float, metres, T >= MIN_NOISE_FRAMES frames of one camera; 0, NaN,
        inf or negative mean no measurement
    bin_width : metres; static_cut : robust spreads; min_pixels : static pixels per bin
        (the ``grid.noise_*`` settings)

    Method: only pixels measured in every frame count (dropouts do not bias the spread,
    they only remove pixels). Each is put in the depth bin of its mean depth. In a bin,
    a pixel is static when its temporal std (ddof 1) is at most the bin's median plus
    ``static_cut`` robust spreads (MAD x 1.4826) of the bin's stds: a person or anything
    moving through a pixel spreads it by decimetres and is left out. The bin's std is
    then that of the static pixels' residuals from their own means, pooled, taken within
    5 robust standard deviations (MAD-based: flying pixels and outliers go, the Gaussian
    stays) and corrected for the mean's degree of freedom (x sqrt(T / (T - 1))). It is
    the std of the readings themselves, quantisation steps included (a Kinect v1's
    disparity steps are 5 cm at 4 m), which is what the named models give. Bins with
    fewer than ``min_pixels`` static pixels are dropped. A bin more than half of whose
    pixels something moved through (a person walking at that depth for all the frames)
    has the mover's spread as its median, so its cut lets the mover in: while at least 3
    bins remain, the bin farthest off the fit of the bins, if more than 1.5 times off (either
    way), is dropped and the rest refitted.

    The bins' stds are fitted (least squares of the relative error, each bin weighed by
    the square root of its pixels: a floor's 100 000 outweigh a still head's 3 000) with
    c0 + c1 z + c2 z^2 when there are at least 4 bins and that fit has c2 >= 0, stays
    positive for z >= 0 and does not fall beyond the nearest bin (no sensor is less noisy
    farther away there; a free quadratic through a few small, low bins dipped to a quarter
    of the floor's noise in between); else with c0 + c2 z^2 (c0, c2 >= 0), which grows with
    depth as both named models do far away; one bin gives c2 z^2 through it. Returns a
    NoiseEstimate.
    Raises ValueError for a bad array, fewer than MIN_NOISE_FRAMES frames, or no bin
    with ``min_pixels`` static pixels.
    """
    array = np.asarray(depths)
    if array.ndim != 3 or array.dtype.kind not in "fiu":
        raise ValueError(f"depths must be a (T, H, W) array of metres, got {array.dtype} {array.shape}")
    num_frames = array.shape[0]
    if num_frames < MIN_NOISE_FRAMES:
        raise ValueError(f"estimating the depth noise needs at least {MIN_NOISE_FRAMES} frames, got {num_frames}")
    if not (bin_width > 0 and static_cut > 0 and min_pixels >= 1):
        raise ValueError(f"need bin_width > 0, static_cut > 0 and min_pixels >= 1, got {bin_width!r}, "
                         f"{static_cut!r}, {min_pixels!r}")
    with np.errstate(invalid="ignore"):
        valid = np.isfinite(array) & (array > 0)
    if not valid.any():
        raise ValueError("estimating the depth noise needs measured pixels, the frames have none")
    far = float(np.percentile(array[valid], _FAR_PERCENTILE))
    series = array[:, valid.all(axis=0)].T.astype(np.float64)  # (N, T) pixels measured in every frame
    means = series.mean(axis=1)
    spreads = series.std(axis=1, ddof=1)
    bins = np.floor(means / bin_width).astype(np.int64)
    depths_b, stds_b, pixels_b = [], [], []
    for b in np.unique(bins):
        members = np.flatnonzero(bins == b)
        if members.size < min_pixels:
            continue
        spread = spreads[members]
        middle = np.median(spread)
        static = members[spread <= middle + static_cut * _MAD_TO_STD * np.median(np.abs(spread - middle))]
        if static.size < min_pixels:
            continue
        residuals = (series[static] - means[static, None]).ravel()
        robust = _MAD_TO_STD * np.median(np.abs(residuals))
        kept = residuals[np.abs(residuals) <= _TRIM * robust]
        depths_b.append(float(np.median(means[static])))
        stds_b.append(float(np.sqrt(np.mean(kept**2) * num_frames / (num_frames - 1))))
        pixels_b.append(static.size)
    if not depths_b:
        raise ValueError(f"estimating the depth noise needs a depth bin ({bin_width:g} m) with at least "
                         f"{min_pixels} static pixels measured in all {num_frames} frames; the frames have "
                         f"{series.shape[0]} such pixels in all")
    z, s, n = np.array(depths_b), np.array(stds_b), np.array(pixels_b, np.int64)
    coefficients = _fit(z, s, n)
    while z.size >= 3:  # drop the bin farthest off the others' fit while it is off by more than _BIN_OUTLIER
        ratio = np.abs(np.log(np.maximum(s, 1e-9) / np.maximum(std_from_coefficients(z, coefficients), 1e-9)))
        worst = int(np.argmax(ratio))
        if ratio[worst] <= math.log(_BIN_OUTLIER):
            break
        z, s, n = (np.delete(a, worst) for a in (z, s, n))
        coefficients = _fit(z, s, n)
    return NoiseEstimate(coefficients, int(n.sum()), num_frames, (float(z.min()), float(z.max())), z, s, n, far)


def _fit(z: np.ndarray, s: np.ndarray, n: np.ndarray) -> np.ndarray:
    """(3,) c0, c1, c2 of the std form fitted to the bins' stds ``s`` at depths ``z`` ((B,) metres),
    of ``n`` (B,) static pixels each, as :func:`estimate_depth_noise` describes."""
    if not np.any(s > 0):
        return np.zeros(3)
    # relative error (the stds span an order of magnitude), a bin weighing by the square root
    # of its pixels (its std is that much surer)
    weight = np.sqrt(n / n.sum()) / np.maximum(s, s[s > 0].min())
    if z.size >= _FULL_FIT_BINS:
        full = np.linalg.lstsq(np.column_stack([np.ones_like(z), z, z**2]) * weight[:, None], s * weight,
                               rcond=None)[0]
        c0, c1, c2 = full
        if c2 >= 0 and _lowest(full) > 0 and c1 + 2 * c2 * z.min() >= 0:  # not falling beyond the nearest bin
            return full
    if z.size >= 2:
        c0, c2 = np.linalg.lstsq(np.column_stack([np.ones_like(z), z**2]) * weight[:, None], s * weight,
                                 rcond=None)[0]
        if c0 >= 0 and c2 >= 0:
            return np.array([c0, 0.0, c2])
        # one of them would be negative: the better of the constant and the pure z^2 through the bins
        constant = np.array([np.sum(weight**2 * s) / np.sum(weight**2), 0.0, 0.0])
        square = np.array([0.0, 0.0, np.sum(weight**2 * s * z**2) / np.sum(weight**2 * z**4)])
        return min((constant, square), key=lambda c: np.sum((weight * (std_from_coefficients(z, c) - s))**2))
    return np.array([0.0, 0.0, s[0] / z[0]**2])


def _lowest(coefficients: np.ndarray) -> float:
    """The least value of c0 + c1 z + c2 z^2 over z >= 0 (-inf when it falls without end)."""
    c0, c1, c2 = coefficients
    if c1 >= 0:
        return float(c0)
    return float(c0 - c1**2 / (4.0 * c2)) if c2 > 0 else -math.inf
