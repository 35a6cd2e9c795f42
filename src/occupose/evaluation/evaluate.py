"""Methods x scenarios x runs: the paper's Table I on our scenes, with plots.

:func:`evaluate` renders every scenario once (``OUT/recordings/<scenario>``, reused when
an earlier evaluation rendered it with the same settings), tracks each with every method
and seed (``OUT/runs/<scenario>/<method>/<seed>/tracks.csv`` and ``summary.json``),
scores the runs against the ground truth and writes

- ``OUT/results.csv``: one row per scenario, method, run and ground-truth person;
- ``OUT/report.md``: Table I (values averaged over the runs), per-joint errors,
  frames/s per method and the plots;
- ``OUT/error_<scenario>.png``: frame error over time per method, ground-truth
  occlusions shaded; ``OUT/error_vs_time.png``: mean error against time per frame.

Renders and runs go to a pool of worker processes (``spawn``), one per core, each with
one numba thread, so that two workers on two cores do not oversubscribe them. Measured on
the 2-core machine (2 scenarios x 2 methods x 120 frames, recordings reused, other jobs
running): two single-threaded workers took 48.8 and 56.0 s where one process with numba's
2 threads took 66.9 and 70.5 s (load 4.5-6.4, about 1.3x faster); at load 6-7 both took
57-71 s. Most of a frame is serial Python between small kernels, which a second numba
thread does not speed up, so the pool is kept as the default. ``jobs=1`` runs
everything in this process, with numba's default threads. Frames/s in the report are
measured while the runs share the cores: ``occupose track`` alone is faster.

Averaging rule: a row of the report's tables is the mean over the runs of each number
(mean, std, percentages, coverage; a run without any estimate has no mean or std and is
left out of those, and FAILs), and its status is FAIL when *any* run FAILs.
"""

from __future__ import annotations

import csv
import hashlib
import json
import math
import multiprocessing
import os
import queue as queue_module
import shutil
from collections.abc import Callable, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from dataclasses import dataclass, field, fields
from pathlib import Path

import numpy as np

from occupose.joints import JOINTS
from occupose.evaluation.errors import TableRow, frame_errors, joint_errors
from occupose.evaluation.matching import Score, match_tracks, score
from occupose.evaluation.pixels import ARM_PARTS, MIN_ARM_POINTS, arm_epsilons
from occupose.evaluation.report import markdown_table, number_cell, table_i_markdown
from occupose.io.joint_table import write_tracks_csv

#: Methods compared when none are named.
DEFAULT_METHODS: tuple[str, ...] = ("ours", "apf", "ps")
#: Seed of every scenario's scene (body size, clothes, sensor noise); runs differ in the tracker seed.
SCENE_SEED = 0
#: A frame is shaded in the error plots where at least this share of a present person's
#: joints is hidden in the ground truth (light), or at least MOSTLY_HIDDEN (dark).
PARTLY_HIDDEN = 0.25
MOSTLY_HIDDEN = 0.75
#: FAIL threshold drawn in the error plots, cm (errors.is_fail).
FAIL_THRESHOLD_CM = 25.0
#: Arm points per person and frame that the arm error (pixels.arm_epsilons) measures at
#: most, an even subsample of those seen.
ARM_SAMPLE = 400
#: Name of the file beside a rendered recording that records how it was rendered.
RENDER_INFO = "render.json"

Progress = Callable[[int, int], None]


# --------------------------------------------------------------------------- results


@dataclass(frozen=True)
class RunResult:
    """One method on one scenario with one seed.

    score : the Table I scores of every ground-truth person (occupose.evaluation.matching.Score)
    person_ids : ground-truth person ids, in the order of ``score.persons``
    frame_errors : (T, P) float64, metres: D_t of each person over the joints the matched
        track reports (NaN where the person is not counted or has no estimate)
    fps : frames per second of tracking, start-up excluded
    seconds : seconds per stage, ``total`` and ``startup`` (TrackingResult.seconds)
    arm_epsilon, truth_arm_epsilon : (T, P) float64, metres, or None for a recording
        without part labels: the second paper's arm error (pixels.arm_epsilons) of each
        person's matched track (NaN without an estimate) and of its ground truth
    """

    scenario: str
    method: str
    seed: int
    score: Score
    person_ids: tuple[int, ...]
    frame_errors: np.ndarray
    fps: float
    seconds: dict[str, float] = field(default_factory=dict)
    arm_epsilon: np.ndarray | None = None
    truth_arm_epsilon: np.ndarray | None = None


@dataclass(frozen=True)
class Evaluation:
    """What :func:`evaluate` did: every run and the files written."""

    runs: list[RunResult]
    report: Path
    results: Path
    plots: list[Path]


# --------------------------------------------------------------------------- checks


def _names(given: Sequence[str] | str | None, valid: Sequence[str], default: Sequence[str], what: str) -> list[str]:
    """Checked list of names (a comma-separated string or a sequence; None: ``default``)."""
    if given is None:
        return list(default)
    names = [n.strip() for n in given.split(",")] if isinstance(given, str) else [str(n) for n in given]
    names = [n for n in names if n]
    if not names:
        raise ValueError(f"no {what} given; valid names: {', '.join(valid)}")
    unknown = [n for n in names if n not in valid]
    if unknown:
        raise ValueError(f"unknown {what} {', '.join(map(repr, unknown))}; valid names: {', '.join(valid)}")
    if len(set(names)) != len(names):
        raise ValueError(f"{what} named twice: {names}")
    return names


def _positive_int(value, what: str) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
        raise ValueError(f"{what} must be an integer >= 1, got {value!r}")
    return int(value)


# --------------------------------------------------------------------------- tasks (run in workers)


def render_recording(scenario: str, out: Path, frames: int | None, procedural: bool,
                     progress: Callable[[int], None] | None = None) -> Path:
    """Render ``scenario`` (scene seed SCENE_SEED) into the recording folder ``out``, or
    keep the one already there when it was rendered with the same settings and the same
    ground-truth motion.

    frames : at most this many frames (None: all); procedural : never use mocap clips.
    An existing folder rendered differently (or half-written) is replaced.
    """
    from occupose.synth.generate import write_scenario
    from occupose.synth.scenarios import build_scenario

    built = build_scenario(scenario, seed=SCENE_SEED, use_mocap=not procedural)
    total = built.num_frames if frames is None else min(frames, built.num_frames)
    # the ground truth's digest: a recording of motion the scenario no longer makes is stale
    truth = hashlib.sha1(b"".join(np.ascontiguousarray(p.joints[:total]).tobytes() for p in built.people))
    info = {"scenario": scenario, "seed": SCENE_SEED, "frames": total, "motion_source": built.motion_source,
            "events": {k: list(v) for k, v in built.events.items()}, "truth": truth.hexdigest()}
    marker = out / RENDER_INFO
    if marker.is_file() and (out / "recording.json").is_file():
        try:
            if json.loads(marker.read_text()) == info:
                if progress is not None:
                    progress(total)
                return out
        except ValueError:
            pass  # unreadable: render again
    if out.exists():
        shutil.rmtree(out)
    write_scenario(built, out, seed=SCENE_SEED, num_frames=total, progress=progress)
    marker.write_text(json.dumps(info) + "\n")  # last: a folder without it is half-written
    return out


def arm_points(rec, person_ids: Sequence[int], max_points: int = ARM_SAMPLE) -> list[list[np.ndarray]]:
    """[person][frame] (N, 3) float64, world metres: the pixels of each person's arms
    (pixels.ARM_PARTS in the recording's part labels) that every camera measured,
    back-projected; at most ``max_points`` per frame, an even subsample. The recording
    must have person and part labels (Recording.has_labels)."""
    from occupose.camera import points_from_depth

    out: list[list[np.ndarray]] = [[] for _ in person_ids]
    for index in range(rec.num_frames):
        seen: list[list[np.ndarray]] = [[] for _ in person_ids]
        for camera in rec.cameras:
            depth = rec.depth_raw(index, camera.name)
            arms = np.isin(rec.label(index, camera.name, "part"), ARM_PARTS)
            person = rec.label(index, camera.name, "person")
            for p, pid in enumerate(person_ids):
                seen[p].append(points_from_depth(np.where(arms & (person == pid), depth, 0), camera)[0])
        for p, pieces in enumerate(seen):
            points = np.concatenate(pieces)
            out[p].append(points[:: -(-len(points) // max_points)] if len(points) > max_points else points)
    return out


def _tracked_arm_epsilons(gt_joints: np.ndarray, arms: list[list[np.ndarray]],
                          tracks: dict[int, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """(T, P) arm error (pixels.arm_epsilons) of each person's matched track (NaN
    without one) and of its ground-truth skeleton, metres."""
    tracked = np.full(gt_joints.shape[:2], np.nan)
    for track_id, person in match_tracks(gt_joints, tracks).items():
        tracked[:, person] = arm_epsilons(arms[person], tracks[track_id])
    truth = np.stack([arm_epsilons(arms[p], gt_joints[:, p]) for p in range(gt_joints.shape[1])], axis=1)
    return tracked, truth.reshape(gt_joints.shape[:2])


def _tracked_frame_errors(gt_joints: np.ndarray, gt_visible: np.ndarray, tracks: dict[int, np.ndarray]) -> np.ndarray:
    """(T, P) D_t of each person against its matched track, as matching.score counts it
    (joints the track reports, frames where some joint of the person is visible)."""
    num_frames, num_people = gt_joints.shape[:2]
    out = np.full((num_frames, num_people), np.nan)
    for track_id, person in match_tracks(gt_joints, tracks).items():
        est = tracks[track_id]
        evaluated = np.any(np.all(np.isfinite(est), axis=2), axis=0)
        gt = gt_joints[:, person, evaluated]
        counted = np.all(np.isfinite(gt), axis=2) & np.any(gt_visible[:, person], axis=1)[:, None]
        out[:, person] = frame_errors(joint_errors(gt, est[:, evaluated]), counted)
    return out


def run_method(recording: Path, scenario: str, method: str, seed: int, out: Path,
               progress: Callable[[int], None] | None = None, **settings) -> RunResult:
    """Track ``recording`` with ``method`` and ``seed`` into ``out``/tracks.csv and
    ``out``/summary.json, and score it against the recording's ground truth."""
    from occupose.io.recording import Recording
    from occupose.tracker import track_recording

    rec = Recording(recording)
    result = track_recording(rec, method, seed=seed, progress=progress, **settings)
    out.mkdir(parents=True, exist_ok=True)
    write_tracks_csv(out / "tracks.csv", result.tracks)
    summary = {"recording": str(rec.path), **result.settings, "frames": result.num_frames,
               "people": len(result.tracks), "seconds": {k: round(v, 4) for k, v in result.seconds.items()},
               "fps": round(result.fps, 2)}
    (out / "summary.json").write_text(json.dumps(summary, indent=2, default=list) + "\n")
    gt = rec.groundtruth()
    joints = {tid: track[0] for tid, track in result.tracks.items()}
    arms = None
    if rec.has_labels("part") and rec.has_labels("person"):
        arms = _tracked_arm_epsilons(gt.joints, arm_points(rec, gt.person_ids), joints)
    return RunResult(
        scenario=scenario, method=method, seed=seed,
        score=score(gt.joints, gt.visible, joints, rec.fps), person_ids=tuple(gt.person_ids),
        frame_errors=_tracked_frame_errors(gt.joints, gt.visible, joints),
        fps=float(result.fps), seconds=dict(result.seconds),
        arm_epsilon=None if arms is None else arms[0], truth_arm_epsilon=None if arms is None else arms[1],
    )


_progress_queue = None


def _init_worker(progress_queue, numba_threads: int) -> None:
    """Pool worker set-up: numba's thread count (before numba is imported: this module
    does not import it) and the queue that reports frames done to the parent."""
    global _progress_queue
    os.environ["NUMBA_NUM_THREADS"] = str(numba_threads)
    _progress_queue = progress_queue


def _in_worker(task: Callable, *args, **kwargs):
    return task(*args, progress=_progress_queue.put, **kwargs)


# --------------------------------------------------------------------------- evaluate


def evaluate(scenarios: Sequence[str] | str | None = None, methods: Sequence[str] | str | None = None,
             runs: int = 3, *, out: str | os.PathLike, frames: int | None = None, procedural: bool = False,
             jobs: int | None = None, progress: Progress | None = None, **settings) -> Evaluation:
    """Run every method on every scenario ``runs`` times (seeds 0..runs-1) and report.

    scenarios : names of occupose.synth.scenarios.SCENARIOS (a list or "a,b"); None: all
    methods : names of occupose.tracker.METHODS; None: DEFAULT_METHODS
    runs : runs per method and scenario, >= 1
    out : folder for recordings/, runs/, results.csv, report.md and the plots
    frames : render and track at most this many frames of each scenario (None: all)
    procedural : procedural motion even when the shared mocap clips are present
    jobs : worker processes (None: one per core; never more than the runs; 1: everything
        in this process)
    progress : callable(n, total) after n more frames were rendered or tracked, total
        being all the frames to render and track
    settings : tracker settings for every method (occupose.tracker.Tracker)

    Returns an Evaluation. Raises ValueError for unknown names or bad counts.
    """
    from occupose.synth.scenarios import SCENARIOS, build_scenario
    from occupose.tracker import METHODS

    scenarios = _names(scenarios, list(SCENARIOS), list(SCENARIOS), "scenario(s)")
    methods = _names(methods, list(METHODS), DEFAULT_METHODS, "method(s)")
    runs = _positive_int(runs, "runs")
    frames = None if frames is None else _positive_int(frames, "frames")
    jobs = len(os.sched_getaffinity(0)) if jobs is None else _positive_int(jobs, "jobs")
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    lengths = {}
    for name in scenarios:
        length = build_scenario(name, seed=SCENE_SEED, use_mocap=not procedural).num_frames
        lengths[name] = length if frames is None else min(frames, length)
    total = sum(lengths[s] * (1 + runs * len(methods)) for s in scenarios)
    report = (lambda n: progress(n, total)) if progress is not None else None
    renders = {s: (render_recording, s, out / "recordings" / s, frames, procedural) for s in scenarios}

    def runs_of(scenario: str) -> list[tuple]:
        return [(run_method, out / "recordings" / scenario, scenario, method, seed,
                 out / "runs" / scenario / method / str(seed)) for method in methods for seed in range(runs)]

    results = []
    jobs = min(jobs, len(scenarios) * len(methods) * runs)
    if jobs == 1:
        for scenario, task in renders.items():
            task[0](*task[1:], progress=report)
            for run in runs_of(scenario):
                results.append(run[0](*run[1:], progress=report, **settings))
    else:
        results = _in_pool(renders, runs_of, jobs, report, settings)
    order = {(s, m): i for i, (s, m) in enumerate((s, m) for s in scenarios for m in methods)}
    results.sort(key=lambda r: (order[r.scenario, r.method], r.seed))
    plots = write_plots(results, out, {s: out / "recordings" / s for s in scenarios})
    results_path = out / "results.csv"
    write_results_csv(results_path, results)
    report_path = out / "report.md"
    report_path.write_text(report_markdown(results, plots, out, jobs=jobs, frames=lengths, procedural=procedural))
    return Evaluation(results, report_path, results_path, plots)


def _in_pool(renders: dict, runs_of: Callable, jobs: int, progress, settings) -> list[RunResult]:
    """Renders, then each scenario's runs as soon as its recording is there, on ``jobs``
    spawned workers with one numba thread each."""
    context = multiprocessing.get_context("spawn")
    frames_done = context.Queue()
    results = []
    with ProcessPoolExecutor(jobs, mp_context=context,
                             initializer=_init_worker, initargs=(frames_done, 1)) as pool:
        pending: dict[Future, str | None] = {pool.submit(_in_worker, *task): scenario
                                             for scenario, task in renders.items()}
        try:
            while pending:
                done, _ = wait(pending, timeout=0.5, return_when=FIRST_COMPLETED)
                _drain(frames_done, progress)
                for future in done:
                    scenario = pending.pop(future)
                    result = future.result()
                    if scenario is None:
                        results.append(result)
                        continue
                    for run in runs_of(scenario):
                        pending[pool.submit(_in_worker, *run, **settings)] = None
        except BaseException:
            pool.shutdown(wait=False, cancel_futures=True)
            raise
    _drain(frames_done, progress)
    return results


def _drain(frames_done, progress) -> None:
    count = 0
    while True:
        try:
            count += frames_done.get_nowait()
        except queue_module.Empty:
            break
    if progress is not None and count:
        progress(count)


# --------------------------------------------------------------------------- tables


def mean_row(rows: Sequence[TableRow]) -> TableRow:
    """The mean of Table I rows over runs: each number averaged over the runs that have
    it (NaN when none does), FAIL when any run FAILs, frames rounded."""
    if not rows:
        raise ValueError("mean_row needs at least one row")
    values = {}
    for f in fields(TableRow):
        column = [getattr(r, f.name) for r in rows]
        if f.name == "fail":
            values[f.name] = any(column)
        elif f.name == "frames":
            values[f.name] = int(round(float(np.mean(column))))
        else:
            finite = [v for v in column if not math.isnan(v)]
            values[f.name] = float(np.mean(finite)) if finite else math.nan
    return TableRow(**values)


def _groups(runs: Sequence[RunResult]) -> dict[str, dict[str, list[tuple[RunResult, int]]]]:
    """{sequence label: {method: [(run, person index)]}} in run order; a scenario with
    several people has one sequence per person ("two_people_crossing, person 2")."""
    groups: dict[str, dict[str, list]] = {}
    for run in runs:
        for index, pid in enumerate(run.person_ids):
            label = run.scenario if len(run.person_ids) == 1 else f"{run.scenario}, person {pid}"
            groups.setdefault(label, {}).setdefault(run.method, []).append((run, index))
    return groups


def table_rows(runs: Sequence[RunResult], visible: bool = False) -> dict[str, dict[str, TableRow]]:
    """{sequence: {method: TableRow averaged over the runs (mean_row)}}; ``visible``:
    over the ground-truth-visible joints only."""
    which = "visible_joints" if visible else "all_joints"
    return {label: {method: mean_row([getattr(r.score.persons[i], which) for r, i in items])
                    for method, items in methods.items()}
            for label, methods in _groups(runs).items()}


def _seconds_keys(runs: Sequence[RunResult]) -> list[str]:
    keys = []
    for run in runs:
        keys += [k for k in run.seconds if k not in keys]
    return keys


def results_table(runs: Sequence[RunResult]) -> list[dict[str, object]]:
    """One dict per scenario, method, run (seed) and ground-truth person: Table I over all
    joints and over visible joints, the arm error of the track and of the ground truth,
    identity switches, frames/s, seconds per stage."""
    stage_keys = _seconds_keys(runs)
    rows = []
    for run in runs:
        for index, (person, pid) in enumerate(zip(run.score.persons, run.person_ids)):
            row: dict[str, object] = {"scenario": run.scenario, "method": run.method, "seed": run.seed,
                                      "person": pid, "track": "" if person.track is None else person.track}
            for prefix, table in (("", person.all_joints), ("visible_", person.visible_joints)):
                row |= {f"{prefix}mean_cm": table.mean_cm, f"{prefix}std_cm": table.std_cm,
                        f"{prefix}under10": table.under10, f"{prefix}under15": table.under15,
                        f"{prefix}under20": table.under20, f"{prefix}over20": table.over20,
                        f"{prefix}fail": int(table.fail), f"{prefix}frames": table.frames,
                        f"{prefix}coverage": table.coverage}
            row |= dict(zip(("arm_eps_cm", "truth_arm_eps_cm"), _arm_errors_cm(run, index)))
            row |= {"identity_switches": person.identity_switches,
                    "unmatched_tracks": len(run.score.unmatched_tracks), "fps": run.fps}
            row |= {f"seconds_{k}": run.seconds.get(k, math.nan) for k in stage_keys}
            rows.append(row)
    return rows


def _arm_errors_cm(run: RunResult, person: int) -> tuple[float, float]:
    """Mean arm error (pixels.arm_epsilons) over the frames that have one, cm, of the
    person's track and of its ground truth; NaN without one (or without part labels)."""
    if run.arm_epsilon is None:
        return math.nan, math.nan
    means = []
    for values in (run.arm_epsilon[:, person], run.truth_arm_epsilon[:, person]):
        finite = values[np.isfinite(values)]
        means.append(100.0 * float(finite.mean()) if finite.size else math.nan)
    return means[0], means[1]


def write_results_csv(path: str | os.PathLike, runs: Sequence[RunResult]) -> Path:
    """Write :func:`results_table` as csv (numbers with 4 decimals, NaN as empty)."""
    rows = results_table(runs)
    path = Path(path)
    with path.open("w", newline="", encoding="utf-8") as handle:
        if not rows:
            return path
        writer = csv.DictWriter(handle, fieldnames=list(rows[0]))
        writer.writeheader()
        for row in rows:
            writer.writerow({k: ("" if isinstance(v, float) and math.isnan(v) else
                                 f"{v:.4f}" if isinstance(v, float) else v) for k, v in row.items()})
    return path


def per_joint_table(runs: Sequence[RunResult]) -> dict[str, dict[str, float]]:
    """{joint: {method: mean error cm over scenarios, runs and people}} (NaN where no
    run of the method reports the joint)."""
    methods = list(dict.fromkeys(r.method for r in runs))
    out = {}
    for joint in JOINTS:
        out[joint] = {}
        for method in methods:
            values = [p.per_joint_cm.get(joint, math.nan) for r in runs if r.method == method for p in r.score.persons]
            finite = [v for v in values if not math.isnan(v)]
            out[joint][method] = float(np.mean(finite)) if finite else math.nan
    return out


def speed_table(runs: Sequence[RunResult]) -> dict[str, dict[str, float]]:
    """{method: {"fps": frames/s, "ms": ms/frame, "<stage> ms": ms/frame per stage}} over
    all runs of the method pooled (all frames over all seconds); fps and ms leave out the
    first (start-up) frame of each run, the stage times include it."""
    out = {}
    for method in dict.fromkeys(r.method for r in runs):
        mine = [r for r in runs if r.method == method]
        frames = sum(len(r.frame_errors) for r in mine)
        seconds = sum(r.seconds.get("total", math.nan) for r in mine)
        ms = 1000.0 * seconds / max(frames - len(mine), 1)
        entry = {"fps": 1000.0 / ms if ms > 0 else math.nan, "ms": ms}
        for key in _seconds_keys(mine):
            if key not in ("total", "startup"):
                entry[f"{key} ms"] = 1000.0 * sum(r.seconds.get(key, math.nan) for r in mine) / max(frames, 1)
        out[method] = entry
    return out


def _arm_section(runs: Sequence[RunResult], methods: list[str]) -> list[str]:
    """The report's lines on the second paper's arm error (none without part labels)."""
    rows = []
    for label, by_method in _groups(runs).items():
        means = {m: [_arm_errors_cm(r, i) for r, i in items] for m, items in by_method.items()}
        if all(math.isnan(v) for pairs in means.values() for pair in pairs for v in pair):
            continue
        tracked = {m: float(np.nanmean([a for a, _ in pairs])) if any(not math.isnan(a) for a, _ in pairs)
                   else math.nan for m, pairs in means.items()}
        finite = [v for v in tracked.values() if not math.isnan(v)]
        best = min(finite) if len(finite) > 1 else math.nan
        truth = next(t for pairs in means.values() for _, t in pairs)
        rows.append([label, *(f"**{number_cell(tracked[m])}**" if round(tracked.get(m, math.nan), 2) == round(best, 2)
                              else number_cell(tracked.get(m, math.nan)) for m in methods), number_cell(truth)])
    if not rows:
        return []
    return ["## Arm error: the second paper's epsilon [cm]", "",
            "Mean over the frames with at least "
            f"{MIN_ARM_POINTS} arm points seen and an estimate, and over the runs, of the mean distance from "
            "the person's arm points (upper arms, forearms, hands in the part labels; every camera) to the "
            "nearest arm bone of the skeleton (occupose.evaluation.pixels). Lowest per sequence in bold. The points lie "
            "on the surface, so the ground truth's skeleton has an epsilon too (last column): what a perfect "
            "skeleton scores.", "",
            markdown_table(["sequence", *methods, "ground truth"], rows, text_columns=1), ""]


def report_markdown(runs: Sequence[RunResult], plots: Sequence[Path] = (), root: Path | None = None, *,
                    jobs: int | None = None, frames: dict[str, int] | None = None, procedural: bool = False) -> str:
    """The evaluation report (markdown): Table I over all joints (best value of each column
    per sequence in bold) and over visible joints, runs that FAIL, identity switches,
    per-joint errors, frames/s per method and the plots (paths relative to ``root``)."""
    seeds = sorted({r.seed for r in runs})
    methods = list(dict.fromkeys(r.method for r in runs))
    lines = ["# Evaluation", ""]
    lines.append(f"Methods {', '.join(methods)}; {len(seeds)} run(s) each (tracker seeds "
                 f"{', '.join(map(str, seeds))}); motion: {'procedural' if procedural else 'mocap where available'}.")
    if frames:
        lines.append("Frames: " + ", ".join(f"{s} {n}" for s, n in frames.items()) + ".")
    lines += ["", "Each value is the mean over the runs (runs without any estimate are left out of "
              "the mean and std); Status is FAIL when any run FAILs (the 2-second rolling mean of D_t "
              "exceeds 25 cm after the first second; occupose.evaluation.errors). Best value of each column per "
              "sequence in **bold**.", "", "## Table I: all joints", "", table_i_markdown(table_rows(runs)), "",
              "## Table I: ground-truth-visible joints only", "", table_i_markdown(table_rows(runs, visible=True)), ""]
    fails = []
    for label, by_method in _groups(runs).items():
        for method, items in by_method.items():
            failed = [r.seed for r, i in items if r.score.persons[i].all_joints.fail]
            if failed:
                fails.append(f"- {label}, {method}: {len(failed)} of {len(items)} runs (seeds "
                             f"{', '.join(map(str, failed))})")
    lines += ["Runs that FAIL:", "", *(fails or ["- none"]), ""]
    nobody = list(dict.fromkeys(r.scenario for r in runs if not r.person_ids))
    if nobody:
        lines += ["Nobody is in view in the ground truth of the frames evaluated (not scored; tracks found):", ""]
        for scenario in nobody:
            found = ", ".join(f"{r.method} seed {r.seed}: {len(r.score.unmatched_tracks)}"
                              for r in runs if r.scenario == scenario)
            lines.append(f"- {scenario} ({found})")
        lines.append("")
    switches = [[label, method, number_cell(float(np.mean([r.score.persons[i].identity_switches for r, i in items]))),
                 number_cell(float(np.mean([len(r.score.unmatched_tracks) for r, i in items])))]
                for label, by_method in _groups(runs).items() for method, items in by_method.items()]
    lines += ["## Identities", "", "Mean over the runs of the person's identity switches and of the "
              "tracks matched to no person.", "",
              markdown_table(["sequence", "method", "identity switches", "unmatched tracks"], switches, text_columns=1), ""]
    lines += _arm_section(runs, methods)
    joints = per_joint_table(runs)
    joint_rows = []
    for joint, values in joints.items():
        finite = [v for v in values.values() if not math.isnan(v)]
        best = min(finite) if finite else math.nan
        joint_rows.append([joint, *(f"**{number_cell(v)}**" if len(finite) > 1 and round(v, 2) == round(best, 2)
                                    else number_cell(v) for v in values.values())])
    lines += ["## Per-joint error [cm]", "", "Mean over scenarios, runs and people; lowest per joint in bold (when several methods report it); "
              "n/a: the method's model does not report the joint.", "",
              markdown_table(["joint", *methods], joint_rows, text_columns=1), ""]
    speeds = speed_table(runs)
    stage_columns = list(dict.fromkeys(k for v in speeds.values() for k in v if k.endswith(" ms")))
    speed_rows = [[m, number_cell(v["fps"], 1), number_cell(v["ms"], 1), *(number_cell(v.get(k, math.nan), 1) for k in stage_columns)]
                  for m, v in speeds.items()]
    timing = ("in parallel, one run per worker and core, one numba thread per worker" if (jobs or 1) > 1
              else "one run at a time with numba's default threads")
    lines += ["## Speed", "", f"Mean over all runs, timed {timing} (`occupose track` alone can be faster); "
              "the first frame (start-up, compilation) excluded; per-stage times include it.", "",
              markdown_table(["method", "frames/s", "ms/frame", *stage_columns], speed_rows, text_columns=1), ""]
    if plots:
        lines += ["## Plots", ""]
        for plot in plots:
            shown = Path(plot).relative_to(root) if root is not None else Path(plot)
            lines += [f"![{shown.stem}]({shown.as_posix()})", ""]
    return "\n".join(lines)


# --------------------------------------------------------------------------- plots


def intervals_from_mask(mask) -> list[tuple[int, int]]:
    """[start, stop) frame intervals where ``mask`` ((T,) bool) is true."""
    mask = np.asarray(mask, bool)
    if mask.ndim != 1:
        raise ValueError(f"mask must have shape (T,), got {mask.shape}")
    edges = np.diff(np.concatenate([[0], mask.astype(np.int8), [0]]))
    return list(zip(np.flatnonzero(edges == 1).tolist(), np.flatnonzero(edges == -1).tolist()))


def hidden_share(gt_joints: np.ndarray, gt_visible: np.ndarray) -> np.ndarray:
    """(T, P) share of each present person's joints hidden in the ground truth (NaN
    where the person is absent). gt_joints : (T, P, 15, 3) metres; gt_visible : (T, P, 15)."""
    present = np.any(np.all(np.isfinite(gt_joints), axis=3), axis=2)
    return np.where(present, 1.0 - gt_visible.mean(axis=2), np.nan)


def write_plots(runs: Sequence[RunResult], out: Path, recordings: dict[str, Path]) -> list[Path]:
    """Error over time per scenario (OUT/error_<scenario>.png) and the error-versus-time
    curve (OUT/error_vs_time.png); returns the paths written."""
    import matplotlib

    matplotlib.use("Agg")
    from occupose.io.recording import Recording

    methods = list(dict.fromkeys(r.method for r in runs))
    colors = {m: f"C{i}" for i, m in enumerate(methods)}
    paths = []
    for scenario, folder in recordings.items():
        mine = [r for r in runs if r.scenario == scenario]
        if not mine:
            continue
        rec = Recording(folder)
        gt = rec.groundtruth()
        if not gt.person_ids:
            continue  # nobody in view in the frames evaluated: nothing to plot
        info = json.loads((folder / RENDER_INFO).read_text()) if (folder / RENDER_INFO).is_file() else {}
        events = {name: tuple(span) for name, span in info.get("events", {}).items()}
        paths.append(_plot_errors(scenario, mine, methods, colors, hidden_share(gt.joints, gt.visible),
                                  gt.person_ids, events, rec.fps, out / f"error_{scenario}.png"))
    if runs:
        paths.append(_plot_speed(runs, methods, colors, out / "error_vs_time.png"))
    return paths


def _plot_errors(scenario, runs, methods, colors, hidden, person_ids, events, fps, path: Path) -> Path:
    import matplotlib.pyplot as plt

    num_people = hidden.shape[1]
    figure, axes = plt.subplots(num_people, 1, figsize=(10, 3.2 * num_people), squeeze=False, sharex=True)
    seconds = np.arange(hidden.shape[0]) / fps
    for p, ax in enumerate(axes[:, 0]):
        share = np.nan_to_num(hidden[:, p], nan=0.0)
        for k, (start, stop) in enumerate(intervals_from_mask(np.isnan(hidden[:, p]))):
            ax.axvspan(start / fps, stop / fps, facecolor="none", edgecolor="0.75", hatch="///", lw=0,
                       label="not in view" if k == 0 else None)
        for low, shade, label in ((PARTLY_HIDDEN, "0.88", f">= {PARTLY_HIDDEN:.0%} joints hidden"),
                                  (MOSTLY_HIDDEN, "0.7", f">= {MOSTLY_HIDDEN:.0%} joints hidden")):
            for k, (start, stop) in enumerate(intervals_from_mask(share >= low)):
                ax.axvspan(start / fps, stop / fps, color=shade, lw=0, label=label if k == 0 else None)
        top = FAIL_THRESHOLD_CM * 2
        for method in methods:
            errors = np.stack([r.frame_errors[:, p] for r in runs if r.method == method]) * 100.0
            finite = np.isfinite(errors)
            counts = finite.sum(axis=0)
            mean = np.where(counts > 0, np.where(finite, errors, 0.0).sum(axis=0) / np.maximum(counts, 1), np.nan)
            ax.plot(seconds, mean, color=colors[method], lw=1.2, label=f"{method} (mean of {len(errors)})")
            if len(errors) > 1:  # NaN bounds (no estimate) leave gaps in the band
                ax.fill_between(seconds, np.where(finite, errors, np.inf).min(axis=0),
                                np.where(finite, errors, -np.inf).max(axis=0), where=counts > 0,
                                color=colors[method], alpha=0.15, lw=0)
            if np.any(np.isfinite(mean)):
                top = max(top, min(float(np.nanmax(mean)) * 1.05, 150.0))
        ax.axhline(FAIL_THRESHOLD_CM, color="k", ls="--", lw=0.8, label="25 cm (FAIL rule)")
        for k, (name, (start, stop)) in enumerate(events.items()):
            ax.axvspan(start / fps, min(stop, hidden.shape[0]) / fps, ymin=0.96, ymax=1.0, color=f"C{k + 5}", lw=0)
            ax.text(start / fps, top * 0.93, f" {name}", fontsize=8, va="top", color=f"C{k + 5}")
        ax.set_ylim(0, top)
        ax.set_xlim(0, seconds[-1] if len(seconds) > 1 else 1)
        ax.set_ylabel(f"D_t [cm]{'' if num_people == 1 else f', person {person_ids[p]}'}")
        ax.legend(fontsize=7, loc="upper right", ncol=2)
    axes[-1, 0].set_xlabel("time [s]")
    axes[0, 0].set_title(f"{scenario}: mean joint error per frame (band: min-max over runs)")
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)
    return path


def _plot_speed(runs, methods, colors, path: Path) -> Path:
    import matplotlib.pyplot as plt

    figure, ax = plt.subplots(figsize=(6, 4.2))
    rows = table_rows(runs)
    speeds = speed_table(runs)
    for method in methods:
        per_sequence = [by_method[method].mean_cm for by_method in rows.values() if method in by_method]
        per_ms = [speeds[method]["ms"]] * len(per_sequence)
        ax.scatter(per_ms, per_sequence, color=colors[method], alpha=0.3, s=14)
        finite = [v for v in per_sequence if not math.isnan(v)]
        if finite:
            x, y = speeds[method]["ms"], float(np.mean(finite))
            ax.scatter([x], [y], color=colors[method], s=60, label=method, edgecolor="k")
            ax.annotate(method, (x, y), textcoords="offset points", xytext=(6, 4), fontsize=9)
    ax.set_xlabel("time per frame [ms] (mean over runs)")
    ax.set_ylabel("mean error [cm]")
    ax.set_title("error versus time per frame\n(large: mean over sequences; small: each sequence)", fontsize=10)
    ax.set_xlim(left=0)
    ax.set_ylim(bottom=0)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    plt.close(figure)
    return path


__all__ = ["DEFAULT_METHODS", "Evaluation", "RunResult", "evaluate", "hidden_share", "intervals_from_mask",
           "mean_row", "per_joint_table", "render_recording", "report_markdown", "results_table", "run_method",
           "speed_table", "table_rows", "write_plots", "write_results_csv"]
