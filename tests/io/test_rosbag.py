"""ROS 1 / ROS 2 bags (RealSense included) through open_source: bags written here with
rosbags' writers, read back bit-exactly; the shared RealSense file against its decoded frame."""

import json
import sys

import numpy as np
import pytest

pytest.importorskip("rosbags")

from occupose.camera import Camera, raw_depth_from_metres  # noqa: E402
from occupose.io.recording import Recording, RecordingWriter  # noqa: E402
from occupose.io.rosbag import FLOAT_DEPTH_SCALE, BagSource, depth_from_image  # noqa: E402
from occupose.io.sources import HeightTilt, SourceError, open_source, reader_for  # noqa: E402
from occupose.paths import shared_data_dir  # noqa: E402
from occupose.testing import (bag_typestore, camera_info_message, image_message, random_raw_depths,  # noqa: E402
                              raw_frames, write_bag, write_depth_bag)

POSE = HeightTilt(1.5, 20.0)
CAMERA = Camera("cam", 64, 48, 250.25, 251.5, 31.75, 23.25, 0.001)
IMAGE, INFO = "sensor_msgs/msg/Image", "sensor_msgs/msg/CameraInfo"


def raw_depths(count, camera=CAMERA, seed=0):
    """``count`` (H, W) uint16 images, a tenth of them 0 (no measurement)."""
    return random_raw_depths(count, (camera.height, camera.width), 300, 9000, seed)



@pytest.mark.parametrize("ros, storage", [(1, None), (2, "sqlite3"), (2, "mcap")])
def test_bags_read_back_bit_exactly_with_intrinsics_and_times(tmp_path, ros, storage):
    depths = raw_depths(4)
    path = write_depth_bag(tmp_path / ("rec.bag" if ros == 1 else "rec"), depths, CAMERA, ros=ros,
                           storage=storage or "sqlite3", fps=15.0, start=1700000000.25)
    source = open_source(path, pose=POSE)
    assert reader_for(path).name == "bag" and source.pose_known
    camera = source.cameras[0]
    assert (camera.width, camera.height, camera.fx, camera.fy, camera.cx, camera.cy, camera.depth_scale) == \
        (64, 48, 250.25, 251.5, 31.75, 23.25, 0.001)
    assert source.num_frames == 4 and source.fps == 15.0 and source.color_cameras == ()
    got, times = raw_frames(source)
    np.testing.assert_array_equal(got, depths)
    np.testing.assert_allclose(times, np.arange(4) / 15.0, atol=5e-7)  # float seconds at 1.7e9 s
    assert source.frame(2).depth["cam0"][5, 7] == np.float32(depths[2, 5, 7] * 0.001)


@pytest.mark.parametrize("storage, suffix", [("sqlite3", ".db3"), ("mcap", ".mcap")])
def test_a_ros2_storage_file_and_a_folder_without_metadata_open(tmp_path, storage, suffix):
    depths = raw_depths(2, seed=1)
    folder = write_depth_bag(tmp_path / "rec", depths, CAMERA, ros=2, storage=storage)
    (file,) = folder.glob(f"*{suffix}")
    np.testing.assert_array_equal(raw_frames(open_source(file, pose=POSE))[0], depths)
    (folder / "metadata.yaml").unlink()
    np.testing.assert_array_equal(raw_frames(open_source(folder, pose=POSE))[0], depths)


def test_a_ros2_bag_folder_named_like_a_ros1_file_opens(tmp_path):
    depths = raw_depths(2, seed=3)
    folder = write_depth_bag(tmp_path / "rec.bag", depths, CAMERA, ros=2)
    assert folder.is_dir() and (folder / "metadata.yaml").is_file()
    np.testing.assert_array_equal(raw_frames(open_source(folder, pose=POSE))[0], depths)

def test_realsense_layout_depth_units_and_stream_fps(tmp_path):
    camera = Camera("cam", 64, 48, 380.5, 380.5, 32.1, 24.2, 0.0001)
    depths = raw_depths(3, camera, seed=2)
    path = write_depth_bag(tmp_path / "rs.bag", depths, camera, encoding="mono16", fps=6.0, realsense=True)
    source = open_source(path, pose=POSE)
    assert source.topic == "/device_0/sensor_0/Depth_0/image/data"
    assert source.info_topic == "/device_0/sensor_0/Depth_0/info/camera_info"
    assert source.cameras[0].depth_scale == 0.0001 and source.fps == 6.0 and source.encoding == "mono16"
    got, times = raw_frames(source)
    np.testing.assert_array_equal(got, depths)
    np.testing.assert_allclose(times, [0.0, 1 / 6, 2 / 6], atol=2e-9)
    metres = next(source.frames()).depth["cam0"]
    assert metres[0, 0] == np.float32(depths[0, 0, 0] * 0.0001)


def test_float_metres_become_millimetres_nan_and_out_of_range_none(tmp_path):
    metres = np.zeros((2, 48, 64), np.float32)
    metres[:] = raw_depths(2, seed=3) * np.float32(0.001)  # whole millimetres: exact back
    metres[0, 0, :8] = [1.0, np.nan, 0.0, -0.5, 2.0004, 2.0006, np.inf, 70.0]
    path = write_depth_bag(tmp_path / "f.bag", metres, CAMERA, encoding="32FC1")
    source = open_source(path, pose=POSE)
    assert source.encoding == "32FC1" and source.cameras[0].depth_scale == FLOAT_DEPTH_SCALE
    got, _ = raw_frames(source)
    np.testing.assert_array_equal(got[0, 0, :8], [1000, 0, 0, 0, 2000, 2001, 0, 0])
    expected = raw_depths(2, seed=3)
    np.testing.assert_array_equal(got[:, 1:], expected[:, 1:])
    np.testing.assert_array_equal(got[1], expected[1])


@pytest.mark.parametrize("encoding, bigendian, padding", [("16UC1", True, 0), ("16UC1", False, 6),
                                                          ("32FC1", True, 4)])
def test_byte_order_and_row_padding_are_honoured(tmp_path, encoding, bigendian, padding):
    depths = raw_depths(2, seed=4)
    data = depths if encoding == "16UC1" else depths * np.float32(0.001)
    path = write_depth_bag(tmp_path / "b.bag", data, CAMERA, encoding=encoding, bigendian=bigendian, padding=padding)
    np.testing.assert_array_equal(raw_frames(open_source(path, pose=POSE))[0], depths)


def test_depth_from_image_on_bytes():
    big = np.array([[1, 258], [65535, 0]], ">u2")
    data = np.concatenate([big.view(np.uint8), np.full((2, 3), 7, np.uint8)], axis=1).ravel()
    np.testing.assert_array_equal(depth_from_image(data, 2, 2, 7, "16UC1", True), [[1, 258], [65535, 0]])
    with pytest.raises(ValueError, match=r"needs step >= 4 and 7 \* 2 bytes; it has step 7 and 13 bytes"):
        depth_from_image(data[:-1], 2, 2, 7, "16UC1", True)
    with pytest.raises(ValueError, match="'bgr8' is not a depth encoding"):
        depth_from_image(data, 2, 2, 7, "bgr8", False)


def two_camera_bag(path, store, depths, *, extra=()):
    """/cam_a/depth and /cam_b/depth (intrinsics differing), plus ``extra`` image topics."""
    cameras = {"a": CAMERA, "b": Camera("b", 64, 48, 300.0, 300.0, 30.0, 20.0)}
    messages = [(f"/cam_{n}/depth/camera_info", INFO, 1, camera_info_message(store, c, frame_id=n))
                for n, c in cameras.items()]
    for index, depth in enumerate(depths):
        for n in cameras:
            messages.append((f"/cam_{n}/depth/image_raw", IMAGE, 10 + index,
                             image_message(store, depth + (n == "b"), "16UC1", 5.0 + index, frame_id=n)))
        messages += [(topic, IMAGE, 10 + index, image_message(store, pixels, encoding, 5.0 + index))
                     for topic, encoding, pixels in extra]
    return write_bag(path, messages, store)


def test_several_depth_topics_are_listed_and_topic_picks_one(tmp_path):
    depths = raw_depths(2, seed=5)
    path = two_camera_bag(tmp_path / "two.bag", bag_typestore(1), depths)
    with pytest.raises(SourceError, match=r"two.bag: several depth image topics: /cam_a/depth/image_raw \(16UC1\), "
                                          r"/cam_b/depth/image_raw \(16UC1\); choose one with --topic"):
        open_source(path, pose=POSE)
    source = open_source(path, pose=POSE, topic="/cam_b/depth/image_raw")
    assert source.info_topic == "/cam_b/depth/camera_info" and source.cameras[0].fx == 300.0
    np.testing.assert_array_equal(raw_frames(source)[0], depths + 1)


def test_a_mono16_infrared_topic_does_not_hide_the_depth_topic(tmp_path):
    store = bag_typestore(1)
    depths = raw_depths(2, seed=6)
    messages = [("/camera/depth/camera_info", INFO, 1, camera_info_message(store, CAMERA))]
    for index, depth in enumerate(depths):
        messages += [("/camera/ir/image_raw", IMAGE, 10 + index, image_message(store, depth // 3, "mono16", index)),
                     ("/camera/depth/image_raw", IMAGE, 10 + index, image_message(store, depth, "mono16", index))]
    source = open_source(write_bag(tmp_path / "ir.bag", messages, store), pose=POSE)
    assert source.topic == "/camera/depth/image_raw"
    np.testing.assert_array_equal(raw_frames(source)[0], depths)


def test_camera_info_of_another_frame_is_not_used(tmp_path):
    store = bag_typestore(2)
    depth = raw_depths(1, seed=7)[0]
    messages = [("/camera/color/camera_info", INFO, 1, camera_info_message(store, CAMERA, frame_id="color")),
                ("/camera/depth/image_raw", IMAGE, 2, image_message(store, depth, "16UC1", 1.0, frame_id="depth"))]
    path = write_bag(tmp_path / "rec", messages, store, ros=2)
    with pytest.raises(SourceError, match=r"rec: no sensor_msgs/msg/CameraInfo topic for /camera/depth/image_raw "
                                          r"\(64x48, frame_id 'depth'\).*/camera/color/camera_info \(64x48, "
                                          r"frame_id 'color'\)"):
        open_source(path, pose=POSE)


def test_bad_bags_are_source_errors_naming_the_file(tmp_path):
    store = bag_typestore(1)
    depth = raw_depths(1)[0]
    (tmp_path / "junk.bag").write_text("hello")
    good = write_depth_bag(tmp_path / "good.bag", raw_depths(20), CAMERA)
    (tmp_path / "cut.bag").write_bytes(good.read_bytes()[: good.stat().st_size // 2])
    write_bag(tmp_path / "units.bag", [("/units", "std_msgs/msg/Float32", 1, store.types["std_msgs/msg/Float32"](
        data=0.001))], store)
    write_bag(tmp_path / "rgb.bag", [("/camera/color/image_raw", IMAGE, 1, image_message(
        store, np.zeros((4, 6, 3), np.uint8), "rgb8", 1.0))], store)
    write_bag(tmp_path / "noinfo.bag", [("/camera/depth/image_raw", IMAGE, 1, image_message(
        store, depth, "16UC1", 1.0))], store)
    cases = [("junk.bag", {}, r"junk.bag: not a readable ROS bag"),
             ("cut.bag", {}, r"cut.bag: not a readable ROS bag"),
             ("units.bag", {}, r"units.bag: no sensor_msgs/msg/Image topic with messages \(topics: /units\)"),
             ("rgb.bag", {}, r"rgb.bag: no depth image topic .*image topics: /camera/color/image_raw \(rgb8\)"),
             ("rgb.bag", {"topic": "/camera/color/image_raw"}, r"rgb.bag: topic /camera/color/image_raw has "
                                                               r"images of encoding 'rgb8', not a depth encoding"),
             ("good.bag", {"topic": "/nope"}, r"good.bag: no topic '/nope'; its image topics are "
                                              r"\['/camera/depth/image_raw'\]"),
             ("good.bag", {"topic": "/camera/depth/camera_info"}, r"good.bag: topic '/camera/depth/camera_info' is "
                                                                  r"a sensor_msgs/msg/CameraInfo, not"),
             ("noinfo.bag", {}, r"noinfo.bag: no sensor_msgs/msg/CameraInfo topic for /camera/depth/image_raw .*"
                                r"CameraInfo topics: none")]
    for name, options, message in cases:
        with pytest.raises(SourceError, match=message):
            open_source(tmp_path / name, pose=POSE, **options)


def test_missing_rosbags_names_the_extra(tmp_path, monkeypatch):
    path = write_depth_bag(tmp_path / "rec.bag", raw_depths(1), CAMERA)
    monkeypatch.setitem(sys.modules, "rosbags", None)  # as if it were not installed
    with pytest.raises(ImportError, match=r"reading ROS bags needs the 'rosbags' package .*"
                                          r"pip install 'occupose\[ros\]'"):
        open_source(path, pose=POSE)


@pytest.mark.parametrize("ros, storage", [(1, "sqlite3"), (2, "sqlite3"), (2, "mcap")])
def test_reading_streams_with_flat_memory(tmp_path, ros, storage):
    import tracemalloc

    camera = Camera("cam", 320, 240, 300.0, 300.0, 160.0, 120.0)
    path = write_depth_bag(tmp_path / ("long.bag" if ros == 1 else "long"), (np.full((240, 320), 1000 + i, np.uint16)
                                                                             for i in range(120)),
                           camera, ros=ros, storage=storage)  # 18 MB of depth
    source = open_source(path, pose=POSE)
    tracemalloc.start()
    try:
        for index, frame in enumerate(source.frames()):
            assert frame.depth["cam0"][0, 0] == np.float32((1000 + index) * 0.001)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    # rosbags holds one chunk (1-4 MB) at a time, never the whole bag
    assert index == 119 and peak < 6e6, f"peak {peak / 1e6:.1f} MB while reading 18 MB of frames"


def test_a_bag_tracks_as_the_folder_it_was_made_from(tmp_path, walk):
    from occupose.run import track_recording

    scenario, rendered = walk
    camera = scenario.cameras[0]
    rendered = rendered[:20]
    with RecordingWriter(tmp_path / "rec", [camera], fps=scenario.fps) as writer:
        for frame in rendered:
            writer.write_frame({camera.name: raw_depth_from_metres(frame.depth[camera.name], camera)})
    bag = write_depth_bag(tmp_path / "rec.bag", (raw_depth_from_metres(f.depth[camera.name], camera)
                                                 for f in rendered), camera, fps=scenario.fps)
    (tmp_path / "pose.json").write_text(json.dumps({"world_from_camera": camera.world_from_camera.tolist()}))
    source = open_source(bag, pose=tmp_path / "pose.json")
    from_bag, from_folder = track_recording(source, seed=0), track_recording(Recording(tmp_path / "rec"), seed=0)
    assert from_bag.num_frames == 20 and list(from_bag.tracks) == list(from_folder.tracks) != []
    for track, (joints, visible) in from_folder.tracks.items():
        np.testing.assert_array_equal(from_bag.tracks[track][0], joints)
        np.testing.assert_array_equal(from_bag.tracks[track][1], visible)


@pytest.mark.shared
def test_the_shared_realsense_bag_decodes_bit_exactly():
    data = shared_data_dir()
    folder = None if data is None else data / "sensors" / "realsense"
    if folder is None or not (folder / "single_depth_color_640x480.bag").is_file():
        pytest.skip("shared RealSense bag (../shared/data/sensors/realsense) not present")
    source = BagSource(folder / "single_depth_color_640x480.bag")
    camera = source.cameras[0]
    assert source.topic == "/device_0/sensor_0/Depth_0/image/data" and source.encoding == "mono16"
    assert (camera.width, camera.height, source.num_frames, source.fps, camera.depth_scale) == (640, 480, 2, 6.0, 0.001)
    np.testing.assert_allclose((camera.fx, camera.fy, camera.cx, camera.cy), (390.43, 390.43, 331.39, 242.19),
                               atol=0.005)
    first = raw_depth_from_metres(next(source.frames()).depth["cam0"], camera)
    np.testing.assert_array_equal(first, np.load(folder / "depth_0_uint16.npy"))
    assert [f.time for f in source.frames()] == pytest.approx([0.0, 0.166676], abs=1e-6)
