"""The floor found in a camera's own frames gives its height and tilt (issue 25, part 2)."""

import math

import numpy as np
import pytest

from occupose.camera import Camera, points_from_depth
from occupose.config import FloorConfig
from occupose.geometry.floor import Floor, fit_floor, plane_inliers
from occupose.io.recording import Recording, RecordingWriter
from occupose.io.sources import HeightTilt, NoWorldPoseError, open_source, place_from_floor, placement, without_pose
from occupose.synth.catalogue import render_scenario


@pytest.fixture(scope="module", params=[("no_occlusion", "kinect_v2"), ("top_view_arms", None),
                                        ("random-8", "realsense_d435")])
def recording(request, tmp_path_factory):
    name, sensor = request.param
    out = tmp_path_factory.mktemp("floor") / name
    render_scenario(name, out, seed=0, frames=FloorConfig().frames, sensor=sensor)
    return Recording(out)


def test_height_and_tilt_within_2_cm_and_1_degree(recording):
    truth, = placement(recording)
    found, = placement(place_from_floor(without_pose(recording)))
    assert found["pose"] == "floor" and truth["pose"] == "recording"
    assert abs(found["height_m"] - truth["height_m"]) < 0.02
    assert abs(found["tilt_deg"] - truth["tilt_deg"]) < 1.0 and abs(found["roll_deg"]) < 1.0


def test_the_floor_is_at_z_0_in_the_world_it_gives(recording):
    placed = open_source(recording.path, find_floor=True)
    frame = next(placed.frames(color=False))
    camera = placed.cameras[0]
    points, _ = points_from_depth(frame.depth[camera.name], camera)
    true_points, _ = points_from_depth(frame.depth[camera.name], recording.cameras[0])
    floor = np.abs(true_points[:, 2]) < 0.03  # the points the truth has on the floor
    assert floor.mean() > 0.05
    # the floor as measured (a random scene's sensor has a systematic depth bias) is at z = 0
    assert abs(np.median(points[floor, 2])) < 0.005


def test_gravity_picks_the_floor_and_a_table_top_is_not_it():
    rng = np.random.default_rng(0)
    pose = HeightTilt(1.5, 30.0).world_from_camera()
    floor = np.column_stack([rng.uniform(-2, 2, 6000), rng.uniform(1, 5, 6000), np.zeros(6000)])
    table = np.column_stack([rng.uniform(-1, 1, 5000), rng.uniform(1.5, 2.5, 5000), np.full(5000, 0.75)])
    wall = np.column_stack([rng.uniform(-2, 2, 8000), np.full(8000, 5.0), rng.uniform(0, 2.5, 8000)])
    world = np.concatenate([floor, table, wall])
    camera = (world - pose[:3, 3]) @ pose[:3, :3]
    camera = camera[camera[:, 2] > 0.3]
    gravity = pose[:3, :3].T @ [0.0, 0.0, -1.0]
    for found in (fit_floor(camera, FloorConfig()), fit_floor(camera, FloorConfig(), gravity=gravity)):
        assert found.height == pytest.approx(1.5, abs=0.01) and found.tilt == pytest.approx(30.0, abs=0.5)
    # an IMU that disagrees with every plane: no floor
    assert fit_floor(camera, FloorConfig(), gravity=pose[:3, :3].T @ [1.0, 0.0, 0.0]) is None


def test_a_plane_at_the_top_of_the_image_is_no_floor():
    rng = np.random.default_rng(1)
    ceiling = np.column_stack([rng.uniform(-2, 2, 5000), np.full(5000, -1.2), rng.uniform(0.5, 4, 5000)])
    assert fit_floor(ceiling, FloorConfig()) is None


def test_world_from_camera_is_the_height_tilt_pose():
    tilt = math.radians(20.0)
    floor = Floor(np.array([0.0, -math.cos(tilt), -math.sin(tilt)]), 1.2, 0.5)
    np.testing.assert_allclose(floor.world_from_camera(), HeightTilt(1.2, 20.0).world_from_camera(), atol=1e-12)
    down = Floor(np.array([0.0, 0.0, -1.0]), 2.9, 0.9)
    np.testing.assert_allclose(down.world_from_camera(), HeightTilt(2.9, 90.0).world_from_camera(), atol=1e-12)


def test_no_floor_in_view_says_how_to_give_the_pose(tmp_path):
    camera = Camera("cam0", 32, 24, 30.0, 30.0, 15.5, 11.5)
    with RecordingWriter(tmp_path / "rec", [camera], 30.0) as writer:
        for _ in range(3):
            writer.write_frame({"cam0": np.zeros((24, 32), np.uint16)})
    with pytest.raises(NoWorldPoseError, match="no floor was found .* --camera-height H --tilt DEGREES"):
        open_source(tmp_path / "rec", find_floor=True)


def test_plane_inliers_counts_as_the_distance_matrix_does():
    rng = np.random.default_rng(3)
    points = rng.uniform(-2.0, 2.0, (5000, 3))
    points[:2000, 2] = 0.01 * rng.standard_normal(2000)  # a plane for some hypotheses to find
    tolerance = 0.02 + 0.01 * np.abs(points[:, 2])
    normals = rng.standard_normal((64, 3))
    normals[:8] = [0.0, 0.0, 1.0]
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    offsets = rng.uniform(-0.5, 0.5, 64)
    offsets[:8] = 0.0
    expected = (np.abs(points @ normals.T + offsets) < tolerance[:, None]).sum(axis=0)
    counts = plane_inliers(points, tolerance, normals, offsets)
    assert counts.dtype == np.int64 and counts[:8].min() >= 1900  # 2 sigma: about 2 % of them are off the plane
    np.testing.assert_array_equal(counts, expected)
