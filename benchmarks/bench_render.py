"""Speed of the synthetic renderer, the sensor noise models and a whole synthetic frame.

Scene: the ``sit_behind_table`` scenario (front room, couch and desk; Kinect v1 640x480),
its person walking in the open (frame 60) and, for 3 people, two copies of that body
beside it. Cases: the full render of everything; the per-frame render of the people over
the pre-rendered static background (what scene generation does), each on one thread and
on all numba threads; each noise model; and one whole frame of ``generate.frames`` (render,
noise and the per-part ground-truth visibility renders).
"""

from __future__ import annotations


import numba
import numpy as np

from benchmarks import median_ms
from occupose.synth.body import primitives_from_joints, random_body_shape
from occupose.synth.generate import frames
from occupose.synth.noise import apply_noise
from occupose.geometry.primitives import concat
from occupose.synth.render import render_camera
from occupose.synth.scenarios import build_scenario

TITLE = "Synthetic rendering, 640x480 (ms per frame)"


def run(repeats: int = 30) -> list[dict]:
    """Time the cases. Returns one dict per case: case, people, primitives, threads, ms_median, ms_min."""
    scenario = build_scenario("sit_behind_table", use_mocap=False)
    cam = scenario.cameras[0]
    joints = scenario.people[0].joints[60]
    shape = random_body_shape(np.random.default_rng(0))

    def people(count):
        return concat([primitives_from_joints(joints + [0.7 * i, 0.3 * i, 0.0], shape, i + 1) for i in range(count)])

    background = render_camera(scenario.static, cam)
    rows = []
    all_threads = numba.config.NUMBA_NUM_THREADS
    for threads in sorted({1, all_threads}):
        numba.set_num_threads(threads)
        for count in (1, 3):
            moving = people(count)
            everything = concat([scenario.static, moving])
            for case, function, k in (
                ("full render", lambda: render_camera(everything, cam), len(everything)),
                ("background + people", lambda: render_camera(moving, cam, background=background), len(moving)),
            ):
                median, best = median_ms(function, repeats)
                rows.append({"case": case, "people": count, "primitives": k, "threads": threads,
                             "ms_median": median, "ms_min": best})
    numba.set_num_threads(all_threads)
    depth = render_camera(concat([scenario.static, people(1)]), cam).depth
    for model in ("structured_light", "tof"):
        rng = np.random.default_rng(0)
        median, best = median_ms(lambda: apply_noise(depth, model, rng, fx=cam.fx), repeats)
        rows.append({"case": f"noise {model}", "people": 1, "primitives": 0, "threads": all_threads,
                     "ms_median": median, "ms_min": best})
    median, best = median_ms(lambda: next(frames(scenario, indices=[60])), max(5, repeats // 3))
    rows.append({"case": "whole synthetic frame with ground truth", "people": 1, "primitives": 16 + len(scenario.static),
                 "threads": all_threads, "ms_median": median, "ms_min": best})
    return rows


if __name__ == "__main__":
    from benchmarks import print_table

    print_table(TITLE, run())
