"""track, convert, show and score read a recording of any format and place one without a
world pose: from the floor in its frames, or from a pose given on the command line."""

from __future__ import annotations

import json

import numpy as np
import pytest
from click.testing import CliRunner

from occupose.camera import raw_depth_from_metres
from occupose.cli import main
from occupose.io.recording import Recording, RecordingWriter
from occupose.io.sources import HeightTilt

FRAMES = 20
FAST = ["--particles", "100", "--layers", "2,1,1", "--set", "start.samples=30"]


@pytest.fixture(scope="module")
def rec(tmp_path_factory, walk):
    scenario, rendered = walk
    path = tmp_path_factory.mktemp("sources") / "rec"
    with RecordingWriter(path, list(scenario.cameras), scenario.fps) as writer:
        for f in rendered[:FRAMES]:
            writer.write_frame({c.name: raw_depth_from_metres(f.depth[c.name], c) for c in scenario.cameras})
    return path


def invoke(*args):
    return CliRunner().invoke(main, [str(a) for a in args])


def test_convert_with_the_floor_found_then_track_equals_tracking_with_the_floor(rec, tmp_path):
    converted = tmp_path / "converted"
    result = invoke("convert", rec, converted, "--find-floor")
    assert result.exit_code == 0, result.output
    assert "m above the floor, tilted" in result.output and "found from the floor" in result.output
    header = json.loads((converted / "recording.json").read_text())
    truth = Recording(rec).cameras[0]
    placed = header["origin"]["cameras"][0]
    assert header["origin"]["reader"] == "folder" and placed["pose"] == "floor"
    assert placed["height_m"] == pytest.approx(truth.position[2], abs=0.02)
    assert placed["tilt_deg"] == pytest.approx(np.degrees(truth.down_angle), abs=1.0)
    copy = Recording(converted)
    for a, b in zip(Recording(rec).frames(), copy.frames()):
        np.testing.assert_array_equal(a.depth[truth.name], b.depth[truth.name])
    direct, via = tmp_path / "direct", tmp_path / "via"
    assert invoke("track", rec, "--out", direct, "--find-floor", *FAST).exit_code == 0
    assert invoke("track", converted, "--out", via, *FAST).exit_code == 0
    assert (direct / "tracks.csv").read_bytes() == (via / "tracks.csv").read_bytes()
    cameras = json.loads((direct / "summary.json").read_text())["cameras"]
    assert cameras == [placed]
    assert json.loads((via / "summary.json").read_text())["cameras"][0]["pose"] == "recording"


def test_a_pose_given_for_a_recording_that_has_one_is_refused(rec, tmp_path):
    result = invoke("track", rec, "--out", tmp_path / "run", "--camera-height", "1.5", "--tilt", "10")
    assert result.exit_code == 1 and "has its own world pose; drop the pose option" in result.output
    assert not (tmp_path / "run").exists()


@pytest.mark.parametrize("args, message", [
    (["--camera-height", "1.5"], "--camera-height and --tilt go together"),
    (["--tilt", "20"], "--camera-height and --tilt go together"),
    (["--camera-height", "0"], "Invalid value for '--camera-height'"),
    (["--tilt", "91"], "Invalid value for '--tilt'"),
    (["--reader", "mp3"], "Invalid value for '--reader'"),
])
def test_bad_pose_options(rec, tmp_path, args, message):
    result = invoke("convert", rec, tmp_path / "out", *args)
    assert result.exit_code != 0 and message in result.output
    assert not (tmp_path / "out").exists()


def test_world_from_camera_file_with_find_floor_is_refused(rec, tmp_path):
    pose = tmp_path / "pose.json"
    pose.write_text(json.dumps({"world_from_camera": HeightTilt(1.0, 0.0).world_from_camera().tolist()}))
    result = invoke("convert", rec, tmp_path / "out", "--world-from-camera", pose, "--find-floor")
    assert result.exit_code == 1 and "either a pose or find_floor, not both" in result.output


def test_show_and_score_take_the_source_options(rec, tmp_path):
    result = invoke("show", rec, "--out", tmp_path / "frame.png", "--find-floor", "--frame", "3")
    assert result.exit_code == 0, result.output
    assert (tmp_path / "frame.png").stat().st_size > 1000
    tracks = tmp_path / "tracks.csv"
    tracks.write_text("frame,track,joint,x,y,z,visible\n")
    result = invoke("score", rec, tracks, "--find-floor", "--unmarked")
    assert result.exit_code == 1 and "nothing to score against" in result.output


def test_export_in_the_camera_frame_uses_the_pose_the_run_found(rec, tmp_path):
    """A run that placed the camera from the floor writes its pose into summary.json, and
    export's camera frame is that pose's, not the recording's own: the exported JSON holds
    the run's (to the 0.1 mm tracks.csv keeps; with the recording's own pose joints move by
    centimetres)."""
    run = tmp_path / "run"
    result = invoke("track", rec, "--out", run, "--find-floor", "--format", "json", "--frame", "camera", *FAST)
    assert result.exit_code == 0, result.output
    entry, = json.loads((run / "summary.json").read_text())["cameras"]
    pose = np.array(entry["world_from_camera"])
    own = Recording(rec).cameras[0].world_from_camera
    assert entry["pose"] == "floor" and pose[2, 3] == pytest.approx(entry["height_m"], abs=1e-4)
    assert np.abs(pose - own).max() > 1e-3  # the found world differs from the recording's a little
    exported = tmp_path / "exported.json"
    result = invoke("export", run / "tracks.csv", "--to", "json", "--frame", "camera", "--out", exported)
    assert result.exit_code == 0, result.output
    ran, again = (json.loads(path.read_text())["frames"] for path in (run / "tracks.json", exported))
    assert [f["frame_id"] for f in ran] == [f["frame_id"] for f in again] and len(ran) == FRAMES
    points = [np.array([[[np.nan] * 3 if j is None else j for j in b["joint_positions"]] for b in f["bodies"]],
                       dtype=float).reshape(-1, 3) for f in (*ran, *again)]
    assert sum(np.isfinite(p).all(axis=1).sum() for p in points[:FRAMES]) >= FRAMES // 2 * 15
    for a, b in zip(points[:FRAMES], points[FRAMES:]):
        np.testing.assert_allclose(a, b, atol=0.1)  # mm; NaN where both have no joint


def test_export_in_the_camera_frame_of_a_recording_without_a_pose_needs_the_runs(rec, tmp_path):
    from occupose.io.joint_table import write_tracks_csv
    from occupose.testing import write_depth_bag

    recording = Recording(rec)
    camera = recording.cameras[0]
    bag = write_depth_bag(tmp_path / "rec.bag", (raw_depth_from_metres(f.depth[camera.name], camera)
                                                 for f in recording.frames()), camera, fps=recording.fps)
    tracks = write_tracks_csv(tmp_path / "tracks.csv", {})  # a run's, its summary.json lost
    result = invoke("export", tracks, "--recording", bag, "--to", "json", "--frame", "camera",
                    "--out", tmp_path / "x.json")
    assert result.exit_code == 1 and "its camera frame is unknown; export in the world frame" in result.output
    assert not (tmp_path / "x.json").exists()


def test_a_bag_of_several_depth_topics_is_exported_with_the_topic_the_run_was_given(rec, tmp_path):
    """summary.json records how the recording was read (reader and options, here the topic
    chosen with --topic), and export opens the bag with them: without them it cannot choose
    between the bag's two depth topics."""
    pytest.importorskip("rosbags")
    from occupose.testing import bag_typestore, camera_info_message, image_message, write_bag

    IMAGE, INFO = "sensor_msgs/msg/Image", "sensor_msgs/msg/CameraInfo"

    recording = Recording(rec)
    camera = recording.cameras[0]
    store = bag_typestore(1)
    messages = [(f"/{n}/depth/camera_info", INFO, 1, camera_info_message(store, camera, frame_id=n)) for n in "ab"]
    for f in recording.frames():
        raw = raw_depth_from_metres(f.depth[camera.name], camera)
        for n, image in (("a", raw), ("b", np.zeros_like(raw))):
            messages.append((f"/{n}/depth/image_raw", IMAGE, 10 + f.index,
                             image_message(store, image, "16UC1", 5.0 + f.index / recording.fps, frame_id=n)))
    bag = write_bag(tmp_path / "two.bag", messages, store)
    height, tilt = camera.position[2], np.degrees(camera.down_angle)
    run = tmp_path / "run"
    result = invoke("track", bag, "--topic", "/a/depth/image_raw", "--camera-height", height, "--tilt", tilt,
                    "--format", "json", "--out", run, *FAST)
    assert result.exit_code == 0, result.output
    summary = json.loads((run / "summary.json").read_text())
    assert summary["source"] == {"reader": "bag", "options": {"topic": "/a/depth/image_raw"}}
    exported = tmp_path / "exported.json"
    result = invoke("export", run / "tracks.csv", "--to", "json", "--out", exported)
    assert result.exit_code == 0, result.output
    ran, again = (json.loads(path.read_text())["frames"] for path in (run / "tracks.json", exported))
    assert ran == again and sum(len(f["bodies"]) for f in ran) >= FRAMES // 2  # the person tracked
    del summary["source"]  # a summary without it: the bag's topics are ambiguous
    (run / "summary.json").write_text(json.dumps(summary))
    result = invoke("export", run / "tracks.csv", "--to", "json", "--out", tmp_path / "x.json")
    assert result.exit_code == 1 and "several depth image topics" in result.output
