"""Shared set-up of the terms that project capsule surface samples into the views (private)."""

from __future__ import annotations

import numpy as np

from occupose.likelihood import _sample_kernels
from occupose.sensors import depth_std_coefficients

#: Angles of the samples about a capsule's axis, either side of the camera-facing direction,
#: degrees: 45 keeps them inside the silhouette of a limb whose model is up to ~40 % too thick.
SAMPLE_SPAN_DEGREES = 45.0


def sample_pattern(samples_along, samples_around):
    """Check the sample counts; return along (T,), cos_around (A,), sin_around (A,) float64
    (see occupose.likelihood._sample_kernels._camera_samples) and the samples per capsule, 2 + T A."""
    for name, count in (("samples_along", samples_along), ("samples_around", samples_around)):
        if isinstance(count, bool) or not isinstance(count, (int, np.integer)) or count < 1:
            raise ValueError(f"{name} must be a positive integer, got {count!r}")
    along = (np.arange(samples_along) + 0.5) / samples_along
    angles = np.radians(np.linspace(-SAMPLE_SPAN_DEGREES, SAMPLE_SPAN_DEGREES, samples_around)
                        if samples_around > 1 else np.zeros(1))
    return along, np.cos(angles), np.sin(angles), 2 + int(samples_along) * int(samples_around)


def offset_depths(depth: np.ndarray, margin: float, noise: str, sign: float) -> np.ndarray:
    """(H, W) float32 metres: depth + sign * (``margin`` + 3 sigma of the ``noise`` model's
    random error at that depth) on measured pixels, 0 where depth is 0.

    depth : (H, W) float32, metres (0 = no measurement); sign : -1 (space seen empty
    beyond) or +1 (hidden beyond).
    """
    margin = float(margin)
    if not (np.isfinite(margin) and margin >= 0):
        raise ValueError(f"margin must be a finite number >= 0 metres, got {margin!r}")
    coefficients = 3.0 * depth_std_coefficients(noise)
    coefficients[0] += margin
    depth = np.ascontiguousarray(depth, dtype=np.float32)
    out = np.empty(depth.shape, np.float32)
    _sample_kernels.offset_depths(depth, *(float(sign) * coefficients), out)
    return out


def camera_arrays(camera):
    """rotation (3, 3) and shift (3,) of camera_from_world."""
    pose = camera.camera_from_world
    return np.ascontiguousarray(pose[:3, :3]), np.ascontiguousarray(pose[:3, 3])
