"""occupose video (MP4) and occupose view (rerun .rrd) end to end on a tiny synthetic
recording, each output read back with an independent reader (PyAV; rerun's own reader
and its `rerun rrd verify`)."""

from __future__ import annotations

import subprocess
import sys
from fractions import Fraction
from pathlib import Path

import av
import matplotlib
import numpy as np
import pytest
import rerun as rr
from click.testing import CliRunner

from occupose.camera import pixels_from_points, raw_depth_from_metres
from occupose.cli import main
from occupose.io.joint_table import write_tracks_csv
from occupose.io.recording import Recording, RecordingWriter
from occupose.joints import BONES, JOINT_INDEX
from occupose.viz import track_color
from occupose.viz_rerun import HIDDEN_SHADE

FRAMES = 8
SHIFT_M = (-1.2, 0.0, 0.0)  # track 2: the person moved 1.2 m to the camera's left
ABSENT = range(5, FRAMES)  # frames without track 2
#: A decoded pixel of a skeleton is within this of the track's colour (8-bit, any channel):
#: H.264 at CRF 18 and 4:2:0 chroma keep a dot's colour to about 30.
SKELETON_TOLERANCE = 60
#: ... and the colour-mapped depth away from the drawing within this on average.
DEPTH_TOLERANCE = 6.0
#: Pixels this close to a drawn joint or bone, or in the text box at the top left, are
#: not compared with the depth colours.
DRAWING_MARGIN_PX = 14
TEXT_BOX_PX = (24, 160)  # rows, columns
LABEL_BOX_PX = (30, 40)  # the track's label: rows above the head, columns right of it


@pytest.fixture(scope="module")
def recording(tmp_path_factory, walk):
    """(the recording folder, its tracks.csv, the tracks {id: (joints (T, 15, 3), visible (T, 15))})."""
    scenario, rendered = walk
    base = tmp_path_factory.mktemp("video")
    rec = base / "rec"
    with RecordingWriter(rec, list(scenario.cameras), scenario.fps) as writer:
        for f in rendered[:FRAMES]:
            writer.write_frame({c.name: raw_depth_from_metres(f.depth[c.name], c) for c in scenario.cameras})
    joints = np.stack([f.joints[0] for f in rendered[:FRAMES]])
    visible = np.stack([f.visible[0] for f in rendered[:FRAMES]])
    assert 0 < visible.sum() < visible.size  # some joints hidden: crosses and dashed bones
    moved = joints + SHIFT_M
    moved[list(ABSENT)] = np.nan
    tracks = {1: (joints, visible), 2: (moved, visible & np.isfinite(moved[..., 0]))}
    write_tracks_csv(base / "tracks.csv", tracks)
    return rec, base / "tracks.csv", tracks


def _decode(path: Path) -> tuple[list[np.ndarray], list[float], object]:
    """(the frames as (H, W, 3) uint8 RGB, their times in seconds, the stream's average rate)."""
    with av.open(str(path)) as container:
        stream = container.streams.video[0]
        decoded = list(container.decode(stream))
        return [f.to_ndarray(format="rgb24") for f in decoded], [float(f.time) for f in decoded], stream.average_rate


def _expected_depth_colors(depth: np.ndarray, high: float) -> np.ndarray:
    """(H, W, 3) float: turbo over 0.5..high metres, black where there is no depth."""
    rgb = matplotlib.colormaps["turbo"](np.clip((depth - 0.5) / (high - 0.5), 0, 1))[..., :3] * 255
    rgb[depth <= 0] = 0
    return rgb


def test_video_draws_every_frame_and_the_skeletons_where_the_joints_project(recording, tmp_path):
    rec_path, tracks_path, tracks = recording
    out = tmp_path / "walk.mp4"
    result = CliRunner().invoke(main, ["video", str(rec_path), "--tracks", str(tracks_path), "--out", str(out)])
    assert result.exit_code == 0, result.output
    rec = Recording(rec_path)
    camera = rec.cameras[0]
    images, times, rate = _decode(out)
    assert len(images) == FRAMES and rate == rec.fps
    assert np.allclose(times, np.arange(FRAMES) / rec.fps)
    assert all(image.shape == (camera.height, camera.width, 3) for image in images)
    high = max(4.5, float(rec.frame(0).depth[camera.name].max()))
    checked = {1: 0, 2: 0}
    for t, image in enumerate(images):
        far = np.ones(image.shape[:2], bool)
        far[:TEXT_BOX_PX[0], :TEXT_BOX_PX[1]] = False
        rows, cols = np.mgrid[:camera.height, :camera.width]
        for track, (joints, visible) in tracks.items():
            if not np.isfinite(joints[t]).all():
                continue
            uv, z = pixels_from_points(joints[t], camera)
            color = np.array(track_color(track))
            for (u, v), front in zip(np.rint(uv).astype(int), z > 0):
                if front and 0 <= u < camera.width and 0 <= v < camera.height:
                    near = image[max(v - 1, 0):v + 2, max(u - 1, 0):u + 2].reshape(-1, 3).astype(int)
                    assert np.abs(near - color).max(axis=1).min() <= SKELETON_TOLERANCE, (t, track, u, v)
                    checked[track] += 1
            u, v = np.rint(uv[JOINT_INDEX["head"]]).astype(int)
            far[max(v - LABEL_BOX_PX[0], 0):v + 1, max(u, 0):u + LABEL_BOX_PX[1]] = False
            for a, b in BONES:  # every pixel near a bone is left out of the depth comparison
                for s in np.linspace(0, 1, 20):
                    u, v = uv[a] + s * (uv[b] - uv[a])
                    far &= (cols - u) ** 2 + (rows - v) ** 2 > DRAWING_MARGIN_PX**2
        expected = _expected_depth_colors(rec.frame(t).depth[camera.name], high)
        assert np.abs(image[far] - expected[far]).mean() <= DEPTH_TOLERANCE
        assert far.mean() > 0.8
        # the skeleton colours do not occur in the depth colours: none of track 1's white away from it
        assert not np.any(image[far].min(axis=1) > 255 - SKELETON_TOLERANCE)
    assert checked[1] >= FRAMES * 12 and checked[2] >= len(range(ABSENT.start)) * 12


def test_video_fps_camera_and_the_overwrite_rule(recording, tmp_path):
    rec_path, tracks_path, _ = recording
    runner = CliRunner()
    out = tmp_path / "walk"
    args = ["video", str(rec_path), "--tracks", str(tracks_path), "--out", str(out), "--fps", "12.5",
            "--camera", "front"]
    result = runner.invoke(main, args)
    assert result.exit_code == 0, result.output
    written = tmp_path / "walk.mp4"
    assert f"wrote {written}" in result.output
    images, times, rate = _decode(written)
    assert rate == Fraction(25, 2) and len(images) == FRAMES and np.allclose(times, np.arange(FRAMES) / 12.5)
    before = written.read_bytes()
    result = runner.invoke(main, args)
    assert result.exit_code != 0 and "exists (use --force" in result.output
    assert written.read_bytes() == before
    assert runner.invoke(main, [*args, "--force"]).exit_code == 0
    theirs = tmp_path / "theirs.mp4"
    theirs.write_bytes(before[: len(before) // 2])
    result = runner.invoke(main, [*args[:4], "--out", str(theirs), "--force"])
    assert result.exit_code != 0 and "not written by occupose" in result.output
    result = runner.invoke(main, [*args[:4], "--out", str(tmp_path / "x.mp4"), "--camera", "top"])
    assert result.exit_code != 0 and "no camera 'top'" in result.output and not (tmp_path / "x.mp4").exists()
    result = runner.invoke(main, [*args[:4], "--out", str(tmp_path / "x.avi")])
    assert result.exit_code != 0 and "ending in .mp4" in result.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["theirs.mp4", "walk.mp4"]  # no temporary left


def _chunks(path: Path) -> dict[str, list]:
    """{entity path: [record batches of its chunks]} of the rrd file's recording."""
    found: dict[str, list] = {}
    for chunk in rr.chunk.RrdReader(path).stream():
        found.setdefault(chunk.entity_path, []).append(chunk.to_record_batch())
    return found


def _column(batches: list, name: str) -> list:
    return [value for batch in batches for value in batch.column(name).to_pylist()]


def _packed(color) -> int:
    """An 8-bit RGB colour as rerun stores it: 0xRRGGBBAA, opaque."""
    r, g, b = (int(c) for c in color)
    return (r << 24) | (g << 16) | (b << 8) | 0xFF


def test_view_writes_a_rerun_recording_of_the_cameras_depth_and_skeletons(recording, tmp_path):
    rec_path, tracks_path, tracks = recording
    out = tmp_path / "walk.rrd"
    result = CliRunner().invoke(main, ["view", str(rec_path), "--tracks", str(tracks_path), "--out", str(out)])
    assert result.exit_code == 0, result.output
    verify = subprocess.run([str(Path(sys.executable).parent / "rerun"), "rrd", "verify", str(out)],
                            capture_output=True, text=True, timeout=60)
    assert verify.returncode == 0, verify.stderr
    assert "verified without error" in verify.stdout + verify.stderr
    [store] = rr.chunk.RrdReader(out).recordings()
    assert store.application_id == "occupose"

    rec = Recording(rec_path)
    camera = rec.cameras[0]
    chunks = _chunks(out)
    base = f"/world/cameras/{camera.name}"
    [[translation]] = _column(chunks[base], "Transform3D:translation")
    assert np.allclose(translation, camera.world_from_camera[:3, 3])
    assert _column(chunks[f"{base}/image"], "Pinhole:resolution") == [[[camera.width, camera.height]]]
    depth = chunks[f"{base}/image/depth"]
    assert _column(depth, "frame") == list(range(FRAMES))
    nanoseconds = [value for batch in depth for value in batch.column("time").cast("int64").to_pylist()]
    assert np.allclose(nanoseconds, np.arange(FRAMES) / rec.fps * 1e9, atol=1)
    assert _column(depth, "DepthImage:meter") == [[1000.0]] * FRAMES
    assert "log_time" not in depth[0].schema.names

    for track, (joints, visible) in tracks.items():
        present = [t for t in range(FRAMES) if np.isfinite(joints[t]).all()]
        points = chunks[f"/world/tracks/{track}/joints"]
        assert _column(points, "frame") == present
        color = np.array(track_color(track))
        for t, positions, colors in zip(present, _column(points, "Points3D:positions"),
                                        _column(points, "Points3D:colors")):
            assert np.allclose(positions, joints[t], atol=1e-6)
            shades = np.where(visible[t][:, None], color, np.rint(color * HIDDEN_SHADE))
            assert colors == [_packed(c) for c in shades]
        bones = chunks[f"/world/tracks/{track}/bones"]
        assert all(len(strips) == len(BONES) for strips in _column(bones, "LineStrips3D:strips"))
    assert _column(chunks["/world/tracks/2"], "frame") == [ABSENT.start]  # cleared once, when it goes


def test_view_refuses_to_overwrite_and_names_its_extra_when_missing(recording, tmp_path, monkeypatch):
    rec_path, tracks_path, _ = recording
    runner = CliRunner()
    out = tmp_path / "walk.rrd"
    args = ["view", str(rec_path), "--tracks", str(tracks_path), "--out", str(out)]
    assert runner.invoke(main, args).exit_code == 0
    result = runner.invoke(main, args)
    assert result.exit_code != 0 and "exists (use --force" in result.output
    assert runner.invoke(main, [*args, "--force"]).exit_code == 0
    theirs = tmp_path / "theirs.rrd"
    theirs.write_text("not a recording")
    result = runner.invoke(main, [*args[:4], "--out", str(theirs), "--force"])
    assert result.exit_code != 0 and "not written by occupose" in result.output
    monkeypatch.setitem(sys.modules, "rerun", None)  # as if not installed
    result = runner.invoke(main, [*args[:4], "--out", str(tmp_path / "other.rrd")])
    assert result.exit_code != 0 and "pip install 'occupose[rerun]'" in result.output
    assert sorted(p.name for p in tmp_path.iterdir()) == ["theirs.rrd", "walk.rrd"]
