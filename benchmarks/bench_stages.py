"""Stages 1-2 per frame inside the tracker: grid, blobs and per-person pixels (``observations``).

``ours`` on 120 frames of ``sit_behind_table`` (one 640x480 Kinect v1) and of
``two_cameras_occlusion`` (two cameras), procedural motion, rendered first; each stage's
mean and median milliseconds over frames 1-119 (the first frame, with numba's code
loaded from its cache, excluded) from ``FrameResult.seconds``, and how many grid cells
had their HMM step run in the last frame (the others would not have changed). The depth
noise is measured on the first frames before tracking, as ``occupose track`` does
(`occupose.run.track_recording`): a Tracker left to measure it itself makes its grid
again and replays those frames through it in the frame it has them (about 0.7 s for one
camera, 0.8 s for two, at frame 29), which would be most of the mean. To compare two
versions of the code, run this module with each one's ``src`` first on PYTHONPATH.
"""

from __future__ import annotations

import os

import numpy as np

from occupose.config import method_config
from occupose.grid.noise import measure_noise
from occupose.synth.generate import frames
from occupose.synth.scenarios import build_scenario
from occupose.tracker import Tracker

TITLE = "Stages 1-2 in the tracker (ours): ms per frame, first frame excluded"
NUM_FRAMES = 120
SCENES = ("sit_behind_table", "two_cameras_occlusion")


def run() -> list[dict]:
    rows = []
    for name in SCENES:
        scene = build_scenario(name, use_mocap=False)
        rendered = list(frames(scene, seed=0, num_frames=NUM_FRAMES))
        config = method_config("ours")
        noise = measure_noise(scene.cameras, (frame.depth for frame in rendered), config.grid, strict=False)
        tracker = Tracker(scene.cameras, scene.fps, config, seed=0, noise=noise)
        seconds = {stage: [] for stage in ("grid", "blobs", "observations")}
        for frame in rendered:
            result = tracker.update(frame.depth)
            for stage, values in seconds.items():
                values.append(1e3 * result.seconds[stage])
        per_frame = {stage: np.array(values[1:]) for stage, values in seconds.items()}
        rows.append({
            "scene": name, "cameras": len(scene.cameras), "cells": tracker.spec.num_cells,
            "cells stepped (last frame)": tracker.grid.stepped,
            **{f"{stage} ms": float(values.mean()) for stage, values in per_frame.items()},
            "stages 1-2 ms (mean)": float(sum(per_frame.values()).mean()),
            "stages 1-2 ms (median)": float(np.median(sum(per_frame.values()))),
            "load": os.getloadavg()[0],
        })
    return rows


if __name__ == "__main__":
    from benchmarks import print_table

    print_table(TITLE, run())
