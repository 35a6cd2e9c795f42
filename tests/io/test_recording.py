import json
import re

import numpy as np
import pytest
from PIL import Image

from occupose.camera import Camera, look_at
from occupose.joints import JOINTS
from occupose.io.recording import (
    Frame,
    GroundTruth,
    Recording,
    RecordingError,
    RecordingWriter,
    open_recording,
)

NUM_FRAMES = 3


def make_cameras() -> list[Camera]:
    return [
        Camera("cam0", 8, 6, 5.0, 5.0, 3.5, 2.5, world_from_camera=look_at((0, -3, 2), (0, 0, 1))),
        Camera("top", 10, 4, 6.0, 6.5, 4.5, 1.5, depth_scale=0.0005,
               world_from_camera=look_at((0, 0, 3), (0, 0, 0))),
    ]


def make_data(rng):
    cameras = make_cameras()
    depths = [{c.name: rng.integers(0, 65536, size=(c.height, c.width)).astype(np.uint16) for c in cameras}
              for _ in range(NUM_FRAMES)]
    colors = [{"cam0": rng.integers(0, 256, size=(6, 8, 3)).astype(np.uint8)} for _ in range(NUM_FRAMES)]
    joints = rng.uniform(-2.0, 2.0, size=(NUM_FRAMES, 2, 15, 3))
    joints[1, 1] = np.nan  # person 7 absent in frame 1
    joints[2, 0, 5] = np.nan  # one unknown joint
    visible = rng.random((NUM_FRAMES, 2, 15)) < 0.7
    visible[np.isnan(joints[..., 0])] = False
    return cameras, depths, colors, joints, visible


def write(path, rng, *, groundtruth=True):
    cameras, depths, colors, joints, visible = make_data(rng)
    with RecordingWriter(path, cameras, fps=30.0) as writer:
        for depth, color in zip(depths, colors):
            writer.write_frame(depth, color)
        if groundtruth:
            writer.write_groundtruth(joints, visible, person_ids=[3, 7])
    return cameras, depths, colors, joints, visible


@pytest.fixture
def rec(tmp_path, rng):
    path = tmp_path / "rec"
    write(path, rng)
    return path


# ------------------------------------------------------------------ round trip


def test_round_trip_depth_colour_and_header(tmp_path, rng):
    path = tmp_path / "rec"
    cameras, depths, colors, _, _ = write(path, rng)
    recording = open_recording(path)
    assert recording.path == path and recording.fps == 30.0 and recording.num_frames == NUM_FRAMES
    assert recording.cameras == cameras
    assert recording.camera("top") == cameras[1]
    assert recording.color_cameras == ("cam0",)
    frames = list(recording.frames())
    assert [f.index for f in frames] == [0, 1, 2] and all(isinstance(f, Frame) for f in frames)
    assert [f.time for f in frames] == [0.0, 1 / 30, 2 / 30]
    for frame, depth, color in zip(frames, depths, colors):
        for camera in cameras:
            raw = recording.depth_raw(frame.index, camera.name)
            assert raw.dtype == np.uint16
            np.testing.assert_array_equal(raw, depth[camera.name])
            assert frame.depth[camera.name].dtype == np.float32
            np.testing.assert_array_equal(
                frame.depth[camera.name], (depth[camera.name] * camera.depth_scale).astype(np.float32))
        assert list(frame.color) == ["cam0"]
        np.testing.assert_array_equal(frame.color["cam0"], color["cam0"])
    assert np.array_equal(recording.frame(2).depth["top"], frames[2].depth["top"])


def test_header_is_the_documented_json(rec):
    header = json.loads((rec / "recording.json").read_text())
    assert header["format"] == "occupose-recording" and header["version"] == 1
    assert header["num_frames"] == NUM_FRAMES and header["fps"] == 30.0
    assert header["cameras"][0]["name"] == "cam0" and header["cameras"][1]["depth_scale"] == 0.0005
    assert sorted(p.name for p in (rec / "cam0" / "depth").iterdir()) == ["000000.png", "000001.png", "000002.png"]
    assert Image.open(rec / "top" / "depth" / "000000.png").mode == "I;16"
    assert not (rec / "top" / "color").exists()


def test_round_trip_groundtruth(tmp_path, rng):
    path = tmp_path / "rec"
    _, _, _, joints, visible = write(path, rng)
    recording = Recording(path)
    assert recording.has_groundtruth
    truth = recording.groundtruth()
    assert isinstance(truth, GroundTruth) and truth.person_ids == (3, 7)
    assert truth.joints.shape == (NUM_FRAMES, 2, 15, 3) and truth.joints.dtype == np.float64
    np.testing.assert_array_equal(np.isnan(truth.joints), np.isnan(joints))
    np.testing.assert_allclose(truth.joints, joints, rtol=0, atol=1e-5, equal_nan=True)
    np.testing.assert_array_equal(truth.visible, visible)
    lines = (path / "groundtruth.csv").read_text().splitlines()
    assert lines[0] == "frame,person,joint,x,y,z,visible"
    assert len(lines) - 1 == int(np.isfinite(joints[..., 0]).sum())  # rows only where known
    assert re.fullmatch(r"0,3,head,-?\d+\.\d{5},-?\d+\.\d{5},-?\d+\.\d{5},[01]", lines[1])


def test_groundtruth_without_visible_column_means_visible(rec):
    (rec / "groundtruth.csv").write_text("frame,person,joint,x,y,z\n1,4,neck,0.1,0.2,1.5\n")
    truth = Recording(rec).groundtruth()
    assert truth.person_ids == (4,) and truth.visible.sum() == 1 and truth.visible[1, 0, 1]
    assert np.isnan(truth.joints[0]).all() and np.isfinite(truth.joints).sum() == 3


def test_recording_without_colour_or_groundtruth(tmp_path, rng):
    camera = make_cameras()[0]
    depth = rng.integers(0, 5000, size=(6, 8)).astype(np.uint16)
    with RecordingWriter(tmp_path / "plain", [camera], fps=15) as writer:
        writer.write_frame({"cam0": depth})
    recording = Recording(tmp_path / "plain")
    assert recording.frame(0).color == {} and not recording.has_groundtruth
    with pytest.raises(FileNotFoundError, match="groundtruth.csv: no such file"):
        recording.groundtruth()


def test_label_images_round_trip_and_errors(tmp_path, rng):
    camera = make_cameras()[0]
    person = rng.integers(0, 3, size=(6, 8)).astype(np.uint8)
    part = rng.integers(0, 16, size=(6, 8)).astype(np.uint8)
    with RecordingWriter(tmp_path / "synth", [camera], fps=30) as writer:
        writer.write_frame({"cam0": np.zeros((6, 8), np.uint16)}, labels={"cam0": {"person": person, "part": part}})
    recording = Recording(tmp_path / "synth")
    np.testing.assert_array_equal(recording.label(0, "cam0", "person"), person)
    np.testing.assert_array_equal(recording.label(0, "cam0", "part"), part)
    assert recording.has_labels("person") and recording.has_labels("part")
    with pytest.raises(ValueError, match="unknown label kind 'skin'; valid: person, part"):
        recording.label(0, "cam0", "skin")
    with pytest.raises(ValueError, match="unknown label kind 'skin'"):
        recording.has_labels("skin")
    with RecordingWriter(tmp_path / "plain", [camera], fps=30) as writer:
        writer.write_frame({"cam0": np.zeros((6, 8), np.uint16)})
        with pytest.raises(ValueError, match="label image 'part' for camera 'cam0' must be .* uint8"):
            writer.write_frame({"cam0": np.zeros((6, 8), np.uint16)}, labels={"cam0": {"part": part.astype(np.int32)}})
    with pytest.raises(RecordingError, match="has no 'person' label images"):
        Recording(tmp_path / "plain").label(0, "cam0", "person")
    assert not Recording(tmp_path / "plain").has_labels("part")


def test_writer_with_exception_leaves_no_header(tmp_path, rng):
    with pytest.raises(RuntimeError):
        with RecordingWriter(tmp_path / "r", make_cameras(), 30.0) as writer:
            writer.write_frame(make_data(rng)[1][0])
            raise RuntimeError("boom")
    assert not (tmp_path / "r" / "recording.json").exists()


# ------------------------------------------------------------------ writer checks


def test_writer_rejects_bad_input(tmp_path, rng):
    cameras, depths, colors, joints, visible = make_data(rng)
    with pytest.raises(FileExistsError, match="must not exist or be empty"):
        (tmp_path / "full").mkdir()
        (tmp_path / "full" / "x").write_text("")
        RecordingWriter(tmp_path / "full", cameras, 30.0)
    for fps in (0.0, 10**400, float("nan"), "30"):
        with pytest.raises(ValueError, match="fps must be a "):
            RecordingWriter(tmp_path / "a", cameras, fps)
    with pytest.raises(ValueError, match="camera names must be unique"):
        RecordingWriter(tmp_path / "b", [cameras[0], cameras[0]], 30.0)
    writer = RecordingWriter(tmp_path / "c", cameras, 30.0)
    with pytest.raises(ValueError, match=r"one image per camera \['cam0', 'top'\], got \['cam0'\]"):
        writer.write_frame({"cam0": depths[0]["cam0"]})
    with pytest.raises(ValueError, match=r"depth for camera 'top' must be uint16 \(4, 10\).*got float32"):
        writer.write_frame(depths[0] | {"top": depths[0]["top"].astype(np.float32)})
    with pytest.raises(ValueError, match=r"color for camera 'cam0' must be uint8 \(6, 8, 3\)"):
        writer.write_frame(depths[0], {"cam0": colors[0]["cam0"][..., :2]})
    writer.write_frame(depths[0], colors[0])
    with pytest.raises(ValueError, match="same cameras in every frame"):
        writer.write_frame(depths[1])
    with pytest.raises(ValueError, match="fully finite or fully NaN"):
        bad = joints.copy()
        bad[0, 0, 0, 1] = np.nan
        writer.write_groundtruth(bad, visible, [3, 7])
    with pytest.raises(ValueError, match="person_ids must be 2 distinct ints"):
        writer.write_groundtruth(joints, visible, [3, 3])
    writer.write_groundtruth(joints, visible, [3, 7])
    with pytest.raises(ValueError, match="ground truth has 3 frames, the recording 1"):
        writer.close()


# ------------------------------------------------------------------ bad recordings: one test each


def expect_error(path, file, message, error=RecordingError, call=lambda r: r):
    """Open the recording at ``path`` (then ``call`` it) and check the error names ``file`` and ``message``."""
    with pytest.raises(error) as info:
        call(Recording(path))
    text = str(info.value)
    assert str(file) in text, text
    assert re.search(message, text), text
    assert "Traceback" not in text


def edit_header(rec, change):
    file = rec / "recording.json"
    header = json.loads(file.read_text())
    change(header)
    file.write_text(json.dumps(header))
    return file


def test_missing_recording_json(rec):
    (rec / "recording.json").unlink()
    expect_error(rec, rec / "recording.json", "no such file", FileNotFoundError)


def test_missing_recording_folder(tmp_path):
    expect_error(tmp_path / "nope", tmp_path / "nope", "no such recording folder", FileNotFoundError)


def test_recording_json_not_json(rec):
    (rec / "recording.json").write_text('{"format": "occupose-recording",')
    expect_error(rec, rec / "recording.json", r"not valid JSON \(.* at line 1 column")


def test_recording_json_not_an_object(rec):
    (rec / "recording.json").write_text("[1, 2]")
    expect_error(rec, rec / "recording.json", "expected a JSON object, got list")


def test_recording_json_wrong_format(rec):
    file = edit_header(rec, lambda h: h.update(format="something-else"))
    expect_error(rec, file, "\"format\" must be 'occupose-recording', got 'something-else'")


def test_recording_json_unsupported_version(rec):
    file = edit_header(rec, lambda h: h.update(version=2))
    expect_error(rec, file, r"unsupported version 2; this occupose reads versions \[1\]")


def test_recording_json_missing_key(rec):
    file = edit_header(rec, lambda h: h.pop("num_frames"))
    expect_error(rec, file, r"missing key\(s\) \['num_frames'\]")


def test_recording_json_unknown_key(rec):
    file = edit_header(rec, lambda h: h.update(frames=3))
    expect_error(rec, file, r"unknown key\(s\) \['frames'\]")


def test_recording_json_bad_fps(rec):
    file = edit_header(rec, lambda h: h.update(fps="30"))
    expect_error(rec, file, "\"fps\" must be a positive number, got '30'")


def test_recording_json_bad_num_frames(rec):
    file = edit_header(rec, lambda h: h.update(num_frames=2.5))
    expect_error(rec, file, "\"num_frames\" must be a non-negative integer, got 2.5")


def test_recording_json_no_cameras(rec):
    file = edit_header(rec, lambda h: h.update(cameras=[]))
    expect_error(rec, file, "\"cameras\" must be a non-empty list")


def test_camera_missing_key(rec):
    file = edit_header(rec, lambda h: h["cameras"][1].pop("cy"))
    expect_error(rec, file, r"cameras\[1\]: missing key\(s\) \['cy'\]")


def test_camera_bad_value(rec):
    file = edit_header(rec, lambda h: h["cameras"][0].update(fx=-5.0))
    expect_error(rec, file, r"cameras\[0\]: camera 'cam0': fx must be a positive finite number, got -5.0")


def test_camera_non_finite_pose(rec):
    file = rec / "recording.json"
    header = json.loads(file.read_text())
    header["cameras"][0]["world_from_camera"][0][3] = float("nan")
    file.write_text(json.dumps(header))  # Python writes the non-standard token NaN
    expect_error(rec, file, r"cameras\[0\]: camera 'cam0': world_from_camera must be finite")


def test_camera_non_rigid_pose(rec):
    file = edit_header(rec, lambda h: h["cameras"][1].update(world_from_camera=np.diag([2.0, 1, 1, 1]).tolist()))
    expect_error(rec, file, r"cameras\[1\]: camera 'top': world_from_camera is not rigid")


def test_camera_pose_not_a_matrix(rec):
    file = edit_header(rec, lambda h: h["cameras"][0].update(world_from_camera="identity"))
    expect_error(rec, file, r"cameras\[0\]: world_from_camera must be a 4x4 list of numbers")


def test_duplicate_camera_names(rec):
    file = edit_header(rec, lambda h: h["cameras"][1].update(name="cam0"))
    expect_error(rec, file, r"camera names must be unique, got \['cam0', 'cam0'\]")


def test_missing_depth_folder(rec):
    for file in (rec / "top" / "depth").iterdir():
        file.unlink()
    (rec / "top" / "depth").rmdir()
    expect_error(rec, rec / "top" / "depth", "no such folder", FileNotFoundError)


def test_missing_depth_frame_file(rec):
    (rec / "top" / "depth" / "000001.png").unlink()
    expect_error(rec, rec / "top" / "depth" / "000001.png", r"missing frame file \(recording has 3 frames\)",
                 FileNotFoundError)


def test_missing_colour_frame_file(rec):
    (rec / "cam0" / "color" / "000002.png").unlink()
    expect_error(rec, rec / "cam0" / "color" / "000002.png", "missing frame file", FileNotFoundError)


def test_depth_png_not_16_bit(rec):
    file = rec / "cam0" / "depth" / "000001.png"
    Image.fromarray(np.zeros((6, 8), np.uint8)).save(file)
    expect_error(rec, file, "expected a 16-bit grayscale depth PNG .* mode 'L'", call=lambda r: r.frame(1))


def test_depth_png_wrong_size(rec):
    file = rec / "top" / "depth" / "000000.png"
    Image.fromarray(np.zeros((4, 9), np.uint16)).save(file)
    expect_error(rec, file, "image is 9x4, the camera is 10x4", call=lambda r: r.depth_raw(0, "top"))


def test_depth_file_not_an_image(rec):
    file = rec / "cam0" / "depth" / "000002.png"
    file.write_bytes(b"not a png at all")
    expect_error(rec, file, "not a readable PNG image", call=lambda r: list(r.frames()))


def test_depth_file_is_a_jpeg(rec):
    file = rec / "cam0" / "depth" / "000000.png"
    Image.fromarray(np.zeros((6, 8), np.uint8)).save(file, format="JPEG")
    expect_error(rec, file, "got a JPEG image", call=lambda r: r.frame(0))


def test_colour_png_not_rgb(rec):
    file = rec / "cam0" / "color" / "000001.png"
    Image.fromarray(np.zeros((6, 8), np.uint8)).save(file)
    expect_error(rec, file, "expected an 8-bit RGB colour PNG .* mode 'L'", call=lambda r: r.frame(1))


def test_frame_index_out_of_range(rec):
    expect_error(rec, rec, r"frame index 3 out of range; the recording has frames 0..2", call=lambda r: r.frame(3))


def test_negative_frame_index(rec):
    expect_error(rec, rec, "frame index -1 out of range", call=lambda r: r.depth_raw(-1, "cam0"))


def test_unknown_camera_name(rec):
    expect_error(rec, rec, r"no camera 'side'; cameras are \['cam0', 'top'\]", call=lambda r: r.depth_raw(0, "side"))


def groundtruth_error(rec, text, message):
    file = rec / "groundtruth.csv"
    file.write_text(text)
    expect_error(rec, file, message, call=lambda r: r.groundtruth())


def test_groundtruth_bad_header(rec):
    groundtruth_error(rec, "frame,person,x,y,z\n", r"bad header \['frame', 'person', 'x', 'y', 'z'\]; expected columns")


def test_groundtruth_empty_file(rec):
    groundtruth_error(rec, "", r"bad header \[\]")


def test_groundtruth_unknown_joint(rec):
    groundtruth_error(rec, "frame,person,joint,x,y,z,visible\n0,1,hed,0,0,1,1\n",
                      r"line 2: unknown joint 'hed'; valid joints: head, neck")


def test_groundtruth_wrong_number_of_values(rec):
    groundtruth_error(rec, "frame,person,joint,x,y,z,visible\n0,1,head,0,0,1\n", "line 2: expected 7 columns, got 6")


def test_groundtruth_non_integer_frame(rec):
    groundtruth_error(rec, "frame,person,joint,x,y,z,visible\n0.5,1,head,0,0,1,1\n",
                      "line 2: frame must be an integer, got '0.5'")


def test_groundtruth_frame_out_of_range(rec):
    groundtruth_error(rec, "frame,person,joint,x,y,z,visible\n0,1,head,0,0,1,1\n3,1,head,0,0,1,1\n",
                      r"line 3: frame 3 out of range; the recording has frames 0..2")


def test_groundtruth_bad_coordinate(rec):
    groundtruth_error(rec, "frame,person,joint,x,y,z,visible\n0,1,head,abc,0,1,1\n",
                      "line 2: x must be a number, got 'abc'")


def test_groundtruth_non_finite_coordinate(rec):
    groundtruth_error(rec, "frame,person,joint,x,y,z,visible\n0,1,head,nan,0,1,1\n", "line 2: x must be finite, got 'nan'")


def test_groundtruth_bad_visible_flag(rec):
    groundtruth_error(rec, "frame,person,joint,x,y,z,visible\n0,1,head,0,0,1,yes\n",
                      "line 2: visible must be 0 or 1, got 'yes'")


def test_groundtruth_duplicate_row(rec):
    groundtruth_error(rec, "frame,person,joint,x,y,z,visible\n0,1,head,0,0,1,1\n0,1,head,0,0,1,0\n",
                      "line 3: duplicate row for frame 0, person 1, joint head")


def test_groundtruth_not_utf8(rec):
    file = rec / "groundtruth.csv"
    file.write_bytes(b"frame,person,joint,x,y,z\n\xff\xfe\n")
    expect_error(rec, file, "not a readable UTF-8 CSV file", call=lambda r: r.groundtruth())


def test_all_joint_names_are_accepted(rec):
    rows = "".join(f"0,1,{name},0,0,{i},1\n" for i, name in enumerate(JOINTS))
    (rec / "groundtruth.csv").write_text("frame,person,joint,x,y,z,visible\n" + rows)
    np.testing.assert_array_equal(Recording(rec).groundtruth().joints[0, 0, :, 2], np.arange(15))


def test_real_azure_kinect_frame_round_trips(tmp_path):
    from occupose.camera import camera_preset, points_from_depth
    from occupose.paths import shared_data_dir

    data = shared_data_dir()
    file = None if data is None else data / "sensors" / "azure_kinect" / "depth_frame0_mm.npy"
    if file is None or not file.is_file():
        pytest.skip("shared sensor data (../shared/data/sensors or OCCUPOSE_DATA) not present")
    depth = np.load(file)
    camera = camera_preset("azure_nfov")
    with RecordingWriter(tmp_path / "azure", [camera], fps=30.0) as writer:
        writer.write_frame({"cam0": depth})
    recording = Recording(tmp_path / "azure")
    np.testing.assert_array_equal(recording.depth_raw(0, "cam0"), depth)
    points, pixels = points_from_depth(recording.frame(0).depth["cam0"], camera, frame="camera")
    assert pixels.size == np.count_nonzero(depth)  # 23.5 % of the pixels are invalid zeros
    assert 0.16 < points[:, 2].min() and points[:, 2].max() < 3.7


def test_colour_is_left_undecoded_when_not_asked_for(rec):
    file = rec / "cam0" / "color" / "000001.png"
    data = file.read_bytes()
    at = data.index(b"IDAT") + 8
    file.write_bytes(data[:at] + bytes(b ^ 0xFF for b in data[at:at + 16]) + data[at + 16:])  # header intact
    recording = Recording(rec)  # the headers are checked, not the image data
    with pytest.raises(RecordingError, match="000001.png: not a readable PNG image"):
        recording.frame(1)
    frame = recording.frame(1, color=False)
    assert frame.color == {} and frame.depth["cam0"].shape == (6, 8)
    assert [f.index for f in recording.frames(color=False)] == [0, 1, 2]


def test_frame_files_past_num_frames_are_refused(rec):
    (rec / "top" / "depth" / "000003.png").write_bytes((rec / "top" / "depth" / "000002.png").read_bytes())
    expect_error(rec, rec / "top" / "depth", r"1 frame file\(s\) past the recording's \"num_frames\" 3 \(000003.png\)")


def _write_timed(path, rng, times):
    cameras, depths, _, _, _ = make_data(rng)
    with RecordingWriter(path, cameras, fps=30.0) as writer:
        for depth, time in zip(depths, times):
            writer.write_frame(depth, time=time)
    return path


def test_uneven_frame_times_round_trip_through_times_csv(tmp_path, rng):
    times = [0.0, 1 / 30, 3 / 30 + 0.0012]  # frame 2 of the camera was dropped
    path = _write_timed(tmp_path / "rec", rng, times)
    assert (path / "times.csv").read_text() == "frame,time\n0,0.000000\n1,0.033333\n2,0.101200\n"
    assert [f.time for f in Recording(path).frames(color=False)] == pytest.approx(times, abs=1e-6)


def test_even_frame_times_write_no_times_csv(tmp_path, rng):
    path = _write_timed(tmp_path / "rec", rng, [i / 30 + 1e-7 for i in range(NUM_FRAMES)])
    assert not (path / "times.csv").exists()
    assert [f.time for f in Recording(path).frames(color=False)] == [i / 30 for i in range(NUM_FRAMES)]


def test_writer_rejects_bad_times(tmp_path, rng):
    cameras, depths, _, _, _ = make_data(rng)
    for k, (times, message) in enumerate([([0.0, None], "for every frame or for none"),
                                          ([None, 0.1], "for every frame or for none"),
                                          ([0.0, -0.1], "not before the previous"),
                                          ([float("nan")], "must be finite")]):
        writer = RecordingWriter(tmp_path / f"r{k}", cameras, fps=30.0)
        with pytest.raises(ValueError, match=message):
            for depth, time in zip(depths, times):
                writer.write_frame(depth, time=time)


@pytest.mark.parametrize("text, message", [
    ("time,frame\n", "first line must be 'frame,time'"),
    ("frame,time\n0,0\n1,0.1\n", "2 frame time\\(s\\), the recording has 3"),
    ("frame,time\n0,0\n2,0.1\n1,0.2\n", "line 3 must be '1,<seconds>'"),
    ("frame,time\n0,0\n1,x\n2,0.2\n", "line 3 must be '1,<seconds>'"),
    ("frame,time\n0,0\n1,0.2\n2,0.1\n", "line 4: frame 2's time '0.1' is not finite or is before"),
    ("frame,time\n0,0\n1,inf\n2,0.1\n", "not finite"),
])
def test_bad_times_csv(tmp_path, rng, text, message):
    path = _write_timed(tmp_path / "rec", rng, [0.0, 0.05, 0.1])
    (path / "times.csv").write_text(text)
    with pytest.raises(RecordingError, match=message):
        Recording(path)


def test_convert_keeps_uneven_frame_times(tmp_path, rng):
    from occupose.io.convert import convert

    times = [0.0, 0.05, 0.2]
    source = Recording(_write_timed(tmp_path / "rec", rng, times))
    copy = Recording(convert(source, tmp_path / "copy"))
    assert (tmp_path / "copy" / "times.csv").read_bytes() == (tmp_path / "rec" / "times.csv").read_bytes()
    assert [f.time for f in copy.frames(color=False)] == times
