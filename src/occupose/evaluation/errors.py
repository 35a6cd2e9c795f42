"""Accuracy of tracked skeletons against ground truth: Table I of the occupancy paper and more.

Every distance is in metres inside this module; tables report centimetres and percent.

Definitions
-----------
joint error
    Euclidean distance between a ground-truth joint and its estimate; NaN where either
    is missing (NaN).
frame error ``D_t``
    Mean of the joint errors of frame ``t`` over the joints that count (finite error,
    and inside the optional mask, e.g. ground-truth-visible joints only).
counted, estimated, missed and excluded frames
    A frame counts for a person when ground truth has the person and at least one of
    their joints is visible to a camera (`score`; a person walking in, or fully behind
    a cabinet, is not scored until something of them can be seen). A counted frame is
    *estimated* when ``D_t`` is finite and *missed* when the tracker has no estimate of
    the person. Other frames are excluded from everything.
table row (Table I)
    ``mean`` and population ``std`` of ``D_t`` over the estimated frames (the paper's
    formula, ``1/T``); percentages over all counted frames of ``D_t <= 10, 15, 20 cm``
    (the paper's text: the error "does not exceed" the bound; Table I's column labels
    write this ``<10cm``) and ``D_t > 20 cm`` (the error "exceeds"), so that ``<20`` and
    ``>20`` add up to 100 %. A missed frame counts as an error above every bound (in
    ``>20``, in none of the others). ``coverage`` is the percentage of counted frames
    that are estimated.
arm error ``epsilon`` (the second paper's)
    Mean distance from a person's observed arm points (pixels of its upper arms,
    forearms and hands: the renderer's part image) to the nearest arm bone
    (shoulder-elbow, elbow-wrist) of a skeleton. The paper measures them "to the
    estimated model state"; a skeleton is what every method reports, and the arms' bones
    alone do not credit an arm point that the trunk would explain. The points lie on the
    surface, a limb's radius from its bone and a hand's length beyond the wrist, so the
    ground-truth skeleton has an epsilon too: the floor any estimate is read against.
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
from typing import Any, Mapping, Sequence

import numpy as np
from numpy.lib.stride_tricks import sliding_window_view
from scipy.optimize import linear_sum_assignment

from occupose.joints import JOINT_INDEX, JOINTS, NUM_JOINTS, PART_INDEX

#: Error a missed frame counts as in the FAIL rule's rolling mean, metres.
MISSED_ERROR_M = 1.0
#: Cost of a frame where a person has ground truth and a track has no estimate, when
#: matching tracks to people (metres, as a mean joint distance).
ABSENT_COST_M = 0.5

#: Upper bounds of the "under" columns of Table I, metres (a frame counts when D_t <= bound).
UNDER_BOUNDS_M: tuple[float, ...] = (0.10, 0.15, 0.20)
#: Lower bound of the "over" column of Table I, metres (a frame counts when D_t > bound).
OVER_BOUND_M = 0.20

#: Column headings of Table I, plus the coverage of the frames with ground truth.
TABLE_COLUMNS: tuple[str, ...] = (
    "<10cm [%]", "<15cm [%]", "<20cm [%]", ">20cm [%]",
    "Avg Err [cm]", "Std Dev [cm]", "Status", "Coverage [%]",
)
# TableRow attribute behind each column, and whether a higher value is better (None: not ranked).
_COLUMN_FIELDS: tuple[tuple[str, bool | None], ...] = (
    ("under10", True), ("under15", True), ("under20", True), ("over20", False),
    ("mean_cm", False), ("std_cm", False), ("fail", None), ("coverage", True),
)

# Cost of an impossible pairing (no common frame) in the assignment problem; far above
# any real mean distance in metres, so the solver pairs as many feasible pairs as it can.
_NO_OVERLAP_COST = 1e6


# --------------------------------------------------------------------------- checks


def _positive_float(value: Any, what: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise ValueError(f"{what} must be a number, got {value!r}")
    number = float(value)
    if not math.isfinite(number) or number <= 0.0:
        raise ValueError(f"{what} must be a positive finite number, got {value!r}")
    return number


def _nonnegative_float(value: Any, what: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise ValueError(f"{what} must be a number, got {value!r}")
    number = float(value)
    if not math.isfinite(number) or number < 0.0:
        raise ValueError(f"{what} must be a finite number >= 0, got {value!r}")
    return number


def _float_array(value: Any, what: str, shape: tuple[int | None, ...]) -> np.ndarray:
    """Return ``value`` as float64 with the given shape (None: any length)."""
    array = np.asarray(value, dtype=np.float64)
    if array.ndim != len(shape) or any(s is not None and s != n for s, n in zip(shape, array.shape)):
        expected = "(" + ", ".join("N" if s is None else str(s) for s in shape) + ")"
        raise ValueError(f"{what} must have shape {expected}, got {array.shape}")
    return array


def _bool_array(value: Any, what: str, shape: tuple[int, ...]) -> np.ndarray:
    array = np.asarray(value)
    if array.dtype != np.bool_:
        raise ValueError(f"{what} must be a boolean array, got dtype {array.dtype}")
    if array.shape != shape:
        raise ValueError(f"{what} must have shape {shape}, got {array.shape}")
    return array


def _frame_values(frame_errors: Any, missed: Any) -> np.ndarray:
    """Frame errors (T,) with missed frames set to +inf, after checking both inputs."""
    values = _float_array(frame_errors, "frame_errors", (None,))
    if np.any(np.isinf(values)) or np.any(values < 0.0):
        raise ValueError(
            "frame_errors must be >= 0 metres, or NaN where a frame has no error "
            "(mark frames without an estimate with `missed`, not with inf)"
        )
    if missed is None:
        return values
    missed = _bool_array(missed, "missed", values.shape)
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
    errors = _float_array(errors, "errors", (None, None))
    counted = np.isfinite(errors)
    if mask is not None:
        counted &= _bool_array(mask, "mask", errors.shape)
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
    errors = _float_array(errors, "errors", (None, None))
    if len(joint_names) != errors.shape[1]:
        raise ValueError(
            f"joint_names has {len(joint_names)} names but errors has {errors.shape[1]} joints"
        )
    means = _nanmean(errors, axis=0) * 100.0
    return {str(name): float(value) for name, value in zip(joint_names, means)}


# --------------------------------------------------------------------------- arm error


#: Body parts (occupose.joints.PARTS labels) whose points the arm error measures.
ARM_PARTS: tuple[int, ...] = tuple(PART_INDEX[f"{side}_{part}"] for side in ("left", "right")
                                   for part in ("upper_arm", "forearm", "hand"))
#: Bones (joint index pairs) the arm points are measured to.
ARM_BONES: tuple[tuple[int, int], ...] = tuple(
    (JOINT_INDEX[f"{side}_{a}"], JOINT_INDEX[f"{side}_{b}"])
    for side in ("left", "right") for a, b in (("shoulder", "elbow"), ("elbow", "wrist")))
#: A frame with fewer arm points than this has no arm error (an arm seen by a few pixels
#: at the edge of a hand says little).
MIN_ARM_POINTS = 20


def segment_distances(points: Any, starts: Any, ends: Any) -> np.ndarray:
    """Distance from each point to the nearest of S segments.

    points : (N, 3) float, metres; starts, ends : (S, 3) float, metres, S >= 1
    Returns (N,) float64, metres.
    """
    points = _float_array(points, "points", (None, 3))
    starts = _float_array(starts, "starts", (None, 3))
    ends = _float_array(ends, "ends", (starts.shape[0], 3))
    if starts.shape[0] == 0:
        raise ValueError("segment_distances needs at least one segment")
    axis = ends - starts                                          # (S, 3)
    length2 = np.maximum(np.einsum("sk,sk->s", axis, axis), 1e-18)
    offset = points[:, None, :] - starts[None]                    # (N, S, 3)
    along = np.clip(np.einsum("nsk,sk->ns", offset, axis) / length2, 0.0, 1.0)
    gap = offset - along[..., None] * axis[None]
    return np.sqrt(np.einsum("nsk,nsk->ns", gap, gap).min(axis=1))


def arm_epsilons(arm_points: Sequence[Any], joints: Any) -> np.ndarray:
    """The second paper's arm error of every frame (module docstring).

    arm_points : T arrays (N_t, 3), metres, world: the person's observed arm points
    joints : (T, 15, 3) float, metres: the skeleton measured (NaN where not reported)
    Returns (T,) float64, metres; NaN where a frame has fewer than MIN_ARM_POINTS points
    or the skeleton misses an arm joint.
    """
    joints = _float_array(joints, "joints", (len(arm_points), NUM_JOINTS, 3))
    starts = np.array([a for a, _ in ARM_BONES])
    ends = np.array([b for _, b in ARM_BONES])
    out = np.full(len(arm_points), np.nan)
    for t, points in enumerate(arm_points):
        skeleton = joints[t]
        if len(points) >= MIN_ARM_POINTS and np.all(np.isfinite(skeleton[np.r_[starts, ends]])):
            out[t] = float(segment_distances(points, skeleton[starts], skeleton[ends]).mean())
    return out


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
    values = _float_array(values, "values", (None,))
    fps = _positive_float(fps, "fps")
    window_s = _positive_float(window_s, "window_s")
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
    fps = _positive_float(fps, "fps")
    after_s = _nonnegative_float(after_s, "after_s")
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
    threshold_m = _positive_float(threshold_m, "threshold_m")
    curve = fail_curve(frame_errors, fps, missed=missed, window_s=window_s, after_s=after_s)
    return bool(np.any(curve[~np.isnan(curve)] > threshold_m))


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
    fail = is_fail(frame_errors, fps, missed=missed)
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
        fail=fail, frames=frames, coverage=percent(estimated.size),
    )


def _cell(value: float) -> str:
    return "n/a" if math.isnan(value) else f"{value:.2f}"


def _cells(row: TableRow) -> list[str]:
    return [
        ("FAIL" if row.fail else "ok") if name == "fail" else _cell(getattr(row, name))
        for name, _ in _COLUMN_FIELDS
    ]


def format_table(rows: Mapping[str, TableRow], *, name_header: str = "method") -> str:
    """Plain-text table in the layout of Table I, columns aligned.

    Parameters
    ----------
    rows : ``{name: TableRow}`` in display order.
    name_header : heading of the first column.

    Returns
    -------
    The table as lines joined by newlines (no trailing newline).
    """
    header = [name_header, *TABLE_COLUMNS]
    body = [[str(name), *_cells(row)] for name, row in rows.items()]
    widths = [max(len(line[i]) for line in [header, *body]) for i in range(len(header))]

    def line(cells: list[str]) -> str:
        first = cells[0].ljust(widths[0])
        rest = (cell.rjust(width) for cell, width in zip(cells[1:], widths[1:]))
        return "  ".join([first, *rest]).rstrip()

    return "\n".join([line(header), *(line(cells) for cells in body)])


def markdown_table(
    groups: Mapping[str, Mapping[str, TableRow]],
    *,
    group_header: str = "sequence",
    name_header: str = "method",
) -> str:
    """Markdown table in the layout of Table I, the best value of each group in bold.

    Parameters
    ----------
    groups : ``{group: {name: TableRow}}``, e.g. sequences, each holding the methods
        compared on it. Within a group, the best value of each column is bold (every
        row that ties on the printed value): lowest for ``>20cm``, ``Avg Err`` and
        ``Std Dev``, highest for ``<10/15/20cm`` and ``Coverage``. Status is not ranked.
    group_header, name_header : headings of the first two columns.

    Returns
    -------
    The markdown table (no trailing newline).
    """
    header = [group_header, name_header, *TABLE_COLUMNS]
    rule = ["---"] * 2 + ["---:"] * len(TABLE_COLUMNS)
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join(rule) + "|"]
    for group, rows in groups.items():
        cells = {name: _cells(row) for name, row in rows.items()}
        for column, (field, higher_better) in enumerate(_COLUMN_FIELDS):
            if higher_better is None:
                continue
            printed = {
                name: round(getattr(row, field), 2)
                for name, row in rows.items()
                if not math.isnan(getattr(row, field))
            }
            if not printed:
                continue
            best = max(printed.values()) if higher_better else min(printed.values())
            for name, value in printed.items():
                if value == best:
                    cells[name][column] = f"**{cells[name][column]}**"
        for index, (name, row_cells) in enumerate(cells.items()):
            first = str(group) if index == 0 else ""
            lines.append("| " + " | ".join([first, str(name), *row_cells]) + " |")
    return "\n".join(lines)


# --------------------------------------------------------------------------- tracks vs people


def _check_people(gt: Any, what: str = "gt") -> np.ndarray:
    gt = np.asarray(gt, dtype=np.float64)
    if gt.ndim != 4 or gt.shape[-1] != 3:
        raise ValueError(f"{what} must have shape (T, P, J, 3), got {gt.shape}")
    return gt


def _check_tracks(
    tracks: Mapping[Any, Any], num_frames: int, num_joints: int
) -> dict[Any, np.ndarray]:
    if not isinstance(tracks, Mapping):
        raise ValueError(
            f"tracks must be a mapping track id -> (T, J, 3) array, got {type(tracks).__name__}"
        )
    checked = {}
    for track_id, joints in tracks.items():
        joints = np.asarray(joints, dtype=np.float64)
        if joints.shape != (num_frames, num_joints, 3):
            raise ValueError(
                f"track {track_id!r} must have shape ({num_frames}, {num_joints}, 3) like the "
                f"ground truth, got {joints.shape}"
            )
        checked[track_id] = joints
    return checked


def _pair_distances(gt: np.ndarray, tracks: dict[Any, np.ndarray]) -> np.ndarray:
    """Mean joint distance of every person and track at every frame.

    gt : (T, P, J, 3); tracks : K arrays (T, J, 3). Returns (T, P, K) metres, NaN where
    the pair has no joint finite in both.
    """
    num_frames, num_people = gt.shape[:2]
    if not tracks:
        return np.full((num_frames, num_people, 0), np.nan)
    stacked = np.stack(list(tracks.values()), axis=1)  # (T, K, J, 3)
    distances = np.linalg.norm(gt[:, :, None] - stacked[:, None], axis=-1)  # (T, P, K, J)
    return _nanmean(distances, axis=3)


def _assign(cost: np.ndarray) -> list[tuple[int, int]]:
    """Optimal pairs (row, column) of a cost matrix with NaN for impossible pairs."""
    if cost.size == 0:
        return []
    feasible = np.isfinite(cost)
    rows, cols = linear_sum_assignment(np.where(feasible, cost, _NO_OVERLAP_COST))
    return [(int(r), int(c)) for r, c in zip(rows, cols) if feasible[r, c]]


def match_tracks(gt: Any, tracks: Mapping[Any, Any]) -> dict[Any, int]:
    """Assign each track to at most one ground-truth person for the whole sequence.

    Parameters
    ----------
    gt : (T, P, J, 3) float, metres
        Ground-truth joints of P people; NaN where a person (or joint) is absent.
    tracks : ``{track_id: (T, J, 3) float, metres}``, NaN where absent.

    Returns
    -------
    ``{track_id: person index}``. The assignment minimises the summed cost
    (`scipy.optimize.linear_sum_assignment`); the cost of a pair is the mean over the
    person's frames of the mean joint distance where both have a joint in common, and
    ``ABSENT_COST_M`` where the person has ground truth and the track has none (so a
    track present in one frame does not beat one that follows the person throughout).
    A pair with no frame in common cannot be matched; a track left over (more tracks
    than people, or no overlap) is unmatched and absent from the result.
    """
    gt = _check_people(gt)
    tracks = _check_tracks(tracks, gt.shape[0], gt.shape[2])
    distances = _pair_distances(gt, tracks)  # (T, P, K)
    person_frames = np.any(np.all(np.isfinite(gt), axis=3), axis=2)  # (T, P)
    track_frames = np.stack([np.any(np.all(np.isfinite(t), axis=2), axis=1) for t in tracks.values()], axis=1) \
        if tracks else np.zeros((gt.shape[0], 0), bool)  # (T, K)
    absent = person_frames[:, :, None] & ~track_frames[:, None, :]
    overlap = np.isfinite(distances)
    total = np.where(overlap, distances, 0.0).sum(axis=0) + ABSENT_COST_M * absent.sum(axis=0)
    frames = (overlap | absent).sum(axis=0)
    cost = np.where(overlap.any(axis=0), total / np.maximum(frames, 1), np.nan)  # (P, K)
    ids = list(tracks)
    return {ids[k]: p for p, k in _assign(cost)}


def identity_switches(gt: Any, tracks: Mapping[Any, Any], *, gate_m: float = 0.5) -> np.ndarray:
    """Number of identity switches of each ground-truth person.

    Each frame, people and tracks are matched optimally on the mean joint distance
    (joints finite in both), keeping only pairs within ``gate_m``. A switch is counted
    when the track covering a person differs from the last track that covered it
    (frames where nothing covers the person are skipped, as in CLEAR MOT).

    Parameters
    ----------
    gt : (T, P, J, 3) float, metres; NaN where absent.
    tracks : ``{track_id: (T, J, 3) float, metres}``; NaN where absent.
    gate_m : float
        Largest mean joint distance of a frame-wise match, metres.

    Returns
    -------
    (P,) int64 switch counts.
    """
    gt = _check_people(gt)
    tracks = _check_tracks(tracks, gt.shape[0], gt.shape[2])
    gate_m = _positive_float(gate_m, "gate_m")
    distances = _pair_distances(gt, tracks)  # (T, P, K)
    switches = np.zeros(gt.shape[1], dtype=np.int64)
    last = np.full(gt.shape[1], -1)
    for cost in distances:
        for person, track in _assign(np.where(cost <= gate_m, cost, np.nan)):
            if last[person] >= 0 and last[person] != track:
                switches[person] += 1
            last[person] = track
    return switches


@dataclass(frozen=True)
class PersonScore:
    """Scores of one ground-truth person.

    Attributes
    ----------
    track : track id matched to the person for the whole sequence, or None.
    all_joints : TableRow over all evaluated joints.
    visible_joints : TableRow over the ground-truth-visible evaluated joints.
    per_joint_cm : ``{joint name: mean error, cm}`` over the evaluated joints.
    identity_switches : int, frame-wise (`identity_switches`).
    """

    track: Any
    all_joints: TableRow
    visible_joints: TableRow
    per_joint_cm: dict[str, float]
    identity_switches: int


@dataclass(frozen=True)
class Score:
    """Scores of one sequence: one `PersonScore` per ground-truth person.

    Attributes
    ----------
    persons : tuple of PersonScore, in ground-truth person order.
    unmatched_tracks : track ids matched to no person.
    identity_switches : total over the people.
    """

    persons: tuple[PersonScore, ...]
    unmatched_tracks: tuple[Any, ...]
    identity_switches: int


def score(
    gt_joints: Any,
    gt_visible: Any,
    tracks: Mapping[Any, Any],
    fps: float,
    *,
    gate_m: float = 0.5,
) -> Score:
    """Score tracked skeletons against ground truth, person by person.

    Tracks are matched to people with `match_tracks`. For each person, the evaluated
    joints are those the matched track reports in at least one frame (the upper-body
    model reports 9 of the 15); the other joints are left out of both sides. A frame
    counts when ground truth has at least one evaluated joint and at least one of the
    person's joints is visible (for the visible-only row: at least one visible evaluated
    joint), and is missed when the track has no
    evaluated joint in it (a frame where both have joints but none in common has no
    error and is left out). A person without a track is missed in every counted frame
    (evaluated joints: all 15).

    Parameters
    ----------
    gt_joints : (T, P, 15, 3) float, metres; NaN where a person is absent.
    gt_visible : (T, P, 15) bool, ground-truth visibility of each joint.
    tracks : ``{track_id: (T, 15, 3) float, metres}``; NaN where not reported.
    fps : float, frames per second.
    gate_m : float, distance gate of the frame-wise matching for identity switches, metres.

    Returns
    -------
    Score.
    """
    gt_joints = _check_people(gt_joints, "gt_joints")
    num_frames, num_people, num_joints = gt_joints.shape[:3]
    if num_joints != NUM_JOINTS:
        raise ValueError(f"gt_joints must hold the {NUM_JOINTS} canonical joints, got {num_joints}")
    gt_visible = _bool_array(gt_visible, "gt_visible", gt_joints.shape[:3])
    tracks = _check_tracks(tracks, num_frames, num_joints)
    fps = _positive_float(fps, "fps")
    matches = match_tracks(gt_joints, tracks)
    track_of = {person: track_id for track_id, person in matches.items()}
    switches = identity_switches(gt_joints, tracks, gate_m=gate_m)
    persons = []
    for person in range(num_people):
        track_id = track_of.get(person)
        if track_id is None:
            est = np.full((num_frames, num_joints, 3), np.nan)
            evaluated = np.ones(num_joints, dtype=bool)
        else:
            est = tracks[track_id]
            evaluated = np.any(np.all(np.isfinite(est), axis=2), axis=0)
        gt = gt_joints[:, person, evaluated]
        est = est[:, evaluated]
        visible = gt_visible[:, person, evaluated]
        in_sight = np.any(gt_visible[:, person], axis=1)[:, None]
        gt_known = np.all(np.isfinite(gt), axis=2) & in_sight
        has_estimate = np.any(np.all(np.isfinite(est), axis=2), axis=1)
        errors = joint_errors(gt, est)
        rows = []
        for counted in (gt_known, gt_known & visible):
            missed = np.any(counted, axis=1) & ~has_estimate
            rows.append(table_row(frame_errors(errors, counted), fps, missed=missed))
        names = [name for name, keep in zip(JOINTS, evaluated) if keep]
        persons.append(PersonScore(
            track=track_id, all_joints=rows[0], visible_joints=rows[1],
            per_joint_cm=per_joint_errors(errors, names),
            identity_switches=int(switches[person]),
        ))
    unmatched = tuple(track_id for track_id in tracks if track_id not in matches)
    return Score(
        persons=tuple(persons), unmatched_tracks=unmatched, identity_switches=int(switches.sum())
    )


# --------------------------------------------------------------------------- pixels


def pixel_assignment_accuracy(assigned: Any, truth: Any, foreground: Any) -> float:
    """Share of foreground pixels assigned to the right person.

    Parameters
    ----------
    assigned : (H, W) int, person label given to each pixel by the tracker (labels
        already mapped to ground-truth person ids).
    truth : (H, W) int, true person label of each pixel.
    foreground : (H, W) bool, pixels that are scored (e.g. the true foreground).

    Returns
    -------
    Fraction in [0, 1]; NaN when ``foreground`` is empty.
    """
    assigned = np.asarray(assigned)
    truth = np.asarray(truth)
    if assigned.ndim != 2 or assigned.shape != truth.shape:
        raise ValueError(
            f"assigned and truth must be (H, W) label images of the same shape, got "
            f"{assigned.shape} and {truth.shape}"
        )
    for name, image in (("assigned", assigned), ("truth", truth)):
        if not np.issubdtype(image.dtype, np.integer):
            raise ValueError(f"{name} must hold integer labels, got dtype {image.dtype}")
    foreground = _bool_array(foreground, "foreground", truth.shape)
    total = int(np.count_nonzero(foreground))
    if total == 0:
        return math.nan
    return float(np.count_nonzero(assigned[foreground] == truth[foreground]) / total)


def foreground_scores(pred_mask: Any, true_mask: Any) -> tuple[float, float, float]:
    """Precision, recall and intersection over union of a foreground mask.

    Parameters
    ----------
    pred_mask, true_mask : (H, W) bool (any matching shape), predicted and true foreground.

    Returns
    -------
    ``(precision, recall, iou)`` as fractions in [0, 1]; each is NaN when its
    denominator (predicted, true, union pixels) is empty.
    """
    pred_mask = np.asarray(pred_mask)
    if pred_mask.dtype != np.bool_:
        raise ValueError(f"pred_mask must be a boolean array, got dtype {pred_mask.dtype}")
    true_mask = _bool_array(true_mask, "true_mask", pred_mask.shape)
    hits = int(np.count_nonzero(pred_mask & true_mask))

    def ratio(denominator: int) -> float:
        return hits / denominator if denominator else math.nan

    return (
        ratio(int(np.count_nonzero(pred_mask))),
        ratio(int(np.count_nonzero(true_mask))),
        ratio(int(np.count_nonzero(pred_mask | true_mask))),
    )
