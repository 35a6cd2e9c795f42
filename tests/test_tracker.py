"""The tracker end to end on short synthetic scenes, its wiring, and bad settings."""

from dataclasses import replace

import numpy as np
import pytest

from occupose.body.dims import DEFAULT_DIMS, dims_from_joints
from occupose.camera import Camera, look_at
from occupose.config import METHODS, ConfigError, ShapeConfig, StartConfig, TrackerConfig
from occupose.evaluation.errors import frame_errors, joint_errors
from occupose.grid.pixels import PersonPixels
from occupose.joints import JOINT_INDEX, JOINTS
from occupose.pose.start import silhouette_fill
from occupose.run import track_frames
from occupose.synth import motion as sm
from occupose.synth.generate import frames
from occupose.synth.scenarios import build_scenario
from occupose.tracker import Tracker

# ------------------------------------------------------------------------------ end to end


def test_tracks_the_walk_from_its_blob_without_a_start_pose(walk):
    scenario, rendered = walk
    tracker = Tracker(scenario.cameras, scenario.fps, "ours", seed=0)
    result = track_frames(tracker, rendered, len(rendered))
    assert list(result.tracks) == [1]
    joints, visible = result.tracks[1]
    tracked = np.flatnonzero(np.isfinite(joints[:, 0, 0]))
    # the blob is extracted within a few frames; the person starts after INIT_FRAMES of them
    # and is tracked back to its blob's first frame (measured: from frame 1)
    assert tracked[0] <= 2 and np.all(np.diff(tracked) == 1) and tracked[-1] == len(rendered) - 1
    gt = np.stack([f.joints[0] for f in rendered])
    errors = frame_errors(joint_errors(gt[tracked], joints[tracked]))
    assert errors.mean() < 0.10  # measured 5.8 cm
    # nothing hides the walker; but in the grid's first, patchy frame of it a shin is tested hidden
    assert np.all(visible[tracked[1:]]) and visible[tracked[0]].sum() >= 12
    assert result.fps > 0 and set(result.seconds) >= {"grid", "blobs", "observations", "pose", "total"}


@pytest.fixture(scope="module")
def walk_in():
    """The first 75 frames of sit_behind_table (procedural motion): a person walks in from
    the image's left edge (first seen at frame 38) and starts at frame 63."""
    scenario = build_scenario("sit_behind_table", use_mocap=False)
    return scenario, list(frames(scenario, seed=0, num_frames=75))


def test_a_person_walking_in_is_tracked_back_over_the_frames_before_its_start(walk_in):
    """LOOK_BACK_FROM frames after its start, a new person is tracked backwards over its
    blob's frames before the start (walking in, cut by the image's edge) until its torso is
    out of view; the frames from the start on are those of a tracker without the look-back."""
    scenario, rendered = walk_in
    runs = {s: track_frames(Tracker(scenario.cameras, scenario.fps, TrackerConfig().with_values({"start.look_back_s": s}), seed=0), rendered,
                            len(rendered)) for s in (0.0, 1.0)}
    assert [list(r.tracks) for r in runs.values()] == [[1], [1]]
    (ahead, _), (joints, visible) = runs[0.0].tracks[1], runs[1.0].tracks[1]
    start = np.flatnonzero(np.isfinite(ahead[:, 0, 0]))[0]
    tracked = np.flatnonzero(np.isfinite(joints[:, 0, 0]))
    assert start == 63 and start - StartConfig.look_back_from > 0
    assert tracked[0] <= start - 10 and np.all(np.diff(tracked) == 1)  # measured: from frame 50
    np.testing.assert_array_equal(joints[start:], ahead[start:])
    assert not visible[tracked[0]].all()  # an arm and a leg tested hidden (measured: the left ones)
    gt = np.stack([f.joints[0] for f in rendered])
    means = []
    for seed in (0, 1, 2):  # the look-back's error varies with the seed (one in nine measured at 11 cm)
        joints = joints if seed == 0 else track_frames(
            Tracker(scenario.cameras, scenario.fps, TrackerConfig().with_values({"start.look_back_s": 1.0}),
                    seed=seed), rendered, len(rendered)).tracks[1][0]
        back = np.flatnonzero(np.isfinite(joints[:start, 0, 0]))
        assert back[0] <= start - 10
        means.append(frame_errors(joint_errors(gt[back[0]:start], joints[back[0]:start])).mean())
    assert np.median(means) < 0.07 and max(means) < 0.15, means  # measured 11.0, 4.8, 5.9 cm
    with pytest.raises(ConfigError, match="start.look_back_s must be >= 0"):
        TrackerConfig().with_values({"start.look_back_s": -1.0})


@pytest.fixture(scope="module")
def narrow_walker():
    """45 frames of a procedural person with the mocap subject's shape (neck 5 cm lower,
    shoulders 0.6 as wide as the average at the stature) walking towards the camera of
    no_occlusion (seen from the front), and that shape."""
    import math

    average = DEFAULT_DIMS.scaled(1.75)
    dims = replace(average, spine=0.78 * average.spine, shoulder_width=0.6 * average.shoulder_width,
                   neck_head=average.neck_head + 0.11 * average.spine)
    scenario = build_scenario("no_occlusion", use_mocap=False)
    joints = sm.MotionBuilder((0.3, 3.8), -math.pi / 2, dims, scenario.fps).walk([(0.3, 2.4)]).joints()
    scenario = replace(scenario, people=(replace(scenario.people[0], joints=joints),))
    return scenario, list(frames(scenario, seed=0, num_frames=45)), dims


def test_a_person_seen_from_the_front_is_resized_once_to_its_neck_and_shoulders(narrow_walker):
    scenario, rendered, dims = narrow_walker
    tracker = Tracker(scenario.cameras, scenario.fps, "ours", seed=0)
    result = track_frames(tracker, rendered, len(rendered))
    person = tracker.people[1]
    assert person.shaped and len(person.shapes) == ShapeConfig.frames  # measured on its first frontal estimates
    assert person.problem.model is person.model  # the filter goes on with the resized model
    # measured: shoulders 0.123 for 0.110 (0.166 before); the neck 1.391 m above the floor
    # standing for 1.396. The walker's head dips (its top near 1.66 m for a stature of 1.75),
    # so the stature measured (1.68 m) is short and the spine alone is not what is measured:
    # the neck's height (legs + spine) under the head's top is.
    assert person.model.dims.shoulder_width == pytest.approx(dims.shoulder_width, abs=0.025)
    neck = person.model.dims.hip_height + person.model.dims.spine
    assert neck == pytest.approx(dims.hip_height + dims.spine, abs=0.02)
    joints = result.tracks[1][0]
    gt = np.stack([f.joints[0] for f in rendered])
    # tracked on with it (measured 6.6 cm over the last 15 frames: the gain of resizing
    # shows over whole scenes, see docs/notes/2026-12-02-shape-measurement.md)
    assert np.nanmean(frame_errors(joint_errors(gt[-15:], joints[-15:]))) < 0.10
    unshaped = Tracker(scenario.cameras, scenario.fps, TrackerConfig().with_values({"shape.learn": False}), seed=0)
    track_frames(unshaped, rendered, len(rendered))
    kept = unshaped.people[1].model.dims  # the average adult's proportions at the measured stature
    assert not unshaped.people[1].shapes
    for name in ("shoulder_width", "spine", "neck_head"):
        assert getattr(kept, name) / kept.height == pytest.approx(getattr(DEFAULT_DIMS, name) / DEFAULT_DIMS.height)


def test_a_person_picked_up_slowly_from_the_ceiling_gets_its_stature_measured_again():
    """Under a ceiling camera the grid picks a person up over its first frames, and the
    start's points do not reach the head yet: the stature is measured again on the first
    ``shape.stature_frames`` upright estimates and the model rescaled; only then is it known (the
    reach term holds the legless model's head below it)."""
    scenario = build_scenario("top_view_arms", use_mocap=False)
    rendered = list(frames(scenario, seed=0, num_frames=40))
    starts = []
    tracker = Tracker(scenario.cameras, scenario.fps, "part-based", seed=0)
    original = tracker._start

    def start(*args):
        person = original(*args)
        if person is not None:
            starts.append(person.model.dims.height)
            assert not person.problem.stature_known
        return person

    tracker._start = start
    track_frames(tracker, rendered, len(rendered))
    person = tracker.people[1]
    truth = dims_from_joints(scenario.people[0].joints).height
    assert starts[0] < truth - 0.2  # measured 1.448 m for 1.749
    assert len(person.tops) == ShapeConfig.stature_frames and person.problem.stature_known
    assert person.model.dims.height == pytest.approx(np.median(person.tops))
    assert person.model.dims.height == pytest.approx(truth, abs=ShapeConfig.stature_change)  # measured 1.727


def test_track_frames_takes_the_first_num_frames_of_longer_input(walk):
    scenario, rendered = walk
    result = track_frames(Tracker(scenario.cameras, scenario.fps, "ours", seed=0), rendered, 20)
    assert result.num_frames == 20 and list(result.tracks) == [1]
    joints, visible = result.tracks[1]
    assert joints.shape == (20, len(JOINTS), 3) and visible.shape == (20, len(JOINTS))
    assert np.isfinite(joints[-1]).all()  # tracked up to the last of the 20


def test_overlapping_the_grid_with_the_pose_stage_tracks_alike(walk):
    """The grid update of frame t + 1 runs during stage 3 of frame t. Without hold masks the
    grid does not depend on the poses, and the tracks are the same to the bit; with them
    (frame t + 1's from the bodies of frame t - 1) the run differs and tracks the person as
    well: the same person, under 8 cm over seeds 0-3 (measured 5.9 cm without, 6.5 with the
    overlap; one seed's two runs part like two seeds do, by 0.3-4 cm on these 40 frames,
    either way)."""
    scenario, rendered = walk
    gt = np.stack([f.joints[0] for f in rendered[:40]])
    results = [track_frames(Tracker(scenario.cameras, scenario.fps, TrackerConfig().with_values({"grid.hold_people": False}), seed=0),
                            rendered[:40], 40, overlap=o) for o in (False, True)]
    assert np.array_equal(results[0].tracks[1][0], results[1].tracks[1][0], equal_nan=True)
    errors = {}
    for overlap in (False, True):
        for seed in range(4):
            result = track_frames(Tracker(scenario.cameras, scenario.fps, "ours", seed=seed),
                                  rendered[:40], 40, overlap=overlap)
            assert list(result.tracks) == [1]
            errors.setdefault(overlap, []).append(np.nanmean(frame_errors(joint_errors(gt, result.tracks[1][0]))))
    assert max(np.mean(e) for e in errors.values()) < 0.08, errors


def test_same_seed_same_tracks(walk):
    scenario, rendered = walk
    runs = [track_frames(Tracker(scenario.cameras, scenario.fps, "ours", seed=s), rendered[:20], 20).tracks
            for s in (3, 3, 4)]
    assert np.array_equal(runs[0][1][0], runs[1][1][0], equal_nan=True)
    assert not np.allclose(runs[0][1][0], runs[2][1][0], equal_nan=True)


def test_a_room_without_people_gives_no_tracks(small_camera):
    camera = small_camera
    tracker = Tracker([camera], 30.0)
    wall = np.full((camera.height, camera.width), 3.5, np.float32)
    for _ in range(10):
        assert tracker.update({"cam": wall}).estimates == {}
    for _ in range(3):  # every pixel invalid (a sensor blinded): no crash, nobody
        assert tracker.update({"cam": np.zeros_like(wall)}).estimates == {}


def test_a_camera_dropping_out_keeps_the_person_and_carries_it(walk):
    """Five blind frames: the person is kept, carried and flagged not visible, then picked
    up again: 10 frames later the joints are within 15 cm on average over seeds 0-2
    (measured 11.2, 9.1, 10.6 cm, and 16.0, 9.3, 11.5 before the feet and hanging-arm terms;
    the test took seed 0 alone until the pick-up was shifted from the filter's estimate,
    when seed 0 went from 9.5 to 16.0 cm)."""
    scenario, rendered = walk
    name = scenario.cameras[0].name
    errors = []
    for seed in (0, 1, 2):
        tracker = Tracker(scenario.cameras, scenario.fps, "ours", seed=seed)
        for f in rendered[:30]:
            out = tracker.update(f.depth).estimates
        assert list(out) == [1] and out[1].visible.all()
        blind = {name: np.zeros_like(rendered[30].depth[name])}
        for _ in range(5):
            out = tracker.update(blind).estimates
            assert list(out) == [1] and not out[1].visible.any()  # kept, carried, flagged not visible
        for f in rendered[35:45]:
            out = tracker.update(f.depth).estimates
        assert list(out) == [1] and out[1].visible.all()
        errors.append(frame_errors(joint_errors(rendered[44].joints[0][None], out[1].joints[None]))[0])
    assert np.mean(errors) < 0.15, errors  # back on the person after the drop-out


def test_bad_settings_are_refused(small_camera):
    camera = small_camera
    with pytest.raises(ConfigError, match="unknown method 'fast'; valid names: ours, apf, ps, part-based"):
        Tracker([camera], 30.0, "fast")
    with pytest.raises(ConfigError, match="config must be a TrackerConfig or a method name"):
        Tracker([camera], 30.0, {"pose": {"particles": 10}})
    # layers for 7 stages of a 3-stage filter: refused when the settings are built, not at a start
    with pytest.raises(ConfigError, match="pose.layers must hold one number per partitioned-sampling stage"):
        TrackerConfig().with_values({"pose.layers": [1, 1, 1, 1, 1, 1, 1]})


def test_auto_model_is_upper_for_a_ceiling_camera(small_camera):
    front = small_camera
    ceiling = Camera("top", 160, 120, 120.0, 120.0, 79.5, 59.5, 0.001,
                     look_at(eye=(0.0, 0.0, 2.9), target=(0.0, 0.01, 0.0)))
    assert Tracker([front], 30.0).model_name == "full"
    assert Tracker([ceiling], 30.0).model_name == "upper"
    assert Tracker([ceiling], 30.0, TrackerConfig().with_values({"pose.model": "full"})).model_name == "full"
    assert METHODS["part-based"].pose.model == "upper"


# ------------------------------------------------------------------------------ the parts

def test_legs_hidden_behind_a_chair_reach_the_feet_below_it():
    """gesture_behind_chair, procedural, 150 frames: the chair's back hides the thighs (or
    the shins under a thigh seen beside it) and the feet show below its seat. Measured:
    the ankles of the hidden legs 6.9 cm from the truth (knees 6.3), 15 cm before the ankle
    was put behind its foot's points and a shin's thigh let reach too."""
    scenario = build_scenario("gesture_behind_chair", use_mocap=False)
    tracker = Tracker(scenario.cameras, scenario.fps, "ours", seed=0)
    truth = scenario.people[0].joints
    errors = []
    for frame in frames(scenario, seed=0, num_frames=150):
        estimates = tracker.update(frame.depth).estimates
        for tid, estimate in estimates.items():
            person = tracker.people[tid]
            hidden = dict(zip(person.model.part_names, ~person.part_visible))
            for side in ("left", "right"):
                if hidden[f"{side}_thigh"] or hidden[f"{side}_shin"]:
                    ankle = JOINT_INDEX[f"{side}_ankle"]
                    errors.append(np.linalg.norm(estimate.joints[ankle] - truth[frame.index, ankle]))
    assert len(errors) > 150  # both legs hidden for most of the scene
    assert np.mean(errors) < 0.09, np.mean(errors)


# ------------------------------------------------------------------------------ the command line



# ------------------------------------------------------------------------------ starting

def _tries_to_start(tracking, monkeypatch, observation, offset: float) -> bool:
    """Whether a blob track 99 holding ``observation``, its centroid ``offset`` metres
    beside person 1's pelvis, starts a person after ``start.frames`` tries."""
    tracker, depths = tracking
    person, tid = tracker.people[1], 99
    states = dict(tracker.blobs.states)
    monkeypatch.setattr(type(tracker.blobs), "states", property(lambda self: states))
    states[tid] = replace(states[1], centroid=np.array([*(person.pose[:2] + [offset, 0.0]), 1.0]))
    tracker._pending.pop(tid, None)
    started = [tracker._start(tid, observation, depths, states[tid].centroid, states[tid].velocity)
               for _ in range(StartConfig.frames)]
    return started[-1] is not None


def test_a_blob_next_to_a_tracked_person_does_not_start_another(tracking, monkeypatch):
    """A second blob 0.3 m from a tracked person's pelvis (a piece of the body split off
    its blob) is kept from starting a person; one 1.5 m away starts."""
    tracker = tracking[0]
    observation = tracker._previous[1]
    assert not _tries_to_start(tracking, monkeypatch, observation, 0.3)
    assert 99 in tracker._fragments
    assert _tries_to_start(tracking, monkeypatch, observation, 1.5)
    assert 99 in tracker._fragments  # since the first, near offset


def test_a_blob_whose_own_points_stay_below_a_seated_head_does_not_start(tracking, monkeypatch):
    """A chair put down beside its carrier: the blob's cells reach the carrier's height, the
    pixels it is given (the carrier's go to the carrier) stay below 1 m."""
    observation = tracking[0]._previous[1]
    low = {c: observation.camera_points[c][:, 2] < 0.9 for c in observation.camera_points}
    chair = PersonPixels(99, {c: observation.pixels[c][low[c]] for c in low},
                            {c: observation.camera_points[c][low[c]] for c in low})
    assert len(chair.points) > 1000
    assert not _tries_to_start(tracking, monkeypatch, chair, 1.5)
    assert _tries_to_start(tracking, monkeypatch, observation, 1.5)  # the whole body does


def test_a_blob_of_scattered_pixels_does_not_start(tracking, monkeypatch):
    """A ghost: a wall's noisy readings, no longer overruled by a second camera whose line of
    sight a person blocks, scattered over the image like every 25th pixel of a person's."""
    observation = tracking[0]._previous[1]
    ghost = PersonPixels(99, {c: observation.pixels[c][::25] for c in observation.pixels},
                            {c: observation.camera_points[c][::25] for c in observation.camera_points})
    assert len(ghost.points) > 200 and ghost.points[:, 2].max() > 1.5
    assert max(silhouette_fill(ghost.pixels[c], 640) for c in ghost.pixels) < StartConfig.min_fill
    assert not _tries_to_start(tracking, monkeypatch, ghost, 1.5)
    assert _tries_to_start(tracking, monkeypatch, observation, 1.5)



def test_pixels_without_a_reading_for_long_enough_are_seen_through_by_the_pose_stage():
    """pose.no_return_seen: a pixel the grid counts as returning nothing (no reading for
    grid.no_return_after frames in a row) reads, for the pose stage, as the camera's far
    range, so a body part drawn over it is in free space; a dropout of one frame does not."""
    scenario = build_scenario("no_occlusion", use_mocap=False)
    camera = scenario.cameras[0]
    config = TrackerConfig.from_dict({"method": "ours", "pose": {"no_return_seen": True},
                                      "grid": {"noise_model": "preset"}})
    tracker = Tracker(scenario.cameras, scenario.fps, config, seed=0)
    after = config.grid.no_return_after
    for index, frame in enumerate(frames(scenario, seed=0, num_frames=after + 1)):
        depth = frame.depth[camera.name].copy()
        depth[:40] = 0.0  # a band beyond range from the first frame
        if index == after:
            depth[300, 300] = 0.0  # one frame's dropout
        tracker.update({camera.name: depth})
    seen = tracker._seen_depths({camera.name: depth})[camera.name]
    far = np.float32(tracker.grid.max_ranges[camera.name])
    assert np.all(seen[:40] == far) and seen[300, 300] == 0.0
    np.testing.assert_array_equal(seen[40:], depth[40:])
    plain = Tracker(scenario.cameras, scenario.fps, config.with_values({"pose.no_return_seen": False}), seed=0)
    assert plain._seen_depths({camera.name: depth})[camera.name] is depth
