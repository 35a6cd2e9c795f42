"""``occupose fit``: single depth images (PNG, .npy, raw uint16) in, tracks.csv, a picture per
image and summary.json out; the camera by preset or JSON file; the shared real Kinect v1 frames."""

import json

import numpy as np
import pytest
from click.testing import CliRunner
from PIL import Image

from occupose.camera import raw_depth_from_metres
from occupose.cli import main
from occupose.io.depth_image import DepthImageError, camera_from_option, read_depth_image
from occupose.io.joint_table import read_joint_table
from occupose.paths import shared_data_dir
from occupose.synth.generate import frames
from occupose.synth.render import render_camera
from occupose.synth.scenarios import build_scenario


@pytest.fixture(scope="module")
def images(tmp_path_factory):
    """Frame 100 of no_occlusion (one person) as a 16-bit PNG, as raw uint16 (no suffix) and as a float
    .npy of a background-removed frame; the empty scene as a PNG; the camera as JSON."""
    folder = tmp_path_factory.mktemp("images")
    scenario = build_scenario("no_occlusion", use_mocap=False)
    camera = scenario.cameras[0]
    frame = next(frames(scenario, 0, indices=[100]))
    depth = frame.depth[camera.name]
    Image.fromarray(raw_depth_from_metres(depth, camera)).save(folder / "person.png")
    raw_depth_from_metres(depth, camera).astype("<u2").tofile(folder / "person_raw")
    np.save(folder / "removed.npy", np.where(frame.rendered[camera.name].person > 0, depth, 0).astype(np.float32))
    Image.fromarray(raw_depth_from_metres(render_camera(scenario.static, camera).depth, camera)).save(
        folder / "empty.png")
    entry = {k: getattr(camera, k) for k in ("width", "height", "fx", "fy", "cx", "cy")}
    (folder / "camera.json").write_text(json.dumps(entry))
    (folder / "placed.json").write_text(json.dumps({**entry, "world_from_camera": camera.world_from_camera.tolist()}))
    return folder, camera, frame


def _fit_args(folder, second: str, camera_file: str, out) -> list[str]:
    """``occupose fit`` of person.png and ``second`` with the empty scene as the background."""
    return ["fit", str(folder / "person.png"), str(folder / second), "--camera", str(folder / camera_file),
            "--background", str(folder / "empty.png"), "--out", str(out)]


def test_fit_writes_tracks_pictures_and_summary_in_the_world_given(images, tmp_path):
    folder, camera, frame = images
    out = tmp_path / "out"
    result = CliRunner().invoke(main, _fit_args(folder, "person_raw", "placed.json", out))
    assert result.exit_code == 0, result.output
    assert "2 person(s) in 2 image(s)" in result.output and "world frame" in result.output
    tracks = read_joint_table(out / "tracks.csv", 2, "tracks")
    assert sorted(tracks) == [1, 2]
    for frame_index, track in ((0, 1), (1, 2)):  # one track per image and person, known in its image only
        joints, visible = tracks[track]
        assert np.isnan(joints[1 - frame_index]).all() and not visible[1 - frame_index].any()
        error = np.linalg.norm(joints[frame_index] - frame.joints[0], axis=1)[frame.visible[0]].mean()
        assert error < 0.05
    np.testing.assert_allclose(tracks[1][0][0], tracks[2][0][1], atol=2e-6)  # PNG and raw: the same image
    summary = json.loads((out / "summary.json").read_text())
    assert summary["frame"] == "world" and summary["images"] == 2 and summary["people"] == 2
    assert summary["config"]["fit"]["steps"] == 15 and summary["config"]["pose"]["particles"] > 0
    assert [f["picture"] for f in summary["frames"]] == ["person.png", "person_raw.png"]
    assert summary["frames"][0]["people"][0]["model"] == "full" and summary["frames"][0]["floor"] is None


def test_two_images_of_one_name_are_refused_before_anything_is_written(images, tmp_path):
    folder, _, _ = images
    (tmp_path / "person.raw").write_bytes((folder / "person_raw").read_bytes())
    result = CliRunner().invoke(main, ["fit", str(folder / "person.png"), str(tmp_path / "person.raw"), "--camera",
                                       str(folder / "camera.json"), "--out", str(tmp_path / "out")])
    assert result.exit_code != 0 and "would both be pictured as person.png" in result.output
    assert not (tmp_path / "out").exists()


def test_fit_in_the_camera_frame_pictures_each_image_and_refuses_to_overwrite(images, tmp_path):
    folder, camera, frame = images
    out = tmp_path / "out"
    args = _fit_args(folder, "removed.npy", "camera.json", out)
    result = CliRunner().invoke(main, args)
    assert result.exit_code == 0, result.output
    summary = json.loads((out / "summary.json").read_text())
    assert summary["frame"] == "camera"
    first = summary["frames"][0]
    assert first["floor"]["camera_height_m"] == pytest.approx(camera.world_from_camera[2, 3], abs=0.03)
    assert [f["picture"] for f in summary["frames"]] == ["person.png", "removed.png"]
    truth = frame.joints[0] @ camera.camera_from_world[:3, :3].T + camera.camera_from_world[:3, 3]
    joints, _ = read_joint_table(out / "tracks.csv", 2, "tracks")[1]
    assert np.linalg.norm(joints[0] - truth, axis=1)[frame.visible[0]].mean() < 0.05
    with Image.open(out / "person.png") as picture:
        assert picture.size == (camera.width, camera.height) and picture.info["Software"] == "occupose"
        pixels = np.asarray(picture.convert("RGB"))
    assert pixels.std() > 10  # a depth image with a skeleton drawn, not a blank
    again = CliRunner().invoke(main, args)
    assert again.exit_code != 0 and "--force" in again.output
    assert CliRunner().invoke(main, [*args, "--force"]).exit_code == 0


def test_an_image_of_the_empty_scene_has_nobody_and_says_so(images, tmp_path):
    folder, _, _ = images
    out = tmp_path / "out"
    result = CliRunner().invoke(main, ["fit", str(folder / "empty.png"), "--camera", str(folder / "camera.json"),
                                       "--background", str(folder / "empty.png"), "--out", str(out)])
    assert result.exit_code == 0, result.output
    assert "0 person(s) in 1 image(s)" in result.output and "nobody was found" in result.output
    assert read_joint_table(out / "tracks.csv", 1, "tracks") == {}
    assert json.loads((out / "summary.json").read_text())["frames"][0]["people"] == []


def test_reading_depth_images_and_cameras(images, tmp_path):
    folder, camera, _ = images
    png = read_depth_image(folder / "person.png", camera)
    np.testing.assert_array_equal(png, read_depth_image(folder / "person_raw", camera))
    assert png.dtype == np.float32 and 0.5 < np.median(png[png > 0]) < 6.0
    np.testing.assert_allclose(read_depth_image(folder / "person.png", camera, depth_scale=0.002), 2 * png, rtol=1e-6)
    preset, world = camera_from_option("kinect_v1")
    assert (preset.width, preset.fx, world) == (640, 594.21, False)
    placed, world = camera_from_option(folder / "placed.json")
    assert world and np.allclose(placed.world_from_camera, camera.world_from_camera)
    assert camera_from_option(folder / "camera.json")[1] is False
    (tmp_path / "short.raw").write_bytes(b"\0" * 100)
    with pytest.raises(DepthImageError, match="has 614400 bytes, this file has 100"):
        read_depth_image(tmp_path / "short.raw", camera)
    Image.fromarray(np.zeros((10, 10, 3), np.uint8)).save(tmp_path / "colour.png")
    with pytest.raises(DepthImageError, match="expected a 16-bit greyscale PNG"):
        read_depth_image(tmp_path / "colour.png", camera)
    np.save(tmp_path / "small.npy", np.zeros((4, 4)))
    with pytest.raises(DepthImageError, match=r"the image is \(4, 4\), camera 'front' is \(480, 640\)"):
        read_depth_image(tmp_path / "small.npy", camera)
    np.save(tmp_path / "negative.npy", -np.ones((480, 640)))
    with pytest.raises(DepthImageError, match="finite and >= 0"):
        read_depth_image(tmp_path / "negative.npy", camera)
    with pytest.raises(DepthImageError, match="neither a camera preset"):
        camera_from_option("kinect_v9")
    (tmp_path / "bad.json").write_text(json.dumps({"width": 640, "fx": 1.0, "lens": "wide"}))
    with pytest.raises(DepthImageError, match=r"missing key\(s\) \['height', 'fy', 'cx', 'cy'\]; unknown key\(s\) "
                                              r"\['lens'\]"):
        camera_from_option(tmp_path / "bad.json")


KINECT_V1 = shared_data_dir() / "sensors" / "kinect_v1_person" if shared_data_dir() else None


@pytest.mark.shared
@pytest.mark.skipif(KINECT_V1 is None or not KINECT_V1.is_dir(), reason="needs ../shared/data/sensors/kinect_v1_person")
def test_the_real_kinect_v1_frames_show_one_person_each_and_two_in_the_last_two(tmp_path):
    files = sorted(KINECT_V1.glob("depth-data-*"))
    result = CliRunner().invoke(main, ["fit", *map(str, files), "--camera", "kinect_v1", "--out", str(tmp_path / "o")])
    assert result.exit_code == 0, result.output
    summary = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert [len(f["people"]) for f in summary["frames"]] == [1] * 10 + [2, 2]
    people = [p for f in summary["frames"] for p in f["people"]]
    assert {p["model"] for p in people} == {"upper"} and summary["frame"] == "camera"
    assert min(p["visible_joints"] for p in people) >= 7  # of the upper model's 9
    tracks = read_joint_table(tmp_path / "o" / "tracks.csv", 12, "tracks")
    heads = np.array([joints[np.isfinite(joints[:, 0, 0])][0, 0] for joints, _ in tracks.values()])
    assert (heads[:, 2] > 0.7).all() and (heads[:, 2] < 2.6).all()  # 0.7-2 m from the camera
    necks = np.array([joints[np.isfinite(joints[:, 1, 0])][0, 1] for joints, _ in tracks.values()])
    assert (heads[:, 1] < necks[:, 1]).all()  # every head above its neck (y down)
