"""occupose track --format and occupose export end to end on a tiny synthetic recording."""

from __future__ import annotations

import json
import sys

import numpy as np
import pytest
from click.testing import CliRunner

from occupose.camera import raw_depth_from_metres
from occupose.cli import main
from occupose.io.joint_table import read_tracks_csv
from occupose.io.output import MANIFEST
from occupose.io.recording import Recording, RecordingWriter
from occupose.io.writers.k4abt_json import K4ABT_FROM_OURS, K4ABT_JOINTS
from occupose.joints import JOINT_INDEX

FRAMES = 20
FAST = ["--particles", "100", "--layers", "2,1,1", "--set", "start.samples=30"]


@pytest.fixture(scope="module")
def run(tmp_path_factory, walk):
    """(the recording, the run folder of `occupose track REC --format json --frame camera`)."""
    scenario, rendered = walk
    base = tmp_path_factory.mktemp("export")
    rec = base / "rec"
    with RecordingWriter(rec, list(scenario.cameras), scenario.fps) as writer:
        for f in rendered[:FRAMES]:
            writer.write_frame({c.name: raw_depth_from_metres(f.depth[c.name], c) for c in scenario.cameras})
    out = base / "run"
    result = CliRunner().invoke(main, ["track", str(rec), "--out", str(out), "--format", "json", "--frame", "camera",
                                       *FAST])
    assert result.exit_code == 0, result.output
    return rec, out


def _camera_points(rec: Recording, points: np.ndarray) -> np.ndarray:
    """(..., 3) world metres -> the first camera's frame."""
    pose = rec.cameras[0].world_from_camera
    return (points - pose[:3, 3]) @ pose[:3, :3]


def test_track_format_writes_json_beside_tracks_csv(run):
    rec_path, out = run
    rec = Recording(rec_path)
    tracks = read_tracks_csv(out / "tracks.csv", FRAMES)
    assert list(tracks) == [1]
    assert sorted(p.name for p in out.iterdir()) == [MANIFEST, "summary.json", "tracks.csv", "tracks.json"]
    assert json.loads((out / MANIFEST).read_text())["files"] == ["summary.json", "tracks.csv", "tracks.json"]
    data = json.loads((out / "tracks.json").read_text())
    assert data["coordinate_frame"] == f"camera:{rec.cameras[0].name}" and data["source_file"] == str(rec_path)
    joints, visible = tracks[1]
    head = JOINT_INDEX["head"]
    compared = 0
    for frame in data["frames"]:
        t = frame["frame_id"]
        assert frame["timestamp_usec"] == round(t * 1e6 / rec.fps)
        if not np.isfinite(joints[t, head]).all():
            continue
        body = frame["bodies"][0]
        expected = _camera_points(rec, joints[t, head]) * 1000.0
        np.testing.assert_allclose(body["joint_positions"][K4ABT_JOINTS.index("HEAD")], expected, atol=0.1)
        assert body["joint_visible"][K4ABT_JOINTS.index(K4ABT_FROM_OURS["head"])] == int(visible[t, head])
        compared += 1
    assert compared >= FRAMES // 2


def test_export_writes_c3d_and_bvh_from_tracks_csv(run, tmp_path):
    ezc3d = pytest.importorskip("ezc3d")
    rec_path, out = run
    tracks = read_tracks_csv(out / "tracks.csv", FRAMES)
    joints, visible = tracks[1]
    runner = CliRunner()
    c3d_path = tmp_path / "t.c3d"
    result = runner.invoke(main, ["export", str(out / "tracks.csv"), "--to", "c3d", "--out", str(c3d_path)])
    assert result.exit_code == 0, result.output
    assert f"wrote {c3d_path}" in result.output
    points = ezc3d.c3d(str(c3d_path))["data"]["points"][:3].transpose(2, 1, 0) / 1000.0
    np.testing.assert_allclose(points[visible], joints[visible], atol=1e-4)  # world metres
    result = runner.invoke(main, ["export", str(out / "tracks.csv"), "--to", "bvh", "--out", str(tmp_path / "t.bvh"),
                                  "--frame", "camera", "--recording", str(rec_path)])
    assert result.exit_code == 0, result.output
    assert (tmp_path / "t.bvh").read_text().startswith("HIERARCHY\nROOT world")


def test_export_bad_input(run, tmp_path):
    rec_path, out = run
    runner = CliRunner()
    tracks_csv = str(out / "tracks.csv")

    def fails(*args):
        result = runner.invoke(main, ["export", *args])
        assert result.exit_code != 0
        return result.output

    assert "'fbx' is not one of 'json', 'bvh', 'c3d'" in fails(tracks_csv, "--to", "fbx", "--out", "x.fbx")
    assert "no such tracks file" in fails(str(tmp_path / "none.csv"), "--to", "json", "--out", str(tmp_path / "a"))
    taken = tmp_path / "taken.json"
    taken.write_text("mine\n")
    assert "exists (use --force" in fails(tracks_csv, "--to", "json", "--out", str(taken))
    assert "was not written by occupose" in fails(tracks_csv, "--to", "json", "--out", str(taken), "--force")
    assert taken.read_text() == "mine\n"
    assert "no camera 'top'" in fails(tracks_csv, "--to", "json", "--out", str(tmp_path / "b.json"),
                                      "--frame", "camera", "--camera", "top")
    assert "only for the camera frame" in fails(tracks_csv, "--to", "json", "--out", str(tmp_path / "b.json"),
                                                "--camera", "cam0")
    lone = tmp_path / "lone"
    lone.mkdir()
    (lone / "tracks.csv").write_bytes((out / "tracks.csv").read_bytes())
    assert "no summary.json beside tracks.csv" in fails(str(lone / "tracks.csv"), "--to", "json", "--out",
                                                         str(tmp_path / "c.json"))
    cut = (out / "tracks.csv").read_text().splitlines(keepends=True)[:-3]  # cut short: no end line
    (lone / "tracks.csv").write_text("".join(cut))
    output = fails(str(lone / "tracks.csv"), "--to", "json", "--out", str(tmp_path / "c.json"),
                   "--recording", str(rec_path))
    assert "no end line" in output
    assert not (tmp_path / "c.json").exists()


def test_track_format_refuses_an_unknown_camera_before_tracking(run, tmp_path):
    rec_path, _ = run
    result = CliRunner().invoke(main, ["track", str(rec_path), "--out", str(tmp_path / "o"), "--format", "c3d",
                                       "--frame", "camera", "--camera", "top"])
    assert result.exit_code != 0 and "no camera 'top' in the recording" in result.output
    assert not (tmp_path / "o").exists()


def test_track_format_with_nobody_tracked_says_no_file_was_written(tmp_path, small_camera):
    rec = tmp_path / "rec"
    with RecordingWriter(rec, [small_camera], 30.0) as writer:
        writer.write_frame({"cam": np.zeros((120, 160), np.uint16)})
    result = CliRunner().invoke(main, ["track", str(rec), "--out", str(tmp_path / "o"), "--format", "c3d"])
    assert result.exit_code == 0, result.output
    assert "nobody was tracked" in result.output and "no tracks.c3d written" in result.output
    assert sorted(p.name for p in (tmp_path / "o").iterdir()) == [MANIFEST, "summary.json", "tracks.csv"]


def test_track_format_c3d_without_its_package_names_the_extra_and_leaves_no_output(run, tmp_path, monkeypatch):
    rec_path, _ = run
    monkeypatch.setitem(sys.modules, "c3d", None)  # as if not installed
    result = CliRunner().invoke(main, ["track", str(rec_path), "--out", str(tmp_path / "o"), "--format", "c3d"])
    assert result.exit_code != 0 and "pip install 'occupose[c3d]'" in result.output
    assert not (tmp_path / "o").exists()
