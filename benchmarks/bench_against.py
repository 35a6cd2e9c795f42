"""`occupose track` of this code against the code of 931038f, in the same run (issue 27).

The reviews measured 931038f (``../shared/reviews``); issue 27's targets are against it. A
git worktree of that commit is made in a temporary folder, and each recording is tracked as
a command by both versions in turn (this code, then the old one, :data:`RUNS` times, after
one warm-up run each that fills its own numba cache), with the venv's Python and each
version's ``src`` first on PYTHONPATH. The recordings are rendered once by this code
(procedural motion, :data:`NUM_FRAMES` frames): ``sit_behind_table`` (one person, one
640x480 Kinect v1), ``two_cameras_occlusion`` (one person, two cameras),
``two_people_crossing`` (two) and ``three_people`` (`bench_speed.three_people`).

Figures from each run's ``summary.json``, median over the runs: frames/s of the tracking
loop (start-up excluded, the same definition in both versions) and ms per frame of each
stage (its seconds over all frames, the first included); and the whole command's wall
seconds (reading, this code's noise measurement and the old code's PNG decoding included).
Ratios are this code's over the old code's, pair by pair (runs in turn, so a drift of the
machine's speed cancels), median. Without git or the commit (e.g. a source archive) the
table says so instead.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from benchmarks.bench_speed import three_people
from occupose.synth.catalogue import render_scenario
from occupose.synth.generate import write_scenario

TITLE = "`occupose track` against 931038f (a worktree of it, the same run, runs in turn): medians, ratios new / old"

BASELINE = "931038f"
NUM_FRAMES = 300
RUNS = 3
SCENES = ("sit_behind_table", "two_cameras_occlusion", "two_people_crossing", "three_people")
STAGES = ("grid", "blobs", "observations", "pose")
ROOT = Path(__file__).resolve().parent.parent


def _worktree(folder: Path) -> str | None:
    """Make a worktree of BASELINE at ``folder``; the reason it could not be made, or None."""
    try:
        subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", str(folder), BASELINE], check=True,
                       capture_output=True, text=True)
    except (OSError, subprocess.CalledProcessError) as error:
        return f"no worktree of {BASELINE}: {getattr(error, 'stderr', '') or error}".strip()
    return None


def _render(name: str, out: Path) -> Path:
    if name == "three_people":
        write_scenario(three_people(), out, seed=0, num_frames=NUM_FRAMES)
        return out
    return render_scenario(name, out, frames=NUM_FRAMES, procedural=True).path


def _track(src: Path, recording: Path, out: Path, cache: Path) -> dict:
    """One `occupose track` of ``recording`` by the code in ``src``: summary figures and wall seconds."""
    shutil.rmtree(out, ignore_errors=True)  # (931038f's track has no --force)
    env = os.environ | {"PYTHONPATH": str(src), "NUMBA_CACHE_DIR": str(cache)}
    start = time.perf_counter()
    subprocess.run([sys.executable, "-c", "from occupose.cli import main; main()", "track", str(recording),
                    "--out", str(out)], check=True, capture_output=True, env=env)
    wall = time.perf_counter() - start
    summary = json.loads((out / "summary.json").read_text())
    frames = summary["frames"]
    return {"fps": summary["fps"], "wall": wall, "people": summary["people"],
            **{stage: 1e3 * summary["seconds"][stage] / frames for stage in STAGES}}


def _row(scene: str, version: str, runs: list[dict]) -> dict:
    median = {key: float(np.median([r[key] for r in runs])) for key in runs[0]}
    return {"scene": scene, "version": version, "people tracked": int(median["people"]),
            "frames/s": median["fps"], **{f"{stage} ms": median[stage] for stage in STAGES},
            "stages 1-2 ms": sum(median[stage] for stage in STAGES[:3]), "command s": median["wall"],
            "load": os.getloadavg()[0]}


def _ratio_row(scene: str, new: list[dict], old: list[dict]) -> dict:
    def ratio(key):
        return float(np.median([a[key] / b[key] for a, b in zip(new, old)]))

    def stages12(r):
        return sum(r[stage] for stage in STAGES[:3])

    return {"scene": scene, "version": "new / old", "people tracked": "",
            "frames/s": ratio("fps"), **{f"{stage} ms": ratio(stage) for stage in STAGES},
            "stages 1-2 ms": float(np.median([stages12(a) / stages12(b) for a, b in zip(new, old)])),
            "command s": ratio("wall"), "load": os.getloadavg()[0]}


def run() -> list[dict]:
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        reason = _worktree(tmp / "old")
        if reason is not None:
            return [{"scene": "-", "version": "-", "note": reason}]
        try:
            versions = {"new": ROOT / "src", "old": tmp / "old" / "src"}
            rows = []
            for scene in SCENES:
                recording = _render(scene, tmp / "rec" / scene)
                runs = {name: [] for name in versions}
                for name, src in versions.items():  # warm-up: each version's numba cache filled
                    _track(src, recording, tmp / "out", tmp / f"cache-{name}")
                for _ in range(RUNS):
                    for name, src in versions.items():
                        runs[name].append(_track(src, recording, tmp / "out", tmp / f"cache-{name}"))
                rows += [_row(scene, "this code", runs["new"]), _row(scene, BASELINE, runs["old"]),
                         _ratio_row(scene, runs["new"], runs["old"])]
                print(f"  {scene}: {rows[-1]['frames/s']:.2f}x the frames/s of {BASELINE}", flush=True)
        finally:
            subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(tmp / "old")],
                           capture_output=True)
    return rows


if __name__ == "__main__":
    from benchmarks import print_table

    print_table(TITLE, run())
