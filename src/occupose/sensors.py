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
"""

from __future__ import annotations

import numpy as np

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
    c0, c1, c2 = depth_std_coefficients(model)
    values = np.asarray(z, dtype=np.float64)
    std = c0 + c1 * values + c2 * values**2
    return float(std) if std.ndim == 0 else std


def depth_std_coefficients(model: str) -> np.ndarray:
    """(3,) float64 c0, c1, c2: :func:`depth_std` of ``model`` is c0 + c1 z + c2 z^2 metres."""
    if model not in _STD_COEFFS:
        raise ValueError(f"unknown noise model {model!r}; valid names: {sorted(_STD_COEFFS)}")
    return _STD_COEFFS[model].copy()
