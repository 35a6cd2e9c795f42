"""Frames per second of the whole tracker (`occupose track`'s loop) for 1, 2 and 3 people.

Method ``ours`` (apf+ps, 200 particles x 5 layers, occlusion handling), one 640x480
Kinect v1, 5 cm grid, procedural motion (the same scenes with or without the shared
data). The frames are rendered first; the clock covers ``Tracker.update`` only, the first
frame (start-up: numba's compiled code loaded from the cache) excluded, as in
``summary.json``. One person is also timed without the overlap of the grid update with
the pose stage (the paper's IV-B concurrency; off by default in ``occupose track``, where
it was slower on an idle machine). Three people: ``two_people_crossing`` with the walker of
``no_occlusion`` added between them.
"""

from __future__ import annotations

import os
from dataclasses import replace

import numpy as np

from occupose.evaluation.pixels import pixel_assignment_accuracy
from occupose.synth.generate import frames
from occupose.synth.scenarios import build_scenario
from occupose.testing import persons_from_tracks
from occupose.run import track_frames
from occupose.tracker import Tracker

TITLE = "Tracker speed: frames/s of `occupose track` (ours), start-up excluded, and ms per frame per stage"

NUM_FRAMES = 300


def three_people():
    """``two_people_crossing`` with the walker of ``no_occlusion`` walking between the two
    (procedural motion): the three-people scene of the speed benchmarks."""
    scene = build_scenario("two_people_crossing", use_mocap=False)
    walker = build_scenario("no_occlusion", use_mocap=False).people[0]
    joints = walker.joints[: scene.num_frames].copy()
    joints[..., 1] += 3.0 - np.nanmean(joints[:, :, 1])  # walks between the other two
    return replace(scene, name="three_people", people=scene.people + (replace(walker, joints=joints),))


def _scenes():
    yield "sit_behind_table", build_scenario("sit_behind_table", use_mocap=False)
    yield "two_people_crossing", build_scenario("two_people_crossing", use_mocap=False)
    yield "three_people", three_people()


def run() -> list[dict]:
    rows = []
    for name, scene in _scenes():
        rendered = list(frames(scene, seed=0, num_frames=NUM_FRAMES))
        for overlap in ((False, True) if name == "sit_behind_table" else (False,)):
            rows.append(_row(name, scene, rendered, overlap))
    return rows


def _row(name, scene, rendered, overlap: bool) -> dict:
    tracker = Tracker(scene.cameras, scene.fps, "ours", seed=0)
    result = track_frames(tracker, rendered, NUM_FRAMES, overlap=overlap)
    per_frame = {stage: 1e3 * seconds / NUM_FRAMES for stage, seconds in result.seconds.items()
                 if stage not in ("total", "startup")}
    tracked = [np.isfinite(j[:, 0, 0]) for j, _ in result.tracks.values()]
    return {
        "scene": name, "people in scene": len(scene.people),
        "people tracked (last frame)": int(sum(t[-1] for t in tracked)),
        "grid overlaps pose": "yes" if overlap else "no",
        "frames/s": result.fps, "grid ms (waited)": per_frame["grid"], "blobs ms": per_frame["blobs"],
        "observations ms": per_frame["observations"], "pose ms": per_frame["pose"],
        "load": os.getloadavg()[0],
    }


ACCURACY_TITLE = "Tracker: pixels assigned to the right person between two people (exclusion principle, real grid and predicted bodies)"


def run_accuracy() -> list[dict]:
    """Share of the foreground pixels both a person and the tracker claim that the tracker
    gives to the right person (track ids mapped to people by majority overlap), per frame
    with both people in view, over each two-person scene (procedural motion)."""
    rows = []
    for name, method, count in (("two_people_crossing", "ours", 200), ("top_view_two_people", "ours", 300),
                                ("top_view_two_people", "part-based", 300)):
        scene = build_scenario(name, use_mocap=False)
        camera = scene.cameras[0].name
        tracker = Tracker(scene.cameras, scene.fps, method, seed=0)
        assigned, truth = [], []
        for frame in frames(scene, seed=0, num_frames=count):
            assigned.append(tracker.update(frame.depth).assigned[camera].copy())
            truth.append(frame.rendered[camera].person.astype(np.int64))
        person_of = persons_from_tracks(assigned, truth)
        lut = np.zeros(max([0, *person_of]) + 1, np.int64)
        lut[list(person_of)] = list(person_of.values())
        scores = []
        for a, t in zip(assigned, truth):
            both = (a > 0) & (t > 0)
            if np.count_nonzero(both) >= 50 and len(np.unique(t[t > 0])) == 2:
                scores.append(pixel_assignment_accuracy(lut[np.minimum(a, len(lut) - 1)], t, both))
        rows.append({"scene": name, "method": method, "frames scored": len(scores),
                     "tracks -> people": str(person_of), "accuracy mean %": 100 * float(np.mean(scores)),
                     "accuracy min %": 100 * float(np.min(scores))})
    return rows
