"""The hold (stage 1): the cells near the predicted bodies, which the grid keeps moving.

cells_near_capsules against a NumPy reference, the capsules that cover a rendered body
(occupose.testing, what tests and benchmarks hold), and a person standing still who stays
moving in the grid when held and fades into the background when not."""

import math

import numpy as np
import pytest

from occupose.camera import Camera, look_at, points_from_depth
from occupose.grid.occupancy import O, OccupancyGrid, frames_until_static
from occupose.grid.hold import cells_near_capsules
from occupose.grid.spec import GridSpec
from occupose.testing import capsules_from_primitives, foreground_from_grid
from occupose.synth.body import primitives_from_joints, random_body_shape
from occupose.synth.noise import apply_noise
from occupose.geometry.primitives import box, concat
from occupose.synth.render import render_camera
from occupose.synth.scenarios import build_scenario


def reference_near_capsules(spec, a, b, radii, margin):
    """cells_near_capsules in NumPy: every cell centre against every capsule."""
    centres = spec.centers().reshape(-1, 1, 3)
    axis = b - a
    t = np.clip(np.sum((centres - a) * axis, axis=2) / np.maximum(np.sum(axis**2, axis=1), 1e-300), 0.0, 1.0)
    distance = np.linalg.norm(centres - (a + t[..., None] * axis), axis=2)
    limit = (1 - t) * radii[:, 0] + t * radii[:, 1] + margin
    return np.any(distance <= limit, axis=1).reshape(spec.shape)


def test_cells_near_capsules_matches_numpy(rng):
    spec = GridSpec((-1.0, -0.5, -0.025), 0.05, (40, 30, 44))
    a = rng.uniform((-1.3, -0.8, -0.2), (1.3, 1.3, 2.3), (12, 3))  # some ends outside the grid
    b = a + rng.normal(0, 0.3, (12, 3))
    b[0] = a[0]  # a sphere
    radii = rng.uniform(0.02, 0.15, (12, 2))
    for margin in (0.0, 0.1):
        got = cells_near_capsules(spec, a, b, radii, margin)
        np.testing.assert_array_equal(got, reference_near_capsules(spec, a, b, radii, margin))
        assert 200 < got.sum() < 0.5 * spec.num_cells
    assert not cells_near_capsules(spec, np.zeros((0, 3)), np.zeros((0, 3)), np.zeros((0, 2))).any()
    far = np.array([[10.0, 10.0, 10.0]])
    assert not cells_near_capsules(spec, far, far, np.full((1, 2), 0.1)).any()
    with pytest.raises(ValueError, match=r"radii \(C, 2\)"):
        cells_near_capsules(spec, a, b, radii[:, :1])
    with pytest.raises(ValueError, match="finite"):
        cells_near_capsules(spec, np.full((1, 3), np.nan), far, np.full((1, 2), 0.1))
    with pytest.raises(ValueError, match="margin"):
        cells_near_capsules(spec, a, b, radii, margin=-0.1)


def test_capsules_from_primitives_cover_the_rendered_body(rng):
    scenario = build_scenario("no_occlusion", use_mocap=False)
    cam = scenario.cameras[0]
    body = primitives_from_joints(scenario.people[0].joints[120], random_body_shape(rng), 1)
    a, b, radii = capsules_from_primitives(body)
    assert a.shape == b.shape == (16, 3) and radii.shape == (16, 2)
    points, _ = points_from_depth(render_camera(body, cam).depth, cam)
    assert len(points) > 5000
    axis = b - a
    t = np.clip(np.sum((points[:, None] - a) * axis, axis=2) / np.sum(axis**2, axis=1), 0.0, 1.0)
    distance = np.linalg.norm(points[:, None] - (a + t[..., None] * axis), axis=2)
    excess = np.min(distance - ((1 - t) * radii[:, 0] + t * radii[:, 1]), axis=1)
    assert excess.max() < 1e-4  # every surface point lies in some capsule (float32 depth)
    # and not much bigger: half the surface is on a capsule, 95 % within 7 cm (the chest's
    # capsule is round, the chest flatter)
    assert np.median(excess) > -0.005 and np.percentile(excess, 5) > -0.07
    with pytest.raises(ValueError, match="Primitives"):
        capsules_from_primitives(a)


def test_hold_keeps_a_person_standing_still_moving():
    # a box-shaped person walks 0.6 m in 24 frames, then stands still for 150 frames: without
    # the hold the grid takes them for background after frames_until_static (77) frames;
    # holding the cells near their body (as the tracker does) keeps them moving
    camera = Camera("cam", 160, 120, 120.0, 120.0, 79.5, 59.5, world_from_camera=look_at((0, 0, 1.2), (0, 3, 1.0)))
    spec = GridSpec((-2.0, 0.5, -0.025), 0.05, (80, 70, 44))
    room = concat([box((0, 3.5, 1.1), (3.0, 0.05, 1.1), (128, 128, 128)),   # wall
                   box((0, 2.0, -0.05), (3.0, 2.0, 0.05), (128, 128, 128))])  # floor
    room = render_camera(room, camera)
    grids = {"held": OccupancyGrid(spec, camera), "free": OccupancyGrid(spec, camera)}
    rng = np.random.default_rng(7)
    walk, still = 24, 150
    share = {name: [] for name in grids}
    for t in range(walk + still):
        person = box((-0.3 + 0.025 * min(t, walk), 2.22, 0.85), (0.15, 0.1, 0.85), (90, 90, 90), person=1)
        rendered = render_camera(person, camera, background=room)
        depth = apply_noise(rendered.depth, "structured_light", rng, fx=camera.fx)
        hold = cells_near_capsules(spec, *capsules_from_primitives(person), margin=0.1)
        for name, grid in grids.items():
            grid.update({"cam": depth}, hold=hold if name == "held" else None)
            truth = rendered.person > 0
            share[name].append(foreground_from_grid(grid.states, spec, depth, camera)[truth].mean())
    held, free = np.array(share["held"]), np.array(share["free"])
    assert held[walk:].min() > 0.95 and free[walk:walk + 50].min() > 0.95  # both moving at first
    assert held[-1] > 0.95 and free[-1] < 0.05
    # without the hold the cells entered last turn static frames_until_static (77) frames after
    assert np.flatnonzero(free < 0.05)[-1] == len(free) - 1
    assert np.flatnonzero(free[walk:] < 0.05)[0] == math.ceil(frames_until_static())
    # the hold takes nothing from the background: the floor cells it covers are as without it
    floor = hold[:, :, 0]
    assert floor.sum() > 20 and np.count_nonzero(grids["free"].states[:, :, 0][floor] == O) > 20
    np.testing.assert_array_equal(grids["held"].states[:, :, 0], grids["free"].states[:, :, 0])
