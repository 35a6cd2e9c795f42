"""Azure Kinect .mkv through open_source: files written here with PyAV, read back
bit-exactly; the shared Azure Kinect recording against its decoded frame."""

import json
import sys

import numpy as np
import pytest

pytest.importorskip("av")

from occupose.camera import Camera, matching_preset, raw_depth_from_metres  # noqa: E402
from occupose.io.mkv import (DEPTH_MODES, MkvSource, camera_from_calibration,  # noqa: E402
                             gravity_from_accelerations, imu_samples)
from occupose.io.recording import RecordingWriter  # noqa: E402
from occupose.io.sources import (HeightTilt, NoWorldPoseError, SourceError, open_source, placement,  # noqa: E402
                                 reader_for)
from occupose.paths import shared_data_dir  # noqa: E402
from occupose.testing import random_raw_depths, raw_frames, AZURE_ACCEL_ROTATION, azure_calibration, write_depth_mkv  # noqa: E402

POSE = HeightTilt(1.5, 20.0)
CAMERA = Camera("cam", 320, 288, 250.25, 251.5, 160.75, 143.25, 0.001)  # NFOV 2x2 binned size

#: The shared device's depth camera: cx, cy, fx, fy normalised to its 1024 x 1024 sensor.
SHARED_NORMALISED = [0.5129697918891907, 0.5169235467910767, 0.4927808940410614, 0.49290284514427185]


def raw_depths(count, camera=CAMERA, seed=0):
    """``count`` (H, W) uint16 images, a tenth of them 0 (no measurement)."""
    return random_raw_depths(count, (camera.height, camera.width), 300, 9000, seed)



def calibration_of(normalised):
    camera = Camera("x", 640, 576, 1.0, 1.0, 0.0, 0.0)
    document = azure_calibration(camera, "NFOV_UNBINNED")
    document["CalibrationInformation"]["Cameras"][0]["Intrinsics"]["ModelParameters"][:4] = normalised
    return document


@pytest.mark.parametrize("mode, expected", [
    # by hand: fx = 0.49278089 * 1024 = 504.60764; cx = 0.51296979 * 1024 - 192 - 0.5 = 525.28107 - 192.5
    ("NFOV_UNBINNED", (640, 576, 504.607635, 504.732513, 332.781067, 348.829712)),
    # fx = 0.49278089 * 512 = 252.30382; cx = 0.51296979 * 512 - 96 - 0.5; cy = 0.51692355 * 512 - 90 - 0.5
    ("NFOV_2X2BINNED", (320, 288, 252.303818, 252.366257, 166.140533, 174.164856)),
    ("WFOV_2X2BINNED", (512, 512, 252.303818, 252.366257, 262.140533, 264.164856)),  # no crop: - 0.5 only
    ("WFOV_UNBINNED", (1024, 1024, 504.607635, 504.732513, 524.781067, 528.829712)),
])
def test_calibration_to_mode_specific_intrinsics_by_hand(mode, expected):
    camera = camera_from_calibration(calibration_of(SHARED_NORMALISED), mode)
    got = (camera.width, camera.height, camera.fx, camera.fy, camera.cx, camera.cy)
    assert got == pytest.approx(expected, abs=1e-5) and camera.depth_scale == 0.001 and camera.name == "cam0"


def test_a_real_nfov_calibration_is_the_azure_preset():
    """The shared device's factory calibration, taken to NFOV unbinned, is the azure_nfov preset
    (its ToF noise model and 3.86 m far range): the preset's cy once came from a centred crop
    (304.83, 12.6 % off) and no real Azure Kinect matched it."""
    camera = camera_from_calibration(calibration_of(SHARED_NORMALISED), "NFOV_UNBINNED")
    assert matching_preset(camera) == "azure_nfov"
    assert matching_preset(camera_from_calibration(calibration_of(SHARED_NORMALISED), "NFOV_2X2BINNED")) is None


def test_bad_calibrations_and_modes_are_value_errors():
    with pytest.raises(ValueError, match="unknown Azure Kinect depth mode 'PASSIVE_IR'; valid: NFOV_2X2BINNED"):
        camera_from_calibration(calibration_of(SHARED_NORMALISED), "PASSIVE_IR")
    with pytest.raises(ValueError, match="not an Azure Kinect calibration"):
        camera_from_calibration({"hello": 1}, "NFOV_UNBINNED")
    document = calibration_of(SHARED_NORMALISED)
    document["CalibrationInformation"]["Cameras"][0]["SensorWidth"] = 512
    with pytest.raises(ValueError, match="sensor is 512x1024, expected 1024x1024"):
        camera_from_calibration(document, "NFOV_UNBINNED")


def test_gravity_is_the_accelerometers_down_in_the_depth_frame():
    identity = calibration_of(SHARED_NORMALISED)
    identity["CalibrationInformation"]["InertialSensors"][0]["Rt"]["Rotation"] = [1, 0, 0, 0, 1, 0, 0, 0, 1]
    # at rest an accelerometer measures up: (0, -9.81, 0) is "image up" in OpenCV axes
    np.testing.assert_allclose(gravity_from_accelerations([[0.0, -9.81, 0.0], [0.0, -9.79, 0.0]], identity),
                               [0.0, 1.0, 0.0])
    rotation = np.array(AZURE_ACCEL_ROTATION)  # depth -> accelerometer
    down = np.array([0.0, np.cos(0.3), np.sin(0.3)])  # the camera tilted 0.3 rad (17.2 degrees) up
    acc = rotation @ (-9.81 * down)
    np.testing.assert_allclose(gravity_from_accelerations(acc[None], calibration_of(SHARED_NORMALISED)), down,
                               atol=1e-6)
    with pytest.raises(ValueError, match="no accelerometer samples"):
        gravity_from_accelerations(np.zeros((0, 3)), identity)
    with pytest.raises(ValueError, match="no direction of gravity"):
        gravity_from_accelerations([[0.0, 0.0, 0.0]], identity)


@pytest.mark.parametrize("mode", ["NFOV_2X2BINNED", "WFOV_2X2BINNED"])
def test_written_mkvs_read_back_bit_exactly_with_intrinsics_and_times(tmp_path, mode):
    (width, height) = DEPTH_MODES[mode][2]
    camera = Camera("cam", width, height, 250.25, 251.5, width / 2 + 0.75, height / 2 - 0.75)
    depths = raw_depths(4, camera)
    path = write_depth_mkv(tmp_path / "rec.mkv", depths, camera, fps=15.0, start_offset_ns=336_277_000)
    source = open_source(path, pose=POSE)
    assert reader_for(path).name == "mkv" and isinstance(source, MkvSource) and source.pose_known
    got = source.cameras[0]
    assert (got.width, got.height, got.depth_scale) == (width, height, 0.001)
    assert (got.fx, got.fy, got.cx, got.cy) == pytest.approx((camera.fx, camera.fy, camera.cx, camera.cy), abs=1e-9)
    assert source.depth_mode == mode and source.num_frames == 4 and source.fps == 15.0 and source.color_cameras == ()
    assert source.start_offset_us == 336_277 and source.gravity == {}
    raw, times = raw_frames(source)
    np.testing.assert_array_equal(raw, depths)
    np.testing.assert_allclose(times, [0.0, 0.067, 0.133, 0.2], atol=1e-9)  # Matroska's ms timecodes from FFmpeg
    first = next(iter(source._raw_frames(False)))[2]
    assert first == pytest.approx(0.336277)  # the device timestamp: pts + K4A_START_OFFSET_NS
    assert source.frame(2).depth["cam0"][5, 7] == np.float32(depths[2, 5, 7] * 0.001)


def test_the_imu_track_gives_gravity_for_the_floor_estimate(tmp_path):
    rotation = np.array(AZURE_ACCEL_ROTATION)
    down = np.array([0.0, np.cos(np.radians(30)), np.sin(np.radians(30))])  # looking 30 degrees down
    rng = np.random.default_rng(1)
    accelerations = rotation @ (-9.81 * down) + rng.normal(0, 0.05, (300, 3))
    path = write_depth_mkv(tmp_path / "imu.mkv", raw_depths(2), CAMERA, accelerations=accelerations)
    samples = imu_samples(path)
    assert len(samples) == 160 and samples["acc_timestamp_ns"][1] == 1_000_000
    np.testing.assert_array_equal(samples["acc"], accelerations[:160].astype(np.float32))
    source = MkvSource(path)
    assert list(source.gravity) == ["cam0"]
    angle = np.degrees(np.arccos(np.clip(source.gravity["cam0"] @ down, -1, 1)))
    assert angle < 0.5, f"gravity {angle:.2f} degrees from the truth"
    assert len(imu_samples(path, count=5)) == 5


def test_bad_mkvs_are_source_errors_naming_the_file(tmp_path):
    (tmp_path / "junk.mkv").write_text("hello")
    good = write_depth_mkv(tmp_path / "good.mkv", raw_depths(20), CAMERA)
    write_depth_mkv(tmp_path / "ir.mkv", raw_depths(1), CAMERA, title="IR")
    write_depth_mkv(tmp_path / "nocal.mkv", raw_depths(1), CAMERA, calibration=False)
    write_depth_mkv(tmp_path / "badcal.mkv", raw_depths(1), CAMERA, calibration={"CalibrationInformation": {}})
    write_depth_mkv(tmp_path / "mode.mkv", raw_depths(1), CAMERA, mode="NFOV_UNBINNED",
                    calibration=calibration_of(SHARED_NORMALISED))
    cut = tmp_path / "cut.mkv"
    cut.write_bytes(good.read_bytes()[:200])  # the header only: no frame
    cases = [("junk.mkv", r"junk.mkv: not a readable Matroska file"),
             ("ir.mkv", r"ir.mkv: 0 video tracks titled 'DEPTH' .*its tracks: video 'IR', attachment"),
             ("nocal.mkv", r"nocal.mkv: no calibration.json attachment to give the depth camera's intrinsics "
                           r"\(attachments: none\)"),
             ("badcal.mkv", r"badcal.mkv: calibration.json: not an Azure Kinect calibration"),
             ("mode.mkv", r"mode.mkv: a 320x288 DEPTH track of depth mode 'NFOV_UNBINNED': not an Azure Kinect "
                          r"depth mode \(NFOV_2X2BINNED 320x288"),
             ("cut.mkv", r"cut.mkv: ")]
    for name, message in cases:
        with pytest.raises(SourceError, match=message):
            open_source(tmp_path / name, pose=POSE)
    with pytest.raises(FileNotFoundError, match="no such .mkv file"):
        MkvSource(tmp_path / "none.mkv")
    cut.write_bytes(good.read_bytes()[: good.stat().st_size // 2])  # cut short: the whole frames before the cut
    source = open_source(cut, pose=POSE)
    assert 5 < source.num_frames < 20
    np.testing.assert_array_equal(raw_frames(source)[0], raw_depths(20)[: source.num_frames])


def test_missing_pyav_names_the_extra(tmp_path, monkeypatch):
    path = write_depth_mkv(tmp_path / "rec.mkv", raw_depths(1), CAMERA)
    monkeypatch.setitem(sys.modules, "av", None)  # as if it were not installed
    with pytest.raises(ImportError, match=r"reading Azure Kinect .mkv files needs the 'av' package .*"
                                          r"pip install 'occupose\[kinect\]'"):
        open_source(path, pose=POSE)


def test_reading_streams_with_flat_memory(tmp_path):
    import tracemalloc

    path = write_depth_mkv(tmp_path / "long.mkv", (np.full((288, 320), 1000 + i, np.uint16) for i in range(120)),
                           CAMERA)  # 22 MB of depth
    source = open_source(path, pose=POSE)
    tracemalloc.start()
    try:
        for index, frame in enumerate(source.frames()):
            assert frame.depth["cam0"][0, 0] == np.float32((1000 + index) * 0.001)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert index == 119 and peak < 3e6, f"peak {peak / 1e6:.1f} MB while reading 22 MB of frames"


def test_an_mkv_tracks_as_the_folder_it_was_made_from(tmp_path):
    """``occupose track`` on an .mkv made from a synthetic recording (with an IMU track that
    agrees with the true pose) gives the folder's tracks.csv, with the pose given and with
    the pose found from the floor (the folder with --find-floor)."""
    from click.testing import CliRunner

    from occupose.cli import main
    from occupose.synth.generate import frames
    from occupose.synth.scenarios import build_scenario

    scenario = build_scenario("no_occlusion", sensor="azure_nfov", use_mocap=False)  # 640 x 576, NFOV unbinned
    camera = scenario.cameras[0]
    raw = [raw_depth_from_metres(f.depth[camera.name], camera) for f in frames(scenario, seed=0, num_frames=20)]
    with RecordingWriter(tmp_path / "rec", [camera], fps=scenario.fps) as writer:
        for image in raw:
            writer.write_frame({camera.name: image})
    up = camera.world_from_camera[:3, :3].T @ [0.0, 0.0, 1.0]  # world up in the camera frame
    accelerations = np.tile(np.array(AZURE_ACCEL_ROTATION) @ (9.81 * up), (200, 1))
    mkv = write_depth_mkv(tmp_path / "rec.mkv", raw, camera, fps=scenario.fps, accelerations=accelerations)
    (tmp_path / "pose.json").write_text(json.dumps({"world_from_camera": camera.world_from_camera.tolist()}))

    def track(*args):
        out = tmp_path / f"run{len(list(tmp_path.glob('run*')))}"
        result = CliRunner().invoke(main, ["track", *map(str, args), "--out", str(out)])
        assert result.exit_code == 0, result.output
        return (out / "tracks.csv").read_text()

    given = track(mkv, "--world-from-camera", tmp_path / "pose.json")
    assert given == track(tmp_path / "rec") and given.count("\n") > 20
    assert track(mkv) == track(tmp_path / "rec", "--find-floor")
    # the floor estimate with the IMU's gravity: the true height and tilt
    source = open_source(mkv)
    np.testing.assert_allclose(source.gravity["cam0"], -up, atol=1e-6)
    (placed,) = placement(source)
    true_tilt = np.degrees(np.arcsin(-camera.world_from_camera[2, 2]))
    assert abs(placed["height_m"] - camera.world_from_camera[2, 3]) < 0.02 and abs(placed["tilt_deg"] - true_tilt) < 1


@pytest.mark.shared
def test_the_shared_azure_kinect_recording_decodes_bit_exactly():
    data = shared_data_dir()
    folder = None if data is None else data / "sensors" / "azure_kinect"
    if folder is None or not (folder / "recording.mkv").is_file():
        pytest.skip("shared Azure Kinect recording (../shared/data/sensors/azure_kinect) not present")
    source = MkvSource(folder / "recording.mkv")
    camera = source.cameras[0]
    assert source.depth_mode == "NFOV_UNBINNED" and source.num_frames == 1 and source.fps == 5.0
    assert (camera.width, camera.height, camera.depth_scale) == (640, 576, 0.001)
    assert (camera.fx, camera.fy, camera.cx, camera.cy) == pytest.approx((504.6076, 504.7325, 332.7811, 348.8297),
                                                                         abs=1e-4)
    depth, _, stamp = next(iter(source._raw_frames(False)))
    np.testing.assert_array_equal(depth["cam0"], np.load(folder / "depth_frame0_mm.npy"))
    assert round(stamp * 1e6) == 800222  # µs, as the Azure Kinect SDK reports that frame
    first = raw_depth_from_metres(next(source.frames()).depth["cam0"], camera)
    np.testing.assert_array_equal(first, np.load(folder / "depth_frame0_mm.npy"))
    calibration = json.loads((folder / "calibration.json").read_text())
    assert source.calibration == calibration
    # one IMU sample: (-2.89, -0.19, -9.44) m/s^2; in the depth frame the camera looks 10.8 degrees up, no roll
    (sample,) = imu_samples(folder / "recording.mkv")
    assert sample["acc_timestamp_ns"] == 336_277_000
    np.testing.assert_allclose(source.gravity["cam0"], [-0.0218, 0.9821, -0.1872], atol=1e-4)
    # a mug on a table before a wall: with the IMU's gravity the wall is not taken for the floor
    with pytest.raises(NoWorldPoseError, match="no floor was found"):
        open_source(folder / "recording.mkv")
