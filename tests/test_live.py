"""occupose live --realsense: bags played through pyrealsense2's playback device in real
time, as a camera would deliver them (no mock of the library)."""

from __future__ import annotations

import io
import json
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from occupose.camera import raw_depth_from_metres
from occupose.cli import main
from occupose.config import method_config
from occupose.joints import JOINT_INDEX
from occupose.synth.generate import frames
from occupose.synth.scenarios import build_scenario
from occupose.testing import write_depth_bag

# ImportError, not only ModuleNotFoundError: pyrealsense2 installed without Debian's libusb-1.0-0 fails to load
pytest.importorskip("pyrealsense2", reason="the realsense extra (pyrealsense2, with Debian's libusb-1.0-0)",
                    exc_type=ImportError)

from occupose.live import RealSenseCamera, track_live  # noqa: E402

SHARED_BAG = Path(__file__).resolve().parents[2] / "shared" / "data" / "sensors" / "realsense" / \
    "single_depth_color_640x480.bag"
FRAMES = 45  # 1.5 s at 30 frames/s


def tracked_lines(text: str) -> tuple[list[dict], list[dict]]:
    """A live run's JSON lines: (one per tracked frame, the look-back's late lines)."""
    lines = [json.loads(line) for line in text.splitlines()]
    return [line for line in lines if not line.get("late")], [line for line in lines if line.get("late")]


@pytest.fixture(scope="module")
def walk_bag(tmp_path_factory):
    """A RealSense bag of no_occlusion's first frames (a person walking in view from the
    first frame), its scene and the camera's true pose as a pose file."""
    scene = build_scenario("no_occlusion", use_mocap=False)
    camera = scene.cameras[0]
    depths = [raw_depth_from_metres(f.depth[camera.name], camera) for f in frames(scene, num_frames=FRAMES)]
    root = tmp_path_factory.mktemp("live")
    bag = write_depth_bag(root / "walk.bag", depths, camera, realsense=True, encoding="mono16", fps=30.0,
                          start=1e-6)
    pose = root / "pose.json"
    pose.write_text(json.dumps({"world_from_camera": camera.world_from_camera.tolist()}))
    return bag, scene, pose


def test_a_synthetic_bag_plays_as_a_camera_and_counts_what_it_drops(walk_bag):
    """In real time the frames tracked depend on the machine's load: what is checked is that
    they come in order from the first and that every one not tracked is counted."""
    bag, scene, pose = walk_bag
    out, said = io.StringIO(), []
    with RealSenseCamera(bag=bag) as source:
        camera = source.camera
        assert (camera.width, camera.height, source.fps) == (640, 480, 30.0)
        assert camera.fx == pytest.approx(scene.cameras[0].fx, rel=1e-6)
        assert camera.depth_scale == pytest.approx(scene.cameras[0].depth_scale, rel=1e-6)
        summary = track_live(source, "ours", out=out, pose=pose, status=said.append)
    lines, _ = tracked_lines(out.getvalue())
    numbers = [line["device_frame"] for line in lines]
    # the bag's first frame (those played before it is held for the warm-up wait in a queue),
    # then always newer ones
    assert numbers[0] == 1 and numbers == sorted(set(numbers))
    gaps = sum(b - a - 1 for a, b in zip(numbers, numbers[1:]))
    assert lines[-1]["dropped"] == summary.dropped == gaps  # every frame not tracked after the first is counted
    assert summary.frames == len(lines) and summary.frames + summary.dropped == numbers[-1] - numbers[0] + 1
    assert said[-1] == summary.status() and f"{summary.dropped} dropped" in said[-1]
    assert [line["frame"] for line in lines] == list(range(len(lines)))
    assert all(line["latency_ms"] > 0 for line in lines)
    # (how many people are tracked depends on the frames dropped: a busy machine drops many,
    # and the person then jumps between them; that is the frame-by-frame test's)


def test_a_bag_played_frame_by_frame_tracks_every_frame_and_its_person(walk_bag):
    bag, scene, pose = walk_bag
    out = io.StringIO()
    with RealSenseCamera(bag=bag, real_time=False) as source:
        summary = track_live(source, "ours", out=out, pose=pose)
    lines, late = tracked_lines(out.getvalue())
    assert [line["device_frame"] for line in lines] == list(range(1, FRAMES + 1))
    assert summary.dropped == 0 and all(line["dropped"] == 0 for line in lines)
    truth = scene.people[0].joints

    def pelvis_errors(lines):
        errors = []
        for line in lines:
            assert len(line["people"]) <= 1
            for person in line["people"]:
                assert len(person["joints"]) == len(person["visible"]) == 15
                pelvis = np.array(person["joints"][JOINT_INDEX["pelvis"]])
                errors.append(np.linalg.norm(pelvis - truth[line["device_frame"] - 1, JOINT_INDEX["pelvis"]]))
        return errors

    errors = pelvis_errors(lines)
    assert len(errors) >= 0.8 * FRAMES  # tracked from its first frames
    assert np.median(errors) < 0.06, errors  # metres (3.1 cm when written, the same on a busy machine)
    # the look-back's late lines: the frames before the person's first line, each once, its
    # own number and time, the person as in occupose track's output
    first = next(line["frame"] for line in lines if line["people"])
    assert late and [line["frame"] for line in late] == list(range(first - len(late), first))
    assert all(line["device_frame"] == line["frame"] + 1 and "latency_ms" not in line for line in late)
    assert {line["time_ms"] for line in late} <= {line["time_ms"] for line in lines}
    assert np.median(pelvis_errors(late)) < 0.1


def test_live_measures_the_noise_on_the_first_frames_it_tracks(walk_bag):
    """grid.noise_model measured (the default): the tracker measures the camera's noise on
    its first grid.noise_frames frames, which it tracks meanwhile with the preset's model."""
    bag, _, pose = walk_bag
    out, said = io.StringIO(), []
    with RealSenseCamera(bag=bag, real_time=False) as source:
        summary = track_live(source, method_config("ours").with_values({"grid.noise_frames": 5}), out=out,
                             pose=pose, status=said.append)
    lines, _ = tracked_lines(out.getvalue())
    assert said[0] == "the camera's depth noise is measured on its first 5 frames tracked"
    assert [line["device_frame"] for line in lines[:5]] == [1, 2, 3, 4, 5]  # tracked, not set aside
    assert summary.noise["model"] == "measured" and summary.noise["frames"] == 5
    with RealSenseCamera(bag=bag, real_time=False) as source:  # a run shorter than the measurement
        short = track_live(source, "ours", out=io.StringIO(), pose=pose, max_frames=3)
    assert short.noise["model"] == "structured_light" and short.noise["unmeasured"] == "not measured"


def test_a_tracker_slower_than_the_camera_drops_frames_and_says_so(walk_bag):
    """With ten times the particles the tracker cannot keep up with 30 frames/s: it takes the
    newest frame each time and counts the others."""
    bag, _, pose = walk_bag
    out, said = io.StringIO(), []
    with RealSenseCamera(bag=bag) as source:
        summary = track_live(source, method_config("ours").with_values({"pose.particles": 2000}), out=out,
                             pose=pose, status=said.append)
    lines, _ = tracked_lines(out.getvalue())
    assert summary.dropped > 0 and summary.frames < FRAMES
    assert summary.frames + summary.dropped == lines[-1]["device_frame"] - lines[0]["device_frame"] + 1
    assert f"{summary.dropped} dropped" in said[-1]


def test_live_on_the_command_line_writes_json_lines_and_refuses_to_overwrite(walk_bag, tmp_path):
    bag, _, pose = walk_bag
    out = tmp_path / "live.jsonl"
    args = ["live", "--realsense", "--bag", str(bag), "--out", str(out), "--world-from-camera", str(pose),
            "--frames", "5"]
    result = CliRunner().invoke(main, args)
    assert result.exit_code == 0, result.output
    lines, _ = tracked_lines(out.read_text())
    assert len(lines) == 5 and "5 frames tracked" in result.output and "the pose given" in result.output
    again = CliRunner().invoke(main, args)
    assert again.exit_code != 0 and "exists" in again.output
    assert CliRunner().invoke(main, [*args, "--force"]).exit_code == 0
    theirs = tmp_path / "theirs.jsonl"
    theirs.write_text("my notes\n")
    refused = CliRunner().invoke(main, [*args[:5], str(theirs), *args[6:], "--force"])
    assert refused.exit_code != 0 and "not written by occupose" in refused.output
    assert theirs.read_text() == "my notes\n"
    floor = CliRunner().invoke(main, [*args[:4], "--out", str(tmp_path / "floor.jsonl"), "--frames", "5"])
    assert floor.exit_code == 0, floor.output  # no pose given: the floor of the first frames places it
    tracked = len(tracked_lines((tmp_path / "floor.jsonl").read_text())[0])  # 5, or fewer where the bag ends first
    assert "placed from the floor" in floor.output and 1 <= tracked <= 5 and f"{tracked} frames tracked" in floor.output
    every = tmp_path / "every.jsonl"
    played = CliRunner().invoke(main, [*args[:5], str(every), *args[6:], "--every-frame"])
    assert played.exit_code == 0, played.output
    assert [line["device_frame"] for line in tracked_lines(every.read_text())[0]] == [1, 2, 3, 4, 5]
    camera = CliRunner().invoke(main, ["live", "--realsense", "--every-frame", "--out", str(tmp_path / "c.jsonl")])
    assert camera.exit_code != 0 and "--every-frame plays a --bag" in camera.output


@pytest.mark.shared
@pytest.mark.skipif(not SHARED_BAG.is_file(), reason="needs ../shared/data/sensors/realsense")
def test_the_shared_bag_of_a_real_d435_plays(tmp_path):
    out = tmp_path / "live.jsonl"
    result = CliRunner().invoke(main, ["live", "--realsense", "--bag", str(SHARED_BAG), "--out", str(out),
                                       "--camera-height", "1.2", "--tilt", "10"])
    assert result.exit_code == 0, result.output
    lines = [json.loads(line) for line in out.read_text().splitlines()]
    assert [line["device_frame"] for line in lines] == [169, 170]  # its two depth frames (6 frames/s)
    assert lines[1]["time_ms"] - lines[0]["time_ms"] == pytest.approx(1000 / 6, abs=1.0)
    assert "2 frames tracked, 0 dropped" in result.output
