"""Speed of the synthetic renderer and the sensor noise models on 640x480 frames.

Scene: a 6 x 6 m room (floor and four walls) with furniture, 12 boxes in all, seen by a
camera in a corner 2.5 m up; people of 16 primitives each (ellipsoids, round cones,
boxes). Cases: the full render of everything, and the per-frame render of the people
over a pre-rendered static background, each on one thread and on all numba threads (a
busy machine slows the threaded runs most); then each noise model (single-threaded) on
the rendered depth.

Run: ``python benchmarks/bench_render.py`` (prints a table); ``run()`` returns the rows.
"""

from __future__ import annotations

import time

import numba
import numpy as np

from occupose.camera import look_at
from occupose.synth import primitives as prim
from occupose.synth.noise import apply_noise
from occupose.synth.render import render

WIDTH, HEIGHT, FX, FY, CX, CY = 640, 480, 525.0, 525.0, 319.5, 239.5


def _heading(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def static_scene() -> prim.Primitives:
    """Room (floor + 4 walls) and 7 furniture boxes: 12 boxes."""
    wall, wood, fabric = (215, 210, 200), (150, 105, 60), (95, 110, 140)
    boxes = [
        prim.box((0.0, 0.0, -0.05), (3.05, 3.05, 0.05), (165, 150, 130)),
        prim.box((3.05, 0.0, 1.4), (0.05, 3.05, 1.4), wall),
        prim.box((-3.05, 0.0, 1.4), (0.05, 3.05, 1.4), wall),
        prim.box((0.0, 3.05, 1.4), (3.05, 0.05, 1.4), wall),
        prim.box((0.0, -3.05, 1.4), (3.05, 0.05, 1.4), wall),
        prim.box((1.0, 1.2, 0.73), (0.6, 0.35, 0.02), wood, _heading(0.3)),      # table top
        prim.box((1.0, 1.2, 0.355), (0.5, 0.25, 0.355), wood, _heading(0.3)),    # its legs as a block
        prim.box((-1.8, 2.6, 0.9), (0.8, 0.2, 0.9), wood),                       # shelf
        prim.box((-1.5, -1.0, 0.22), (0.45, 0.9, 0.22), fabric, _heading(-0.2)), # sofa seat
        prim.box((-1.9, -1.1, 0.5), (0.1, 0.9, 0.3), fabric, _heading(-0.2)),    # sofa back
        prim.box((0.3, 1.8, 0.23), (0.22, 0.22, 0.02), wood),                    # chair seat
        prim.box((0.3, 2.0, 0.5), (0.22, 0.02, 0.3), wood),                      # chair back
    ]
    return prim.concat(boxes)


def person(x: float, y: float, heading: float, person_id: int) -> prim.Primitives:
    """A standing person of 16 primitives at floor position (x, y)."""
    rot = _heading(heading)

    def at(local):
        return np.array([x, y, 0.0]) + rot @ np.asarray(local, float)

    skin, shirt, trousers, shoes = (224, 172, 105), (40, 60, 120), (50, 50, 55), (30, 30, 30)
    parts = [
        prim.ellipsoid(at((0, 0, 1.62)), (0.09, 0.08, 0.11), skin, rot, person_id, 1),
        prim.round_cone(at((0, 0, 1.42)), at((0, 0, 1.52)), 0.05, 0.045, skin, person_id, 1),
        prim.ellipsoid(at((0, 0, 1.25)), (0.12, 0.18, 0.22), shirt, rot, person_id, 2),
        prim.ellipsoid(at((0, 0, 0.95)), (0.11, 0.17, 0.12), trousers, rot, person_id, 3),
    ]
    for side, (upper, fore, hand, thigh, shin, foot) in ((1, (4, 5, 6, 10, 11, 12)), (-1, (7, 8, 9, 13, 14, 15))):
        shoulder, elbow, wrist = at((0, side * 0.2, 1.42)), at((0.05, side * 0.24, 1.14)), at((0.12, side * 0.25, 0.9))
        hip, knee, ankle = at((0, side * 0.1, 0.9)), at((0.03, side * 0.11, 0.48)), at((0, side * 0.11, 0.08))
        parts += [
            prim.round_cone(shoulder, elbow, 0.055, 0.045, shirt, person_id, upper),
            prim.round_cone(elbow, wrist, 0.045, 0.035, skin, person_id, fore),
            prim.box(at((0.14, side * 0.25, 0.83)), (0.03, 0.02, 0.07), skin, rot, person_id, hand),
            prim.round_cone(hip, knee, 0.08, 0.055, trousers, person_id, thigh),
            prim.round_cone(knee, ankle, 0.055, 0.04, trousers, person_id, shin),
            prim.box(at((0.06, side * 0.11, 0.04)), (0.12, 0.045, 0.04), shoes, rot, person_id, foot),
        ]
    return prim.concat(parts)


def people(count: int) -> prim.Primitives:
    spots = [(0.0, 0.0, 0.5), (1.2, -1.0, 2.0), (-0.8, 1.0, -1.0)]
    return prim.concat([person(*spots[i], i + 1) for i in range(count)])


def _median_ms(function, repeats: int, warmup: int = 3) -> tuple[float, float]:
    for _ in range(warmup):
        function()
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        times.append(time.perf_counter() - start)
    return 1e3 * float(np.median(times)), 1e3 * float(np.min(times))


def run(repeats: int = 30) -> list[dict]:
    """Time the cases, on one thread and on all numba threads.

    Returns one dict per case: case, people, primitives, threads, ms_median, ms_min.
    """
    pose = look_at((-2.7, -2.7, 2.5), (0.5, 0.5, 0.8))
    view = (WIDTH, HEIGHT, FX, FY, CX, CY, pose)
    static = static_scene()
    background = render(static, *view)
    rows = []
    all_threads = numba.config.NUMBA_NUM_THREADS
    for threads in sorted({1, all_threads}):
        numba.set_num_threads(threads)
        for count in (1, 3):
            moving = people(count)
            everything = prim.concat([static, moving])
            for case, function, k in (
                ("full render", lambda: render(everything, *view), len(everything)),
                ("background + people", lambda: render(moving, *view, background=background), len(moving)),
            ):
                median, best = _median_ms(function, repeats)
                rows.append({"case": case, "people": count, "primitives": k, "threads": threads,
                             "ms_median": median, "ms_min": best})
    numba.set_num_threads(all_threads)
    depth = render(prim.concat([static, people(1)]), *view).depth
    for model in ("structured_light", "tof"):
        rng = np.random.default_rng(0)
        median, best = _median_ms(lambda: apply_noise(depth, model, rng, fx=FX), repeats)
        rows.append({"case": f"noise {model}", "people": 1, "primitives": 0, "threads": 1,
                     "ms_median": median, "ms_min": best})
    return rows


if __name__ == "__main__":
    print(f"{'case':<24}{'people':>7}{'prims':>7}{'threads':>8}{'ms median':>11}{'ms min':>9}   (640x480)")
    for row in run():
        print(f"{row['case']:<24}{row['people']:>7}{row['primitives']:>7}{row['threads']:>8}"
              f"{row['ms_median']:>11.2f}{row['ms_min']:>9.2f}")
