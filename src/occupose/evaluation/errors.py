"""Accuracy of tracked skeletons against ground truth: joint and frame errors, Table I of the occupancy paper.

Every distance is in metres inside this module; a `TableRow` reports centimetres and percent.

Definitions
-----------
joint error
    Euclidean distance between a ground-truth joint and its estimate; NaN where either
    is missing (NaN).
frame error ``D_t``
    Mean of the joint errors of frame ``t`` over the joints that count (finite error,
    and inside the optional mask, e.g. ground-truth-visible joints only). In a scored
    sequence (`occupose.evaluation.matching.score`) a joint that ground truth has and the
    track leaves out, in a frame the track has, has the error ``MISSED_ERROR_M``.
counted, estimated, missed and excluded frames
    A frame counts for a person when ground truth has the person and at least one of
    their joints is visible to a camera (`occupose.evaluation.matching.score`; a person
    walking in, or fully behind a cabinet, is not scored until something of them can be
    seen). A counted frame is *estimated* when ``D_t`` is finite and *missed* when the
    tracker has no estimate of the person. Other frames are excluded from everything.
table row (Table I)
    ``mean`` and population ``std`` of ``D_t`` over the estimated frames (the paper's
    formula, ``1/T``); percentages over all counted frames of ``D_t <= 10, 15, 20 cm``
    (the paper's text: the error "does not exceed" the bound; Table I's column labels
    write this ``<10cm``) and ``D_t > 20 cm`` (the error "exceeds"), so that ``<20`` and
    ``>20`` add up to 100 %. A missed frame counts as an error above every bound (in
    ``>20``, in none of the others). ``coverage`` is the percentage of counted frames
    that are estimated.
FAIL
    The rolling mean of ``D_t`` over a trailing window of ``window_s`` seconds
    (``round(window_s * fps)`` frames, the current frame included; windows reaching
    before the first frame average the frames they hold) exceeds ``threshold_m``
    (strictly) at some frame at least ``after_s`` seconds after the person's first
    counted frame: a grace period for the tracker to start. Excluded frames are skipped
    inside a window; a missed frame counts as an error of ``MISSED_ERROR_M`` (1 m), so
    a person lost for good FAILs while a single dropped frame does not, except inside
    the grace period, where missed frames are skipped too: a person entering the view is
    counted from the first frame one joint shows (a hand at the image border), and
    without this the frames the tracker takes to find them would weigh 1 m each in the
    few-frame windows right after the grace period. A person never found still FAILs.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Sequence

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view

from occupose._validate import bool_array, float_array, nonnegative_float, positive_float

#: Error a missed frame counts as in the FAIL rule's rolling mean, metres.
MISSED_ERROR_M = 1.0

#: Upper bounds of the "under" columns of Table I, metres (a frame counts when D_t <= bound).
UNDER_BOUNDS_M: tuple[float, ...] = (0.10, 0.15, 0.20)
#: Lower bound of the "over" column of Table I, metres (a frame counts when D_t > bound).
OVER_BOUND_M = 0.20


# --------------------------------------------------------------------------- checks


def _frame_values(frame_errors: Any, missed: Any) -> np.ndarray:
    """Frame errors (T,) with missed frames set to +inf, after checking both inputs."""
    values = float_array(frame_errors, "frame_errors", (None,))
    if np.any(np.isinf(values)) or np.any(values < 0.0):
        raise ValueError(
            "frame_errors must be >= 0 metres, or NaN where a frame has no error "
            "(mark frames without an estimate with `missed`, not with inf)"
        )
    if missed is None:
        return values
    missed = bool_array(missed, "missed", values.shape)
    clash = missed & np.isfinite(values)
    if np.any(clash):
        raise ValueError(
            f"frames {np.flatnonzero(clash)[:10].tolist()} are marked missed but have a finite "
            "frame error; a missed frame must have NaN error"
        )
    return np.where(missed, np.inf, values)


def _nanmean(values: np.ndarray, axis: int) -> np.ndarray:
    """Mean over ``axis`` of the finite entries; NaN where there are none (no warning)."""
    finite = np.isfinite(values)
    counts = finite.sum(axis=axis)
    sums = np.where(finite, values, 0.0).sum(axis=axis)
    out = np.full(sums.shape, np.nan)
    np.divide(sums, counts, out=out, where=counts > 0)
    return out


# --------------------------------------------------------------------------- errors


def joint_errors(gt: Any, est: Any) -> np.ndarray:
    """Euclidean error of every estimated joint.

    Parameters
    ----------
    gt, est : (T, J, 3) float, metres (any matching shape ending in 3 is accepted)
        Ground-truth and estimated joint positions; NaN where a joint is missing.

    Returns
    -------
    (T, J) float64, metres; NaN where either position has a NaN coordinate.
    """
    gt = np.asarray(gt, dtype=np.float64)
    est = np.asarray(est, dtype=np.float64)
    if gt.shape != est.shape or gt.ndim < 1 or gt.shape[-1] != 3:
        raise ValueError(
            f"gt and est must have the same shape (..., 3), got {gt.shape} and {est.shape}"
        )
    return np.linalg.norm(gt - est, axis=-1)


def frame_errors(errors: Any, mask: Any = None) -> np.ndarray:
    """Frame error ``D_t``: mean joint error of each frame.

    Parameters
    ----------
    errors : (T, J) float, metres
        Joint errors (from `joint_errors`); NaN where a joint has no error.
    mask : (T, J) bool, optional
        Joints that count (e.g. ground-truth-visible ones); all when None.

    Returns
    -------
    (T,) float64, metres: mean over the joints where ``mask`` is true and the error is
    finite; NaN for a frame where no joint counts.
    """
    errors = float_array(errors, "errors", (None, None))
    counted = np.isfinite(errors)
    if mask is not None:
        counted &= bool_array(mask, "mask", errors.shape)
    return _nanmean(np.where(counted, errors, np.nan), axis=1)


def per_joint_errors(errors: Any, joint_names: Sequence[str]) -> dict[str, float]:
    """Mean error of each joint over the frames where it has one.

    Parameters
    ----------
    errors : (T, J) float, metres
        Joint errors; NaN where a joint has no error.
    joint_names : J names, in the column order of ``errors``.

    Returns
    -------
    ``{name: mean error in cm}``; NaN for a joint without any finite error.
    """
    errors = float_array(errors, "errors", (None, None))
    if len(joint_names) != errors.shape[1]:
        raise ValueError(
            f"joint_names has {len(joint_names)} names but errors has {errors.shape[1]} joints"
        )
    means = _nanmean(errors, axis=0) * 100.0
    return {str(name): float(value) for name, value in zip(joint_names, means)}


# --------------------------------------------------------------------------- FAIL rule


def rolling_mean(values: Any, fps: float, *, window_s: float = 2.0) -> np.ndarray:
    """Trailing rolling mean over ``window_s`` seconds.

    Parameters
    ----------
    values : (T,) float
        One value per frame; NaN frames are skipped, +inf is averaged as infinity.
    fps : float
        Frames per second.
    window_s : float
        Window duration in seconds: ``max(1, round(window_s * fps))`` frames, ending at
        (and including) the current frame. Windows reaching before frame 0 average the
        frames available.

    Returns
    -------
    (T,) float64: mean of the non-NaN values in each window; NaN where there are none.
    """
    values = float_array(values, "values", (None,))
    fps = positive_float(fps, "fps")
    window_s = positive_float(window_s, "window_s")
    length = max(1, int(round(window_s * fps)))
    if values.size == 0:
        return values.copy()
    padded = np.concatenate([np.full(length - 1, np.nan), values])
    windows = sliding_window_view(padded, length)
    counted = ~np.isnan(windows)
    counts = counted.sum(axis=1)
    sums = np.where(counted, windows, 0.0).sum(axis=1)
    out = np.full(values.shape, np.nan)
    np.divide(sums, counts, out=out, where=counts > 0)
    return out


def fail_curve(
    frame_errors: Any,
    fps: float,
    *,
    missed: Any = None,
    window_s: float = 2.0,
    after_s: float = 1.0,
) -> np.ndarray:
    """Rolling mean of ``D_t`` that the FAIL rule judges (module docstring).

    Parameters
    ----------
    frame_errors : (T,) float, metres
        ``D_t``; NaN for frames without an error (missed or excluded).
    fps : float
        Frames per second; frame ``i`` is at ``i / fps`` seconds.
    missed : (T,) bool, optional
        Frames where ground truth has the person and the tracker has no estimate
        (their ``frame_errors`` must be NaN); they count as ``MISSED_ERROR_M``.
    window_s, after_s : float
        Window duration and grace period after the first counted frame, seconds
        (missed frames inside it are skipped).

    Returns
    -------
    (T,) float64, metres: NaN before the end of the grace period and where a window
    holds no counted frame.
    """
    values = _frame_values(frame_errors, missed)
    fps = positive_float(fps, "fps")
    after_s = nonnegative_float(after_s, "after_s")
    counted = np.flatnonzero(~np.isnan(values))
    start = counted[0] + int(math.ceil(after_s * fps - 1e-9)) if counted.size else values.size
    values[:start][np.isinf(values[:start])] = np.nan  # the tracker's time to find the person
    curve = rolling_mean(np.where(np.isinf(values), MISSED_ERROR_M, values), fps, window_s=window_s)
    curve[:start] = np.nan
    return curve


def is_fail(
    frame_errors: Any,
    fps: float,
    *,
    missed: Any = None,
    window_s: float = 2.0,
    threshold_m: float = 0.25,
    after_s: float = 1.0,
) -> bool:
    """Automatic FAIL status: the rolling mean of `fail_curve` exceeds ``threshold_m``.

    Parameters as in `fail_curve`; ``threshold_m`` in metres, compared strictly (a
    rolling mean of exactly 25 cm does not FAIL).
    """
    return fail_frame(frame_errors, fps, missed=missed, window_s=window_s, threshold_m=threshold_m,
                      after_s=after_s) is not None


def fail_frame(
    frame_errors: Any,
    fps: float,
    *,
    missed: Any = None,
    window_s: float = 2.0,
    threshold_m: float = 0.25,
    after_s: float = 1.0,
) -> int | None:
    """The first frame at which the FAIL rule trips (the rolling mean of `fail_curve`
    exceeds ``threshold_m``), or None for no FAIL. Parameters as in `is_fail`."""
    threshold_m = positive_float(threshold_m, "threshold_m")
    curve = fail_curve(frame_errors, fps, missed=missed, window_s=window_s, after_s=after_s)
    over = np.flatnonzero(np.nan_to_num(curve, nan=0.0) > threshold_m)
    return int(over[0]) if over.size else None


# --------------------------------------------------------------------------- Table I


@dataclass(frozen=True)
class TableRow:
    """One row of Table I for one person, sequence and method.

    Attributes
    ----------
    mean_cm, std_cm : float
        Mean and population standard deviation of ``D_t`` over estimated frames, cm
        (NaN when no frame is estimated).
    under10, under15, under20, over20 : float
        Percent of counted frames with ``D_t <= 10, 15, 20 cm`` and ``> 20 cm``
        (missed frames count in ``over20``); NaN when no frame counts.
    fail : bool
        The automatic FAIL status (`is_fail`).
    fail_frame : int or None
        The first frame at which the FAIL rule trips (`fail_frame`), None without a FAIL.
    frames : int
        Counted frames (ground truth has the person).
    coverage : float
        Percent of counted frames that are estimated; NaN when no frame counts.
    """

    mean_cm: float
    std_cm: float
    under10: float
    under15: float
    under20: float
    over20: float
    fail: bool
    frames: int
    coverage: float
    fail_frame: int | None = None

    def format(self) -> str:
        """One-line summary, e.g. ``avg 12.34 cm, std 5.67 cm, <10 20.00 %, ..., ok, 300 frames``."""
        return (
            f"avg {_cell(self.mean_cm)} cm, std {_cell(self.std_cm)} cm, "
            f"<10 {_cell(self.under10)} %, <15 {_cell(self.under15)} %, "
            f"<20 {_cell(self.under20)} %, >20 {_cell(self.over20)} %, "
            f"{'FAIL' if self.fail else 'ok'}, {self.frames} frames, "
            f"coverage {_cell(self.coverage)} %"
        )


def table_row(frame_errors: Any, fps: float, *, missed: Any = None) -> TableRow:
    """Table I row from the frame errors of one person.

    Parameters
    ----------
    frame_errors : (T,) float, metres
        ``D_t``; NaN for frames without an error: missed frames (flagged in ``missed``)
        and frames where ground truth has no person (excluded).
    fps : float
        Frames per second (for the FAIL rule).
    missed : (T,) bool, optional
        Frames where ground truth has the person but the tracker has no estimate.

    Returns
    -------
    TableRow (definitions in the module docstring).
    """
    values = _frame_values(frame_errors, missed)
    tripped = fail_frame(frame_errors, fps, missed=missed)
    estimated = values[np.isfinite(values)]
    frames = int(np.count_nonzero(~np.isnan(values)))
    if estimated.size:
        mean_cm = float(estimated.mean() * 100.0)
        std_cm = float(estimated.std() * 100.0)
    else:
        mean_cm = std_cm = math.nan

    def percent(count: int) -> float:
        return 100.0 * count / frames if frames else math.nan

    under = [percent(int(np.count_nonzero(estimated <= bound))) for bound in UNDER_BOUNDS_M]
    over = percent(int(np.count_nonzero(values > OVER_BOUND_M)))  # +inf (missed) included
    return TableRow(
        mean_cm=mean_cm, std_cm=std_cm,
        under10=under[0], under15=under[1], under20=under[2], over20=over,
        fail=tripped is not None, frames=frames, coverage=percent(estimated.size), fail_frame=tripped,
    )


def _cell(value: float) -> str:
    return "n/a" if math.isnan(value) else f"{value:.2f}"
