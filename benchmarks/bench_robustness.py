"""Robustness benchmark: scenes x tracker seeds, scored per condition bucket (issue 24).

Each scene is rendered once by today's code (``OUT/recordings/<scene>``, reused while the
scene is unchanged: occupose.evaluation.evaluate.render_recording), tracked with every seed
by ``occupose track`` run as a separate process (``OUT/runs/<code>/<scene>/<seed>``), and
scored by today's scorer (occupose.evaluation.robustness), so that old code is judged by the
same rules as new. ``--baseline COMMIT`` tracks the same recordings with that commit's code
as well: a git worktree of it (``~/.cache/occupose/worktrees/<commit>``, made once) run by
this interpreter with its ``src`` first on the path, so it must need no library this
environment lacks. 931038f reads today's recordings. ``--variant "carry.twin=true"`` tracks
them with today's code and those settings as well (``occupose track --set``), for an A/B of
a setting in the same run.

The small version (`run`, called by ``make bench``): ``SMALL_SCENES`` x 1 seed x
``SMALL_FRAMES`` frames, today's code only. The full version, as the issue asks::

    python -m benchmarks.bench_robustness --scenes random:60 --seeds 3 --baseline 931038f

Writes ``OUT/robustness.json`` (every run) and ``OUT/robustness.md`` (overall, then per
condition). Two tracking processes at a time by default (``--jobs``), each with one numba
thread.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import time
import warnings
from concurrent.futures import ThreadPoolExecutor
from collections.abc import Sequence
from pathlib import Path

from tqdm import tqdm

from occupose.evaluation.report import markdown_table
from occupose.evaluation.robustness import Run, condition_keys, recording_conditions, score_run, summarise

TITLE = "Robustness: the small randomized suite, per condition (cm, %)"
RESULTS = Path(__file__).parent / "results" / "robustness"
ROOT = Path(__file__).resolve().parents[1]
#: The small version's scenes, tracker seeds and frames (``make bench``).
SMALL_SCENES = ("no_occlusion", "top_view_two_people")
SMALL_SEEDS = 1
SMALL_FRAMES = 60
#: Label of today's code in the tables.
CURRENT = "current"
#: Columns of the tables: (heading, key of robustness.bucket_figures, format).
COLUMNS = (
    ("runs", "runs", "{:d}"), ("person-runs", "person_runs", "{:d}"),
    ("mean [cm]", "mean_cm", "{:.2f}"), ("median [cm]", "median_cm", "{:.2f}"),
    ("<20 cm frames [%]", "under20", "{:.1f}"), ("joints <10 cm [%]", "within10", "{:.1f}"),
    ("coverage [%]", "coverage", "{:.1f}"), ("FAIL [%]", "fail_rate", "{:.1f}"),
    ("no switch [%]", "switch_free", "{:.1f}"), ("right tracks [%]", "right_tracks", "{:.1f}"),
)
_LAUNCH = "import sys; from occupose.cli import main; sys.exit(main())"


def scene_names(spec: str) -> list[str]:
    """Scene names from ``a,b,random:N`` (``random:N``: random-0 .. random-N-1)."""
    names: list[str] = []
    for part in (p.strip() for p in spec.split(",")):
        if part.startswith("random:"):
            count = part.split(":", 1)[1]
            if not count.isdigit() or int(count) < 1:
                raise ValueError(f"random:N needs a positive count, got {part!r}")
            names += [f"random-{i}" for i in range(int(count))]
        elif part:
            names.append(part)
    if not names:
        raise ValueError("no scene named")
    return names


def baseline_tree(commit: str) -> Path:
    """A git worktree of ``commit`` of this repository (made once, then reused)."""
    full = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--verify", f"{commit}^{{commit}}"],
                          capture_output=True, text=True)
    if full.returncode:
        raise ValueError(f"baseline {commit!r} is not a commit of {ROOT}: {full.stderr.strip()}")
    commit = full.stdout.strip()
    home = Path(os.environ.get("XDG_CACHE_HOME", Path.home() / ".cache"))
    tree = home / "occupose" / "worktrees" / commit[:12]
    if not (tree / "src" / "occupose").is_dir():
        subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", str(tree), commit], check=True,
                       capture_output=True)
    return tree


def track_command(source: Path, recording: Path, out: Path, seed: int, settings: Sequence[str] = ()
                  ) -> tuple[list[str], dict[str, str]]:
    """(argv, environment) of ``occupose track`` of the code in ``source`` (a folder holding
    the ``occupose`` package) on one recording, with one numba thread and the ``--set``
    assignments ``settings`` (``KEY=VALUE``)."""
    env = dict(os.environ, PYTHONPATH=str(source), NUMBA_NUM_THREADS="1")
    argv = [sys.executable, "-c", _LAUNCH, "track", str(recording), "--out", str(out), "--seed", str(seed)]
    return argv + [f"--set={assignment}" for assignment in settings], env


def _track(task: tuple[Path, Sequence[str], Path, Path, int]) -> Path:
    source, settings, recording, out, seed = task
    if (out / "tracks.csv").is_file() and (out / "summary.json").is_file():
        return out  # tracked by an earlier, whole run
    partial = out.with_name(out.name + ".partial")  # renamed when whole: an interrupted run is redone
    for stale in (partial, out):
        shutil.rmtree(stale, ignore_errors=True)
    argv, env = track_command(source, recording, partial, seed, settings)
    done = subprocess.run(argv, env=env, capture_output=True, text=True)
    if done.returncode:
        raise RuntimeError(f"tracking {recording} failed ({done.returncode}):\n{done.stderr[-2000:]}")
    partial.rename(out)
    return out


def score_folder(scene: str, seed: int, recording: Path, run: Path) -> Run:
    """The robustness `Run` of ``run``/tracks.csv against ``recording``'s ground truth."""
    from occupose.io.joint_table import UnmarkedTableWarning, read_tracks_csv
    from occupose.io.recording import Recording

    rec = Recording(recording)
    gt = rec.groundtruth()
    with warnings.catch_warnings():  # a baseline's code may predate the end line; a run here is whole (_track)
        warnings.simplefilter("ignore", UnmarkedTableWarning)
        table = read_tracks_csv(run / "tracks.csv", rec.num_frames, allow_unmarked=True)
    tracks = {k: v[0] for k, v in table.items()}
    conditions = recording_conditions(recording, rec.cameras, len(gt.person_ids))
    return score_run(scene, seed, conditions, gt.joints, gt.visible, tracks, rec.fps)


def benchmark(scenes: list[str], seeds: int, frames: int | None, out: Path, baseline: str | None = None,
              jobs: int = 2, procedural: bool = False, variants: Sequence[str] = ()) -> dict[str, list[Run]]:
    """Render, track and score; ``{code label: runs}``, the baseline (if any) first, then
    today's code, then today's code with each of ``variants`` (``KEY=VALUE[;KEY=VALUE...]``,
    settings as ``occupose track --set`` takes them; labelled by that string)."""
    from occupose.evaluation.evaluate import render_recording

    codes: dict[str, tuple[Path, tuple[str, ...]]] = {}
    if baseline is not None:
        codes[baseline] = (baseline_tree(baseline) / "src", ())
    codes[CURRENT] = (ROOT / "src", ())
    for variant in variants:
        settings = tuple(a.strip() for a in variant.split(";") if a.strip())
        if not settings or not all("=" in a for a in settings):
            raise ValueError(f"a variant is KEY=VALUE[;KEY=VALUE...], got {variant!r}")
        codes[variant] = (ROOT / "src", settings)
    recordings = {}
    for scene in tqdm(scenes, desc="rendering", unit="scene"):
        recordings[scene] = render_recording(scene, out / "recordings" / scene, frames, procedural)
    folders = {label: out / "runs" / (_folder_name(label) if label in variants else label) for label in codes}
    for label in codes:  # today's code changes: its runs are made afresh; a baseline commit's are kept
        if label != baseline:
            shutil.rmtree(folders[label], ignore_errors=True)
    # scene by scene, every code's runs together: the runs finished so far are comparable pairs
    tasks = [(source, settings, recordings[scene], folders[label] / scene / str(seed), seed)
             for scene in scenes for seed in range(seeds) for label, (source, settings) in codes.items()]
    for task in tasks:
        task[3].parent.mkdir(parents=True, exist_ok=True)
    with ThreadPoolExecutor(jobs) as pool:
        list(tqdm(pool.map(_track, tasks), total=len(tasks), desc="tracking", unit="run"))
    results: dict[str, list[Run]] = {label: [] for label in codes}
    for label in codes:
        for scene in scenes:
            for seed in range(seeds):
                run = folders[label] / scene / str(seed)
                results[label].append(score_folder(scene, seed, recordings[scene], run))
    return results


def _folder_name(variant: str) -> str:
    """A folder name for a variant's runs: its settings with unsafe characters replaced."""
    return "set-" + "".join(c if c.isalnum() or c in "._=-" else "_" for c in variant)


def tables(results: dict[str, list[Run]]) -> str:
    """Markdown: the overall table, then one per condition key; a row per bucket and code."""
    headings = ["bucket", "code"] + [c[0] for c in COLUMNS]
    all_runs = [run for runs in results.values() for run in runs]
    sections = []
    for key in [None] + condition_keys(all_runs):
        rows = []
        buckets = list(dict.fromkeys(b for runs in results.values() for b in summarise(runs, key)))
        for bucket in buckets:
            for label, runs in results.items():
                figures = summarise(runs, key).get(bucket)
                if figures is not None:
                    rows.append([bucket, label] + [_cell(fmt, figures[k]) for _, k, fmt in COLUMNS])
        sections.append(f"#### {'overall' if key is None else 'by ' + key}\n\n" + markdown_table(headings, rows))
    sections.append(fails_table(results))
    return "\n".join(sections)


#: A FAIL with at most this many of the 15 joints visible where it trips is counted as "mostly hidden".
MOSTLY_HIDDEN_JOINTS = 9


def fails_table(results: dict[str, list[Run]]) -> str:
    """Markdown: where each FAIL trips (robustness.PersonRun's fail_frame, visible_at_fail,
    missed_before_fail), a row per FAILing person-run, and how many were mostly hidden
    (at most MOSTLY_HIDDEN_JOINTS joints visible there) or mostly without an estimate
    (half the window or more)."""
    headings = ["code", "scene", "seed", "person", "mean [cm]", "trips at frame", "joints visible there",
                "window without estimate [%]"]
    rows, counts = [], []
    for label, runs in results.items():
        fails = [p for run in runs for p in run.persons if p.fail and p.fail_frame is not None]
        rows += [[label, p.scene, str(p.seed), str(p.person), _cell("{:.1f}", p.mean_cm), str(p.fail_frame),
                  str(p.visible_at_fail), f"{100 * p.missed_before_fail:.0f}"] for p in fails]
        hidden = sum(p.visible_at_fail <= MOSTLY_HIDDEN_JOINTS for p in fails)
        missed = sum(p.missed_before_fail >= 0.5 for p in fails)
        counts.append(f"{label}: {len(fails)} FAILs, {hidden} with at most {MOSTLY_HIDDEN_JOINTS} of 15 joints "
                      f"visible where they trip, {missed} without an estimate in half their window or more")
    return ("#### FAILs: where the rule trips\n\n" + "; ".join(counts) + ".\n\n"
            + (markdown_table(headings, rows) if rows else ""))


def _cell(fmt: str, value) -> str:
    return "n/a" if isinstance(value, float) and value != value else fmt.format(value)


def write(results: dict[str, list[Run]], out: Path, note: str) -> Path:
    """``out``/robustness.json and ``out``/robustness.md; returns the markdown's path."""
    out.mkdir(parents=True, exist_ok=True)
    (out / "robustness.json").write_text(json.dumps(
        {label: [run.as_dict() for run in runs] for label, runs in results.items()}, indent=1) + "\n")
    path = out / "robustness.md"
    path.write_text(f"# Robustness benchmark\n\n{note}\n\n{tables(results)}")
    return path


def run() -> list[dict]:
    """The small version, for ``make bench``: rows of the overall and per-view figures."""
    results = benchmark(list(SMALL_SCENES), SMALL_SEEDS, SMALL_FRAMES, RESULTS / "small")
    runs = results[CURRENT]
    rows = []
    for key in (None, "view"):
        for bucket, figures in summarise(runs, key).items():
            rows.append({"bucket": bucket, **{heading: figures[k] for heading, k, _ in COLUMNS}})
    return rows


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(prog="python -m benchmarks.bench_robustness", description=__doc__.split("\n")[0])
    parser.add_argument("--scenes", default=",".join(SMALL_SCENES), help="names and random:N, comma-separated")
    parser.add_argument("--seeds", type=int, default=SMALL_SEEDS, help="tracker seeds 0..N-1 per scene")
    parser.add_argument("--frames", type=int, default=SMALL_FRAMES, help="frames per scene (0: all)")
    parser.add_argument("--baseline", default=None, help="also track with this commit's code (e.g. 931038f)")
    parser.add_argument("--variant", action="append", default=[], metavar="KEY=VALUE[;KEY=VALUE]",
                        help="also track with today's code and these settings (repeatable)")
    parser.add_argument("--jobs", type=int, default=2, help="tracking processes at a time")
    parser.add_argument("--procedural", action="store_true", help="procedural motion even with the shared mocap")
    parser.add_argument("--out", type=Path, default=RESULTS, help="folder for recordings, runs and the tables")
    args = parser.parse_args(argv)
    if args.seeds < 1 or args.jobs < 1 or args.frames < 0:
        parser.error("--seeds and --jobs must be >= 1, --frames >= 0")
    started = time.time()
    scenes = scene_names(args.scenes)
    results = benchmark(scenes, args.seeds, args.frames or None, args.out, args.baseline, args.jobs, args.procedural,
                        args.variant)
    note = (f"{len(scenes)} scenes x {args.seeds} seeds, {args.frames or 'all'} frames, "
            f"{time.strftime('%Y-%m-%d')}, {time.time() - started:.0f} s.")
    print(tables(results))
    print(f"saved {write(results, args.out, note)}")


if __name__ == "__main__":
    main()
