"""The command line end to end on a tiny synthetic recording."""

import json

import numpy as np
import pytest
from click.testing import CliRunner
from PIL import Image

from occupose.camera import raw_depth_from_metres
from occupose.cli import main
from occupose.config import TrackerConfig
from occupose.io.joint_table import read_tracks_csv, write_tracks_csv
from occupose.io.recording import Recording, RecordingWriter
from occupose.synth.scenarios import SCENARIOS


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    out = tmp_path_factory.mktemp("cli") / "rec"
    result = CliRunner().invoke(main, ["synth", "no_occlusion", str(out), "--frames", "40", "--procedural", "--seed", "2"])
    assert result.exit_code == 0, result.output
    assert "wrote" in result.output and "40 frames" in result.output
    return out


def test_scenarios_lists_every_scenario_with_a_line():
    result = CliRunner().invoke(main, ["scenarios"])
    assert result.exit_code == 0
    lines = result.output.strip().splitlines()
    assert [line.split()[0] for line in lines] == list(SCENARIOS)


def test_synth_refuses_bad_input(tmp_path, recording):
    runner = CliRunner()
    result = runner.invoke(main, ["synth", "dance", str(tmp_path / "x")])
    assert result.exit_code != 0 and "unknown scenario 'dance'" in result.output
    result = runner.invoke(main, ["synth", "no_occlusion", str(recording), "--frames", "2"])
    assert result.exit_code != 0 and "exists and is not empty (use --force" in result.output
    result = runner.invoke(main, ["synth", "no_occlusion", str(tmp_path / "y"), "--frames", "9999"])
    assert result.exit_code != 0 and "--frames must be in 1..390" in result.output
    result = runner.invoke(main, ["synth", "no_occlusion", str(tmp_path / "z"), "--sensor", "webcam"])
    assert result.exit_code != 0 and "unknown camera preset 'webcam'" in result.output


def test_synth_sensor_option_changes_the_camera(tmp_path):
    out = tmp_path / "azure"
    result = CliRunner().invoke(main, ["synth", "top_view_arms", str(out), "--frames", "2", "--sensor", "azure_nfov",
                                       "--procedural"])
    assert result.exit_code == 0, result.output
    cam = Recording(out).cameras[0]
    assert (cam.width, cam.height) == (640, 576)


def test_show_writes_a_picture(tmp_path, recording):
    out = tmp_path / "frame.png"
    result = CliRunner().invoke(main, ["show", str(recording), "--frame", "30", "--out", str(out)])
    assert result.exit_code == 0, result.output
    image = np.asarray(Image.open(out).convert("RGB"))
    assert image.shape[0] > 200 and image.std() > 20  # a real picture, not a blank canvas
    result = CliRunner().invoke(main, ["show", str(recording), "--frame", "40", "--out", str(out)])
    assert result.exit_code != 0 and "frame 40 is out of range" in result.output


def test_score_prints_table_one_rows(tmp_path, recording):
    rec = Recording(recording)
    gt = rec.groundtruth()
    joints = gt.joints[:, 0].copy()
    joints[:, :, 0] += 0.05  # a tracker 5 cm off along x everywhere
    present = np.isfinite(joints[..., 0])
    tracks = tmp_path / "tracks.csv"
    write_tracks_csv(tracks, {7: (joints, present)})
    result = CliRunner().invoke(main, ["score", str(recording), str(tracks)])
    assert result.exit_code == 0, result.output
    row = next(line for line in result.output.splitlines() if "all joints" in line)
    assert "person 1 (track 7)" in row
    assert " 5.00 " in row and "100.00" in row  # mean 5 cm, every frame under 10 cm
    assert "identity switches: 0" in result.output


def test_score_without_groundtruth_is_a_clear_error(tmp_path, recording):
    (tmp_path / "t.csv").write_text("frame,track,joint,x,y,z,visible\n")
    import shutil

    copy = tmp_path / "nogt"
    shutil.copytree(recording, copy)
    (copy / "groundtruth.csv").unlink()
    result = CliRunner().invoke(main, ["score", str(copy), str(tmp_path / "t.csv")])
    assert result.exit_code != 0 and "no groundtruth.csv" in result.output


def test_force_replaces_only_recordings_and_validates_first(tmp_path, recording):
    runner = CliRunner()
    keep = tmp_path / "keep"
    keep.mkdir()
    (keep / "notes.txt").write_text("precious")
    result = runner.invoke(main, ["synth", "dance", str(keep), "--force"])
    assert result.exit_code != 0 and "unknown scenario" in result.output
    result = runner.invoke(main, ["synth", "no_occlusion", str(keep), "--frames", "2", "--force"])
    assert result.exit_code != 0 and "was not written by occupose" in result.output
    assert (keep / "notes.txt").read_text() == "precious"
    afile = tmp_path / "a.txt"
    afile.write_text("x")
    result = runner.invoke(main, ["synth", "no_occlusion", str(afile), "--frames", "2"])
    assert result.exit_code != 0 and "exists and is not a folder" in result.output
    old = tmp_path / "old"
    assert runner.invoke(main, ["synth", "no_occlusion", str(old), "--frames", "2", "--procedural"]).exit_code == 0
    result = runner.invoke(main, ["synth", "no_occlusion", str(old), "--frames", "3", "--procedural", "--force"])
    assert result.exit_code == 0 and Recording(old).num_frames == 3


def test_show_and_score_on_a_folder_that_is_not_a_recording(tmp_path):
    empty = tmp_path / "empty"
    empty.mkdir()
    (tmp_path / "t.csv").write_text("frame,track,joint,x,y,z,visible\n")
    for args in (["show", str(empty), "--out", str(tmp_path / "x.png")], ["score", str(empty), str(tmp_path / "t.csv")]):
        result = CliRunner().invoke(main, args)
        assert result.exit_code != 0 and "recording.json" in result.output and "Traceback" not in result.output


def test_demo_tracks_scores_and_pictures(tmp_path):
    result = CliRunner().invoke(main, ["demo", "--out", str(tmp_path), "--frames", "80"])
    assert result.exit_code == 0, result.output
    assert "ground truth: 1 person(s)" in result.output and "1 track(s) at" in result.output
    assert "person 1 (track 1) all joints" in result.output  # the Table I rows
    assert (tmp_path / "sit_behind_table-ours" / "tracks.csv").is_file()
    pictures = list(tmp_path.glob("sit_behind_table_frame*.png"))
    assert len(pictures) == 1 and "picture: " in result.output
    result = CliRunner().invoke(main, ["demo", "--out", str(tmp_path / "early"), "--frames", "10"])
    assert result.exit_code == 0 and "nobody is in view in the first 10 frames" in result.output


def test_track_command_writes_tracks_and_summary(tmp_path, walk):
    scenario, rendered = walk
    rec = tmp_path / "rec"
    with RecordingWriter(rec, list(scenario.cameras), scenario.fps) as writer:
        for f in rendered[:25]:
            writer.write_frame({c.name: raw_depth_from_metres(f.depth[c.name], c) for c in scenario.cameras})
        writer.write_groundtruth(np.stack([f.joints for f in rendered[:25]]),
                                 np.stack([f.visible for f in rendered[:25]]), [1])
    out = tmp_path / "out"
    settings = tmp_path / "settings.toml"
    settings.write_text('method = "ours"\n[pose]\ngate_m = 0.3\n[carry]\nrejoin_m = 0.8\n')
    result = CliRunner().invoke(main, ["track", str(rec), "--out", str(out), "--particles", "100",
                                       "--layers", "2,1,1", "--config", str(settings), "--set", "start.samples=30"])
    assert result.exit_code == 0, result.output
    assert "1 track(s) in 25 frames" in result.output and "person 1 (track 1) all joints" in result.output
    summary = json.loads((out / "summary.json").read_text())
    assert summary["method"] == "ours" and summary["seed"] == 0
    assert summary["source"] == {"reader": "folder", "options": {}}
    assert summary["model"] == "full"  # what auto chose for a front camera
    assert summary["frames"] == 25 and summary["people"] == 1 and summary["fps"] > 0
    # the whole resolved config: the file's, the flags' and --set's values, the method's defaults
    config = TrackerConfig.from_dict(summary["config"])
    assert config == TrackerConfig().with_values({"pose.particles": 100, "pose.layers": (2, 1, 1), "pose.gate_m": 0.3,
                                                  "carry.rejoin_m": 0.8, "start.samples": 30})
    tracks = read_tracks_csv(out / "tracks.csv", 25)
    assert list(tracks) == [1] and np.isfinite(tracks[1][0][-1]).all()


def test_track_command_bad_input(tmp_path, small_camera):
    runner = CliRunner()
    result = runner.invoke(main, ["track", str(tmp_path), "--out", str(tmp_path / "o")])
    assert result.exit_code != 0 and "recording.json" in result.output
    config = tmp_path / "c.json"
    config.write_text("[1, 2]")
    rec = tmp_path / "rec"
    with RecordingWriter(rec, [small_camera], 30.0) as writer:
        writer.write_frame({"cam": np.zeros((120, 160), np.uint16)})
    result = runner.invoke(main, ["track", str(rec), "--out", str(tmp_path / "o"), "--config", str(config)])
    assert result.exit_code != 0 and "a config must be a table of sections" in result.output
    config.write_text('{"pose": {"occlusion": "false"}}')
    result = runner.invoke(main, ["track", str(rec), "--out", str(tmp_path / "o"), "--config", str(config)])
    assert result.exit_code != 0 and "unknown setting 'pose.occlusion'; pose has:" in result.output
    config.write_text('{"occlusion": {"enabled": "false"}}')
    result = runner.invoke(main, ["track", str(rec), "--out", str(tmp_path / "o"), "--config", str(config)])
    assert result.exit_code != 0 and "occlusion.enabled must be true or false, got 'false' (str)" in result.output
    result = runner.invoke(main, ["track", str(rec), "--out", str(tmp_path / "o"), "--filter", "nonsense"])
    assert result.exit_code != 0 and "pose.filter must be one of sir, apf, ps, apf+ps, part-based" in result.output
    result = runner.invoke(main, ["track", str(rec), "--out", str(tmp_path / "o"), "--set", "pose.gate_m"])
    assert result.exit_code != 0 and "--set takes KEY=VALUE" in result.output
    result = runner.invoke(main, ["track", str(rec), "--out", str(tmp_path / "o"), "--layers", "x"])
    assert result.exit_code != 0 and "--layers must be an integer" in result.output
    result = runner.invoke(main, ["track", str(rec), "--out", str(tmp_path / "o"), "--method", "magic"])
    assert result.exit_code != 0 and "unknown method 'magic'" in result.output
    result = runner.invoke(main, ["track", str(rec), "--out", str(tmp_path / "o")])
    assert result.exit_code == 0 and "nobody was tracked" in result.output
    assert Recording(rec).num_frames == 1


def test_an_empty_recording_is_refused_clearly(tmp_path, small_camera):
    rec = tmp_path / "empty"
    with RecordingWriter(rec, [small_camera], 30.0):
        pass
    result = CliRunner().invoke(main, ["track", str(rec), "--out", str(tmp_path / "o")])
    assert result.exit_code != 0 and "the recording has no frames, nothing to track" in result.output



def test_a_filter_given_alone_takes_the_layers_it_accepts(tmp_path, small_camera):
    """--filter ps on ours (annealed in 2, 1, 2 layers): ps has no layers, apf one number,
    apf+ps on ps (no layers) ours' layers."""
    from occupose.cli import build_config

    config, name = build_config(None, None, {"pose.filter": "ps"})
    assert name == "ours" and config.pose.filter == "ps" and config.pose.layers is None
    config, _ = build_config(None, None, {"pose.filter": "apf"})
    assert config.pose.layers == 5  # the same 5 layers in one stage
    config, _ = build_config(None, "ps", {"pose.filter": "apf+ps"})
    assert config.pose.layers == (2, 1, 2)  # ours' split
    config, _ = build_config(None, "ps", {}, ("grid.max_range=4.2", 'grid.noise_model="none"', "blobs.join_m=none"))
    assert (config.grid.max_range, config.grid.noise_model, config.blobs.join_m) == (4.2, "none", None)


def test_config_command_prints_settings_that_read_back(tmp_path):
    runner = CliRunner()
    result = runner.invoke(main, ["config", "--method", "apf", "--set", "pose.particles=300", "--set",
                                  "grid.noise_model=preset"])
    assert result.exit_code == 0, result.output
    assert 'method = "apf"' in result.output and "particles = 300" in result.output
    assert 'noise_model = "preset"' in result.output and "# max_range = none" in result.output  # TOML has no none
    path = tmp_path / "printed.toml"
    path.write_text(result.output)
    expected = TrackerConfig.from_dict({"method": "apf", "pose": {"particles": 300}, "grid": {"noise_model": "preset"}})
    assert TrackerConfig.from_file(path) == expected
