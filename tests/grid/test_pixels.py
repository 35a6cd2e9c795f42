"""Stage 2: each tracked person's pixels and points (exclusion principle), on small rendered
scenes and on the synthetic scenarios with the real occupancy grid."""

from dataclasses import replace

import numpy as np
import pytest

from occupose.camera import Camera, look_at, points_from_depth
from occupose.grid.blobs import blobs_from_mask
from occupose.grid.hold import cells_near_capsules
from occupose.grid.pixels import (
    FALLBACKS, PersonPixels, _nearest_track, distance_to_points, pixels_from_depth,
    predicted_from_tracks, window_of_box,
)
from occupose.grid.occupancy import OccupancyGrid, spec_from_cameras
from occupose.grid.spec import GridSpec
from occupose.grid.tracking import BlobTracker
from occupose.evaluation.pixels import foreground_scores, pixel_assignment_accuracy
from occupose.synth.body import primitives_from_joints
from occupose.synth.noise import apply_noise
from occupose.geometry.primitives import box, concat
from occupose.testing import capsules_from_primitives, persons_from_tracks
from occupose.synth.render import render_camera
from occupose.synth.scenarios import build_scenario

CAMERA = Camera("cam", 160, 120, 120.0, 120.0, 79.5, 59.5, world_from_camera=look_at((0, 0, 1.2), (0, 3, 1.0)))
SPEC = GridSpec((-2.0, 0.5, 0.0), 0.05, (80, 70, 44))
GREY = (128, 128, 128)


def scene(*people_x, gap_y=2.0):
    """Rendered boxes 0.3 m wide and 1.7 m tall at x = people_x, y = gap_y, before a wall."""
    wall = box((0, 3.5, 1.1), (3.0, 0.05, 1.1), GREY)
    bodies = [box((x, gap_y, 0.85), (0.15, 0.1, 0.85), GREY, person=i + 1) for i, x in enumerate(people_x)]
    return render_camera(concat([wall, *bodies]), CAMERA)


def oracle_labels(rendered, spec=SPEC, **options):
    """Blobs of the cells that the rendered people's points fall in (a perfect moving mask)."""
    points, pixels = points_from_depth(rendered.depth, CAMERA)
    index, inside = spec.cells_from_points(points[(rendered.person.reshape(-1)[pixels] > 0)])
    mask = np.zeros(spec.shape, bool)
    mask[tuple(index[inside].T)] = True
    return blobs_from_mask(mask, spec, **options)


def accuracy(assigned, truth, mapping):
    """Pixel-assignment accuracy over the pixels that are a person's and assigned to someone."""
    lut = np.zeros(max(int(assigned.max()), max(mapping, default=0)) + 1, np.int64)
    for track, person in mapping.items():
        lut[track] = person
    return pixel_assignment_accuracy(lut[assigned], truth, (truth > 0) & (assigned > 0))


# --------------------------------------------------------------------------- unit tests


SIDE = Camera("side", 120, 90, 90.0, 90.0, 59.5, 44.5, world_from_camera=look_at((2.5, 2.0, 1.5), (0, 2.0, 0.9)))


def test_two_cameras_split_their_own_pixels():
    wall = box((0, 3.5, 1.1), (3.0, 0.05, 1.1), GREY)
    bodies = concat([wall, box((-0.6, 2.0, 0.85), (0.15, 0.1, 0.85), GREY, person=1),
                     box((0.6, 2.6, 0.85), (0.15, 0.1, 0.85), GREY, person=2)])
    views = {cam.name: render_camera(bodies, cam) for cam in (CAMERA, SIDE)}
    mask = np.zeros(SPEC.shape, bool)
    for cam in (CAMERA, SIDE):
        points, pixels = points_from_depth(views[cam.name].depth, cam)
        index, inside = SPEC.cells_from_points(points[views[cam.name].person.reshape(-1)[pixels] > 0])
        mask[tuple(index[inside].T)] = True
    labels, blobs = blobs_from_mask(mask, SPEC)
    tracks = BlobTracker(30.0).update(blobs)
    depths = {name: view.depth for name, view in views.items()}
    observations, assigned = pixels_from_depth(depths, [CAMERA, SIDE], SPEC, labels, tracks)
    for name, view in views.items():
        truth = view.person.astype(np.int64)
        assert accuracy(assigned[name], truth, persons_from_tracks([assigned[name]], [truth])) == 1.0
        assert foreground_scores(assigned[name] > 0, truth > 0)[1] > 0.95
    for obs in observations.values():
        assert set(obs.pixels) == {"cam", "side"} and all(len(p) > 50 for p in obs.pixels.values())
        np.testing.assert_array_equal(obs.points, np.concatenate([obs.camera_points["cam"], obs.camera_points["side"]]))


def test_pixels_go_to_the_track_of_their_cell():
    rendered = scene(-0.6, 0.6)
    labels, blobs = oracle_labels(rendered)
    tracks = BlobTracker(30.0).update(blobs)
    observations, assigned = pixels_from_depth({"cam": rendered.depth}, [CAMERA], SPEC, labels, tracks)
    image = assigned["cam"]
    truth = rendered.person.astype(np.int64)
    assert image.dtype == np.int32 and image.shape == (120, 160)
    mapping = persons_from_tracks([image], [truth])
    assert sorted(mapping.values()) == [1, 2]
    assert accuracy(image, truth, mapping) == 1.0
    precision, recall, _ = foreground_scores(image > 0, truth > 0)
    assert precision == 1.0 and recall > 0.99  # the wall behind is nobody's
    points, pixels = points_from_depth(rendered.depth, CAMERA)
    for tid, obs in observations.items():
        assert isinstance(obs, PersonPixels) and obs.track_id == tid
        np.testing.assert_array_equal(obs.pixels["cam"], np.flatnonzero(image.reshape(-1) == tid))
        np.testing.assert_allclose(obs.points, points[np.isin(pixels, obs.pixels["cam"])])


def test_only_the_window_of_the_tracks_box_is_read():
    """Each camera reads only the window its view of the tracks' box (one cell wider)
    covers; the observations equal those of reading every pixel (the same blobs with a box
    as large as the grid), for two cameras, with and without the grid's states."""
    wall = box((0, 3.5, 1.1), (3.0, 0.05, 1.1), GREY)
    bodies = concat([wall, box((-0.6, 2.0, 0.85), (0.15, 0.1, 0.85), GREY, person=1),
                     box((0.3, 2.6, 0.85), (0.15, 0.1, 0.85), GREY, person=2)])
    depths = {cam.name: render_camera(bodies, cam).depth for cam in (CAMERA, SIDE)}
    mask = np.zeros(SPEC.shape, bool)
    mask[26:30, 28:33, 2:34] = True  # the first box's cells and the wall's edge of them: E there
    mask[45:49, 40:44, 2:34] = True
    labels, blobs = blobs_from_mask(mask, SPEC)
    tracks = BlobTracker(30.0).update(blobs)
    whole = {t: replace(b, low=np.asarray(SPEC.origin), high=SPEC.high) for t, b in tracks.items()}
    for cam in (CAMERA, SIDE):
        v0, v1, u0, u1 = window_of_box(cam, *(np.asarray(SPEC.origin), SPEC.high))
        assert (v0, v1, u0, u1) == (0, cam.height, 0, cam.width)  # the grid's box: every pixel
    v0, v1, u0, u1 = window_of_box(CAMERA, blobs[0].low, blobs[0].high)
    assert (v1 - v0) * (u1 - u0) < 0.3 * CAMERA.height * CAMERA.width
    states = np.where(mask, 1, 2).astype(np.uint8)
    for given in (None, states):
        got, assigned = pixels_from_depth(depths, [CAMERA, SIDE], SPEC, labels, tracks, states=given)
        expected, assigned_whole = pixels_from_depth(depths, [CAMERA, SIDE], SPEC, labels, whole, states=given)
        for name in depths:
            np.testing.assert_array_equal(assigned[name], assigned_whole[name])
            assert (assigned[name] > 0).sum() > 300
        for tid, obs in got.items():
            for name in depths:
                np.testing.assert_array_equal(obs.pixels[name], expected[tid].pixels[name])
                np.testing.assert_array_equal(obs.camera_points[name], expected[tid].camera_points[name])


def test_shared_blob_goes_to_the_nearest_predicted_body():
    rendered = scene(-0.15, 0.15)  # two boxes side by side: one blob
    labels, (blob,) = oracle_labels(rendered)
    truth = rendered.person.astype(np.int64)
    points, pixels = points_from_depth(rendered.depth, CAMERA)
    person = truth.reshape(-1)[pixels]
    tracks = {7: blob, 9: blob}
    bodies = {7: distance_to_points(points[person == 1]), 9: distance_to_points(points[person == 2])}
    _, assigned = pixels_from_depth({"cam": rendered.depth}, [CAMERA], SPEC, labels, tracks, predicted=bodies)
    assert accuracy(assigned["cam"], truth, {7: 1, 9: 2}) == 1.0
    # the centroid fallback splits at the middle plane, which here is right too...
    centers = {7: np.array([-0.15, 2.0, 0.85]), 9: np.array([0.15, 2.0, 0.85])}
    _, by_centre = pixels_from_depth({"cam": rendered.depth}, [CAMERA], SPEC, labels, tracks, centers=centers)
    assert accuracy(by_centre["cam"], truth, {7: 1, 9: 2}) > 0.99
    # ...and where a body does not reach (or a track has none), the centre distance counts
    _, mixed = pixels_from_depth({"cam": rendered.depth}, [CAMERA], SPEC, labels, tracks,
                                       centers=centers, predicted={7: bodies[7]})
    mixed = mixed["cam"].reshape(-1)[pixels]
    assert np.all(mixed[person == 1] == 7)
    beyond = np.isinf(bodies[7](points)) & (person == 2)
    assert beyond.sum() > 100 and np.all(mixed[beyond] == 9)


def test_nearest_track_pruned_by_cells_matches_pixel_by_pixel(rng):
    # the cell-centre shortcut must give what asking every point gives (1-Lipschitz distances)
    spec = GridSpec((0.0, 0.0, 0.0), 0.05, (20, 20, 20))
    points = rng.uniform(0.0, 1.0, (5000, 3))
    cells = np.ravel_multi_index(spec.cells_from_points(points)[0].T, spec.shape)
    ids = [3, 5, 8]
    code = rng.integers(1, 8, spec.num_cells).astype(np.int64)[cells]  # each cell a random set of candidates
    seeds = {tid: rng.uniform(0.0, 1.0, (4, 3)) for tid in ids}
    predicted = {tid: (lambda s: lambda p: np.min(np.linalg.norm(p[:, None] - s[None], axis=2), axis=1))(seeds[tid])
                 for tid in ids}
    got = _nearest_track(points, cells, code, ids, predicted, lambda p, tid: np.full(len(p), np.inf), spec)
    distance = np.stack([predicted[t](points) for t in ids], axis=1)
    distance[(code[:, None] & (1 << np.arange(3))) == 0] = np.inf
    np.testing.assert_array_equal(got, np.asarray(ids)[np.argmin(distance, axis=1)])


def test_points_no_body_reaches_use_the_fallback():
    spec = GridSpec((0.0, 0.0, 0.0), 0.05, (40, 40, 40))
    points = np.array([[0.5, 0.5, 1.0], [1.5, 0.5, 1.0], [1.0, 0.5, 1.0]])
    cells = np.ravel_multi_index(spec.cells_from_points(points)[0].T, spec.shape)
    near_a = distance_to_points(np.array([[0.5, 0.5, 1.0]]), reach=0.1)
    near_b = distance_to_points(np.array([[1.5, 0.5, 1.0]]), reach=0.1)
    assert np.isinf(near_a(points[1:])).all() and near_a(points[:1])[0] == 0.0
    centre = {1: np.array([0.9, 0.5, 1.0]), 2: np.array([1.6, 0.5, 1.0])}
    owner = _nearest_track(points, cells, np.full(3, 3, np.int64), [1, 2], {1: near_a, 2: near_b},
                           lambda p, tid: FALLBACKS["horizontal"](p, centre[tid]), spec)
    np.testing.assert_array_equal(owner, [1, 2, 1])  # the middle point: nearer track 1's centre
    alone = _nearest_track(points, cells, np.full(3, 3, np.int64), [1, 2], {1: near_a},
                           lambda p, tid: FALLBACKS["horizontal"](p, centre[tid]), spec)
    np.testing.assert_array_equal(alone, [1, 2, 1])


def test_predicted_from_tracks_uses_the_last_observation_moved_on():
    tracker = BlobTracker(10.0)
    spec = GridSpec((-2.0, -2.0, 0.0), 0.05, (80, 80, 40))
    for t in range(3):
        mask = np.zeros(spec.shape, bool)
        mask[30 + 2 * t:36 + 2 * t, 38:42, 0:34] = True  # walks +x at 1 m/s
        tracker.update(blobs_from_mask(mask, spec)[1])
    state = tracker.states[1]
    assert state.velocity[0] == pytest.approx(1.0)
    before = PersonPixels(1, {"cam": np.arange(2)}, {"cam": np.array([[0.0, 0.0, 1.0], [0.0, 0.1, 1.0]])})
    bodies = predicted_from_tracks(tracker.states, {1: before}, 10.0)
    np.testing.assert_allclose(bodies[1](np.array([[0.1, 0.0, 1.0], [0.05, 0.0, 1.0]])), [0.0, 0.05], atol=1e-12)
    own = predicted_from_tracks(tracker.states, {}, 10.0)[1]  # no observation yet: its cells
    assert own(state.points).max() == 0.0
    with pytest.raises(ValueError, match="fps"):
        predicted_from_tracks(tracker.states, {}, 0.0)


def test_persons_from_tracks_by_majority():
    truth = np.array([[1, 1, 1, 2, 2, 0]])
    assigned = np.array([[5, 5, 6, 6, 6, 5]])
    assert persons_from_tracks([assigned], [truth]) == {5: 1, 6: 2}
    assert persons_from_tracks([assigned, assigned], [truth, np.zeros_like(truth)]) == {5: 1, 6: 2}
    assert persons_from_tracks([np.zeros((2, 2), int)], [np.ones((2, 2), int)]) == {}


def test_bad_input_to_observations():
    rendered = scene(0.0)
    labels, blobs = oracle_labels(rendered)
    tracks = {1: blobs[0]}
    depths = {"cam": rendered.depth}
    with pytest.raises(ValueError, match="integer array of the grid's shape"):
        pixels_from_depth(depths, [CAMERA], SPEC, labels[:-1], tracks)
    with pytest.raises(ValueError, match="depths must map each camera name"):
        pixels_from_depth({"other": rendered.depth}, [CAMERA], SPEC, labels, tracks)
    with pytest.raises(ValueError, match="valid names"):
        pixels_from_depth(depths, [CAMERA], SPEC, labels, tracks, fallback="nearest")
    with pytest.raises(ValueError, match="positive int track ids to Blob"):
        pixels_from_depth(depths, [CAMERA], SPEC, labels, {0: blobs[0]})
    with pytest.raises(ValueError, match="may only name tracked ids"):
        pixels_from_depth(depths, [CAMERA], SPEC, labels, tracks, centers={2: np.zeros(3)})
    with pytest.raises(ValueError, match="depth image for camera"):
        pixels_from_depth({"cam": rendered.depth[:-1]}, [CAMERA], SPEC, labels, tracks)
    with pytest.raises(ValueError, match=r"\(M, 3\)"):
        distance_to_points(np.zeros((0, 3)))
    observations, assigned = pixels_from_depth(depths, [CAMERA], SPEC, labels, {})
    assert observations == {} and not assigned["cam"].any()


# ------------------------------------------------------------------- synthetic scenarios


def quick_frames(scenario, indices, seed=0):
    """Render the scenario's frames (first camera) as :func:`occupose.synth.generate.frames`
    does, without the per-part visibility renders (5x faster): yields (index, truth person
    image (H, W) int64, noisy depth (H, W) float32, present (P,) bool, people's primitives)."""
    cam = scenario.cameras[0]
    room = render_camera(scenario.static, cam)
    model, options = scenario.noise[cam.name]
    rng = np.random.default_rng(seed)
    for t in indices:
        bodies = [primitives_from_joints(person.joints[t], person.shape, p + 1)
                  for p, person in enumerate(scenario.people)]
        rendered = render_camera(concat([scenario.moving_at(t), *bodies]), cam, background=room)
        truth = rendered.person.astype(np.int64)
        present = np.array([np.any(truth == p + 1) for p in range(len(bodies))])
        yield t, truth, apply_noise(rendered.depth, model, rng, fx=cam.fx, **options), present, concat(bodies)


def run_pipeline(scenario, indices, *, warm_up=0, seed=0, oracle_from=None, oracle_to=None, hold=True):
    """Grid, blobs, tracker and observations over ``indices`` (one camera).

    warm_up : frames of the empty room (the static scene with sensor noise) shown to the
        grid first. oracle_from : from this frame index on, also run the same stages on a
        perfect moving mask (the cells of the rendered people's points) instead of the grid,
        up to (not including) ``oracle_to`` if given.
    hold : hold the grid's cells within MARGIN of the true bodies of each frame (a perfect
        prediction of the bodies the tracker will give), so people standing still stay moving.
    Returns {"grid": runs, "oracle": runs}, runs per frame (assigned image, truth image,
    present, {track id: merged_with}).
    """
    cam = scenario.cameras[0]
    spec = spec_from_cameras(scenario.cameras[:1])
    grid = OccupancyGrid(spec, cam)
    rng = np.random.default_rng(seed + 1000)
    room = render_camera(scenario.static, cam).depth
    model, options = scenario.noise[cam.name]
    for _ in range(warm_up):
        grid.update({cam.name: apply_noise(room, model, rng, fx=cam.fx, **options)})
    kinds = ["grid"] + ([] if oracle_from is None else ["oracle"])
    trackers = {kind: BlobTracker(scenario.fps) for kind in kinds}
    previous = {kind: {} for kind in kinds}
    out = {kind: [] for kind in kinds}
    for index, truth, depth, present, bodies in quick_frames(scenario, indices, seed):
        held = cells_near_capsules(spec, *capsules_from_primitives(bodies)) if hold else None
        grid.update({cam.name: depth}, hold=held)
        for kind in kinds:
            if kind == "grid":
                moving, states = grid.moving_mask(), grid.states
            elif index < oracle_from or (oracle_to is not None and index >= oracle_to):
                continue
            else:
                points, _ = points_from_depth(np.where(truth > 0, depth, 0), cam)
                cells, inside = spec.cells_from_points(points)
                moving, states = np.zeros(spec.shape, bool), None
                moving[tuple(cells[inside].T)] = True
            labels, blobs = blobs_from_mask(moving, spec)
            tracker = trackers[kind]
            tracks = tracker.update(blobs)
            bodies_ahead = predicted_from_tracks(tracker.states, previous[kind], scenario.fps)
            previous[kind], assigned = pixels_from_depth({cam.name: depth}, [cam], spec, labels, tracks,
                                                               states=states, predicted=bodies_ahead)
            merged = {tid: s.merged_with for tid, s in tracker.states.items() if tid in tracks}
            out[kind].append((assigned[cam.name], truth, present, merged))
    return out


@pytest.fixture(scope="module")
def crossing():
    # A walks +x at y = 3.5, B walks -x at y = 2.5 and passes in front of A (frames ~45-63,
    # A down to 16 % of its pixels at frame 52); both in view and walking from frame 0
    scenario = build_scenario("two_people_crossing", use_mocap=False)
    return run_pipeline(scenario, range(0, 110))["grid"]


def test_crossing_ids_persist_without_a_swap(crossing):
    both = [(i, a, t) for i, (a, t, present, _) in enumerate(crossing) if present.all()]
    assert len(both) == 110
    mapping = persons_from_tracks([a[::4, ::4] for _, a, _ in both], [t[::4, ::4] for _, _, t in both])
    assert sorted(mapping.values()) == [1, 2] and len(mapping) == 2  # two tracks, one per person
    checked = []
    for index, assigned, truth in both:  # the same owner in every frame: before, during and after
        if (assigned > 0).sum() > 500:
            frame_mapping = persons_from_tracks([assigned], [truth])
            assert all(mapping[track] == person for track, person in frame_mapping.items())
            checked.append(index)
    assert min(checked) < 30 and max(checked) > 90 and {48, 50, 52, 54, 56} <= set(checked)


def test_crossing_pixel_assignment(crossing):
    scores = [accuracy(a, t, persons_from_tracks([a], [t])) for a, t, present, _ in crossing if present.all()]
    mapping = persons_from_tracks([a[::4, ::4] for a, *_ in crossing], [t[::4, ::4] for _, t, *_ in crossing])
    whole = [accuracy(a, t, mapping) for a, t, present, _ in crossing if present.all()]
    assert np.nanmean(whole) >= 0.98 and np.nanmean(scores) >= 0.98
    recall = [foreground_scores(a > 0, t > 0)[1] for a, t, present, _ in crossing if present.all()]
    assert np.nanmedian(recall) > 0.9


@pytest.fixture(scope="module")
def top_view():
    # The people step in and stand face to face from frame ~25, moving their arms; the grid
    # holds the cells near their true bodies (as the tracker will hold its predicted bodies),
    # so their still bodies stay moving: the grid is scored on the whole scene. The same
    # stages on a perfect moving mask cover the arms' first long overlap (frames 0-89).
    scenario = build_scenario("top_view_two_people", use_mocap=False)
    runs = run_pipeline(scenario, range(0, scenario.num_frames), oracle_from=0, oracle_to=90)
    return runs["grid"], runs["oracle"]


def test_top_view_merged_pair_pixel_assignment(top_view):
    for run in top_view:
        assert any(merged for *_, merged in run for merged in merged.values())  # arms join the two
        # each track's person by majority over every 4th pixel (all of them: 90 M pixels)
        mapping = persons_from_tracks([a[::4, ::4] for a, *_ in run], [t[::4, ::4] for _, t, *_ in run])
        assert sorted(mapping.values()) == [1, 2]
        scores = [accuracy(a, t, mapping) for a, t, present, _ in run if present.all()]
        assert np.nanmean(scores) >= 0.98 and np.nanmin(scores) >= 0.95
    recall = [foreground_scores(a > 0, t > 0)[1] for a, t, *_ in top_view[0]]
    assert np.mean(recall[30:]) > 0.85  # the bodies standing still are still extracted
