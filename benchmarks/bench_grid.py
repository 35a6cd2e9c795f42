"""Stage 1: speed of the occupancy grid, and its foreground against a per-pixel MOG2 baseline.

Speed (``run``): one grid update (the fused numba kernel) for 80 x 80 x 50 cells of 5 cm
from one 640x480 Kinect v1 depth image (the rendered ``sit_behind_table`` scene, frame
300), on one thread and on all numba threads; the same for the whole front-room grid and
for two cameras; the back-projection of a depth image to cells and to foreground; the
update with a hold mask (the cells near one body), and the hold mask itself
(`cells_near_capsules`, margin 0.1 m) from the capsules covering one and two true bodies
of ``two_people_crossing`` (16 per body).

Accuracy (``run_accuracy``): every frame of four scenarios from frame 0 (no empty-room
start: the person is in view from the first frame), procedural motion, seed 0. Foreground =
pixels whose 3D point lies in an M cell (grid) or pixels MOG2 flags (OpenCV, depth in cm,
history 500); truth = the renderer's person pixels. Precision, recall and IoU are
averaged over frames 10 onwards in which the person covers at least 500 pixels (in
``moved_chair`` the carried chair counts against precision for both methods).
``HMM grid, true bodies held``: the grid with the hold mask of the true bodies (cells within
0.1 m of the capsules covering them, as the tracker will hold its predicted bodies), so that
people who stand still stay foreground. ``person_in_view`` is the first frame with 500
person pixels, ``extracted_after`` the frames from then until the IoU stays >= 0.5 for 10 frames; ``chair_static_after`` the
frames from the moment the chair is put down until less than 10 % of its pixels are
foreground (and stay so).
"""

from __future__ import annotations

import os

import numba
import numpy as np

from benchmarks import median_ms
from occupose.grid.baseline import DepthBackgroundSubtractor
from occupose.grid.hold import cells_near_capsules
from occupose.grid.occupancy import OccupancyGrid, cells_from_depth, spec_from_cameras
from occupose.grid.spec import GridSpec
from occupose.evaluation.pixels import foreground_scores
from occupose.synth.body import primitives_from_joints
from occupose.synth.generate import frames
from occupose.geometry.primitives import concat
from occupose.synth.render import render_camera
from occupose.synth.scenarios import build_scenario
from occupose.testing import capsules_from_primitives, foreground_from_grid

TITLE = "Occupancy grid: one update and back-projection (ms per frame)"
ACCURACY_TITLE = "Occupancy grid (HMM) vs per-pixel MOG2 on depth: foreground per scenario"
SCENARIOS = ("no_occlusion", "moved_chair", "sit_behind_table", "two_people_crossing")
MIN_PERSON_PIXELS = 500


def run(repeats: int = 50) -> list[dict]:
    """Time the cases. Returns one dict per case: case, cells, cameras, threads, ms_median, ms_min,
    load_1min (the machine's load average when the case finished: other processes share the cores)."""
    scenario = build_scenario("two_cameras_occlusion", use_mocap=False)
    frame = next(frames(scenario, indices=[300]))
    front = scenario.cameras[0]
    box = GridSpec((-2.0, 0.5, -0.025), 0.05, (80, 80, 50))
    cases = [
        ("grid update 80x80x50", box, scenario.cameras[:1]),
        ("grid update, front-room grid", spec_from_cameras(scenario.cameras[:1]), scenario.cameras[:1]),
        ("grid update, two cameras", spec_from_cameras(scenario.cameras), scenario.cameras),
    ]
    # the true bodies' capsules (two people of two_people_crossing placed in the box)
    crossing = build_scenario("two_people_crossing", use_mocap=False)
    bodies = [primitives_from_joints(p.joints[60] + (0.0, -0.8, 0.0), p.shape, i + 1)
              for i, p in enumerate(crossing.people)]
    capsules = capsules_from_primitives(concat(bodies))
    one = capsules_from_primitives(bodies[0])
    rows = []
    all_threads = numba.config.NUMBA_NUM_THREADS
    for threads in sorted({1, all_threads}):
        numba.set_num_threads(threads)
        for name, spec, cameras in cases:
            grid = OccupancyGrid(spec, cameras)
            depths = {cam.name: frame.depth[cam.name] for cam in cameras}
            median, best = median_ms(lambda: grid.update(depths), repeats)
            rows.append({"case": name, "cells": spec.num_cells, "cameras": len(cameras), "threads": threads,
                         "ms_median": median, "ms_min": best, "load_1min": os.getloadavg()[0]})
        grid = OccupancyGrid(box, [front])
        depth = frame.depth[front.name]
        for _ in range(10):
            grid.update({front.name: depth})
        hold = cells_near_capsules(box, *capsules)
        for name, function in (
            ("cells_from_depth (with states)", lambda: cells_from_depth(depth, front, box, grid.states)),
            ("foreground_from_grid", lambda: foreground_from_grid(grid.states, box, depth, front)),
            ("grid update 80x80x50 with a hold mask (one person)", lambda: grid.update({front.name: depth}, hold)),
            ("cells_near_capsules, 16 capsules (one body)", lambda: cells_near_capsules(box, *one)),
            ("cells_near_capsules, 32 capsules (two bodies)", lambda: cells_near_capsules(box, *capsules)),
        ):
            median, best = median_ms(function, repeats)
            rows.append({"case": name, "cells": box.num_cells, "cameras": 1, "threads": threads,
                         "ms_median": median, "ms_min": best, "load_1min": os.getloadavg()[0]})
    numba.set_num_threads(all_threads)
    return rows


def _first_stable(good: np.ndarray, run_length: int | None = None) -> int | None:
    """First index from which ``good`` (bool) holds for ``run_length`` values in a row (None:
    to the end); None when never."""
    for i in range(len(good)):
        window = good[i:] if run_length is None else good[i:i + run_length]
        if (run_length is None or len(window) == run_length) and window.all():
            return i
    return None


def _scenario_rows(name: str, seed: int = 0) -> list[dict]:
    scenario = build_scenario(name, use_mocap=False)
    cam = scenario.cameras[0]
    spec = spec_from_cameras(scenario.cameras)
    grid = OccupancyGrid(spec, scenario.cameras)
    held = OccupancyGrid(spec, scenario.cameras)
    mog2 = DepthBackgroundSubtractor("mog2")
    drop = scenario.events["carried"][1] if "carried" in scenario.events else None
    methods = ("HMM grid", "HMM grid, true bodies held", "MOG2")
    scores = {method: [] for method in methods}
    chair_share = {method: [] for method in methods}
    person_pixels = []
    for frame in frames(scenario, seed=seed):
        depth = frame.depth[cam.name]
        grid.update(frame.depth)
        bodies = [primitives_from_joints(frame.joints[p], person.shape, p + 1)
                  for p, person in enumerate(scenario.people) if frame.present[p]]
        held.update(frame.depth, hold=cells_near_capsules(spec, *capsules_from_primitives(concat(bodies))))
        masks = {"HMM grid": foreground_from_grid(grid.states, spec, depth, cam),
                 "HMM grid, true bodies held": foreground_from_grid(held.states, spec, depth, cam),
                 "MOG2": mog2.apply(depth)}
        truth = frame.rendered[cam.name].person > 0
        person_pixels.append(int(truth.sum()))
        for method, mask in masks.items():
            scores[method].append(foreground_scores(mask, truth))
        if drop is not None and frame.index >= drop:
            rendered = frame.rendered[cam.name]
            alone = render_camera(scenario.moving_at(frame.index), cam).depth
            chair = (alone > 0) & (np.abs(alone - rendered.depth) < 1e-6) & (rendered.person == 0)
            for method, mask in masks.items():
                chair_share[method].append(mask[chair].mean())
    person_pixels = np.array(person_pixels)
    in_view = person_pixels >= MIN_PERSON_PIXELS
    judged = (np.arange(len(person_pixels)) >= 10) & in_view
    appear = int(np.argmax(in_view))
    rows = []
    for method, values in scores.items():
        values = np.array(values, dtype=float)
        good = ~in_view | (np.nan_to_num(values[:, 2]) >= 0.5)
        extracted = _first_stable(good[appear:], 10)
        row = {"scenario": name, "method": method, "empty_room_start": "no",
               "precision": float(np.nanmean(values[judged, 0])), "recall": float(np.nanmean(values[judged, 1])),
               "iou": float(np.nanmean(values[judged, 2])), "person_in_view": appear,
               "extracted_after": "never" if extracted is None else extracted, "chair_static_after": "-"}
        if drop is not None:
            static = _first_stable(np.array(chair_share[method]) < 0.1)
            row["chair_static_after"] = f"> {len(chair_share[method])}" if static is None else static
        rows.append(row)
    return rows


def run_accuracy(seed: int = 0) -> list[dict]:
    """Foreground of the grid and of MOG2 on every frame of each scenario. Returns one dict per
    scenario and method: scenario, method, empty_room_start, precision, recall, iou,
    person_in_view (frame), extracted_after (frames), chair_static_after (frames after the drop)."""
    return [row for name in SCENARIOS for row in _scenario_rows(name, seed)]


if __name__ == "__main__":
    from benchmarks import print_table

    print_table(TITLE, run())
    print()
    print_table(ACCURACY_TITLE, run_accuracy())
