"""Methods x scenarios x runs: the paper's Table I on our scenes, with plots.

:func:`evaluate` renders every scenario once (``OUT/recordings/<scenario>``; with
``force``, an earlier evaluation's render with the same settings is reused), tracks each
with every method and seed (``OUT/runs/<scenario>/<method>/<seed>/tracks.csv`` and
``summary.json``),
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

The tables, ``results.csv``, ``report.md`` and the plots are occupose.evaluation.report's
(which also states how the runs are averaged); this module runs and collects.
"""

from __future__ import annotations

import json
import multiprocessing
import os
import queue as queue_module
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from occupose._validate import positive_int
from occupose.evaluation.errors import frame_errors
from occupose.evaluation.matching import match_tracks, person_errors, score
from occupose.evaluation.pixels import ARM_PARTS, arm_epsilons
from occupose.evaluation.report import RunResult, report_markdown, write_plots, write_results_csv
from occupose.io.output import link_tree, staged_folder

#: Methods compared when none are named.
DEFAULT_METHODS: tuple[str, ...] = ("ours", "apf", "ps")
#: Seed of every scenario's scene (body size, clothes, sensor noise); runs differ in the tracker seed.
SCENE_SEED = 0
#: Arm points per person and frame that the arm error (pixels.arm_epsilons) measures at
#: most, an even subsample of those seen.
ARM_SAMPLE = 400

Progress = Callable[[int, int], None]


# --------------------------------------------------------------------------- results


@dataclass(frozen=True)
class Evaluation:
    """What :func:`evaluate` did: every run and the files written."""

    runs: list[RunResult]
    report: Path
    results: Path
    plots: list[Path]


# --------------------------------------------------------------------------- checks


def _names(given: Sequence[str] | str | None, valid: Sequence[str], default: Sequence[str], what: str,
           also: Callable[[str], bool] | None = None, also_text: str = "") -> list[str]:
    """Checked list of names (a comma-separated string or a sequence; None: ``default``).

    also : names it accepts besides ``valid`` (``also_text`` says which, in the error)."""
    if given is None:
        return list(default)
    names = [n.strip() for n in given.split(",")] if isinstance(given, str) else [str(n) for n in given]
    names = [n for n in names if n]
    if not names:
        raise ValueError(f"no {what} given; valid names: {', '.join(valid)}")
    unknown = [n for n in names if n not in valid and not (also is not None and also(n))]
    if unknown:
        raise ValueError(f"unknown {what} {', '.join(map(repr, unknown))}; valid names: {', '.join(valid)}"
                         + (f", {also_text}" if also_text else ""))
    if len(set(names)) != len(names):
        raise ValueError(f"{what} named twice: {names}")
    return names


def suite_scenarios(suite: str) -> list[str]:
    """The scenario names of a suite: ``"catalogue"`` (every scenario of the catalogue) or
    ``"random:N"`` (the random scenes of seeds 0..N-1, ``random-0`` ... ``random-<N-1>``)."""
    from occupose.synth.random_scenes import suite as random_suite
    from occupose.synth.scenarios import SCENARIOS

    kind, _, count = str(suite).partition(":")
    if kind == "catalogue" and not count:
        return list(SCENARIOS)
    if kind == "random" and count.isdigit() and int(count) >= 1:
        return random_suite(int(count))
    raise ValueError(f"unknown suite {suite!r}; valid: catalogue, random:N (N >= 1 scenes, seeds 0..N-1)")


# --------------------------------------------------------------------------- tasks (run in workers)


def render_recording(scenario: str, out: Path, frames: int | None, procedural: bool,
                     progress: Callable[[int], None] | None = None) -> Path:
    """Render ``scenario`` (scene seed SCENE_SEED; a random scene ``random-<N>``: noise
    seed N) into the recording folder ``out``, or
    keep the one already there when it was rendered with the same settings and the same
    ground-truth motion (occupose.synth.catalogue, policy "reuse").

    frames : at most this many frames (None: all); procedural : never use mocap clips.
    An existing folder rendered differently (or half-written) is replaced.
    """
    from occupose.synth.catalogue import render_scenario
    from occupose.synth.random_scenes import is_random_name, seed_of

    def report(done: int, total: int) -> None:
        if done:
            progress(done)

    seed = seed_of(scenario) if is_random_name(scenario) else SCENE_SEED
    return render_scenario(scenario, out, seed=seed, frames=frames, procedural=procedural, exists="reuse",
                           clip_frames=True, progress=None if progress is None else report).path


def _render_events(folder: Path) -> dict[str, tuple[int, int]]:
    """{event name: (start, stop) frames} of the scenario rendered into ``folder``, as
    render_recording noted them ({} without a note)."""
    from occupose.synth.catalogue import RENDER_INFO

    marker = folder / RENDER_INFO
    info = json.loads(marker.read_text()) if marker.is_file() else {}
    return {name: tuple(span) for name, span in info.get("events", {}).items()}


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
    (`occupose.evaluation.matching.person_errors`)."""
    num_frames, num_people = gt_joints.shape[:2]
    out = np.full((num_frames, num_people), np.nan)
    for track_id, person in match_tracks(gt_joints, tracks).items():
        errors, known, _ = person_errors(gt_joints[:, person], gt_visible[:, person], tracks[track_id])
        out[:, person] = frame_errors(errors, known)
    return out


def run_method(recording: Path, scenario: str, method: str, seed: int, out: Path,
               progress: Callable[[int], None] | None = None, overrides: Mapping[str, Any] | None = None,
               recording_as: Path | None = None) -> RunResult:
    """Track ``recording`` with ``method`` (its config with ``overrides``, dotted keys) and
    ``seed`` into ``out``/tracks.csv and ``out``/summary.json, and score it against the
    recording's ground truth. recording_as : the recording's path for summary.json, when
    it is read from elsewhere until the evaluation is complete (None: ``recording``)."""
    from occupose.config import method_config
    from occupose.io.recording import Recording
    from occupose.run import track_recording, write_run

    rec = Recording(recording)
    config = method_config(method).with_values(overrides or {})
    result = track_recording(rec, config, seed=seed, progress=progress, warm_up=True)  # no stall in the fps
    write_run(out, result, rec.path if recording_as is None else recording_as, method)
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
    from occupose._numba import configure

    global _progress_queue
    configure(threads=numba_threads)
    _progress_queue = progress_queue


def _in_worker(task: Callable, *args, **kwargs):
    return task(*args, progress=_progress_queue.put, **kwargs)


# --------------------------------------------------------------------------- evaluate


def evaluate(scenarios: Sequence[str] | str | None = None, methods: Sequence[str] | str | None = None,
             runs: int = 3, *, out: str | os.PathLike, frames: int | None = None, procedural: bool = False,
             jobs: int | None = None, progress: Progress | None = None,
             overrides: Mapping[str, Any] | None = None, force: bool = False) -> Evaluation:
    """Run every method on every scenario ``runs`` times (seeds 0..runs-1) and report.

    scenarios : names of occupose.synth.scenarios.SCENARIOS or random scenes ``random-<seed>``
        (a list or "a,b"; :func:`suite_scenarios` names whole suites); None: the catalogue
    methods : names of occupose.config.METHODS; None: DEFAULT_METHODS
    runs : runs per method and scenario, >= 1
    out : folder for recordings/, runs/, results.csv, report.md and the plots
    frames : render and track at most this many frames of each scenario (None: all)
    procedural : procedural motion even when the shared mocap clips are present
    jobs : worker processes (None: one per core; never more than the runs; 1: everything
        in this process)
    progress : callable(n, total) after n more frames were rendered or tracked, total
        being all the frames to render and track
    overrides : config values for every method, dotted keys (``{"pose.particles": 300}``)
    force : replace an earlier evaluation of occupose in ``out`` (its renders are reused
        where the settings match); without it ``out`` must not exist or be empty. The
        evaluation is made beside ``out`` and swapped in whole
        (:func:`occupose.io.output.staged_folder`).

    Returns an Evaluation. Raises ValueError for unknown names or bad counts, and
    :class:`occupose.io.output.OutputError` (a ValueError) for an ``out`` it may not write.
    """
    from occupose.synth.random_scenes import PREFIX, is_random_name
    from occupose.synth.scenarios import SCENARIOS, build_scenario
    from occupose.config import METHODS

    scenarios = _names(scenarios, list(SCENARIOS), list(SCENARIOS), "scenario(s)", also=is_random_name,
                       also_text=f"or {PREFIX}<seed>")
    methods = _names(methods, list(METHODS), DEFAULT_METHODS, "method(s)")
    runs = positive_int(runs, "runs")
    frames = None if frames is None else positive_int(frames, "frames")
    jobs = len(os.sched_getaffinity(0)) if jobs is None else positive_int(jobs, "jobs")
    out = Path(out)
    lengths = {}
    for name in scenarios:
        length = build_scenario(name, seed=SCENE_SEED, use_mocap=not procedural).num_frames
        lengths[name] = length if frames is None else min(frames, length)
    with staged_folder(out, "evaluation", force=force) as folder:
        for name in scenarios:  # an earlier evaluation's renders, reused if rendered alike (render_recording)
            if (out / "recordings" / name / "recording.json").is_file():
                link_tree(out / "recordings" / name, folder / "recordings" / name)
        results, plots, jobs = _run_all(folder, scenarios, methods, runs, lengths, frames, procedural, jobs,
                                        progress, overrides, final=out)
        results_path = write_results_csv(folder / "results.csv", results)
        report_path = folder / "report.md"
        report_path.write_text(report_markdown(results, plots, folder, jobs=jobs, frames=lengths,
                                               procedural=procedural))
    return Evaluation(results, out / report_path.name, out / results_path.name,
                      [out / plot.relative_to(folder) for plot in plots])


def _run_all(out: Path, scenarios: list[str], methods: list[str], runs: int, lengths: dict[str, int],
             frames: int | None, procedural: bool, jobs: int, progress: Progress | None, overrides,
             final: Path) -> tuple[list[RunResult], list[Path], int]:
    """Render, run and plot everything of :func:`evaluate` in the folder ``out`` (to be
    moved to ``final``); returns (the runs in order, the plots, the jobs used)."""
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
                results.append(run[0](*run[1:], progress=report, overrides=overrides,
                                      recording_as=final / "recordings" / scenario))
    else:
        results = _in_pool(renders, runs_of, jobs, report, overrides, final)
    order = {(s, m): i for i, (s, m) in enumerate((s, m) for s in scenarios for m in methods)}
    results.sort(key=lambda r: (order[r.scenario, r.method], r.seed))
    recordings = {s: out / "recordings" / s for s in scenarios}
    plots = write_plots(results, out, recordings, {s: _render_events(folder) for s, folder in recordings.items()})
    return results, plots, jobs


def _in_pool(renders: dict, runs_of: Callable, jobs: int, progress, overrides, final: Path) -> list[RunResult]:
    """Renders, then each scenario's runs as soon as its recording is there, on ``jobs``
    spawned workers with one numba thread each (``final``: the evaluation's folder when
    complete, for the runs' summaries)."""
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
                        pending[pool.submit(_in_worker, *run, overrides=overrides,
                                            recording_as=final / "recordings" / scenario)] = None
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


__all__ = ["DEFAULT_METHODS", "Evaluation", "arm_points", "evaluate", "render_recording", "run_method", "suite_scenarios"]
