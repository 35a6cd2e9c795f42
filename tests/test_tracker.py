"""The tracker end to end on short synthetic scenes, its parts, and bad input."""

import json
from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pytest
from click.testing import CliRunner

from occupose.body.dims import DEFAULT_DIMS, dims_from_joints
from occupose.body import body_model, capsules_from_poses, joints_from_poses, standing_pose
from occupose.camera import Camera, look_at, raw_depth_from_metres
from occupose.cli import main
from occupose.grid.pixels import Observation as GridObservation
from occupose.joints import JOINT_INDEX, JOINTS
from occupose.evaluation.errors import frame_errors, joint_errors
from occupose.pose.occlusion import hidden_parts_in_views, joint_parts, part_tree, planted_legs
from occupose.io.joint_table import read_tracks_csv
from occupose.io.recording import Recording, RecordingWriter
from occupose.synth import motion as sm
from occupose.synth.generate import frames
from occupose.synth.scenarios import build_scenario
from occupose.tracker import (
    CARRY_FRAMES,
    GATE_KEEP,
    GATE_M,
    INIT_FRAMES,
    LATER_SPEED,
    LEG_DOFS,
    LOOK_BACK_FROM,
    METHODS,
    MIN_FILL,
    SHAPE_FRAMES,
    STATURE_CHANGE,
    STATURE_FRAMES,
    START_CHECK_S,
    WALK_FRAMES,
    WALK_FROM,
    WALK_PRIOR,
    WALK_RAMP,
    WALKING_SPEED,
    Tracker,
    _Person,
    silhouette_fill,
    track_frames,
)


@pytest.fixture(scope="module")
def walk():
    """The first 60 frames of no_occlusion (procedural motion): frames and ground truth."""
    scenario = build_scenario("no_occlusion", use_mocap=False)
    rendered = list(frames(scenario, seed=0, num_frames=60))
    return scenario, rendered


def _camera() -> Camera:
    return Camera("cam", 160, 120, 120.0, 120.0, 79.5, 59.5, 0.001,
                  look_at(eye=(0.0, -3.0, 1.2), target=(0.0, 0.0, 1.0)))


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
    runs = {s: track_frames(Tracker(scenario.cameras, scenario.fps, "ours", seed=0, look_back_s=s), rendered,
                            len(rendered)) for s in (0.0, 1.0)}
    assert [list(r.tracks) for r in runs.values()] == [[1], [1]]
    (ahead, _), (joints, visible) = runs[0.0].tracks[1], runs[1.0].tracks[1]
    start = np.flatnonzero(np.isfinite(ahead[:, 0, 0]))[0]
    tracked = np.flatnonzero(np.isfinite(joints[:, 0, 0]))
    assert start == 63 and start - LOOK_BACK_FROM > 0
    assert tracked[0] <= start - 10 and np.all(np.diff(tracked) == 1)  # measured: from frame 50
    np.testing.assert_array_equal(joints[start:], ahead[start:])
    gt = np.stack([f.joints[0] for f in rendered])
    errors = frame_errors(joint_errors(gt[tracked[0]:start], joints[tracked[0]:start]))
    assert errors.mean() < 0.09 and errors.max() < 0.15  # measured 6.0 and 7.8 cm
    assert not visible[tracked[0]].all()  # an arm and a leg tested hidden (measured: the left ones)
    with pytest.raises(ValueError, match="look_back_s"):
        Tracker(scenario.cameras, scenario.fps, look_back_s=-1.0)


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
    assert person.shaped and len(person.shapes) == SHAPE_FRAMES  # measured on its first frontal estimates
    assert person.problem.model is person.model  # the filter goes on with the resized model
    # measured: 0.121 for 0.110 (0.166 before) and 0.462 for 0.460 (0.535 before): shaped at estimate 12,
    # rescaled to the stature measured again (1.585 -> 1.638 m) at 31
    assert person.model.dims.shoulder_width == pytest.approx(dims.shoulder_width, abs=0.025)
    assert person.model.dims.spine == pytest.approx(dims.spine, abs=0.03)
    joints = result.tracks[1][0]
    gt = np.stack([f.joints[0] for f in rendered])
    # tracked on with it (measured 8.0 cm over the last 15 frames, 7.7 without resizing: the
    # gain shows over whole scenes, see the README)
    assert np.nanmean(frame_errors(joint_errors(gt[-15:], joints[-15:]))) < 0.10
    unshaped = Tracker(scenario.cameras, scenario.fps, "ours", seed=0, shape=False)
    track_frames(unshaped, rendered, len(rendered))
    kept = unshaped.people[1].model.dims  # the average adult's proportions at the measured stature
    assert not unshaped.people[1].shapes
    for name in ("shoulder_width", "spine", "neck_head"):
        assert getattr(kept, name) / kept.height == pytest.approx(getattr(DEFAULT_DIMS, name) / DEFAULT_DIMS.height)


def test_a_person_picked_up_slowly_from_the_ceiling_gets_its_stature_measured_again():
    """Under a ceiling camera the grid picks a person up over its first frames, and the
    start's points do not reach the head yet: the stature is measured again on the first
    STATURE_FRAMES upright estimates and the model rescaled; only then is it known (the
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
    assert len(person.tops) == STATURE_FRAMES and person.problem.stature_known
    assert person.model.dims.height == pytest.approx(np.median(person.tops))
    assert person.model.dims.height == pytest.approx(truth, abs=STATURE_CHANGE)  # measured 1.727


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
    results = [track_frames(Tracker(scenario.cameras, scenario.fps, "ours", seed=0, hold_people=False),
                            rendered[:40], 40, overlap=o) for o in (False, True)]
    assert np.array_equal(results[0].tracks[1][0], results[1].tracks[1][0], equal_nan=True)
    errors = {}
    for overlap in (False, True):
        for seed in range(4):
            result = track_frames(Tracker(scenario.cameras, scenario.fps, "ours", seed=seed, hold_people=True),
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


def test_a_room_without_people_gives_no_tracks():
    camera = _camera()
    tracker = Tracker([camera], 30.0)
    wall = np.full((camera.height, camera.width), 3.5, np.float32)
    for _ in range(10):
        assert tracker.update({"cam": wall}) == {}
    for _ in range(3):  # every pixel invalid (a sensor blinded): no crash, nobody
        assert tracker.update({"cam": np.zeros_like(wall)}) == {}


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
            out = tracker.update(f.depth)
        assert list(out) == [1] and out[1].visible.all()
        blind = {name: np.zeros_like(rendered[30].depth[name])}
        for _ in range(5):
            out = tracker.update(blind)
            assert list(out) == [1] and not out[1].visible.any()  # kept, carried, flagged not visible
        for f in rendered[35:45]:
            out = tracker.update(f.depth)
        assert list(out) == [1] and out[1].visible.all()
        errors.append(frame_errors(joint_errors(rendered[44].joints[0][None], out[1].joints[None]))[0])
    assert np.mean(errors) < 0.15, errors  # back on the person after the drop-out


def test_bad_settings_are_refused():
    camera = _camera()
    with pytest.raises(ValueError, match="unknown method 'fast'; valid names: ours, apf, ps, part-based"):
        Tracker([camera], 30.0, "fast")
    with pytest.raises(ValueError, match=r"unknown method setting\(s\) \['particle'\]"):
        Tracker([camera], 30.0, particle=10)
    with pytest.raises(ValueError, match="model must be 'auto', 'full' or 'upper'"):
        Tracker([camera], 30.0, model="legs")


def test_auto_model_is_upper_for_a_ceiling_camera():
    front = _camera()
    ceiling = Camera("top", 160, 120, 120.0, 120.0, 79.5, 59.5, 0.001,
                     look_at(eye=(0.0, 0.0, 2.9), target=(0.0, 0.01, 0.0)))
    assert Tracker([front], 30.0).model_name == "full"
    assert Tracker([ceiling], 30.0).model_name == "upper"
    assert Tracker([ceiling], 30.0, model="full").model_name == "full"
    assert METHODS["part-based"].model == "upper"


# ------------------------------------------------------------------------------ the parts


def test_part_tree_of_the_full_model():
    model = body_model("full")
    parents, dofs = part_tree(model)
    names = model.part_names
    named = {names[k]: (names[p] if p >= 0 else None) for k, p in enumerate(parents)}
    assert named == {"torso": None, "head": "torso", "left_upper_arm": "torso", "left_forearm": "left_upper_arm",
                     "right_upper_arm": "torso", "right_forearm": "right_upper_arm", "left_thigh": "torso",
                     "left_shin": "left_thigh", "right_thigh": "torso", "right_shin": "right_thigh"}
    assert sorted(np.concatenate(dofs).tolist()) == list(range(model.num_dofs))


def test_joints_are_visible_when_the_parts_placing_them_are():
    model = body_model("full")
    parts = {JOINTS[j]: sorted(model.part_names[k] for k in p) for j, p in enumerate(joint_parts(model))}
    assert parts["pelvis"] == ["torso"] and parts["left_hip"] == ["torso"]
    assert parts["left_knee"] == ["left_thigh", "torso"]
    assert parts["right_ankle"] == ["right_shin", "right_thigh", "torso"]
    assert parts["head"] == ["head", "torso"]
    upper = body_model("upper")
    assert [len(p) for p in joint_parts(upper)][JOINT_INDEX["left_knee"]] == 0  # not reported


def test_hidden_parts_behind_a_surface_that_is_not_the_person():
    camera = _camera()
    model = body_model("full")
    pose = standing_pose(model, (0.0, 0.0), np.pi / 2 + np.pi)  # facing the camera at y = -3
    a, b = (x[0] for x in capsules_from_poses(model, pose[None]))
    depth = np.full((camera.height, camera.width), 3.5, np.float32)
    owners = np.zeros(depth.shape, np.int32)
    depth[70:, :] = 2.0  # a table top edge in front of the legs (image rows below the hips)
    args = (a, b, model.capsule_radii, model.capsule_part, model.num_parts, {"cam": depth})
    hidden = hidden_parts_in_views(*args, {"cam": owners}, [camera], track_id=1)
    names = [n for n, h in zip(model.part_names, hidden) if h]
    assert {"left_shin", "right_shin"} <= set(names)
    assert "torso" not in names and "head" not in names
    owners[70:, :] = 1  # the same surface is the person's own: nothing is hidden
    assert not hidden_parts_in_views(*args, {"cam": owners}, [camera], track_id=1).any()
    far = standing_pose(model, (6.0, 0.0), 0.0)  # outside the image: hidden from the only camera
    a, b = (x[0] for x in capsules_from_poses(model, far[None]))
    owners[:] = 0
    assert hidden_parts_in_views(a, b, model.capsule_radii, model.capsule_part, model.num_parts, {"cam": depth},
                                 {"cam": owners}, [camera], track_id=1).all()


def test_planted_legs_keep_the_feet_on_the_floor():
    model = body_model("full")
    pose = standing_pose(model)
    seated = pose.copy()
    seated[2] = 0.5  # pelvis at seat height, legs still straight: they would sink into the floor
    fixed = planted_legs(model, seated, ["left", "right"])
    joints = joints_from_poses(model, fixed[None])[0]
    for side in ("left", "right"):
        assert abs(joints[JOINT_INDEX[f"{side}_ankle"], 2] - model.dims.ankle_height) < 0.03
        assert fixed[model.dof_names.index(f"{side}_knee")] > 1.2  # bent like a seated leg
    standing = planted_legs(model, pose, ["left"])
    assert standing[model.dof_names.index("left_knee")] < 0.15  # a standing leg stays straight
    assert np.array_equal(standing[model.dof_names.index("right_knee")], pose[model.dof_names.index("right_knee")])
    # a seen thigh (seated, forward) over a hidden shin last seen folded back: only the knee moves
    folded = fixed.copy()
    folded[model.dof_names.index("right_knee")] = 2.1
    shin = planted_legs(model, folded, [], ["right"])
    changed = np.flatnonzero(shin != folded)
    assert [model.dof_names[i] for i in changed] == ["right_knee"]
    ankle = joints_from_poses(model, shin[None])[0, JOINT_INDEX["right_ankle"]]
    assert abs(ankle[2] - model.dims.ankle_height) < 0.03


def test_planted_legs_reach_the_feet_that_show():
    """A hidden leg whose foot shows (below a chair's back) reaches it, knee forwards; a
    hidden shin under a seen thigh bends to put its ankle nearest its foot."""
    model = body_model("full")
    pose = standing_pose(model, (0.0, 2.5), -np.pi / 2)  # facing -y
    joints = joints_from_poses(model, pose[None])[0]
    foot = joints[JOINT_INDEX["left_ankle"]] + [0.05, -0.2, 0.0]  # 20 cm forwards, 5 cm out
    pose[2] -= 0.1  # the pelvis 10 cm lower: the leg must bend to reach it
    planted = planted_legs(model, pose, ["left"], feet={"left": foot})
    got = joints_from_poses(model, planted[None])[0]
    assert np.linalg.norm(got[JOINT_INDEX["left_ankle"]] - foot) < 0.01
    hip, knee, ankle = (got[JOINT_INDEX[f"left_{j}"]] for j in ("hip", "knee", "ankle"))
    assert (knee - (hip + ankle) / 2)[1] < -0.05  # the knee bends forwards (-y)
    assert np.array_equal(planted[model.dof_names.index("right_knee")], pose[model.dof_names.index("right_knee")])
    # a seated thigh over a hidden shin: the knee bend whose ankle is nearest the foot
    seated = pose.copy()
    seated[2] = 0.5
    seated[model.dof_names.index("right_hip_flex")] = 1.5
    knee = joints_from_poses(model, seated[None])[0, JOINT_INDEX["right_knee"]]
    tucked = knee + [0.0, 0.25, -(knee[2] - model.dims.ankle_height) * 0.8]  # the foot drawn back under the seat
    shin = planted_legs(model, seated, [], ["right"], feet={"right": tucked})
    ankle = joints_from_poses(model, shin[None])[0, JOINT_INDEX["right_ankle"]]
    plain = joints_from_poses(model, planted_legs(model, seated, [], ["right"])[None])[0, JOINT_INDEX["right_ankle"]]
    assert np.linalg.norm(ankle - tucked) < 0.06 < np.linalg.norm(plain - tucked)


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
        estimates = tracker.update(frame.depth)
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


def test_track_command_writes_tracks_and_summary(tmp_path, walk):
    scenario, rendered = walk
    rec = tmp_path / "rec"
    with RecordingWriter(rec, list(scenario.cameras), scenario.fps) as writer:
        for f in rendered[:25]:
            writer.write_frame({c.name: raw_depth_from_metres(f.depth[c.name], c) for c in scenario.cameras})
        writer.write_groundtruth(np.stack([f.joints for f in rendered[:25]]),
                                 np.stack([f.visible for f in rendered[:25]]), [1])
    out = tmp_path / "out"
    result = CliRunner().invoke(main, ["track", str(rec), "--out", str(out), "--particles", "100",
                                       "--layers", "2,1,1"])
    assert result.exit_code == 0, result.output
    assert "1 track(s) in 25 frames" in result.output and "person 1 (track 1) all joints" in result.output
    summary = json.loads((out / "summary.json").read_text())
    assert summary["method"] == "ours" and summary["particles"] == 100 and summary["layers"] == [2, 1, 1]
    assert summary["model"] == "full"  # what auto chose for a front camera
    assert summary["frames"] == 25 and summary["people"] == 1 and summary["fps"] > 0
    tracks = read_tracks_csv(out / "tracks.csv", 25)
    assert list(tracks) == [1] and np.isfinite(tracks[1][0][-1]).all()


def test_track_command_bad_input(tmp_path):
    runner = CliRunner()
    result = runner.invoke(main, ["track", str(tmp_path), "--out", str(tmp_path / "o")])
    assert result.exit_code != 0 and "recording.json" in result.output
    config = tmp_path / "c.json"
    config.write_text("[1, 2]")
    rec = tmp_path / "rec"
    with RecordingWriter(rec, [_camera()], 30.0) as writer:
        writer.write_frame({"cam": np.zeros((120, 160), np.uint16)})
    result = runner.invoke(main, ["track", str(rec), "--out", str(tmp_path / "o"), "--config", str(config)])
    assert result.exit_code != 0 and "the config must be a table of settings" in result.output
    result = runner.invoke(main, ["track", str(rec), "--out", str(tmp_path / "o"), "--layers", "x"])
    assert result.exit_code != 0 and "--layers must be an integer" in result.output
    result = runner.invoke(main, ["track", str(rec), "--out", str(tmp_path / "o"), "--method", "magic"])
    assert result.exit_code != 0 and "unknown method 'magic'" in result.output
    result = runner.invoke(main, ["track", str(rec), "--out", str(tmp_path / "o")])
    assert result.exit_code == 0 and "nobody was tracked" in result.output
    assert Recording(rec).num_frames == 1


def test_an_empty_recording_is_refused_clearly(tmp_path):
    rec = tmp_path / "empty"
    with RecordingWriter(rec, [_camera()], 30.0):
        pass
    result = CliRunner().invoke(main, ["track", str(rec), "--out", str(tmp_path / "o")])
    assert result.exit_code != 0 and "the recording has no frames, nothing to track" in result.output


def test_a_person_cut_by_the_image_edge_does_not_start():
    """A person not fully in view (pixels at the left, right or top edge) is not started: its
    points would misjudge its size; the bottom edge (feet cut near the camera) is allowed."""
    camera = _camera()
    tracker = Tracker([camera], 30.0)

    def observation(rows, cols):
        v, u = np.meshgrid(np.arange(*rows), np.arange(*cols), indexing="ij")
        pixels = np.sort((v * camera.width + u).reshape(-1))
        return GridObservation(1, {"cam": pixels}, {"cam": np.zeros((pixels.size, 3))})

    assert not tracker._at_border(observation((20, 110), (60, 90)))
    assert not tracker._at_border(observation((20, 120), (60, 90)))  # feet at the bottom edge
    assert tracker._at_border(observation((20, 110), (0, 30)))  # left edge
    assert tracker._at_border(observation((20, 110), (140, 160)))  # right edge
    assert tracker._at_border(observation((0, 60), (60, 90)))  # top edge


def test_with_two_cameras_one_that_sees_the_whole_person_is_enough_to_start():
    front, side = _camera(), replace(_camera(), name="side")
    tracker = Tracker([front, side], 30.0)

    def pixels(rows, cols):
        v, u = np.meshgrid(np.arange(*rows), np.arange(*cols), indexing="ij")
        return np.sort((v * front.width + u).reshape(-1))

    def observation(front_pixels, side_pixels):
        return GridObservation(1, {"cam": front_pixels, "side": side_pixels},
                               {"cam": np.zeros((front_pixels.size, 3)), "side": np.zeros((side_pixels.size, 3))})

    whole, cut, none = pixels((20, 110), (60, 90)), pixels((20, 110), (0, 30)), np.zeros(0, np.int64)
    assert not tracker._at_border(observation(whole, cut))
    assert not tracker._at_border(observation(cut, whole))
    assert tracker._at_border(observation(cut, cut))
    assert tracker._at_border(observation(cut, none))  # the only camera that sees it cuts it
    assert tracker._at_border(observation(none, none))


def _tries_to_start(tracking, monkeypatch, observation, offset: float) -> bool:
    """Whether a blob track 99 holding ``observation``, its centroid ``offset`` metres
    beside person 1's pelvis, starts a person after INIT_FRAMES tries."""
    tracker, depths = tracking
    person, tid = tracker.people[1], 99
    states = dict(tracker.blobs.states)
    monkeypatch.setattr(type(tracker.blobs), "states", property(lambda self: states))
    states[tid] = replace(states[1], centroid=np.array([*(person.pose[:2] + [offset, 0.0]), 1.0]))
    tracker._pending.pop(tid, None)
    blob = SimpleNamespace(top=1.8, centroid=states[tid].centroid)  # its cells reach 1.8 m
    started = [tracker._start(tid, observation, depths, tracker.last_assigned, blob)
               for _ in range(INIT_FRAMES)]
    return started[-1] is not None


@pytest.fixture
def tracking(walk):
    """(a tracker that has tracked the walk's first 12 frames (person 1), the 12th frame's depths)."""
    scenario, rendered = walk
    tracker = Tracker(scenario.cameras, scenario.fps, "ours", seed=0)
    for f in rendered[:12]:
        out = tracker.update(f.depth)
    assert list(out) == [1]
    return tracker, rendered[11].depth


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
    chair = GridObservation(99, {c: observation.pixels[c][low[c]] for c in low},
                            {c: observation.camera_points[c][low[c]] for c in low})
    assert len(chair.points) > 1000
    assert not _tries_to_start(tracking, monkeypatch, chair, 1.5)
    assert _tries_to_start(tracking, monkeypatch, observation, 1.5)  # the whole body does


def test_silhouette_fill_of_solid_and_scattered_pixels():
    width = 160
    v, u = np.meshgrid(np.arange(20, 110), np.arange(60, 90), indexing="ij")
    solid = np.sort((v * width + u).reshape(-1))
    assert silhouette_fill(solid, width) == pytest.approx(1.0, abs=0.01)
    scattered = np.sort(np.random.default_rng(0).choice(solid, solid.size // 20, replace=False))
    assert silhouette_fill(scattered, width) == pytest.approx(0.05, abs=0.01)
    assert silhouette_fill(np.zeros(0, np.int64), width) == 0.0


def test_a_blob_of_scattered_pixels_does_not_start(tracking, monkeypatch):
    """A ghost: a wall's noisy readings, no longer overruled by a second camera whose line of
    sight a person blocks, scattered over the image like every 25th pixel of a person's."""
    observation = tracking[0]._previous[1]
    ghost = GridObservation(99, {c: observation.pixels[c][::25] for c in observation.pixels},
                            {c: observation.camera_points[c][::25] for c in observation.camera_points})
    assert len(ghost.points) > 200 and ghost.points[:, 2].max() > 1.5
    assert max(silhouette_fill(ghost.pixels[c], 640) for c in ghost.pixels) < MIN_FILL
    assert not _tries_to_start(tracking, monkeypatch, ghost, 1.5)
    assert _tries_to_start(tracking, monkeypatch, observation, 1.5)


def test_points_far_from_the_predicted_body_are_left_out_of_the_likelihood(tracking):
    """The validation gate: pixels of the person's blob whose points are farther than GATE_M
    from its predicted body (a chair it carries) are not given to the likelihood; its own
    are. Without a predicted body (a new person), or with one so far off that the gate
    would leave fewer than GATE_KEEP of them, every pixel is."""
    tracker, depths = tracking
    person, observation = tracker.people[1], tracker._previous[1]
    cam = tracker.cameras[0].name
    own = observation.pixels[cam]
    # a carried box: pixels beside the person's, its points 0.65 .. 0.85 m in front of the
    # pelvis (beyond the hand that swings forward), at the pelvis's height
    box = np.setdiff1d(np.arange(own.max() + 1, own.max() + 400, 2), own)
    heading = person.pose[person.model.dof_names.index("heading")]
    ahead = np.linspace(0.65, 0.85, len(box))
    box_points = person.pose[:3] + np.column_stack([ahead * np.cos(heading), ahead * np.sin(heading),
                                                    np.linspace(-0.1, 0.1, len(box))])
    carried = GridObservation(1, {cam: np.concatenate([own, box])},
                              {cam: np.concatenate([observation.camera_points[cam], box_points])})
    assert person.body_distance()(box_points).min() > GATE_M
    assert len(box) < (1 - GATE_KEEP) * len(own)  # the box is a small share: the gate applies
    mask = tracker._views(carried, depths, person.model, person.body_distance())[0].mask.ravel()
    assert not mask[box].any()
    assert mask[own].mean() > 0.98  # measured 1.0: the walker's estimate fits its points
    everything = tracker._views(carried, depths, person.model)[0].mask.ravel()
    assert everything[box].all() and everything[own].all()
    # a prediction 1 m off would keep none of the person's points: the gate stands aside
    off = person.pose.copy()
    off[0] += 1.0
    assert person.body_distance(off)(carried.camera_points[cam]).min() > GATE_M
    assert tracker._views(carried, depths, person.model, person.body_distance(off))[0].mask.ravel()[own].all()


def test_a_person_walking_faces_the_way_it_walks_standing_still_no_prior():
    person = _Person(body_model("full"), METHODS["ours"], 30.0, np.random.default_rng(0))
    assert person.walking() is None and not person.standing()  # no path yet: neither
    person.path = [np.array([0.0, 0.04 * i]) for i in range(WALK_FRAMES)]  # 1.2 m/s along +y
    direction, weight = person.walking()
    assert direction == pytest.approx(np.pi / 2) and weight == pytest.approx(WALK_PRIOR)
    assert not person.standing()
    person.path = [np.array([-0.02 * i, 0.0]) for i in range(WALK_FRAMES)]  # 0.6 m/s along -x
    direction, weight = person.walking()
    assert abs(direction) == pytest.approx(np.pi) and weight == pytest.approx(WALK_PRIOR * (0.6 - WALK_FROM) / WALK_RAMP)
    person.path = [np.array([0.01 * i, 0.0]) for i in range(WALK_FRAMES)]  # 0.3 m/s: standing, swaying
    assert person.walking() is None and person.standing()


def test_a_person_run_backwards_faces_the_way_its_path_comes_from():
    """Run back in time (Tracker._look_back), a person's path goes the way it walked from:
    its walking prior points the other way, and it is turned round when its path goes the
    way it faces."""
    model = body_model("full")
    person = _Person(model, METHODS["ours"], 30.0, np.random.default_rng(0), backwards=True)
    person.path = [np.array([0.0, 0.04 * i]) for i in range(WALK_FRAMES)]  # +y back in time
    direction, weight = person.walking()
    assert direction == pytest.approx(-np.pi / 2) and weight == pytest.approx(WALK_PRIOR)
    pose = standing_pose(model, (0.0, 0.0), np.pi / 2)  # facing +y
    person.estimator.initialise(pose, 0.0)
    person.pose, person.estimates, person.since_turn = pose, 10, CARRY_FRAMES
    person.face_the_way_walked()
    assert person.pose[model.dof_names.index("heading")] == pytest.approx(-np.pi / 2)


@pytest.mark.parametrize("speed, estimates, turned", [(1.2, 100, True), (0.5, 100, False), (0.5, 10, True)])
def test_a_person_walking_backwards_is_turned_round_at_the_start_or_when_walking_fast(speed, estimates, turned):
    """The estimate faces +x while the path goes along -x: turned round (heading + pi) at
    a walk above WALKING_SPEED in the first START_CHECK_S seconds, later only above
    LATER_SPEED (a person turning to sit down still shows the way it came)."""
    assert WALKING_SPEED < 0.5 < LATER_SPEED < 1.2 and 10 <= START_CHECK_S * 30 < 100
    model = body_model("full")
    person = _Person(model, METHODS["ours"], 30.0, np.random.default_rng(0))
    pose = standing_pose(model, (0.0, 0.0), 0.0)
    person.estimator.initialise(pose, 0.0)
    person.pose, person.estimates, person.since_turn = pose, estimates, CARRY_FRAMES
    person.path = [np.array([-speed / 30.0 * i, 0.0]) for i in range(CARRY_FRAMES)]
    person.face_the_way_walked()
    heading = person.pose[model.dof_names.index("heading")]
    assert abs(abs(heading) - np.pi) < 1e-9 if turned else heading == 0.0


def test_a_person_back_from_a_gap_walks_on_the_way_it_walked_before():
    model = body_model("full")
    person = _Person(model, METHODS["ours"], 30.0, np.random.default_rng(0))
    pose = standing_pose(model, (0.0, 0.0), 0.0)
    person.estimator.initialise(pose, 0.0)
    person.pose, person.centroid = pose, np.array([0.0, 0.0, 1.0])
    person.path = [np.array([0.04 * i, 0.0]) for i in range(WALK_FRAMES)]  # 1.2 m/s along +x
    person.lost = True
    person.come_back(np.array([2.0, 1.0, 1.0]))  # back at another blob after a gap
    assert not person.lost
    np.testing.assert_allclose(person.pose[:2], [2.0, 1.0])
    np.testing.assert_allclose(person.estimator.filter.estimate[:2], [2.0, 1.0])
    np.testing.assert_allclose(person.path[-1], [2.0, 1.0])  # the jump is no step: same way, same speed
    direction, weight = person.walking()
    assert direction == pytest.approx(0.0) and weight == pytest.approx(WALK_PRIOR)
    person.carry()  # hidden again at once: carried on along +x
    np.testing.assert_allclose(person.pose[:2], [2.04, 1.0])


@pytest.mark.parametrize("speed", [1.2, 0.3])
def test_a_person_carried_out_of_sight_at_a_walk_stands_its_legs(speed):
    """Carried at a walker's speed (above WALK_FROM), the legs' DOFs, and their occlusion
    memory, take the standing pose's (the middle of a gait cycle), the trunk, head and arms
    kept; coming back, the particles follow. Carried standing, nothing but the root's x, y
    moves."""
    model = body_model("full")
    person = _Person(model, METHODS["ours"], 30.0, np.random.default_rng(0))
    stride = standing_pose(model, (0.0, 0.0), 0.0)
    for name, angle in (("left_hip_flex", 0.4), ("right_hip_flex", -0.3), ("right_knee", 0.6),
                        ("left_shoulder_flex", -0.3), ("right_elbow", 0.5), ("trunk_lean", 0.1)):
        stride[model.dof(name)] = angle
    person.estimator.initialise(stride, 0.0)
    person.pose, person.centroid = stride.copy(), np.array([0.0, 0.0, 1.0])
    person.occlusion.memory = stride.copy()
    person.path = [np.array([speed / 30.0 * i, 0.0]) for i in range(CARRY_FRAMES)]
    person.carry()
    legs = np.array([n.startswith(LEG_DOFS) for n in model.dof_names])
    assert legs.sum() == 8 and person.walked_on == (speed > WALK_FROM)
    rest = standing_pose(model) if person.walked_on else stride
    np.testing.assert_allclose(person.pose[legs], rest[legs])
    np.testing.assert_allclose(person.occlusion.memory[legs], rest[legs])
    np.testing.assert_allclose(person.pose[2:][~legs[2:]], stride[2:][~legs[2:]])  # z, heading, trunk, head, arms
    person.come_back(np.array([0.5, 0.0, 1.0]))
    np.testing.assert_allclose(person.estimator.filter.particles[:, legs],
                               np.broadcast_to(rest[legs], (len(person.estimator.filter.particles), 8)), atol=1e-12)
    np.testing.assert_allclose(person.estimator.filter.estimate, person.pose, atol=1e-12)


def test_a_person_walking_behind_a_cabinet_is_carried_at_its_speed_in_full_view():
    """The estimates of a person walking into occlusion stall at the cabinet's edge: the
    carry takes its step from the last estimates with every part in view (while they are
    recent): their mean step or their blob's median velocity (the first frames of the blob
    being cut do not count), whichever is faster; a person suspended on its blob while
    walking comes back where it was carried to, not at its blob's centroid (which stays at
    the edge). The estimates in full view need not follow one another."""
    model = body_model("full")
    person = _Person(model, METHODS["ours"], 30.0, np.random.default_rng(0))
    pose = standing_pose(model, (0.0, 0.0), 0.0)
    person.estimator.initialise(pose, 0.0)
    person.centroid = np.array([0.0, 0.0, 1.0])
    shin = model.part_names.index("right_shin")
    for i in range(10):  # in full view, the blob at 1.2 m/s along +x (the last two: being cut),
        person.part_visible[shin] = i not in (4, 5)  # but for a shin counted hidden twice; the
        blob = [1.2, 0.0] if i < 8 else [0.7, 0.1]  # estimates lag, at 0.6 m/s
        person.settle(pose + np.eye(model.num_dofs)[0] * 0.02 * i, np.array(blob))
    person.part_visible[shin] = False
    for i in range(5):  # partly hidden: the estimate slows to 0.3 m/s, the blob stalls
        person.settle(pose + np.eye(model.num_dofs)[0] * (0.18 + 0.01 * (i + 1)), np.array([0.2, 0.0]))
    np.testing.assert_allclose(person.step(), [0.04, 0.0])
    person.carry()
    np.testing.assert_allclose(person.pose[:2], [0.27, 0.0])
    assert person.walked_on  # carried at 1.2 m/s: it comes back there, not on its blob
    person.come_back(np.array([0.9, 0.3, 1.0]))
    np.testing.assert_allclose(person.pose[:2], [0.27, 0.0])
    np.testing.assert_allclose(person.estimator.filter.estimate[:2], [0.27, 0.0])
    assert not person.walked_on and not person.lost
    for _ in range(CARRY_FRAMES):  # standing partly hidden for long: its own recent path again
        person.settle(person.pose, np.array([0.3, 0.0]))
    np.testing.assert_allclose(person.step(), [0.0, 0.0], atol=1e-12)
    person.carry()
    assert not person.walked_on  # carried standing: it comes back on its blob
    person.come_back(np.array([0.9, 0.3, 1.0]))
    np.testing.assert_allclose(person.pose[:2], np.array([0.9, 0.3]) + person.anchor)
    person.part_visible[:] = True
    for i in range(3):  # in full view again, 0.6 m/s along -y: the walk before is too old to count
        person.settle(person.pose - np.eye(model.num_dofs)[1] * 0.02, np.array([0.0, -0.6]))
    np.testing.assert_allclose(person.step(), [0.0, -0.02], atol=1e-12)
    for i in range(3):  # speeding up to 0.9 m/s, the blob's velocity lagging at 0.6: the estimates'
        person.settle(person.pose - np.eye(model.num_dofs)[1] * 0.03, np.array([0.0, -0.6]))
    np.testing.assert_allclose(person.step(), [0.0, -0.026], atol=1e-12)  # (2 x 0.02 + 3 x 0.03) / 5
