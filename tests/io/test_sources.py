"""The frame-source interface: the registry, the folder reader, poses given by the user."""

import json
import math

import numpy as np
import pytest

from occupose.camera import Camera, points_from_depth
from occupose.io.recording import Recording, RecordingWriter
from occupose.io.sources import (READERS, FrameSource, HeightTilt, SourceError, StreamSource,
                                 open_source, pose_from_file, reader_for, require)


class NpyFolder(StreamSource):
    """A reader of a throwaway format for these tests: ``frames.npy``, (T, H, W) uint16 mm,
    one camera, no pose."""

    def __init__(self, path):
        self.path = path
        self._depth = np.load(path / "frames.npy", mmap_mode="r")
        self.fps, self.num_frames = 10.0, len(self._depth)
        height, width = self._depth.shape[1:]
        self.cameras = [Camera("cam0", width, height, 50.0, 50.0, (width - 1) / 2, (height - 1) / 2)]

    def _raw_frames(self, color):
        for index, image in enumerate(self._depth):  # a device clock starting at 1000 s, frame 2 late
            yield {"cam0": np.array(image)}, {}, 1000.0 + 0.1 * index + (0.003 if index == 2 else 0.0)


@pytest.fixture
def npy_source(tmp_path):
    depth = np.full((5, 12, 16), 2000, np.uint16)
    depth[:, 8:] = 1500
    depth[3] = 0
    np.save(tmp_path / "frames.npy", depth)
    return NpyFolder(tmp_path)


def test_stream_source_frames_in_metres_and_by_index(npy_source):
    frames = list(npy_source.frames())
    assert [f.index for f in frames] == [0, 1, 2, 3, 4]
    assert frames[0].depth["cam0"].dtype == np.float32
    assert frames[0].depth["cam0"][0, 0] == np.float32(2.0) and frames[0].depth["cam0"][9, 0] == np.float32(1.5)
    assert not frames[3].depth["cam0"].any()
    assert [f.time for f in frames] == pytest.approx([0.0, 0.1, 0.203, 0.3, 0.4])
    assert npy_source.frame(4).index == 4
    with pytest.raises(SourceError, match=r"frame index 5 out of range; the recording has frames 0..4"):
        npy_source.frame(5)
    assert isinstance(npy_source, FrameSource) and not npy_source.has_groundtruth


def test_placed_copy_has_the_poses_and_leaves_the_source(npy_source):
    pose = HeightTilt(1.5, 30.0).world_from_camera()
    placed = npy_source.placed({"cam0": pose})
    assert placed.pose_known and not npy_source.pose_known
    np.testing.assert_array_equal(placed.cameras[0].world_from_camera, pose)
    np.testing.assert_array_equal(npy_source.cameras[0].world_from_camera, np.eye(4))
    assert len(list(placed.frames())) == 5


@pytest.mark.parametrize("tilt", [0.0, 25.0, 90.0])
def test_height_tilt_puts_the_camera_there(tilt):
    pose = HeightTilt(2.0, tilt).world_from_camera()
    np.testing.assert_allclose(pose[:3, 3], (0.0, 0.0, 2.0))
    down = math.degrees(math.asin(-pose[2, 2]))  # the optical axis below the horizontal
    assert down == pytest.approx(tilt, abs=1e-9)
    assert pose[2, 0] == pytest.approx(0.0, abs=1e-12)  # no roll: image x stays horizontal


def test_height_tilt_image_centre_ray_meets_the_floor_where_geometry_says():
    camera = Camera("c", 11, 11, 10.0, 10.0, 5.0, 5.0, 0.001, HeightTilt(1.2, 45.0).world_from_camera())
    depth = np.zeros((11, 11), np.float32)
    depth[5, 5] = 1.2 * math.sqrt(2.0)  # along the axis at 45 degrees the floor is h * sqrt(2) away
    point = points_from_depth(depth, camera)[0].reshape(3)
    np.testing.assert_allclose(point, (0.0, 1.2, 0.0), atol=1e-6)


@pytest.mark.parametrize("height, tilt, message", [(0.0, 10.0, "height must be a positive"),
                                                  (float("nan"), 10.0, "height"), (1.0, 95.0, "tilt must be")])
def test_height_tilt_refuses_bad_values(height, tilt, message):
    with pytest.raises(ValueError, match=message):
        HeightTilt(height, tilt)


def test_pose_file_for_every_camera_or_per_camera(tmp_path):
    pose = HeightTilt(1.0, 10.0).world_from_camera()
    both = tmp_path / "both.json"
    both.write_text(json.dumps({"world_from_camera": pose.tolist()}))
    assert set(pose_from_file(both, ["a", "b"])) == {"a", "b"}
    each = tmp_path / "each.json"
    each.write_text(json.dumps({"cameras": {"a": {"world_from_camera": pose.tolist()}}}))
    np.testing.assert_array_equal(pose_from_file(each, ["a"])["a"], pose)
    with pytest.raises(SourceError, match=r"no pose for camera\(s\) \['b'\]"):
        pose_from_file(each, ["a", "b"])
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"world_from_camera": np.diag([2.0, 1.0, 1.0, 1.0]).tolist()}))
    with pytest.raises(SourceError, match="bad.json: camera 'a'.*not rigid"):
        pose_from_file(bad, ["a"])
    (tmp_path / "junk.json").write_text("{")
    with pytest.raises(SourceError, match="junk.json: not a readable JSON pose file"):
        pose_from_file(tmp_path / "junk.json", ["a"])


def write_folder(path):
    camera = Camera("cam0", 8, 6, 10.0, 10.0, 3.5, 2.5, 0.001, HeightTilt(1.0, 20.0).world_from_camera())
    with RecordingWriter(path, [camera], fps=15.0) as writer:
        for value in (1000, 1200):
            writer.write_frame({"cam0": np.full((6, 8), value, np.uint16)})
    return path


def test_folder_recordings_open_as_themselves(tmp_path):
    folder = write_folder(tmp_path / "rec")
    source = open_source(folder)
    assert isinstance(source, Recording) and source.num_frames == 2 and source.fps == 15.0
    assert reader_for(folder).name == "folder" and list(READERS)[0] == "folder"
    with pytest.raises(SourceError, match="has its own world pose; drop the pose option"):
        open_source(folder, pose=HeightTilt(1.0, 0.0))
    with pytest.raises(SourceError, match=r"takes no reader options, got \['topic'\]"):
        open_source(folder, topic="/depth")


def test_unknown_paths_and_formats_name_what_is_known(tmp_path):
    (tmp_path / "notes.txt").write_text("x")
    with pytest.raises(SourceError, match=r"notes.txt: not a recording of any known format \(folder: "):
        open_source(tmp_path / "notes.txt")
    with pytest.raises(FileNotFoundError, match="no such recording"):
        open_source(tmp_path / "absent.mkv")
    with pytest.raises(SourceError, match="unknown recording format 'avi'; valid: folder"):
        open_source(tmp_path / "notes.txt", format="avi")
    with pytest.raises(FileNotFoundError, match="recording.json"):  # a folder without its header: the folder's error
        open_source(tmp_path)


def test_a_source_without_pose_is_placed_by_the_given_pose(npy_source, monkeypatch):
    from occupose.io import sources

    monkeypatch.setitem(READERS, "npy", sources.Reader("npy", "test frames", None,
                                                       lambda p: (p / "frames.npy").is_file(), NpyFolder))
    monkeypatch.setattr(sources, "READERS", {"npy": READERS["npy"], **READERS})
    placed = open_source(npy_source.path, pose=HeightTilt(1.3, 15.0))
    assert placed.pose_known and placed.cameras[0].position[2] == pytest.approx(1.3)


def test_missing_library_names_the_extra():
    with pytest.raises(ImportError, match=r"pip install 'occupose\[kinect\]'"):
        require("occupose_no_such_module", "kinect", "reading Azure Kinect recordings")
