"""Robustness figures: per person-run metrics and their aggregates per condition bucket.

A *run* is one recording tracked once (one tracker seed); a *person-run* is one ground-truth
person of a run in the sensor's sight for at least ``MIN_PRESENCE_S`` (a person the sensor
never sees is no person of the run). Each person-run gets, from
occupose.evaluation.matching.score (the tracks matched to people for the whole sequence):

mean_cm
    Table I's mean of ``D_t`` over all evaluated joints (errors module), cm; NaN when no
    frame is estimated.
under20
    Percent of counted frames with ``D_t <= 20 cm`` (a missed frame is not under).
within10
    ITOP-style: percent of the ground-truth-visible evaluated joints of the counted frames
    whose estimate is within 10 cm (``WITHIN_M``); a joint without an estimate is not within.
coverage
    Percent of counted frames that are estimated.
fail
    The automatic FAIL rule of occupose.evaluation.errors (``is_fail``).
fail_frame, visible_at_fail, missed_before_fail
    Where a FAIL trips (None without one): the first frame at which the rule trips
    (``fail_frame`` of errors), the person's ground-truth-visible joints in that frame
    (of 15: a person mostly hidden, or entering or leaving the image, shows few), and the
    share of the counted frames of the rule's window ending there (``FAIL_WINDOW_S``) that
    have no estimate (a person not yet started, or lost).
switches
    Identity switches of the person (matching.identity_switches).

and each run gets ``people`` (ground-truth people with at least ``MIN_PRESENCE_S`` of
counted frames) and ``tracks`` (tracks that report a skeleton in at least ``MIN_PRESENCE_S``
of frames, so a ghost of a few frames is not a track; in a recording shorter than that, in
all of its frames); the run has the right track count
when the two are equal.

`summarise` groups person-runs by a condition (a key of the recording's conditions) and
reports per bucket: runs, person-runs, the mean and median of the person-runs' mean_cm,
the means of under20, within10 and coverage, the FAIL rate (percent of person-runs), the
percent of multi-person runs without any identity switch and the percent of runs with the
right track count.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping, Sequence
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from occupose._validate import positive_float
from occupose.evaluation.errors import joint_errors
from occupose.evaluation.matching import evaluated_joints, score

#: Distance under which a joint counts as found (ITOP's 10 cm rule), metres.
WITHIN_M = 0.10
#: Shortest presence, seconds, for a person to count among a run's people and a track among its tracks.
MIN_PRESENCE_S = 1.0
#: Files of a recording folder that may hold its drawn conditions (a ``"conditions"`` object), in order.
CONDITION_FILES = ("scene.json", "render.json", "recording.json")
#: A camera whose optical axis points down more steeply than this, degrees below horizontal, is a top view.
TOP_VIEW_PITCH_DEG = 60.0
#: A numeric condition with more distinct values than this is bucketed in this many bins of about equal counts.
NUMERIC_BINS = 3
#: The FAIL rule's window (occupose.evaluation.errors.fail_curve's default), seconds.
FAIL_WINDOW_S = 2.0


@dataclass(frozen=True)
class PersonRun:
    """Figures of one ground-truth person in one run (module docstring)."""

    scene: str
    seed: int
    person: int
    mean_cm: float
    under20: float
    within10: float
    coverage: float
    fail: bool
    switches: int
    fail_frame: int | None = None
    visible_at_fail: int | None = None
    missed_before_fail: float | None = None


@dataclass(frozen=True)
class Run:
    """One tracked recording: its conditions, people, tracks and person-runs."""

    scene: str
    seed: int
    conditions: dict[str, Any]
    people: int
    tracks: int
    persons: tuple[PersonRun, ...] = field(default=())

    @property
    def right_tracks(self) -> bool:
        """Whether the run has as many lasting tracks as people."""
        return self.tracks == self.people

    @property
    def switches(self) -> int:
        """Identity switches of all its people."""
        return sum(p.switches for p in self.persons)

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready form (`run_from_dict` reads it back)."""
        return asdict(self)


def run_from_dict(data: Mapping[str, Any]) -> Run:
    """The `Run` that `Run.as_dict` wrote."""
    persons = tuple(PersonRun(**p) for p in data["persons"])
    return Run(scene=data["scene"], seed=int(data["seed"]), conditions=dict(data["conditions"]),
               people=int(data["people"]), tracks=int(data["tracks"]), persons=persons)


# --------------------------------------------------------------------------- per run


def within_share(gt_joints: Any, gt_visible: Any, est: Any, *, within_m: float = WITHIN_M) -> float:
    """Percent of the visible ground-truth joints whose estimate is within ``within_m``.

    gt_joints, est : (T, J, 3) float, metres, NaN where absent; gt_visible : (T, J) bool.
    Only joints visible and known in ground truth count; a missing estimate is not within.
    NaN when no joint counts.
    """
    gt_joints = np.asarray(gt_joints, dtype=np.float64)
    counted = np.asarray(gt_visible, dtype=bool) & np.all(np.isfinite(gt_joints), axis=-1)
    total = int(np.count_nonzero(counted))
    if total == 0:
        return math.nan
    errors = joint_errors(gt_joints, est)
    found = counted & (np.nan_to_num(errors, nan=np.inf) <= positive_float(within_m, "within_m"))
    return 100.0 * float(np.count_nonzero(found)) / total


def score_run(scene: str, seed: int, conditions: Mapping[str, Any], gt_joints: Any, gt_visible: Any,
              tracks: Mapping[Any, Any], fps: float) -> Run:
    """The `Run` of one tracked recording.

    gt_joints : (T, P, 15, 3) float, metres; gt_visible : (T, P, 15) bool;
    tracks : ``{track_id: (T, 15, 3) float, metres}``, NaN where not reported; fps : frames/s.
    """
    result = score(gt_joints, gt_visible, tracks, fps)
    gt_joints = np.asarray(gt_joints, dtype=np.float64)
    gt_visible = np.asarray(gt_visible, dtype=bool)
    lasting = max(1, min(int(round(MIN_PRESENCE_S * fps)), gt_joints.shape[0]))  # a short recording: all of it
    present = np.any(gt_visible, axis=2).sum(axis=0)  # (P,) frames in sight
    persons = []
    for index, person in enumerate(result.persons):
        if present[index] < lasting:  # no person of the run (never in the sensor's sight, or too briefly)
            continue
        if person.track is None:
            est = np.full(gt_joints.shape[:1] + gt_joints.shape[2:], np.nan)
            evaluated = evaluated_joints(None)
        else:
            est = np.asarray(tracks[person.track], dtype=np.float64)
            evaluated = evaluated_joints(est)
        in_sight = np.any(gt_visible[:, index], axis=1)[:, None]
        visible = gt_visible[:, index][:, evaluated] & in_sight
        row = person.all_joints
        persons.append(PersonRun(
            scene=scene, seed=seed, person=index, mean_cm=row.mean_cm, under20=row.under20,
            within10=within_share(gt_joints[:, index][:, evaluated], visible, est[:, evaluated]),
            coverage=row.coverage, fail=row.fail, switches=person.identity_switches,
            **_where_it_fails(row.fail_frame, gt_joints[:, index][:, evaluated], gt_visible[:, index],
                              est[:, evaluated], fps),
        ))
    people = int(np.count_nonzero(present >= lasting))
    reported = [int(np.count_nonzero(np.any(np.all(np.isfinite(np.asarray(t)), axis=2), axis=1)))
                for t in tracks.values()]
    return Run(scene=scene, seed=seed, conditions=dict(conditions), people=people,
               tracks=sum(frames >= lasting for frames in reported), persons=tuple(persons))


def _where_it_fails(frame: int | None, gt_joints: np.ndarray, gt_visible: np.ndarray, est: np.ndarray,
                    fps: float) -> dict[str, Any]:
    """PersonRun's fail_frame, visible_at_fail and missed_before_fail (module docstring) of
    one person: gt_joints, est (T, E, 3) metres over the evaluated joints, gt_visible (T, 15)."""
    if frame is None:
        return {}
    counted = np.any(np.all(np.isfinite(gt_joints), axis=2), axis=1) & np.any(gt_visible, axis=1)
    missed = counted & ~np.any(np.all(np.isfinite(est), axis=2), axis=1)
    window = slice(max(0, frame + 1 - int(round(FAIL_WINDOW_S * fps))), frame + 1)
    return {"fail_frame": frame, "visible_at_fail": int(np.count_nonzero(gt_visible[frame])),
            "missed_before_fail": float(missed[window].sum() / max(1, counted[window].sum()))}


def recording_conditions(folder: str | Path, cameras: Sequence[Any], num_people: int) -> dict[str, Any]:
    """The conditions a recording was drawn under: the ``"conditions"`` object of the first of
    ``CONDITION_FILES`` in ``folder`` that has a non-empty one (a catalogue scene's is
    empty); else the two that can be read off any recording: ``view`` ("top" when some
    camera's optical axis points down by more than ``TOP_VIEW_PITCH_DEG``, else "front")
    and ``people`` (``num_people``)."""
    folder = Path(folder)
    for name in CONDITION_FILES:
        path = folder / name
        if path.is_file():
            data = json.loads(path.read_text())
            if isinstance(data, dict) and isinstance(data.get("conditions"), dict) and data["conditions"]:
                return dict(data["conditions"])
    pitch = [math.degrees(math.asin(-float(np.asarray(c.world_from_camera)[2, 2]))) for c in cameras]
    return {"view": "top" if max(pitch) > TOP_VIEW_PITCH_DEG else "front", "people": int(num_people)}


# --------------------------------------------------------------------------- aggregates


def _mean(values: Sequence[float]) -> float:
    finite = [v for v in values if not math.isnan(v)]
    return float(np.mean(finite)) if finite else math.nan


def _median(values: Sequence[float]) -> float:
    finite = [v for v in values if not math.isnan(v)]
    return float(np.median(finite)) if finite else math.nan


def bucket_figures(runs: Sequence[Run]) -> dict[str, float | int]:
    """Aggregates of ``runs`` (module docstring): runs, person_runs, mean_cm, median_cm,
    under20, within10, coverage, fail_rate, switch_free and right_tracks (percent; NaN when
    no run or person-run counts). A person-run never estimated has no mean_cm; it counts in
    the FAIL rate, under20, within10 and coverage."""
    persons = [p for run in runs for p in run.persons]
    multi = [run for run in runs if run.people > 1]
    return {
        "runs": len(runs),
        "person_runs": len(persons),
        "mean_cm": _mean([p.mean_cm for p in persons]),
        "median_cm": _median([p.mean_cm for p in persons]),
        "under20": _mean([p.under20 for p in persons]),
        "within10": _mean([p.within10 for p in persons]),
        "coverage": _mean([p.coverage for p in persons]),
        "fail_rate": 100.0 * sum(p.fail for p in persons) / len(persons) if persons else math.nan,
        "switch_free": 100.0 * sum(run.switches == 0 for run in multi) / len(multi) if multi else math.nan,
        "right_tracks": 100.0 * sum(run.right_tracks for run in runs) / len(runs) if runs else math.nan,
    }


def summarise(runs: Sequence[Run], by: str | None = None) -> dict[str, dict[str, float | int]]:
    """`bucket_figures` per value of the condition ``by`` (runs without it go to "n/a"),
    buckets in sorted order; a numeric condition with more than ``NUMERIC_BINS`` values (a
    camera's height, a noise level) in ``NUMERIC_BINS`` bins of about equal counts, named
    "low..high" and in increasing order; ``by=None``: one bucket "all"."""
    if by is None:
        return {"all": bucket_figures(runs)}
    values = [run.conditions.get(by) for run in runs]
    numbers = [v for v in values if _is_number(v)]
    groups: dict[str, list[Run]] = {}
    if len(set(numbers)) > NUMERIC_BINS:
        edges = np.quantile(numbers, np.linspace(0.0, 1.0, NUMERIC_BINS + 1))
        names = [f"{lo:.3g}..{hi:.3g}" for lo, hi in zip(edges[:-1], edges[1:])]
        for name in names:
            groups[name] = []
        for run, value in zip(runs, values):
            name = names[min(int(np.searchsorted(edges, value, side="right")) - 1, NUMERIC_BINS - 1)] \
                if _is_number(value) else "n/a"
            groups.setdefault(name, []).append(run)
        return {name: bucket_figures(group) for name, group in groups.items() if group}
    for run, value in zip(runs, values):
        groups.setdefault("n/a" if value is None else str(value), []).append(run)
    return {value: bucket_figures(groups[value]) for value in sorted(groups)}


def _is_number(value) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def condition_keys(runs: Sequence[Run]) -> list[str]:
    """The condition keys that some run has with a single value (a name, a number or a
    flag: not a list such as ``focal_scale`` or a table such as ``persons``), in
    first-seen order."""
    keys: dict[str, None] = {}
    for run in runs:
        keys.update(dict.fromkeys(k for k, v in run.conditions.items()
                                  if isinstance(v, (str, int, float, bool))))
    return list(keys)


__all__ = [
    "CONDITION_FILES", "MIN_PRESENCE_S", "NUMERIC_BINS", "PersonRun", "Run", "TOP_VIEW_PITCH_DEG", "WITHIN_M",
    "bucket_figures", "condition_keys", "recording_conditions", "run_from_dict", "score_run", "summarise", "within_share",
]
