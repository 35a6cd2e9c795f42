"""Speed of the body models' forward kinematics and pose fitting.

Cases: ``capsules_from_poses`` and ``joints_from_poses`` for 200 and 1000 particles of the
``full`` (25 DOF, 11 cones) and ``upper`` (17 DOF, 13 cones) models, random poses within
the joint limits, on one numba thread and on all of them; ``pose_from_joints`` on frames of
procedural motion (walking, waving, sitting). Medians over repeats (the cores may be shared).
"""

from __future__ import annotations

import time

import numba
import numpy as np

from benchmarks import median_seconds
from occupose.body import BODY_MODELS, capsules_from_poses, joints_from_poses, pose_from_joints
from occupose.synth.motion import MotionBuilder

TITLE = "Body models: forward kinematics and pose fitting (microseconds per call)"


def _median_us_call(function, repeats: int, warmup: int = 5) -> tuple[float, float]:
    median, best = median_seconds(function, repeats, warmup)
    return 1e6 * median, 1e6 * best


def run(repeats: int = 200) -> list[dict]:
    """Time the cases. Returns one dict per case: case, model, particles, threads, us_median, us_min."""
    rng = np.random.default_rng(0)
    rows = []
    all_threads = numba.config.NUMBA_NUM_THREADS
    for threads in sorted({1, all_threads}):
        numba.set_num_threads(threads)
        for name, model in BODY_MODELS.items():
            for count in (200, 1000):
                poses = rng.uniform(model.limits[:, 0], model.limits[:, 1], size=(count, model.num_dofs))
                for case, function in (("capsules_from_poses", capsules_from_poses),
                                       ("joints_from_poses", joints_from_poses)):
                    median, best = _median_us_call(lambda: function(model, poses), repeats)
                    rows.append({"case": case, "model": name, "particles": count, "threads": threads,
                                 "us_median": median, "us_min": best})
    numba.set_num_threads(all_threads)
    builder = MotionBuilder((0.0, 0.0), 0.3)
    joints = builder.walk([(2.0, 0.5)]).wave("right").sit_down(0.45).joints()[::10]
    for name, model in BODY_MODELS.items():
        times = []
        for frame in joints:
            start = time.perf_counter()
            pose_from_joints(model, frame)
            times.append(time.perf_counter() - start)
        rows.append({"case": "pose_from_joints", "model": name, "particles": 1, "threads": all_threads,
                     "us_median": 1e6 * float(np.median(times)), "us_min": 1e6 * float(np.min(times))})
    return rows


if __name__ == "__main__":
    from benchmarks import print_table

    print_table(TITLE, run())
