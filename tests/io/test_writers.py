"""The JSON, BVH and C3D writers, each file read back by an independent reader."""

from __future__ import annotations

import json
import sys

import numpy as np
import pytest

from occupose.io.output import OutputError
from occupose.io.writers import WRITERS, tracks_from_table, tracks_in_camera, write_tracks, writer_for
from occupose.io.writers.k4abt_json import K4ABT_FROM_OURS, K4ABT_JOINTS
from occupose.joints import JOINT_INDEX, JOINTS

FPS = 25.0


@pytest.fixture
def tracks(standing_skeleton):
    """Two tracks (ids 3 and 11) over 6 frames, seed 0: track 11 absent in frames 0-1, its
    left wrist unknown in frame 4; about a third of the known joints hidden."""
    rng = np.random.default_rng(0)
    num_frames = 6
    table = {}
    for ident, shift in ((3, (0.0, 0.0)), (11, (1.5, 0.5))):
        joints = standing_skeleton + np.array([*shift, 0.0]) + rng.normal(0.0, 0.02, (num_frames, 15, 3))
        joints[:, :, 0] += np.linspace(0.0, 0.3, num_frames)[:, None]  # walking along x
        visible = rng.random((num_frames, 15)) > 0.33
        table[ident] = (joints, visible)
    joints, visible = table[11]
    joints[:2], visible[:2] = np.nan, False
    joints[4, JOINT_INDEX["left_wrist"]], visible[4, JOINT_INDEX["left_wrist"]] = np.nan, False
    return tracks_from_table(table, num_frames, FPS, "rec")


def test_the_registry_names_every_format_and_refuses_others():
    assert list(WRITERS) == ["json", "bvh", "c3d"]
    with pytest.raises(ValueError, match="unknown output format 'fbx'; valid: json, bvh, c3d"):
        writer_for("fbx")


def test_json_has_the_offline_processors_layout_and_our_positions(tmp_path, tracks):
    data = json.loads(write_tracks(tmp_path / "t.json", tracks, "json").read_text())
    assert data["k4abt_sdk_version"] is None and data["source_file"] == "rec" and data["units"] == "mm"
    assert data["coordinate_frame"] == "world"
    assert len(data["joint_names"]) == 32 and len(data["bone_list"]) == 31
    assert all(a in data["joint_names"] and b in data["joint_names"] for a, b in data["bone_list"])
    assert len(data["frames"]) == 6
    for t, frame in enumerate(data["frames"]):
        assert frame["frame_id"] == t and frame["timestamp_usec"] == t * 40_000  # 25 fps
        ids = [body["body_id"] for body in frame["bodies"]]
        assert ids == ([3] if t < 2 else [3, 11]) and frame["num_bodies"] == len(ids)
        for body in frame["bodies"]:
            p = list(tracks.ids).index(body["body_id"])
            assert len(body["joint_positions"]) == len(body["joint_visible"]) == 32
            assert body["joint_orientations"] == [None] * 32
            for index, name in enumerate(K4ABT_JOINTS):
                ours = [j for j, theirs in K4ABT_FROM_OURS.items() if theirs == name]
                position, flag = body["joint_positions"][index], body["joint_visible"][index]
                if not ours or not tracks.known[t, p, JOINT_INDEX[ours[0]]]:
                    assert position is None and flag is None
                    continue
                j = JOINT_INDEX[ours[0]]
                np.testing.assert_allclose(np.array(position) / 1000.0, tracks.joints[t, p, j], atol=1e-6)
                assert flag == int(tracks.visible[t, p, j])
    body = data["frames"][4]["bodies"][1]
    assert body["joint_positions"][K4ABT_JOINTS.index("WRIST_LEFT")] is None
    assert sum(v is not None for v in body["joint_positions"]) == 14


def test_c3d_reads_back_in_ezc3d_with_residual_minus_one_where_hidden(tmp_path, tracks):
    ezc3d = pytest.importorskip("ezc3d")
    c3d = ezc3d.c3d(str(write_tracks(tmp_path / "t.c3d", tracks, "c3d")))
    point = c3d["parameters"]["POINT"]
    assert point["LABELS"]["value"] == [f"t{i}_{j}" for i in (3, 11) for j in JOINTS]
    assert point["RATE"]["value"][0] == FPS and point["UNITS"]["value"] == ["mm"]
    points = c3d["data"]["points"]  # (4, markers, frames), mm
    residuals = c3d["data"]["meta_points"]["residuals"][0]  # (markers, frames)
    assert points.shape == (4, 30, 6)
    written = tracks.joints.reshape(6, 30, 3)
    valid = tracks.visible.reshape(6, 30)
    read = points[:3].transpose(2, 1, 0) / 1000.0
    np.testing.assert_allclose(read[valid], written[valid], atol=1e-4)
    assert np.array_equal(residuals.T < 0, ~valid) and np.all(residuals.T[~valid] == -1)
    assert np.isnan(read[~valid]).all()


def _bvh_positions(path, num_frames):
    """{joint name: (T, 3) world metres} from bvhio's forward kinematics."""
    bvhio = pytest.importorskip("bvhio")
    root = bvhio.readAsHierarchy(str(path))
    joints = root.filter("")
    positions = {j.Name: np.empty((num_frames, 3)) for j in joints}
    for t in range(num_frames):
        root.loadPose(t)
        for j in joints:
            x, y, z = j.PositionWorld
            positions[j.Name][t] = (x / 100.0, -z / 100.0, y / 100.0)  # cm, y up -> metres, z up
    return positions


def test_bvh_reads_back_in_bvhio(tmp_path, tracks):
    path = write_tracks(tmp_path / "t.bvh", tracks, "bvh")
    assert "Frame Time: 0.040000000" in path.read_text()
    positions = _bvh_positions(path, 6)
    assert len(positions) == 1 + 2 * 15 and "t11_left_knee" in positions
    for p, ident in enumerate(tracks.ids):
        for j, name in enumerate(JOINTS):
            known = tracks.known[:, p, j]
            np.testing.assert_allclose(positions[f"t{ident}_{name}"][known], tracks.joints[known, p, j], atol=1e-4)
    # track 11's unknown left wrist in frame 4: its elbow plus the mean bone vector
    wrist, elbow = JOINT_INDEX["left_wrist"], JOINT_INDEX["left_elbow"]
    both = tracks.known[:, 1, wrist] & tracks.known[:, 1, elbow]
    mean_bone = (tracks.joints[both, 1, wrist] - tracks.joints[both, 1, elbow]).mean(axis=0)
    np.testing.assert_allclose(positions["t11_left_wrist"][4], tracks.joints[4, 1, elbow] + mean_bone, atol=1e-4)
    # track 11's frames before it was tracked: its first pelvis
    np.testing.assert_allclose(positions["t11_pelvis"][:2], tracks.joints[[2, 2], 1, JOINT_INDEX["pelvis"]],
                               atol=1e-4)


def test_camera_frame_is_the_hand_computed_transform(tmp_path, tracks):
    # a camera at (0, -3, 1.5) looking along world +y: its x is world x, its y (down) world -z
    world_from_camera = np.array([[1.0, 0, 0, 0], [0, 0, 1, -3.0], [0, -1, 0, 1.5], [0, 0, 0, 1]])
    joints = np.full((1, 15, 3), np.nan)
    joints[0, 0] = (0.5, 1.0, 1.0)
    one = tracks_from_table({1: (joints, np.isfinite(joints[..., 0]))}, 1, FPS)
    camera = tracks_in_camera(one, world_from_camera, "cam")
    np.testing.assert_allclose(camera.joints[0, 0, 0], (0.5, 0.5, 4.0), atol=1e-12)
    assert camera.frame == "camera:cam" and np.isnan(camera.joints[0, 0, 1:]).all()
    data = json.loads(write_tracks(tmp_path / "c.json", camera, "json").read_text())
    assert data["coordinate_frame"] == "camera:cam"
    assert data["frames"][0]["bodies"][0]["joint_positions"][K4ABT_JOINTS.index("HEAD")] == [500.0, 500.0, 4000.0]
    with pytest.raises(ValueError, match="already in the camera:cam frame"):
        tracks_in_camera(camera, world_from_camera, "cam")
    # BVH of the camera frame: y up is the camera's -y, the camera looks along BVH's -z
    bvh = _bvh_positions(write_tracks(tmp_path / "c.bvh", camera, "bvh"), 1)
    # (as a world point read from BVH: (X, -Z, Y) / 100 of the BVH's (50, -50, -400) cm)
    np.testing.assert_allclose(bvh["t1_head"][0], (0.5, 4.0, -0.5), atol=1e-4)


@pytest.mark.parametrize("format", ["json", "bvh", "c3d"])
def test_outputs_follow_the_overwrite_rule(tmp_path, tracks, format):
    path = tmp_path / f"t.{format}"
    write_tracks(path, tracks, format)
    with pytest.raises(OutputError, match="exists \\(use --force"):
        write_tracks(path, tracks, format)
    before = path.read_bytes()
    write_tracks(path, tracks, format, force=True)
    assert path.read_bytes() == before  # the same file again: the writers are deterministic
    theirs = tmp_path / f"theirs.{format}"
    theirs.write_text("a file of someone else\n")
    with pytest.raises(OutputError, match="was not written by occupose"):
        write_tracks(theirs, tracks, format, force=True)
    assert theirs.read_text() == "a file of someone else\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted([path.name, theirs.name])  # no temporary left


def test_tracks_from_table_checks_its_input(standing_skeleton):
    joints = np.broadcast_to(standing_skeleton, (2, 15, 3))
    with pytest.raises(ValueError, match="fps must be a positive finite number"):
        tracks_from_table({1: (joints, np.ones((2, 15), bool))}, 2, 0.0)
    with pytest.raises(ValueError, match="track 1 joints must have shape \\(3, 15, 3\\)"):
        tracks_from_table({1: (joints, np.ones((2, 15), bool))}, 3, FPS)


def test_c3d_without_its_package_names_the_extra(tmp_path, tracks, monkeypatch):
    monkeypatch.setitem(sys.modules, "c3d", None)  # as if not installed
    with pytest.raises(ImportError, match=r"writing C3D files needs the 'c3d' package .*pip install 'occupose\[c3d\]'"):
        write_tracks(tmp_path / "t.c3d", tracks, "c3d")
    assert not any(tmp_path.iterdir())


def test_no_tracks_give_json_and_bvh_without_bodies_and_no_c3d(tmp_path):
    empty = tracks_from_table({}, 3, FPS)
    data = json.loads(write_tracks(tmp_path / "e.json", empty, "json").read_text())
    assert [f["num_bodies"] for f in data["frames"]] == [0, 0, 0]
    assert _bvh_positions(write_tracks(tmp_path / "e.bvh", empty, "bvh"), 3).keys() == {"world"}
    with pytest.raises(ValueError, match="no track to write: a C3D file needs at least one marker"):
        write_tracks(tmp_path / "e.c3d", empty, "c3d")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["e.bvh", "e.json"]
