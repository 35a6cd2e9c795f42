import math

import numpy as np
import pytest

from occupose.camera import (
    CAMERA_KEYS,
    CAMERA_PRESETS,
    Camera,
    SensorSpec,
    camera_from_dict,
    camera_preset,
    look_at,
    pixels_from_points,
    points_at_pixels,
    points_from_depth,
    raw_depth_from_metres,
    sensor_spec,
)


def small_camera(pose=None) -> Camera:
    return Camera("cam0", 8, 6, fx=5.0, fy=4.0, cx=3.5, cy=2.5,
                  world_from_camera=np.eye(4) if pose is None else pose)


def tilted_pose() -> np.ndarray:
    return look_at((2.0, -3.0, 2.5), (0.3, 0.5, 1.0))


# ------------------------------------------------------------------ Camera


def test_camera_stores_a_read_only_float_copy_of_its_pose():
    pose = tilted_pose()
    camera = small_camera(pose)
    pose[0, 3] = 99.0
    assert camera.world_from_camera.dtype == np.float64
    assert camera.world_from_camera[0, 3] == 2.0
    with pytest.raises(ValueError):
        camera.world_from_camera[0, 3] = 1.0


def test_camera_from_world_is_the_inverse():
    camera = small_camera(tilted_pose())
    np.testing.assert_allclose(camera.camera_from_world @ camera.world_from_camera, np.eye(4), atol=1e-12)
    np.testing.assert_array_equal(camera.position, [2.0, -3.0, 2.5])
    np.testing.assert_array_equal(camera.intrinsic_matrix, [[5, 0, 3.5], [0, 4, 2.5], [0, 0, 1]])


def test_to_dict_matches_the_recording_json_entry_and_round_trips():
    camera = small_camera(tilted_pose())
    entry = camera.to_dict()
    assert list(entry) == list(CAMERA_KEYS)
    assert entry["width"] == 8 and isinstance(entry["width"], int)
    assert entry["depth_scale"] == 0.001
    assert len(entry["world_from_camera"]) == 4 and all(len(r) == 4 for r in entry["world_from_camera"])
    assert camera_from_dict(entry) == camera
    assert camera_from_dict(entry) != small_camera()


@pytest.mark.parametrize(
    "change, message",
    [
        ({"width": 0}, "width must be a positive integer"),
        ({"height": 4.5}, "height must be a positive integer"),
        ({"fx": -1.0}, "fx must be a positive finite number"),
        ({"fy": float("nan")}, "fy must be a positive finite number"),
        ({"cx": float("inf")}, "cx must be a finite number"),
        ({"depth_scale": 0.0}, "depth_scale must be a positive"),
        ({"name": ""}, "non-empty string"),
        ({"name": "a/b"}, "folder name"),
        ({"fx": 10 ** 400}, "fx must be a positive finite number"),  # beyond any float: no OverflowError
        ({"cy": -(10 ** 400)}, "cy must be a finite number"),
    ],
)
def test_camera_rejects_bad_values(change, message):
    kwargs = dict(name="cam0", width=8, height=6, fx=5.0, fy=4.0, cx=3.5, cy=2.5) | change
    with pytest.raises(ValueError, match=message):
        Camera(**kwargs)


@pytest.mark.parametrize(
    "pose, message",
    [
        (np.eye(3), r"\(4, 4\) matrix"),
        (np.full((4, 4), np.nan), "must be finite"),
        (np.diag([1.0, 1.0, 1.0, 2.0]), "last row"),
        (np.diag([1.0, 1.1, 1.0, 1.0]), "not rigid"),
        (np.diag([1.0, 1.0, -1.0, 1.0]), r"det\(R\) = -1"),
        # R^T R overflows to inf - inf = NaN: still not rigid, and no RuntimeWarning
        (np.block([[np.array([[1, -1, 1], [1, 1, -1], [-1, 1, 1]]) * 1e200, np.zeros((3, 1))],
                   [np.zeros((1, 3)), np.ones((1, 1))]]), "not rigid"),
        ([[10 ** 400, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]], "must be a \\(4, 4\\) array of numbers"),
    ],
)
@pytest.mark.filterwarnings("error")
def test_camera_rejects_non_rigid_poses(pose, message):
    with pytest.raises(ValueError, match=message):
        small_camera(pose)


def test_camera_from_dict_errors_name_the_source():
    entry = small_camera().to_dict()
    del entry["fx"]
    with pytest.raises(ValueError, match=r"^rec.json: cameras\[0\]: missing key\(s\) \['fx'\]"):
        camera_from_dict(entry, source="rec.json: cameras[0]")
    with pytest.raises(ValueError, match=r"unknown key\(s\) \['fX'\]"):
        camera_from_dict(small_camera().to_dict() | {"fX": 1.0})
    with pytest.raises(ValueError, match="4x4 list of numbers"):
        camera_from_dict(small_camera().to_dict() | {"world_from_camera": [[1, 0, 0, 0]]})
    with pytest.raises(ValueError, match="^src: camera 'cam0': width must be a positive integer"):
        camera_from_dict(small_camera().to_dict() | {"width": "8"}, source="src")


# ------------------------------------------------------------------ projection


def reference_points(depth_m: np.ndarray, camera: Camera) -> np.ndarray:
    """Slow per-pixel back-projection to world points, pixels in row-major order."""
    out = []
    for v in range(camera.height):
        for u in range(camera.width):
            z = depth_m[v, u]
            if z > 0:
                p = np.array([(u - camera.cx) * z / camera.fx, (v - camera.cy) * z / camera.fy, z, 1.0])
                out.append((camera.world_from_camera @ p)[:3])
    return np.array(out)


def test_points_from_depth_matches_a_per_pixel_reference(rng):
    camera = small_camera(tilted_pose())
    raw = rng.integers(500, 4000, size=(6, 8)).astype(np.uint16)
    raw[rng.random((6, 8)) < 0.3] = 0
    points, pixels = points_from_depth(raw, camera)
    assert points.dtype == np.float64 and pixels.dtype == np.int64
    np.testing.assert_array_equal(pixels, np.flatnonzero(raw))
    np.testing.assert_allclose(points, reference_points(raw * 0.001, camera), atol=1e-12)
    # float metres give the same points; NaN, inf and negatives count as no measurement
    metres = raw * 0.001
    metres[metres == 0] = np.array([np.nan, -1.0, np.inf, 0.0])[rng.integers(0, 4, size=(metres == 0).sum())]
    points_f, pixels_f = points_from_depth(metres.astype(np.float64), camera)
    np.testing.assert_array_equal(pixels_f, pixels)
    np.testing.assert_allclose(points_f, points, atol=1e-12)


def test_points_at_chosen_pixels_are_those_rows_of_points_from_depth(rng):
    camera = small_camera(tilted_pose())
    raw = rng.integers(500, 4000, size=(6, 8)).astype(np.uint16)
    raw[rng.random((6, 8)) < 0.3] = 0
    for depth in (raw, raw * np.float32(0.001)):
        points, pixels = points_from_depth(depth, camera)
        chosen = np.sort(rng.choice(pixels.size, 9, replace=False))
        for frame in ("world", "camera"):
            every, _ = points_from_depth(depth, camera, frame=frame)
            np.testing.assert_array_equal(points_at_pixels(depth, pixels[chosen], camera, frame=frame), every[chosen])
    with pytest.raises(ValueError, match="must be a"):
        points_at_pixels(raw[:, :4], pixels, camera)


def test_points_in_camera_frame_have_depth_as_z():
    camera = small_camera(tilted_pose())
    depth = np.full((6, 8), 2.0, dtype=np.float32)
    points, pixels = points_from_depth(depth, camera, frame="camera")
    assert pixels.size == 48
    np.testing.assert_array_equal(points[:, 2], 2.0)
    # pixel (u=0, v=0): x = (0 - 3.5) * 2 / 5, y = (0 - 2.5) * 2 / 4
    np.testing.assert_allclose(points[0], [-1.4, -1.25, 2.0])


def test_round_trip_pixels_to_points_to_pixels_is_exact(rng):
    camera = camera_preset("kinect_v1", world_from_camera=tilted_pose())
    raw = rng.integers(0, 6000, size=(480, 640)).astype(np.uint16)
    points, pixels = points_from_depth(raw, camera)
    uv, z = pixels_from_points(points, camera)
    v, u = np.divmod(pixels, 640)
    np.testing.assert_allclose(uv[:, 0], u, rtol=0, atol=1e-9)
    np.testing.assert_allclose(uv[:, 1], v, rtol=0, atol=1e-9)
    np.testing.assert_allclose(z, raw.ravel()[pixels] * 0.001, rtol=0, atol=1e-9)


def test_points_behind_the_camera_get_non_positive_depth():
    camera = small_camera()
    uv, z = pixels_from_points(np.array([[0.0, 0.0, -1.0], [1.0, 0.0, 0.0], [0.0, 0.0, 2.0]]), camera)
    assert z[0] < 0 and z[1] == 0 and z[2] == 2.0
    np.testing.assert_array_equal(uv[2], [3.5, 2.5])


def test_projection_input_checks():
    camera = small_camera()
    with pytest.raises(ValueError, match=r"shape \(6, 8\), got \(8, 6\)"):
        points_from_depth(np.zeros((8, 6), np.uint16), camera)
    with pytest.raises(ValueError, match="uint16 raw values or float metres, got int32"):
        points_from_depth(np.zeros((6, 8), np.int32), camera)
    with pytest.raises(ValueError, match=r"frame must be one of \['world', 'camera'\]"):
        points_from_depth(np.zeros((6, 8), np.uint16), camera, frame="image")
    with pytest.raises(ValueError, match=r"shape \(N, 3\)"):
        pixels_from_points(np.zeros((4, 2)), camera)


def test_raw_depth_from_metres_rounds_and_marks_missing():
    camera = Camera("c", 3, 2, 1.0, 1.0, 1.0, 0.5)
    depth = np.array([[1.2344, 1.2346, 0.0], [np.nan, -2.0, 70.0]])
    np.testing.assert_array_equal(raw_depth_from_metres(depth, camera), [[1234, 1235, 0], [0, 0, 0]])
    assert raw_depth_from_metres(depth, camera).dtype == np.uint16
    with pytest.raises(ValueError, match="float"):
        raw_depth_from_metres(np.zeros((2, 3), np.uint16), camera)


# ------------------------------------------------------------------ look_at


def test_look_at_looks_at_the_target_with_image_up_along_world_up():
    eye, target = np.array([3.0, -2.0, 2.4]), np.array([0.5, 1.0, 0.9])
    camera = camera_preset("kinect_v2", world_from_camera=look_at(eye, target))
    uv, z = pixels_from_points(np.array([target, target + [0, 0, 0.5]]), camera)
    np.testing.assert_allclose(uv[0], [camera.cx, camera.cy], atol=1e-9)
    np.testing.assert_allclose(z[0], np.linalg.norm(target - eye))
    assert uv[1, 1] < uv[0, 1]  # a point above the target appears higher in the image
    assert abs(uv[1, 0] - uv[0, 0]) < 1e-9  # camera x axis is horizontal
    pose = camera.world_from_camera
    assert abs(pose[2, 0]) < 1e-12 and np.linalg.det(pose[:3, :3]) == pytest.approx(1.0)


def test_look_at_straight_down_uses_world_y_as_image_up():
    pose = look_at((1.0, 2.0, 3.0), (1.0, 2.0, 0.0))
    np.testing.assert_allclose(pose[:3, :3], [[1, 0, 0], [0, -1, 0], [0, 0, -1]], atol=1e-12)
    camera = small_camera(pose)
    uv, z = pixels_from_points(np.array([[1.5, 2.0, 0.0], [1.0, 2.5, 0.0]]), camera)
    assert uv[0, 0] > camera.cx  # world +x is image right
    assert uv[1, 1] < camera.cy  # world +y is image up
    np.testing.assert_allclose(z, 3.0)
    # looking along y with up = +y falls back to world +z as the up hint
    pose = look_at((0.0, 0.0, 1.0), (0.0, 5.0, 1.0), up=(0.0, 1.0, 0.0))
    np.testing.assert_allclose(pose[:3, 1], [0, 0, -1], atol=1e-12)


def test_look_at_rejects_degenerate_input():
    with pytest.raises(ValueError, match="eye and target must differ"):
        look_at((1, 1, 1), (1, 1, 1))
    with pytest.raises(ValueError, match="up must be a non-zero"):
        look_at((0, 0, 0), (1, 0, 0), up=(0, 0, 0))
    with pytest.raises(ValueError, match="finite"):
        look_at((0, 0, np.nan), (1, 0, 0))


# ------------------------------------------------------------------ presets


def test_presets_carry_the_documented_sensor_values():
    assert sorted(CAMERA_PRESETS) == ["azure_nfov", "kinect_v1", "kinect_v2", "realsense_d435"]
    assert CAMERA_PRESETS["kinect_v1"] == SensorSpec(
        "kinect_v1", 640, 480, 594.21, 591.04, 339.5, 242.7, 0.5, 4.5, "structured_light")
    assert CAMERA_PRESETS["kinect_v2"] == SensorSpec("kinect_v2", 512, 424, 365.5, 365.5, 254.9, 205.4, 0.5, 4.5, "tof")
    assert CAMERA_PRESETS["realsense_d435"] == SensorSpec(
        "realsense_d435", 640, 480, 382.6, 382.6, 319.0, 246.3, 0.3, 3.0, "structured_light")
    azure = sensor_spec("azure_nfov")
    assert (azure.width, azure.height, azure.cx, azure.cy, azure.noise) == (640, 576, 332.78, 348.83, "tof")
    assert (azure.near, azure.far) == (0.5, 3.86)
    # 75 x 65 degree field of view
    # factory calibration: normalised fx 0.49278 of the 1024-px sensor; pinhole FOV ~65 x 59 deg
    assert azure.fx == pytest.approx(0.4927809 * 1024, abs=0.01) and azure.fy == pytest.approx(0.4929028 * 1024, abs=0.01)
    assert math.degrees(2 * math.atan(320 / azure.fx)) == pytest.approx(64.8, abs=0.1)


def test_camera_preset_builds_a_camera():
    pose = look_at((0, -3, 2), (0, 0, 1))
    camera = camera_preset("realsense_d435", world_from_camera=pose, camera_name="top")
    assert camera == Camera("top", 640, 480, 382.6, 382.6, 319.0, 246.3, 0.001, pose)
    assert camera_preset("kinect_v1").name == "cam0"
    np.testing.assert_array_equal(camera_preset("kinect_v1").world_from_camera, np.eye(4))


def test_unknown_preset_lists_valid_names():
    with pytest.raises(ValueError, match=r"unknown camera preset 'kinect'; valid names: \['azure_nfov', 'kinect_v1'"):
        camera_preset("kinect")
