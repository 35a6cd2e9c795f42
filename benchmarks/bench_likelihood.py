"""Speed of the likelihoods: one evaluate() of P particles on a synthetic frame.

Scene: a person facing a Kinect v1 3 m away (640x480, noise-free render of occupose.synth),
the observation their pixels (2000 points, person box about 240 x 460 pixels), particles
the fitted true pose of the ``full`` model (11 round cones) diffused by 0.1 rad / 3 cm per
DOF; the ``upper`` model (13 round cones) from a ceiling camera for the points term too.
Throughput counts particle x evaluation pairs per second: observed points (points),
surface samples (free: 27 per capsule, color: 32) or grid pixels (render: every 4th pixel
of the person box). Wall-clock medians over repeats with all numba threads, and the
median CPU time of the same call on one thread (``cpu_ms_1thread``, from which the
per-core throughput), which other processes on the machine disturb much less; ``load``
is the 1-minute load average when the case started (a load above the core count means
the wall-clock figures were slowed by other processes).
"""

from __future__ import annotations

import os
import time

import numba
import numpy as np

from occupose.body import BODY_MODELS, capsules_from_poses, pose_from_joints
from occupose.camera import camera_preset, look_at
from occupose.likelihood import View, make_likelihood, observation_from_views
from occupose.synth import motion as pm
from occupose.synth import scene
from occupose.synth.body import primitives_from_joints, random_body_shape
from occupose.geometry.primitives import concat
from occupose.synth.render import render_camera

TITLE = "Likelihoods: one evaluate() of P particles, 2000 observed points (ms, millions of evaluations/s)"

NUM_POINTS = 2000


def _observation(joints, eye, target, walls):
    camera = camera_preset("kinect_v1", world_from_camera=look_at(eye, target))
    body = primitives_from_joints(joints, random_body_shape(np.random.default_rng(0)), 1)
    rendered = render_camera(concat([scene.room(walls=walls), body]), camera)
    view = View(camera, rendered.depth, rendered.person == 1, rendered.color)
    return observation_from_views([view], max_points=NUM_POINTS)


def _particles(model, joints, count, rng):
    pose = pose_from_joints(model, joints)
    spread = np.where(model.angular, 0.1, 0.03)
    poses = np.clip(pose + rng.normal(size=(count, model.num_dofs)) * spread, model.limits[:, 0], model.limits[:, 1])
    a, b = capsules_from_poses(model, poses)
    return a, b, model.capsule_radii, model.capsule_part, model.num_parts


def _median_ms(function, repeats: int, clock=time.perf_counter) -> tuple[float, float]:
    function()  # compile / warm up
    times = []
    for _ in range(repeats):
        start = clock()
        function()
        times.append(clock() - start)
    return 1e3 * float(np.median(times)), 1e3 * float(np.min(times))


def run(repeats: int = 11) -> list[dict]:
    """Time each likelihood at 200 and 1000 particles. Returns one dict per case: likelihood,
    model, particles, evaluations per particle (what), threads, ms_median, ms_min,
    M_evals_per_s (median, wall clock), cpu_ms_1thread, M_evals_per_s_per_core, load."""
    rng = np.random.default_rng(0)
    joints = pm.joints_from_procedural(pm.pose_with(pm.stance(), right_shoulder_flex=0.6, right_elbow=0.8,
                                              left_shoulder_abd=0.5))
    front = _observation(joints, (3.0, 0.0, 1.4), (0.0, 0.0, 0.9), ("-x",))
    top = _observation(joints, (0.0, 0.0, 3.2), (0.0, 0.0, 0.0), ())
    full, upper = BODY_MODELS["full"], BODY_MODELS["upper"]
    v0, v1, u0, u1 = front.views[0].roi
    grid = len(range(v0, v1, 4)) * len(range(u0, u1, 4))
    cases = [
        ("points", full, front, {}, NUM_POINTS, "points"),
        ("points", upper, top, {}, NUM_POINTS, "points"),
        ("free", full, front, {}, 27 * full.num_capsules, "samples"),
        ("points+free", full, front, {}, NUM_POINTS, "points"),
        ("render", full, front, {}, grid, "grid pixels"),
        ("color", full, front, {}, 32 * full.num_capsules, "samples"),
    ]
    rows = []
    threads = numba.get_num_threads()
    for name, model, obs, options, per_particle, what in cases:
        likelihood = make_likelihood(name, obs, **options)
        if name == "color":
            reference = likelihood.histograms(*_particles(model, joints, 1, rng))[0]
            likelihood.set_reference(reference)
        for count in (200, 1000):
            capsules = _particles(model, joints, count, rng)
            load = os.getloadavg()[0]
            median, best = _median_ms(lambda: likelihood.evaluate(*capsules), repeats)
            numba.set_num_threads(1)
            cpu, _ = _median_ms(lambda: likelihood.evaluate(*capsules), max(3, repeats // 2), time.process_time)
            numba.set_num_threads(threads)
            rows.append({"likelihood": name, "model": model.name, "particles": count,
                         "evals per particle": f"{per_particle} {what}", "threads": threads,
                         "ms_median": median, "ms_min": best, "M_evals_per_s": count * per_particle / median / 1e3,
                         "cpu_ms_1thread": cpu, "M_evals_per_s_per_core": count * per_particle / cpu / 1e3,
                         "load": round(load, 2)})
    return rows


if __name__ == "__main__":
    from benchmarks import print_table

    print_table(TITLE, run())
