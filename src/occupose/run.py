"""Tracking a whole recording: frames in, every track's joints out, and a run's files.

:func:`track_recording` runs a :class:`occupose.tracker.Tracker` over a recording and
returns a :class:`TrackingResult`; :func:`write_run` writes it as ``tracks.csv`` and
``summary.json`` (the resolved config included, so a run's output says everything that
shaped it), and :func:`track_into` does both, the output checked before the tracking.
:func:`track_frames` is the loop itself, for frames from anywhere. A run's folder is
written whole or not at all, under the overwrite rule of :mod:`occupose.io.output`.
"""

from __future__ import annotations

import itertools
import json
import os
import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from occupose._validate import callback, flag, seed_value
from occupose.bounds import check_cameras, check_fps
from occupose.config import TrackerConfig, as_config
from occupose.grid.noise import measure_noise
from occupose.joints import NUM_JOINTS
from occupose.tracker import STAGES, Tracker


@dataclass
class TrackingResult:
    """The output of :func:`track_frames` and :func:`track_recording`.

    tracks : {track id: (joints (T, 15, 3) float64 metres, NaN where not tracked,
        visible (T, 15) bool)}
    seconds : seconds spent per stage (grid, blobs, observations, pose) and ``total``
        (all frames, reading excluded), ``startup`` (first frame, numba compilation included),
        ``warm_up`` (the kernels compiled before the first frame, when asked for)
    fps : frames per second of tracking, the first frame (start-up) excluded
    num_frames : frames tracked
    config : the settings of the run; seed : its seed; model : the body model it used
    overlap : whether the grid ran a frame ahead on a second thread (its hold mask then
        comes from the bodies one frame older, so the tracks may differ)
    noise : camera name -> what the grid assumed of it (:meth:`occupose.grid.noise.CameraNoise.to_dict`)
    cameras : each camera's height, tilt, roll and where its pose came from
        (:func:`occupose.io.sources.placement`)
    source : how the recording was read: its reader and the options that open it again
        (:func:`occupose.io.sources.source_of`)
    """

    tracks: dict[int, tuple[np.ndarray, np.ndarray]]
    seconds: dict[str, float] = field(default_factory=dict)
    fps: float = 0.0
    num_frames: int = 0
    config: TrackerConfig = field(default_factory=TrackerConfig)
    seed: int = 0
    model: str = ""
    overlap: bool = False
    noise: dict[str, dict] = field(default_factory=dict)
    cameras: list[dict] = field(default_factory=list)
    source: dict = field(default_factory=dict)


def track_frames(tracker: Tracker, frames: Iterable, num_frames: int, progress: Callable[[int], None] | None = None,
                 overlap: bool = False) -> TrackingResult:
    """Run ``tracker`` over ``frames`` (an iterable of objects with ``.index`` and
    ``.depth``, e.g. ``Recording.frames()``, indices from 0), the first ``num_frames`` of
    them. ``progress`` : callable(n) called after each frame, or None. ``overlap`` : update
    the grid with the next frame while the pose stage works on the current one
    (:meth:`Tracker.update`'s ``upcoming``)."""
    if not isinstance(tracker, Tracker):
        raise TypeError(f"tracker must be an occupose.tracker.Tracker, got {type(tracker).__name__}")
    if isinstance(num_frames, bool) or not isinstance(num_frames, (int, np.integer)) or num_frames < 0:
        raise ValueError(f"num_frames must be an integer >= 0, got {num_frames!r}")
    progress, overlap = callback(progress, "progress"), flag(overlap, "overlap")
    joints = {}
    visible = {}
    seconds = dict.fromkeys(STAGES, 0.0)
    startup = 0.0
    total = 0.0
    frames = itertools.islice(frames, num_frames)
    upcoming = next(frames, None)
    indices = []  # of the frames taken so far
    while upcoming is not None:
        frame, upcoming = upcoming, next(frames, None)
        indices.append(frame.index)
        start = time.perf_counter()
        result = tracker.update(frame.depth, upcoming.depth if overlap and upcoming is not None else None)
        spent = time.perf_counter() - start
        if len(indices) == 1:
            startup = spent
        else:
            total += spent
        for stage, value in result.seconds.items():
            seconds[stage] += value
        found = [(tid, frame.index, est) for tid, est in result.estimates.items()]
        found += [(tid, indices[-1 - ago], est) for tid, earlier in result.looked_back.items() for ago, est in earlier]
        for tid, index, est in found:
            if tid not in joints:
                joints[tid] = np.full((num_frames, NUM_JOINTS, 3), np.nan)
                visible[tid] = np.zeros((num_frames, NUM_JOINTS), bool)
            joints[tid][index] = est.joints
            visible[tid][index] = est.visible
        if progress is not None:
            progress(1)
    tracker.close()
    fps = (num_frames - 1) / total if num_frames > 1 and total > 0 else 0.0
    return TrackingResult({t: (joints[t], visible[t]) for t in sorted(joints)}, dict(seconds, total=total,
                          startup=startup), fps, num_frames, tracker.config, tracker.seed, tracker.model_name, overlap,
                          {name: c.to_dict() for name, c in tracker.noise.items()})


def _as_recording(recording):
    """``recording`` (a frame source, or the path of a recording of any format, opened with
    :func:`occupose.io.sources.open_source`) as a frame source."""
    from occupose.io.sources import FrameSource, open_source

    if isinstance(recording, (str, os.PathLike)):
        recording = open_source(recording)
    if not isinstance(recording, FrameSource):
        raise TypeError(f"recording must be a frame source (occupose.io.sources.FrameSource, e.g. a Recording) or "
                        f"the path of a recording, got {type(recording).__name__}")
    return recording


def track_recording(recording, config: TrackerConfig | str = "ours", *, seed: int = 0,
                    progress: Callable[[int], None] | None = None, overlap: bool = False,
                    warm_up: bool | Callable[[str], None] = False) -> TrackingResult:
    """Track every person of a recording.

    recording : a frame source (:class:`occupose.io.sources.FrameSource`, e.g. a Recording) or the
        path of a recording of any format (:func:`occupose.io.sources.open_source`)
    config : a TrackerConfig or a method name (:data:`occupose.config.METHODS`)
    seed : the run's seed; progress : callable(n) after each frame, or None
    overlap : as :func:`track_frames`; off by default: on an idle 2-core machine the grid's
        thread competes with the likelihood kernels' two threads (benchmarks/bench_speed.py)
    warm_up : compile the kernels of this run before its first frame
        (:func:`occupose.warmup.warm_up`; once per machine and settings, a fraction of a second
        after that): True, or a callable told once, with a message, when it compiles; the
        seconds it took are ``seconds["warm_up"]``. False: each kernel compiles at its first
        call, in the middle of tracking on a machine that has not compiled it before.
    With ``grid.noise_model`` measured, each camera's noise is measured from the first
    ``grid.noise_frames`` frames first (:func:`occupose.grid.noise.measure_noise`).
    The frames are read and decoded on a thread of their own, a few ahead
    (:class:`occupose.io.prefetch.Prefetch`). An empty recording (no frames) gives an empty
    result. Only depth is read: the tracker takes no colour (the colour images were checked
    when the recording was opened).
    """
    from occupose.io.prefetch import Prefetch
    from occupose.io.sources import placement, source_of

    recording = _as_recording(recording)
    config = as_config(config)
    seed, progress, overlap = seed_value(seed), callback(progress, "progress"), flag(overlap, "overlap")
    check_fps(recording.fps, config.limits)  # before the frames the noise is measured on are read
    check_cameras(recording.cameras, config.limits)
    warm_seconds = _warm_up(config, recording.cameras, warm_up)
    noise = None
    if config.grid.noise_model == "measured":
        first = (frame.depth for frame in itertools.islice(recording.frames(color=False), config.grid.noise_frames))
        noise = measure_noise(recording.cameras, first, config.grid, strict=False)
    tracker = Tracker(recording.cameras, recording.fps, config, seed=seed, noise=noise)
    with Prefetch(recording.frames(color=False)) as frames:  # the next frames decoded while this one is tracked
        result = track_frames(tracker, frames, recording.num_frames, progress, overlap=overlap)
    result.cameras = placement(recording)
    result.source = source_of(recording)
    if warm_seconds is not None:
        result.seconds["warm_up"] = warm_seconds
    return result


def _warm_up(config: TrackerConfig, cameras, warm_up: bool | Callable[[str], None]) -> float | None:
    """track_recording's warm-up: seconds it took, None when not asked for."""
    from occupose import warmup

    if warm_up is False:
        return None
    if warm_up is not True and not callable(warm_up):
        raise TypeError(f"warm_up must be True, False or a callable(message), got {type(warm_up).__name__}")
    start = time.perf_counter()
    warmup.warm_up(config, cameras, report=warm_up if callable(warm_up) else None)
    return round(time.perf_counter() - start, 3)


def summary_of(result: TrackingResult, recording_path: str | os.PathLike, method: str | None = None) -> dict:
    """The ``summary.json`` of a run: the recording, the method's name (if it was run as
    one: the base of its config), seed, body model, the whole resolved config, whether the
    grid ran ahead on a thread, each camera's noise model and far range and its pose (height,
    tilt, roll, and whether the recording had it, it was given or found from the floor),
    how the recording was read (its reader and the reader options that open it again, such
    as a bag's topic), frames, people, seconds per stage and frames/s (start-up excluded)."""
    return {"recording": str(recording_path), "source": result.source, "method": method, "seed": result.seed, "model": result.model,
            "config": result.config.to_dict(), "overlap": result.overlap, "noise": result.noise,
            "cameras": result.cameras,
            "frames": result.num_frames, "people": len(result.tracks),
            "seconds": {k: round(v, 4) for k, v in result.seconds.items()}, "fps": round(result.fps, 2)}


def _write_run_files(folder: Path, result: TrackingResult, recording, method: str | None,
                     formats: Sequence[str] = (), frame: str = "world", camera: str | None = None) -> None:
    """A run's tracks.csv and summary.json, and ``tracks.<suffix>`` of each of ``formats``
    (:data:`occupose.io.writers.WRITERS`, in ``frame`` of ``camera``:
    :func:`occupose.io.export.check_frame`) when anybody was tracked, into the (staged)
    ``folder``. ``recording`` : its path, or with ``formats`` the frame source itself (its
    fps, frames and cameras)."""
    from occupose.io.joint_table import write_tracks_csv
    from occupose.io.output import write_text

    path = recording if isinstance(recording, (str, os.PathLike)) else recording.path
    write_tracks_csv(folder / "tracks.csv", result.tracks)
    write_text(folder / "summary.json", json.dumps(summary_of(result, path, method), indent=2) + "\n")
    if formats and result.tracks:
        from occupose.io.export import tracks_for_output
        from occupose.io.writers import write_tracks, writer_for

        tracks = tracks_for_output(result.tracks, recording, frame, camera)
        for name in formats:
            write_tracks(folder / f"tracks{writer_for(name).suffix}", tracks, name)


def write_run(out: str | os.PathLike, result: TrackingResult, recording_path: str | os.PathLike,
              method: str | None = None, *, force: bool = False) -> Path:
    """Write ``out``/tracks.csv and ``out``/summary.json (:func:`summary_of`), whole or not
    at all; returns the tracks.csv path. ``out`` must not exist or be empty, or with
    ``force`` hold an earlier run (:func:`occupose.io.output.staged_folder`); it may not be
    inside the recording. Raises :class:`occupose.io.output.OutputError` otherwise."""
    from occupose.io.output import staged_folder

    with staged_folder(out, "run", force=force, inputs=(recording_path,)) as folder:
        _write_run_files(folder, result, recording_path, method)
    return Path(out) / "tracks.csv"


def track_into(out: str | os.PathLike, recording, config: TrackerConfig | str = "ours", *, method: str | None = None,
               seed: int = 0, force: bool = False, progress: Callable[[int], None] | None = None,
               formats: Sequence[str] = (), frame: str = "world", camera: str | None = None,
               warm_up: bool | Callable[[str], None] = False) -> tuple[Path, TrackingResult]:
    """:func:`track_recording`, then :func:`write_run` into ``out`` (``method`` names the
    config in the summary), with ``out`` checked and its hidden folder made before the
    tracking starts, so a run is not lost to an output that cannot be written. ``formats``
    : other outputs beside tracks.csv, ``tracks.<suffix>`` of each
    (:data:`occupose.io.writers.WRITERS`), in ``frame`` (``"world"`` or ``"camera"``, the
    camera named or the first: :func:`occupose.io.export.check_frame`), all checked before
    the tracking (their optional packages too); ``warm_up`` as :func:`track_recording`'s.
    Returns (the tracks.csv path, the result)."""
    from occupose.io.export import check_frame
    from occupose.io.output import staged_folder
    from occupose.io.writers import writer_for

    recording = _as_recording(recording)
    formats = tuple(formats)
    for name in formats:
        writer_for(name).check_available()
    check_frame(frame, camera, recording.cameras)
    with staged_folder(out, "run", force=force, inputs=(recording.path,)) as folder:
        result = track_recording(recording, config, seed=seed, progress=progress, warm_up=warm_up)
        _write_run_files(folder, result, recording, method, formats, frame, camera)
    return Path(out) / "tracks.csv", result
