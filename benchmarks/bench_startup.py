"""A machine's first run against its second: no compile stall (issue 27).

`occupose track` of ``sit_behind_table`` (procedural motion, 120 frames) run twice as a
command, in a numba cache folder of its own that starts empty: the first run compiles
every kernel before its first frame (``warm_up`` in its summary.json), the second loads
them from the cache. The target: the first run's frames/s (start-up excluded) within 20 %
of the second's. Before the warm-up (a5a32a1) the first run tracked at 3.3 frames/s
against 55 (docs/notes/2026-12-06-compile-stall.md).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from occupose.synth.catalogue import render_scenario

TITLE = "First run on a machine (empty numba cache) against the second: frames/s of `occupose track`"

SCENE = "sit_behind_table"
NUM_FRAMES = 120


def _track(recording: Path, out: Path, cache: Path) -> dict:
    start = time.perf_counter()
    command = Path(sys.executable).parent / "occupose"  # the venv's command, as a user runs it
    subprocess.run([str(command), "track", str(recording), "--out", str(out), "--force"],
                   check=True, capture_output=True, env=os.environ | {"NUMBA_CACHE_DIR": str(cache)})
    wall = time.perf_counter() - start
    summary = json.loads((out / "summary.json").read_text())
    return {"fps": summary["fps"], "warm_up": summary["seconds"]["warm_up"], "wall": wall}


def run() -> list[dict]:
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        recording = render_scenario(SCENE, tmp / "rec", frames=NUM_FRAMES, procedural=True).path
        first = _track(recording, tmp / "first", tmp / "cache")
        second = _track(recording, tmp / "second", tmp / "cache")
    return [{"run": name, "frames/s": round(r["fps"], 1), "warm-up s": round(r["warm_up"], 2),
             "command s": round(r["wall"], 1), "frames/s / second run's": round(r["fps"] / second["fps"], 2)}
            for name, r in (("first (empty cache)", first), ("second", second))]
