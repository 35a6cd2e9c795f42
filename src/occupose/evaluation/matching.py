"""Which track is which person: tracks matched to ground-truth people, identity switches, and
the scores of a sequence (`score`: each person's Table I rows of occupose.evaluation.errors).

Distances are in metres. Tracks are ``{track_id: (T, J, 3) float}`` mappings, ground truth
a ``(T, P, J, 3)`` array; NaN where absent.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Mapping

import numpy as np
from scipy.optimize import linear_sum_assignment

from occupose._validate import bool_array, positive_float
from occupose.evaluation.errors import (
    MISSED_ERROR_M,
    TableRow,
    _nanmean,
    frame_errors,
    joint_errors,
    per_joint_errors,
    table_row,
)
from occupose.joints import JOINTS, NUM_JOINTS, UPPER_JOINTS

#: Cost of a frame where a person has ground truth and a track has no estimate, when
#: matching tracks to people (metres, as a mean joint distance).
ABSENT_COST_M = 0.5

# The joints of the upper-body model, (15,) bool: a track reporting no other joint is scored on them.
_UPPER = np.isin(JOINTS, UPPER_JOINTS)

# Cost of an impossible pairing (no common frame) in the assignment problem; far above
# any real mean distance in metres, so the solver pairs as many feasible pairs as it can.
_NO_OVERLAP_COST = 1e6


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
    gate_m = positive_float(gate_m, "gate_m")
    distances = _pair_distances(gt, tracks)  # (T, P, K)
    switches = np.zeros(gt.shape[1], dtype=np.int64)
    last = np.full(gt.shape[1], -1)
    for cost in distances:
        for person, track in _assign(np.where(cost <= gate_m, cost, np.nan)):
            if last[person] >= 0 and last[person] != track:
                switches[person] += 1
            last[person] = track
    return switches


def evaluated_joints(est: np.ndarray | None) -> np.ndarray:
    """(15,) bool, the joints a track is scored on (`score`): the upper-body model's 9 when
    ``est`` ((T, 15, 3) metres, NaN where not reported) reports no hip, knee or ankle in
    any frame, else all 15 (also for no track, None)."""
    if est is None:
        return np.ones(NUM_JOINTS, dtype=bool)
    reported = np.any(np.all(np.isfinite(est), axis=2), axis=0)
    return _UPPER.copy() if not reported[~_UPPER].any() else np.ones(NUM_JOINTS, dtype=bool)


def person_errors(gt: np.ndarray, gt_visible: np.ndarray, est: np.ndarray | None
                  ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The joint errors of one person against its track, as `score` counts them.

    Parameters
    ----------
    gt : (T, 15, 3) float64, metres; NaN where the person (or a joint) is absent.
    gt_visible : (T, 15) bool, ground-truth visibility.
    est : (T, 15, 3) float64 metres, NaN where not reported; None for no track.

    Returns
    -------
    errors : (T, E) float64, metres, over the E evaluated joints (`score`): the distance
        where both have the joint, ``MISSED_ERROR_M`` where ground truth has it and the
        track, in a frame it has, does not; NaN elsewhere (a frame without the track).
    known : (T, E) bool, ground truth has the joint and some joint of the person is visible.
    evaluated : (15,) bool, the evaluated joints.
    """
    evaluated = evaluated_joints(est)
    est = np.full(gt.shape, np.nan) if est is None else est
    gt, est = gt[:, evaluated], est[:, evaluated]
    gt_has, est_has = np.all(np.isfinite(gt), axis=2), np.all(np.isfinite(est), axis=2)
    errors = joint_errors(gt, est)
    errors[gt_has & ~est_has & est_has.any(axis=1)[:, None]] = MISSED_ERROR_M
    known = gt_has & np.any(gt_visible, axis=1)[:, None]
    return errors, known, evaluated


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
    joints are all 15, or the 9 of the upper-body model (`occupose.joints.UPPER_JOINTS`)
    when the matched track reports none of the others (no hip, knee or ankle) in any
    frame; the other joints are left out of both sides. A frame counts when ground truth
    has at least one evaluated joint and at least one of the person's joints is visible
    (for the visible-only row: at least one visible evaluated joint), and is missed when
    the track has no evaluated joint in it. In a frame the track has, an evaluated joint
    that ground truth has (for the visible-only row: has visible) and the track does not
    counts as an error of ``MISSED_ERROR_M`` (1 m), so leaving joints out never improves
    a score. A person without a track is missed in every counted frame (evaluated joints:
    all 15).

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
    gt_visible = bool_array(gt_visible, "gt_visible", gt_joints.shape[:3])
    tracks = _check_tracks(tracks, num_frames, num_joints)
    fps = positive_float(fps, "fps")
    matches = match_tracks(gt_joints, tracks)
    track_of = {person: track_id for track_id, person in matches.items()}
    switches = identity_switches(gt_joints, tracks, gate_m=gate_m)
    persons = []
    for person in range(num_people):
        track_id = track_of.get(person)
        est = None if track_id is None else tracks[track_id]
        errors, known, evaluated = person_errors(gt_joints[:, person], gt_visible[:, person], est)
        has_estimate = np.isfinite(errors).any(axis=1)
        rows = []
        for counted in (known, known & gt_visible[:, person, evaluated]):
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
