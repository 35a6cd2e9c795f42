"""Argument checks at the library's boundary (private).

Each check returns the value converted (a float, an int, a float64 or boolean array) or
raises a ValueError naming the argument, what was expected and what arrived.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np


def positive_int(value: Any, what: str) -> int:
    """``value`` as an int >= 1 (a bool is not an integer here)."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
        raise ValueError(f"{what} must be an integer >= 1, got {value!r}")
    return int(value)


def seed_value(value: Any, what: str = "seed") -> int:
    """``value`` as a seed: an int >= 0 (a bool or a float is not a seed). TypeError for
    another type, ValueError for a negative int."""
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise TypeError(f"{what} must be an integer >= 0, got {value!r} ({type(value).__name__})")
    if value < 0:
        raise ValueError(f"{what} must be an integer >= 0, got {value!r}")
    return int(value)


def flag(value: Any, what: str) -> bool:
    """``value`` when it is a bool (TypeError otherwise: a string "false" is no false)."""
    if not isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{what} must be True or False, got {value!r} ({type(value).__name__})")
    return bool(value)


def callback(value: Any, what: str) -> Any:
    """``value`` when it is callable or None (TypeError otherwise)."""
    if value is not None and not callable(value):
        raise TypeError(f"{what} must be a function or None, got {value!r} ({type(value).__name__})")
    return value


def positive_float(value: Any, what: str) -> float:
    """``value`` as a finite float > 0."""
    number = _number(value, what)
    if not math.isfinite(number) or number <= 0.0:
        raise ValueError(f"{what} must be a positive finite number, got {value!r}")
    return number


def nonnegative_float(value: Any, what: str) -> float:
    """``value`` as a finite float >= 0."""
    number = _number(value, what)
    if not math.isfinite(number) or number < 0.0:
        raise ValueError(f"{what} must be a finite number >= 0, got {value!r}")
    return number


def _number(value: Any, what: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise ValueError(f"{what} must be a number, got {value!r}")
    try:
        return float(value)
    except OverflowError:  # an integer beyond the largest float: not finite
        return math.inf


def float_array(value: Any, what: str, shape: tuple[int | None, ...]) -> np.ndarray:
    """``value`` as float64 with the given shape (None: any length)."""
    array = np.asarray(value, dtype=np.float64)
    if array.ndim != len(shape) or any(s is not None and s != n for s, n in zip(shape, array.shape)):
        expected = "(" + ", ".join("N" if s is None else str(s) for s in shape) + ")"
        raise ValueError(f"{what} must have shape {expected}, got {array.shape}")
    return array


def bool_array(value: Any, what: str, shape: tuple[int, ...]) -> np.ndarray:
    """``value`` as it is, after checking it is a boolean array of exactly ``shape``."""
    array = np.asarray(value)
    if array.dtype != np.bool_:
        raise ValueError(f"{what} must be a boolean array, got dtype {array.dtype}")
    if array.shape != shape:
        raise ValueError(f"{what} must have shape {shape}, got {array.shape}")
    return array


def joints_array(joints: Any, what: str = "joints", min_ndim: int = 2) -> np.ndarray:
    """``joints`` as float64 of shape (..., 15, 3) (canonical joints) with at least
    ``min_ndim`` dimensions."""
    from occupose.joints import NUM_JOINTS

    joints = np.asarray(joints, dtype=np.float64)
    if joints.ndim < min_ndim or joints.shape[-2:] != (NUM_JOINTS, 3):
        raise ValueError(f"{what} must have shape (..., {NUM_JOINTS}, 3) with at least {min_ndim} "
                         f"dimensions, got {joints.shape}")
    return joints
