"""TUM RGB-D folders through open_source: folders written here, read back bit-exactly, and
the --tum-camera option of the command line."""

import json

import numpy as np
import pytest
from click.testing import CliRunner
from PIL import Image

from occupose.camera import Camera, raw_depth_from_metres
from occupose.io.recording import Recording, RecordingWriter
from occupose.io.sources import HeightTilt, SourceError, open_source, reader_for
from occupose.io.tum import DEPTH_FACTOR, TUM_CAMERAS, TumSource, intrinsics_for, read_list
from occupose.testing import random_raw_depths, raw_frames, write_tum_folder

POSE = HeightTilt(1.5, 20.0)
INTRINSICS = {"fx": 250.25, "fy": 251.5, "cx": 31.75, "cy": 23.25}


def raw_depths(count, size=(48, 64), seed=0):
    """``count`` (H, W) uint16 images (metres * 5000), a tenth of them 0 (no measurement)."""
    return random_raw_depths(count, size, 1500, 45000, seed)



def test_a_tum_folder_reads_back_bit_exactly_with_its_timestamps(tmp_path):
    depths = raw_depths(4, (480, 640))
    stamps = [1305031102.175304, 1305031102.211214, 1305031102.243211, 1305031102.278258]  # freiburg1_xyz's
    path = write_tum_folder(tmp_path / "rgbd_dataset_freiburg1_xyz", depths, stamps=stamps)
    source = open_source(path, pose=POSE)
    assert reader_for(path).name == "tum" and isinstance(source, TumSource) and source.pose_known
    camera = source.cameras[0]
    assert (camera.width, camera.height, camera.fx, camera.fy, camera.cx, camera.cy) == (640, 480, *TUM_CAMERAS["fr1"])
    assert camera.depth_scale == 1 / DEPTH_FACTOR == 0.0002 and source.num_frames == 4 and source.color_cameras == ()
    assert source.fps == round(1 / 0.035047, 3)  # the median interval
    raw, times = raw_frames(source)
    np.testing.assert_array_equal(raw, depths)
    np.testing.assert_allclose(times, np.array(stamps) - stamps[0], atol=1e-6)
    metres = source.frame(1).depth["cam0"]
    assert metres[3, 4] == np.float32(depths[1, 3, 4] * 0.0002) and metres[depths[1] == 0].max() == 0.0


def test_the_camera_by_name_from_the_folder_or_given(tmp_path):
    for number in (1, 2, 3):
        folder = tmp_path / f"rgbd_dataset_freiburg{number}_desk"
        assert intrinsics_for(folder, None) == TUM_CAMERAS[f"fr{number}"]
    plain = tmp_path / "mine"
    assert intrinsics_for(plain, "fr2") == intrinsics_for(plain, "freiburg2") == TUM_CAMERAS["fr2"]
    assert intrinsics_for(plain, INTRINSICS) == (250.25, 251.5, 31.75, 23.25)
    (tmp_path / "cam.json").write_text(json.dumps(INTRINSICS))
    assert intrinsics_for(plain, tmp_path / "cam.json") == (250.25, 251.5, 31.75, 23.25)
    with pytest.raises(SourceError, match=r"mine: which TUM camera recorded it is not in the folder's name "
                                          r"\(freiburg1, freiburg2 or freiburg3\); give it with --tum-camera"):
        intrinsics_for(plain, None)
    with pytest.raises(SourceError, match=r"unknown TUM camera 'fr4'; valid: fr1, fr2, fr3, or a JSON file"):
        intrinsics_for(plain, "fr4")
    (tmp_path / "bad.json").write_text(json.dumps({"fx": 1.0}))
    with pytest.raises(SourceError, match=r"bad.json: expected \{\"fx\": ..., \"fy\""):
        intrinsics_for(plain, tmp_path / "bad.json")


def test_a_folder_of_another_size_takes_its_camera_from_a_file(tmp_path):
    depths = raw_depths(2)
    path = write_tum_folder(tmp_path / "freiburg3_small", depths)
    with pytest.raises(SourceError, match=r"a 64x48 depth image; the TUM cameras' intrinsics are for 640x480"):
        open_source(path, pose=POSE)
    source = open_source(path, pose=POSE, camera=INTRINSICS)
    assert (source.cameras[0].fx, source.cameras[0].cx) == (250.25, 31.75)
    np.testing.assert_array_equal(raw_frames(source)[0], depths)


def test_list_files_skip_comments_and_name_bad_lines(tmp_path):
    listing = tmp_path / "depth.txt"
    listing.write_text("# depth maps\n\n1.5 depth/a.png\n  # another comment\n2.0 depth/b.png\n")
    assert read_list(listing) == [(1.5, "depth/a.png"), (2.0, "depth/b.png")]
    listing.write_text("# depth maps\n1.5 depth/a.png\nhello depth/b.png\n")
    with pytest.raises(SourceError, match=r"depth.txt, line 3: expected 'timestamp filename', got 'hello depth/b"):
        read_list(listing)
    listing.write_text("# only comments\n")
    with pytest.raises(SourceError, match=r"depth.txt: no 'timestamp filename' lines"):
        read_list(listing)


def test_bad_folders_are_source_errors_naming_the_file(tmp_path):
    good = write_tum_folder(tmp_path / "good", raw_depths(3))
    missing = write_tum_folder(tmp_path / "missing", raw_depths(3))
    sorted((missing / "depth").glob("*.png"))[1].unlink()
    rgb = write_tum_folder(tmp_path / "rgb", raw_depths(1))
    Image.fromarray(np.zeros((48, 64, 3), np.uint8)).save(next((rgb / "depth").glob("*.png")))
    sizes = write_tum_folder(tmp_path / "sizes", raw_depths(1))
    write_tum_folder(tmp_path / "sizes_b", raw_depths(1, (40, 64)), start=2e9)
    with open(sizes / "depth.txt", "a") as listing:
        listing.write(f"2000000000.000000 {(tmp_path / 'sizes_b' / 'depth' / '2000000000.000000.png').resolve()}\n")
    cases = [("missing", {"camera": INTRINSICS}, r"missing/depth.txt: 1 listed file\(s\) missing: depth/"),
             ("rgb", {"camera": INTRINSICS}, r"\.png: expected a 16-bit grayscale PNG, got a PNG image of mode "
                                             r"'RGB'"),
             ("good", {"camera": "fr9"}, r"unknown TUM camera 'fr9'"),
             ("good", {"topic": "/x"}, r"good: a TUM RGB-D folder takes only the reader option camera, got "
                                       r"\['topic'\]")]
    for name, options, message in cases:
        with pytest.raises(SourceError, match=message):
            open_source(tmp_path / name, pose=POSE, **options)
    source = open_source(sizes, pose=POSE, camera=INTRINSICS)
    with pytest.raises(SourceError, match=r"a 64x40 depth image in a folder of 64x48"):
        list(source.frames())
    with pytest.raises(SourceError, match=r"no depth.txt"):
        TumSource(tmp_path)


def test_reading_streams_with_flat_memory(tmp_path):
    import tracemalloc

    path = write_tum_folder(tmp_path / "long", (np.full((240, 320), 5000 + i, np.uint16) for i in range(120)))
    source = open_source(path, pose=POSE, camera=INTRINSICS)  # 18 MB of depth
    tracemalloc.start()
    try:
        for index, frame in enumerate(source.frames()):
            assert frame.depth["cam0"][0, 0] == np.float32((5000 + index) * 0.0002)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert index == 119 and peak < 3e6, f"peak {peak / 1e6:.1f} MB while reading 18 MB of frames"


def test_a_tum_folder_tracks_as_the_folder_it_was_made_from(tmp_path, walk):
    from dataclasses import replace

    from occupose.cli import main

    scenario, rendered = walk
    camera = replace(scenario.cameras[0], depth_scale=1 / DEPTH_FACTOR)  # the folder at TUM's 0.2 mm too
    rendered = rendered[:20]
    raw = [raw_depth_from_metres(f.depth[camera.name], camera) for f in rendered]
    with RecordingWriter(tmp_path / "rec", [camera], fps=scenario.fps) as writer:
        for image in raw:
            writer.write_frame({camera.name: image})
    tum = write_tum_folder(tmp_path / "tum", raw, fps=scenario.fps)
    (tmp_path / "cam.json").write_text(json.dumps({"fx": camera.fx, "fy": camera.fy, "cx": camera.cx,
                                                   "cy": camera.cy}))
    (tmp_path / "pose.json").write_text(json.dumps({"world_from_camera": camera.world_from_camera.tolist()}))
    runner = CliRunner()
    result = runner.invoke(main, ["track", str(tum), "--out", str(tmp_path / "run_tum"), "--tum-camera",
                                  str(tmp_path / "cam.json"), "--world-from-camera", str(tmp_path / "pose.json")])
    assert result.exit_code == 0, result.output
    result = runner.invoke(main, ["track", str(tmp_path / "rec"), "--out", str(tmp_path / "run_folder")])
    assert result.exit_code == 0, result.output
    from_tum = (tmp_path / "run_tum" / "tracks.csv").read_text()
    assert from_tum == (tmp_path / "run_folder" / "tracks.csv").read_text() and from_tum.count("\n") > 20
    assert Recording(tmp_path / "rec").num_frames == open_source(tum, pose=POSE,
                                                                 camera=tmp_path / "cam.json").num_frames
