"""Stage 2: speed of labelling + blob tracking, and how well the pixels are split between people.

Speed (``run``): per frame, `blobs_from_mask` + `BlobTracker.update` on an 80 x 80 x 50
grid of 5 cm cells, over a sequence of frames (tracker state carried over), median and 90th
percentile of the per-frame times. Moving cells from two sources: (a) the cells holding
the rendered points of 1-3 people walking side by side (the ``no_occlusion`` walk, frames
0-59, copies 0.8 m nearer and farther and 0.5 m apart), a clean mask; (b) the HMM grid
itself on ``two_people_crossing`` (frames 0-129, noise components included). For (b) also the time of `pixels_from_depth` (one
640x480 camera, previous-observation bodies). The load average is reported: the cores
are shared with other processes.

Accuracy (``run_accuracy``): pixel assignment between the two people of
``two_people_crossing`` and ``top_view_two_people`` (every frame, procedural motion, seed 0).
``accuracy`` = share of the pixels that are a person's and assigned to a track that went
to the right person (tracks mapped to people by majority overlap over the whole run, so
an identity swap would count as wrong), mean and minimum over the frames where both
people are present and some pixel is assigned; ``precision``/``recall`` of the assigned
pixels as foreground against the renderer's person image (and ``iou``); ``id_swaps`` = frames whose own
majority mapping disagrees with the whole run's. Moving cells from the HMM grid or from
the perfect mask of (a); the exclusion principle's bodies: the previous frame's
observation (`predicted_from_tracks`), the tracker's cell shares, or the centroid fallback.
``hold``: the grid's hold mask (`OccupancyGrid.update`), which keeps people who stand still
moving: ``true bodies`` = cells within MARGIN (0.1 m) of the capsules covering the true
bodies of the frame (`capsules_from_primitives`: a perfect prediction, standing in for the
tracker's predicted bodies), ``previous blobs`` = the cells of the previous frame's tracked
blobs dilated by a ball of 0.1 m, ``none`` = no hold (people fade after 77 frames still).
"""

from __future__ import annotations

import os
import time

import numpy as np

from occupose.camera import points_from_depth
from scipy import ndimage

from occupose.grid.blobs import blobs_from_mask
from occupose.grid.hold import MARGIN, cells_near_capsules
from occupose.grid.pixels import (
    distance_to_points, pixels_from_depth, predicted_from_tracks,
)
from occupose.grid.occupancy import OccupancyGrid, spec_from_cameras
from occupose.grid.spec import GridSpec
from occupose.grid.tracking import BlobTracker
from occupose.evaluation.pixels import foreground_scores, pixel_assignment_accuracy
from occupose.synth.body import primitives_from_joints, random_body_shape
from occupose.synth.generate import frames
from occupose.geometry.primitives import concat
from occupose.synth.render import render_camera
from occupose.synth.scenarios import build_scenario
from occupose.testing import capsules_from_primitives, persons_from_tracks

TITLE = "Blobs: labelling + blob tracking on 80x80x50 cells, and per-person observations (ms per frame)"
ACCURACY_TITLE = "Blobs: pixel assignment between two people (exclusion principle)"
BOX = GridSpec((-2.0, 1.5, -0.025), 0.05, (80, 80, 50))
#: Dilation of the previous frame's blob cells for the "previous blobs" hold: a ball of
#: two cells' radius (MARGIN = 0.1 m).
_BALL = np.sum(np.mgrid[-2:3, -2:3, -2:3] ** 2, axis=0) <= 4
OFFSETS = ((0.0, 0.0), (0.5, 0.8), (-0.5, -0.8))


def _mask_of_points(points: np.ndarray, spec: GridSpec) -> np.ndarray:
    index, inside = spec.cells_from_points(points)
    mask = np.zeros(spec.shape, bool)
    mask[tuple(index[inside].T)] = True
    return mask


def _time_sequence(masks: list[np.ndarray], fps: float, spec: GridSpec, rounds: int = 3) -> np.ndarray:
    """Per-frame seconds of labelling + tracking over the mask sequence, ``rounds`` times."""
    times = []
    blobs_from_mask(masks[0], spec)  # numba compile / cache load
    for _ in range(rounds):
        tracker = BlobTracker(fps)
        for mask in masks:
            start = time.perf_counter()
            tracker.update(blobs_from_mask(mask, spec)[1])
            times.append(time.perf_counter() - start)
    return np.array(times)


def _row(case, people, frames_, times, blobs=None) -> dict:
    return {"case": case, "people": people, "frames": frames_,
            "ms_median": 1e3 * float(np.median(times)), "ms_p90": 1e3 * float(np.percentile(times, 90)),
            "blobs_per_frame": "-" if blobs is None else f"{blobs:.1f}", "load_1min": os.getloadavg()[0]}


def run(num_frames: int = 60) -> list[dict]:
    """Time the cases. Returns one dict per case: case, people, frames, ms_median, ms_p90,
    blobs_per_frame, load_1min."""
    walk = build_scenario("no_occlusion", use_mocap=False)
    cam = walk.cameras[0]
    shape = random_body_shape(np.random.default_rng(0))
    start = 0  # walking from x = 1.3 to x = -1.2
    rows = []
    for count in (1, 2, 3):
        masks = []
        for t in range(start, start + num_frames):
            bodies = [primitives_from_joints(walk.people[0].joints[t] + [dx, dy, 0.0], shape, i + 1)
                      for i, (dx, dy) in enumerate(OFFSETS[:count])]
            depth = render_camera(concat(bodies), cam).depth
            masks.append(_mask_of_points(points_from_depth(depth, cam)[0], BOX))
        blobs = np.mean([len(blobs_from_mask(m, BOX)[1]) for m in masks])
        rows.append(_row("label + track, rendered people's cells", count, num_frames,
                         _time_sequence(masks, walk.fps, BOX), blobs))
    crossing = build_scenario("two_people_crossing", use_mocap=False)
    grid = OccupancyGrid(BOX, crossing.cameras)
    masks, label_track, observe, counts = [], [], [], []
    tracker, previous = BlobTracker(crossing.fps), {}
    for frame in frames(crossing, indices=range(0, 130)):
        grid.update(frame.depth)
        masks.append(grid.moving_mask())
        begin = time.perf_counter()
        labels, blobs = blobs_from_mask(masks[-1], BOX)
        tracks = tracker.update(blobs)
        middle = time.perf_counter()
        bodies = predicted_from_tracks(tracker.states, previous, crossing.fps)
        previous, _ = pixels_from_depth(frame.depth, crossing.cameras, BOX, labels, tracks,
                                              states=grid.states, predicted=bodies)
        end = time.perf_counter()
        label_track.append(middle - begin)
        observe.append(end - middle)
        counts.append(len(blobs))
    rows.append(_row("label + track, HMM grid (two_people_crossing)", 2, len(masks),
                     _time_sequence(masks, crossing.fps, BOX), float(np.mean(counts))))
    rows.append(_row("pixels_from_depth, HMM grid (two_people_crossing)", 2, len(masks),
                     np.array(observe[5:]), float(np.mean(counts))))
    return rows


# ------------------------------------------------------------------------------ accuracy


def _bodies(kind, tracker, previous, fps, tracks):
    states = tracker.states
    if kind == "previous observation":
        return predicted_from_tracks(states, previous, fps)
    if kind == "tracker cell shares":
        return {tid: distance_to_points(states[tid].points) for tid in tracks}
    return {}  # centroid fallback only


def _hold(mode, frame, scenario, spec, tracker):
    """The grid's hold mask for this frame (None: no hold)."""
    if mode == "true bodies":
        bodies = [primitives_from_joints(frame.joints[p], person.shape, p + 1)
                  for p, person in enumerate(scenario.people) if frame.present[p]]
        return cells_near_capsules(spec, *capsules_from_primitives(concat(bodies)), MARGIN)
    if mode == "previous blobs":
        mask = np.zeros(spec.num_cells, bool)
        for state in tracker.states.values():
            if state.blob is not None:
                mask[state.blob.cells] = True
        return ndimage.binary_dilation(mask.reshape(spec.shape), _BALL)
    return None


def _runs(name, pipelines, *, seed=0):
    """Run the stages over every frame; pipelines: list of (hold, moving cells source, body
    kind), one grid per hold mode. Returns per pipeline the per-frame (assigned image, truth
    image, present)."""
    scenario = build_scenario(name, use_mocap=False)
    cam = scenario.cameras[0]
    spec = spec_from_cameras(scenario.cameras)
    grids = {hold: OccupancyGrid(spec, scenario.cameras) for hold, _, _ in pipelines}
    trackers = [BlobTracker(scenario.fps) for _ in pipelines]
    # the tracker whose blobs hold the cells of the "previous blobs" grid
    holder = {hold: trackers[p] for p, (hold, source, _) in enumerate(pipelines) if source == "HMM grid"}
    previous = [{} for _ in pipelines]
    out = [[] for _ in pipelines]
    for frame in frames(scenario, seed):
        truth = frame.rendered[cam.name].person.astype(np.int64)
        for hold, grid in grids.items():
            grid.update(frame.depth, hold=_hold(hold, frame, scenario, spec, holder.get(hold)))
        oracle = _mask_of_points(points_from_depth(np.where(truth > 0, frame.depth[cam.name], 0), cam)[0], spec)
        for p, (hold, source, kind) in enumerate(pipelines):
            grid = grids[hold]
            moving, states = (grid.moving_mask(), grid.states) if source == "HMM grid" else (oracle, None)
            labels, blobs = blobs_from_mask(moving, spec)
            tracks = trackers[p].update(blobs)
            bodies = _bodies(kind, trackers[p], previous[p], scenario.fps, tracks)
            centers = {tid: s.centroid for tid, s in trackers[p].states.items() if tid in tracks}
            previous[p], assigned = pixels_from_depth(frame.depth, scenario.cameras, spec, labels, tracks,
                                                            states=states, centers=centers, predicted=bodies)
            out[p].append((assigned[cam.name], truth, frame.present.copy()))
    return out


def _score(run, frames_from=0, frames_to=None) -> dict:
    run = run[frames_from:frames_to]
    mapping = persons_from_tracks([a for a, _, _ in run], [t for _, t, _ in run])
    lut = np.zeros(max([int(a.max()) for a, _, _ in run] + list(mapping) + [0]) + 1, np.int64)
    for track, person in mapping.items():
        lut[track] = person
    accuracy, precision, recall, iou, swaps = [], [], [], [], 0
    for assigned, truth, present in run:
        if not present.all():
            continue
        p, r, i = foreground_scores(assigned > 0, truth > 0)
        precision.append(p)
        recall.append(r)
        iou.append(i)
        scored = (truth > 0) & (assigned > 0)
        if scored.any():
            accuracy.append(pixel_assignment_accuracy(lut[assigned], truth, scored))
            own = persons_from_tracks([assigned], [truth])
            swaps += any(mapping.get(track) != person for track, person in own.items())
    return {"frames": len(precision), "scored_frames": len(accuracy),
            "accuracy_mean_%": 100 * float(np.mean(accuracy)) if accuracy else float("nan"),
            "accuracy_min_%": 100 * float(np.min(accuracy)) if accuracy else float("nan"),
            "precision_%": 100 * float(np.nanmean(precision)), "recall_%": 100 * float(np.nanmean(recall)),
            "iou_%": 100 * float(np.nanmean(iou)), "id_swaps": swaps}


def run_accuracy() -> list[dict]:
    """One dict per (scenario, hold, moving cells, bodies): the scores of ``_score`` over all frames."""
    rows = []
    for name, pipelines in (
        ("two_people_crossing", [("true bodies", "HMM grid", "previous observation"),
                                 ("true bodies", "HMM grid", "centroid fallback"),
                                 ("none", "HMM grid", "previous observation")]),
        ("top_view_two_people", [("true bodies", "HMM grid", "previous observation"),
                                 ("previous blobs", "HMM grid", "previous observation"),
                                 ("none", "HMM grid", "previous observation"),
                                 ("none", "perfect mask", "previous observation"),
                                 ("none", "perfect mask", "tracker cell shares"),
                                 ("none", "perfect mask", "centroid fallback")]),
    ):
        for (hold, source, kind), run in zip(pipelines, _runs(name, pipelines)):
            rows.append({"scenario": name, "hold": hold if source == "HMM grid" else "-", "moving_cells": source,
                         "bodies": kind, "range": "all", **_score(run)})
    return rows


if __name__ == "__main__":
    from benchmarks import print_table

    print_table(TITLE, run())
    print()
    print_table(ACCURACY_TITLE, run_accuracy())
