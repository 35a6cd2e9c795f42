"""The baseline the occupancy grid has to beat: per-pixel background subtraction on the depth image.

OpenCV's Gaussian-mixture (MOG2) or k-nearest-neighbour (KNN) background subtractor runs on
the depth image in centimetres (float32), learning the background from the first frames
on, like the grid (no empty-room start). Pixels without a measurement are never foreground.
OpenCV is the optional extra ``baseline``: ``pip install occupose[baseline]``.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np


def _cv2():
    try:
        import cv2
    except ImportError:
        raise ImportError(
            "the background-subtraction baseline needs OpenCV: pip install occupose[baseline]"
        ) from None
    return cv2


def _mog2(history: int, threshold: float | None):
    # varThreshold: squared Mahalanobis distance to a mixture component (OpenCV's default 16)
    return _cv2().createBackgroundSubtractorMOG2(
        history=history, varThreshold=16.0 if threshold is None else threshold, detectShadows=False)


def _knn(history: int, threshold: float | None):
    # dist2Threshold: squared distance to the stored samples, here in cm^2 (OpenCV's default 400)
    return _cv2().createBackgroundSubtractorKNN(
        history=history, dist2Threshold=400.0 if threshold is None else threshold, detectShadows=False)


#: Background subtractors by name: builder(history, threshold or None for OpenCV's default).
BACKGROUND_SUBTRACTORS: dict[str, Callable] = {"mog2": _mog2, "knn": _knn}


class DepthBackgroundSubtractor:
    """Per-pixel background subtraction on a depth image, frame after frame.

    method : a key of BACKGROUND_SUBTRACTORS ("mog2", "knn")
    history : int, frames the background model remembers
    threshold : OpenCV's varThreshold (MOG2) or dist2Threshold in cm^2 (KNN); None: OpenCV's default
    units_per_metre : float, scale of the depth fed to OpenCV (100: centimetres)
    """

    def __init__(self, method: str = "mog2", *, history: int = 500, threshold: float | None = None,
                 units_per_metre: float = 100.0):
        if method not in BACKGROUND_SUBTRACTORS:
            raise ValueError(f"unknown background subtractor {method!r}; valid names: {sorted(BACKGROUND_SUBTRACTORS)}")
        if isinstance(history, bool) or not isinstance(history, (int, np.integer)) or history < 1:
            raise ValueError(f"history must be a positive number of frames, got {history!r}")
        if not (np.isfinite(units_per_metre) and units_per_metre > 0):
            raise ValueError(f"units_per_metre must be positive, got {units_per_metre!r}")
        self.method = method
        self.units_per_metre = float(units_per_metre)
        self._model = BACKGROUND_SUBTRACTORS[method](int(history), threshold)
        self._shape: tuple[int, int] | None = None

    def apply(self, depth: np.ndarray) -> np.ndarray:
        """Update the background model with a depth image and return its foreground.

        depth : (H, W) float metres, 0 = no measurement (the same shape every frame)
        Returns (H, W) bool, True where the depth differs from the learnt background.
        """
        depth = np.asarray(depth)
        if depth.ndim != 2 or depth.dtype.kind != "f":
            raise ValueError(f"depth must be a 2-D float image in metres, got {depth.dtype} {depth.shape}")
        if self._shape is not None and depth.shape != self._shape:
            raise ValueError(f"depth image shape changed from {self._shape} to {depth.shape}")
        self._shape = depth.shape
        valid = np.isfinite(depth) & (depth > 0)
        scaled = np.where(valid, depth * self.units_per_metre, 0.0).astype(np.float32)
        return (self._model.apply(scaled) > 0) & valid
