"""Many recordings tracked at once, one output folder each, resumable (``occupose batch``).

:func:`track_batch` tracks each input into ``out/<name>`` exactly as ``occupose track``
does (:func:`occupose.run.track_into`), on an executor of :data:`EXECUTORS`:

- ``local``: a pool of ``jobs`` worker processes on this machine, one numba thread each
  (one job: in this process, numba's threads as usual);
- ``dask``: an existing Dask distributed cluster at ``scheduler`` (the ``dask`` extra). Its
  workers must have occupose installed; start them with one thread each (``dask worker
  ADDRESS --nthreads 1``) and ``NUMBA_NUM_THREADS=1``, so that kernels do not compete.

A recording whose folder already holds a complete run (its ``summary.json``: a run's folder
is written whole or not at all) is skipped, unless ``force``, which tracks it again. A
recording that fails (unreadable, no floor found, an output that may not be written) is
reported with its error and the others are finished. Each outcome is a :class:`Outcome`;
:func:`write_table` writes them as ``out/batch.csv``.
"""

from __future__ import annotations

import csv
import io
import json
import os
import re
from collections.abc import Callable, Iterator, Sequence
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import asdict, dataclass, field, fields
from multiprocessing import get_context
from pathlib import Path
from typing import Any

#: The table of a batch, in its output folder (``write_table``).
TABLE = "batch.csv"
#: The file of a complete run in a recording's folder (written last, with the others).
DONE_FILE = "summary.json"
#: Characters kept in a folder name made from an input's name; others become ``_``.
_NAME_CHARS = re.compile(r"[^A-Za-z0-9._-]+")


@dataclass(frozen=True)
class Task:
    """One recording of a batch: the input, its output folder and how to track it.

    config : the run's settings (``TrackerConfig.to_dict()``); method : their base's name,
    for summary.json; source : :func:`occupose.io.sources.open_source`'s keyword options
    (format, pose, find_floor and the reader's own); formats, frame, camera : the other
    outputs, as :func:`occupose.run.track_into`'s."""

    input: str
    out: str
    config: dict
    method: str | None = None
    seed: int = 0
    source: dict = field(default_factory=dict)
    formats: tuple[str, ...] = ()
    frame: str = "world"
    camera: str | None = None
    force: bool = False


@dataclass(frozen=True)
class Outcome:
    """What became of one recording: ``status`` done, skipped (a complete run was there) or
    failed (``error`` says why); frames tracked, tracks written, frames/s of the tracking
    (start-up excluded) and wall seconds of the recording's whole job (opening and warm-up
    included). A skipped recording reports its earlier run's frames, tracks and frames/s."""

    input: str
    out: str
    status: str
    frames: int | None = None
    tracks: int | None = None
    fps: float | None = None
    seconds: float | None = None
    error: str = ""


def output_names(inputs: Sequence[str | os.PathLike]) -> list[str]:
    """A folder name for each input: its file or folder name without the suffix of a file;
    a name taken by an earlier input gets ``-2``, ``-3``, ... in input order."""
    names, taken = [], set()
    for path in map(Path, inputs):
        base = _NAME_CHARS.sub("_", path.stem if path.is_file() else path.name) or "recording"
        name, n = base, 1
        while name in taken:
            n += 1
            name = f"{base}-{n}"
        taken.add(name)
        names.append(name)
    return names


def _earlier(task: Task) -> Outcome | None:
    """The outcome of a complete earlier run in ``task.out`` (skipped), or None."""
    summary = Path(task.out) / DONE_FILE
    if task.force or not summary.is_file():
        return None
    try:
        data = json.loads(summary.read_text())
    except (OSError, ValueError):
        return None  # not a run of occupose: tracking it will say why it may not write there
    return Outcome(task.input, task.out, "skipped", data.get("frames"), data.get("people"), data.get("fps"))


def track_one(task: Task) -> Outcome:
    """Track one recording of a batch (the work function every executor runs; importable,
    so that worker processes and Dask workers find it). Never raises for the recording's
    own errors: they become a failed :class:`Outcome`."""
    import time

    from occupose.config import TrackerConfig
    from occupose.io.sources import open_source
    from occupose.run import track_into

    earlier = _earlier(task)
    if earlier is not None:
        return earlier
    start = time.perf_counter()
    try:
        config = TrackerConfig.from_dict(task.config)
        source = open_source(task.input, floor=config.floor, **task.source)
        if source.num_frames == 0:
            raise ValueError("the recording has no frames, nothing to track")
        _, result = track_into(task.out, source, config, method=task.method, seed=task.seed, force=task.force,
                               formats=task.formats, frame=task.frame, camera=task.camera, warm_up=True)
    except Exception as error:  # noqa: BLE001 - one recording's failure is reported, the batch goes on
        return Outcome(task.input, task.out, "failed", seconds=round(time.perf_counter() - start, 2),
                       error=f"{type(error).__name__}: {error}")
    return Outcome(task.input, task.out, "done", result.num_frames, len(result.tracks), round(result.fps, 2),
                   round(time.perf_counter() - start, 2))


def _worker_setup() -> None:
    """A local worker process: one numba thread (before numba is imported in it)."""
    from occupose._numba import configure

    configure(threads=1)


def _run_local(tasks: Sequence[Task], jobs: int, scheduler: str | None) -> Iterator[Outcome]:
    if jobs == 1:
        yield from map(track_one, tasks)
        return
    # spawn: a fresh interpreter per worker, so its numba thread count takes effect
    with ProcessPoolExecutor(jobs, mp_context=get_context("spawn"), initializer=_worker_setup) as pool:
        for future in as_completed([pool.submit(track_one, task) for task in tasks]):
            yield future.result()


def _run_dask(tasks: Sequence[Task], jobs: int, scheduler: str | None) -> Iterator[Outcome]:
    try:
        from dask.distributed import Client, as_completed as completed
    except ImportError as error:
        raise ImportError("--scheduler needs Dask distributed: pip install 'occupose[dask]'") from error
    with Client(scheduler, set_as_default=False) as client:
        for future in completed(client.map(track_one, list(tasks), pure=False), loop=client.loop):
            yield client.gather(future)


#: The executors by name: ``run(tasks, jobs, scheduler)`` yields each task's Outcome as it ends.
EXECUTORS: dict[str, Callable[[Sequence[Task], int, str | None], Iterator[Outcome]]] = {
    "local": _run_local,
    "dask": _run_dask,
}


def plan(inputs: Sequence[str | os.PathLike], out: str | os.PathLike, config: dict, *, method: str | None = None,
         seed: int = 0, source: dict | None = None, formats: Sequence[str] = (), frame: str = "world",
         camera: str | None = None, force: bool = False) -> list[Task]:
    """The tasks of a batch: each input into ``out/<name>`` (:func:`output_names`).
    Raises ValueError for no inputs, or an input given twice."""
    if not inputs:
        raise ValueError("no recordings given")
    resolved = [str(Path(p).resolve()) for p in inputs]
    twice = sorted({p for p in resolved if resolved.count(p) > 1})
    if twice:
        raise ValueError(f"recordings given more than once: {', '.join(twice)}")
    out = Path(out)
    return [Task(str(path), str(out / name), config, method, seed, dict(source or {}), tuple(formats), frame,
                 camera, force) for path, name in zip(inputs, output_names(inputs))]


def track_batch(tasks: Sequence[Task], *, jobs: int = 1, scheduler: str | None = None,
                progress: Callable[[Outcome], None] | None = None) -> list[Outcome]:
    """Run the tasks (:func:`plan`) locally on ``jobs`` processes, or on the Dask cluster at
    ``scheduler``; ``progress(outcome)`` after each recording. Returns the outcomes in the
    tasks' order."""
    if isinstance(jobs, bool) or not isinstance(jobs, int) or jobs < 1:
        raise ValueError(f"jobs must be an integer >= 1, got {jobs!r}")
    run = EXECUTORS["dask" if scheduler is not None else "local"]
    by_out = {}
    for outcome in run(tasks, min(jobs, max(len(tasks), 1)), scheduler):
        by_out[outcome.out] = outcome
        if progress is not None:
            progress(outcome)
    return [by_out[task.out] for task in tasks]


def table_text(outcomes: Sequence[Outcome]) -> str:
    """The outcomes as an aligned text table (the end of ``occupose batch``), one line each."""
    head = ("recording", "status", "frames", "tracks", "frames/s", "seconds", "error")
    rows = [(Path(o.input).name, o.status, *("" if v is None else str(v) for v in (o.frames, o.tracks, o.fps, o.seconds)),
             o.error) for o in outcomes]
    widths = [max(len(r[i]) for r in (head, *rows)) for i in range(len(head) - 1)]
    return "\n".join("  ".join(cell.ljust(w) for cell, w in zip(r, widths)) + "  " + r[-1] for r in (head, *rows))


def write_table(path: str | os.PathLike, outcomes: Sequence[Outcome]) -> Path:
    """Write the outcomes as CSV (the :class:`Outcome` fields as columns), whole or not at all."""
    from occupose.io.output import write_text

    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, [f.name for f in fields(Outcome)], lineterminator="\n")
    writer.writeheader()
    writer.writerows(asdict(o) for o in outcomes)
    return write_text(path, buffer.getvalue())


def summary_counts(outcomes: Sequence[Outcome]) -> dict[str, Any]:
    """{status: count} over done, skipped and failed."""
    return {status: sum(o.status == status for o in outcomes) for status in ("done", "skipped", "failed")}
