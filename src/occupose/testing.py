"""Helpers for the tests and benchmarks only: ground truth the tracker never sees.

Nothing in ``src/`` imports this module, and it may import anything, the scene generator
included. It holds what tests and benchmarks use to feed a stage the truth (the true
bodies' capsules, one person's observations straight from the renderer) or to score a
stage against it (foreground from the grid, track -> person by pixel overlap).

- :func:`capsules_from_primitives`: capsules covering a rendered body, to hold the true
  bodies in the occupancy grid (:func:`occupose.grid.hold.cells_near_capsules`);
- :func:`foreground_from_grid`: the pixels whose 3D point lies in a moving grid cell;
- :func:`persons_from_tracks`: the ground-truth person of each track id, by pixel overlap;
- :func:`person_observations` and :data:`UPPER_BODY_PARTS`: one person's likelihood
  observations taken from the renderer's labels (stage 3 without stages 1-2);
- :func:`folder_snapshot`: every entry under a folder, to tell that a command changed
  nothing there;
- :func:`write_depth_bag`, :func:`write_bag`, :func:`image_message`,
  :func:`camera_info_message`: ROS 1 / ROS 2 bags of depth images written with rosbags;
- :func:`write_depth_mkv`, :func:`azure_calibration`: Azure Kinect style ``.mkv`` files of
  depth images written with PyAV;
- :func:`write_tum_folder`: TUM RGB-D folders of depth images.
"""

from __future__ import annotations

import hashlib
import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from occupose.camera import Camera
from occupose.geometry.primitives import BOX, ROUND_CONE, Primitives
from occupose.grid.occupancy import M, cells_from_depth
from occupose.grid.spec import GridSpec
from occupose.joints import PARTS
from occupose.likelihood import View, observation_from_views
from occupose.synth.generate import frames
from occupose.synth.scenarios import Scenario

# ------------------------------------------------------------------------- the grid (stages 1-2)


def capsules_from_primitives(prims: Primitives) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Capsules covering a batch of renderer primitives (e.g. a true body,
    :func:`occupose.synth.body.primitives_from_joints`).

    Round cones are taken as they are; a box or an ellipsoid becomes the capsule along its
    longest axis, from ``center - s axis`` to ``center + s axis`` (``s`` the longest half
    extent), with the radius of its cross-section (the other two half extents' norm for a
    box, their maximum for an ellipsoid), which contains it.
    Returns a, b : (K, 3) float64 world metres and radii : (K, 2) float64 metres.
    """
    if not isinstance(prims, Primitives):
        raise ValueError(f"prims must be occupose.geometry.primitives.Primitives, got {type(prims).__name__}")
    cone = prims.kind == ROUND_CONE
    longest = np.argmax(prims.size, axis=1)
    rows = np.arange(len(prims))
    axis = prims.axes[rows, :, longest]  # (K, 3): the column of the longest local axis
    half = prims.size[rows, longest]
    others = np.sort(prims.size, axis=1)[:, :2]  # the two shorter half extents
    radius = np.where(prims.kind == BOX, np.hypot(others[:, 0], others[:, 1]), others[:, 1])
    a = np.where(cone[:, None], prims.center, prims.center - half[:, None] * axis)
    b = np.where(cone[:, None], prims.end, prims.center + half[:, None] * axis)
    radii = np.where(cone[:, None], prims.size[:, :2], radius[:, None])
    return np.ascontiguousarray(a), np.ascontiguousarray(b), np.ascontiguousarray(radii)


def foreground_from_grid(states: np.ndarray, spec: GridSpec, depth: np.ndarray, camera: Camera) -> np.ndarray:
    """Pixels whose back-projected 3D point lies in a moving cell (the paper's Fig. 2(d)).

    states : (nx, ny, nz) uint8 cell states (points in E cells go to their nearest occupied
        neighbour, see :func:`occupose.grid.occupancy.cells_from_depth`), or a bool cell mask (used as is)
    spec : GridSpec of ``states``; depth : (H, W) float metres or uint16 raw; camera : Camera
    Returns (H, W) bool foreground.
    """
    states = np.asarray(states)
    if states.dtype == np.bool_:
        if states.shape != spec.shape:
            raise ValueError(f"cell mask must have the grid's shape {spec.shape}, got {states.shape}")
        mask, index = states, cells_from_depth(depth, camera, spec)
    else:
        index = cells_from_depth(depth, camera, spec, states)  # checks the states: uint8, the grid's shape
        mask = states == M
    return np.where(index >= 0, mask.reshape(-1)[np.maximum(index, 0)], False)


def persons_from_tracks(assigned: Sequence[np.ndarray], truth: Sequence[np.ndarray]) -> dict[int, int]:
    """Ground-truth person of each track id by majority overlap (for scoring).

    assigned : sequence of (H, W) int track-id images (0 = nobody), e.g. over frames and cameras
    truth : sequence of (H, W) int person-id images of the same shapes (0 = nobody)
    Returns ``{track_id: person_id}`` for every track id that overlaps some person; the
    person is the one sharing the most pixels with the track over all the images.
    """
    assigned, truth = list(assigned), list(truth)
    if len(assigned) != len(truth) or any(np.shape(a) != np.shape(t) for a, t in zip(assigned, truth)):
        raise ValueError("assigned and truth must be sequences of label images of matching shapes")
    if not assigned:
        return {}
    tracks = np.concatenate([np.asarray(a).reshape(-1) for a in assigned]).astype(np.int64)
    people = np.concatenate([np.asarray(t).reshape(-1) for t in truth]).astype(np.int64)
    both = (tracks > 0) & (people > 0)
    tracks, people = tracks[both], people[both]
    if tracks.size == 0:
        return {}
    pairs, counts = np.unique(tracks * (people.max() + 1) + people, return_counts=True)
    track_of, person_of = np.divmod(pairs, people.max() + 1)
    order = np.lexsort((-counts, track_of))  # by track, most shared pixels first
    first = np.unique(track_of[order], return_index=True)[1]
    return {int(track_of[order][i]): int(person_of[order][i]) for i in first}



def mark_column(mask: np.ndarray, spec: GridSpec, x: float, y: float, *, width: float = 0.3, depth: float = 0.1,
                z_low: float = 0.0, z_high: float = 1.7) -> np.ndarray:
    """Mark the cells of a box centred at (``x``, ``y``) metres, ``width`` x ``depth`` across and
    from ``z_low`` to ``z_high`` high, in the cell mask ``mask`` (``spec.shape`` bool) as moving:
    a crude standing person. Returns ``mask``."""
    low = np.floor((np.array([x - width / 2, y - depth / 2, z_low]) - spec.origin) / spec.cell + 1e-9).astype(int)
    high = np.floor((np.array([x + width / 2, y + depth / 2, z_high]) - spec.origin) / spec.cell - 1e-9).astype(int) + 1
    mask[low[0]:high[0], low[1]:high[1], low[2]:high[2]] = True
    return mask


def column_blobs(spec: GridSpec, positions: Sequence[tuple[float, float]], **box) -> list:
    """The blobs (:func:`occupose.grid.blobs.blobs_from_mask`) of one :func:`mark_column` at
    each (x, y) of ``positions``; ``box`` : its size keywords."""
    from occupose.grid.blobs import blobs_from_mask

    mask = np.zeros(spec.shape, bool)
    for x, y in positions:
        mark_column(mask, spec, x, y, **box)
    return blobs_from_mask(mask, spec)[1]

# ------------------------------------------------------------------------- stage 3 alone


#: Renderer part labels of the upper body (head, chest, pelvis, arms and hands): the second
#: paper thresholds its top-view images to these pixels for its upper-body model.
UPPER_BODY_PARTS = tuple(PARTS.index(name) for name in (
    "head", "chest", "pelvis", "left_upper_arm", "left_forearm", "left_hand",
    "right_upper_arm", "right_forearm", "right_hand"))


def person_observations(scenario: Scenario, num_frames: int, *, person: int = 1, parts: Sequence[int] | None = None,
                        max_points: int = 1000, seed: int = 0) -> list:
    """One person's likelihood observations straight from the renderer (no stages 1-2).

    For testing and benchmarking stage 3 alone: each of the first ``num_frames`` frames
    gives an :class:`occupose.likelihood.Observation` of the first camera, the person's
    pixels taken from the renderer's person-id image (person ids from 1), with ``parts``
    only those of these part labels (e.g. :data:`UPPER_BODY_PARTS`); ``max_points`` points.
    """
    camera = scenario.cameras[0]
    out = []
    for frame in frames(scenario, seed=seed, num_frames=num_frames):
        rendered = frame.rendered[camera.name]
        mask = rendered.person == person
        if parts is not None:
            mask &= np.isin(rendered.part, parts)
        out.append(observation_from_views([View(camera, frame.depth[camera.name], mask)], max_points=max_points))
    return out


def folder_snapshot(folder: str | os.PathLike) -> dict[str, str]:
    """Every entry under ``folder``, hidden ones included, by its path relative to it (with
    ``/``): a file's SHA-256, ``"folder"``, or a symbolic link's ``"-> target"`` (not
    followed). Two snapshots are equal when nothing under the folder changed."""
    folder = Path(folder)
    entries = {}
    for root, dirs, files in os.walk(folder):
        for name in dirs + files:
            path = Path(root) / name
            key = path.relative_to(folder).as_posix()
            if path.is_symlink():
                entries[key] = "-> " + os.readlink(path)
            elif path.is_dir():
                entries[key] = "folder"
            else:
                entries[key] = hashlib.sha256(path.read_bytes()).hexdigest()
    return entries


#: The RealSense stream info message (librealsense's ``realsense_msgs/StreamInfo``), for
#: :func:`write_depth_bag`'s RealSense layout.
STREAM_INFO_MSG = "uint32 fps\nstring encoding\nbool is_recommended\n"
#: The device of :func:`write_depth_bag`'s RealSense layout, as its recorder writes it.
REALSENSE_DEVICE_INFO = (("Name", "Intel RealSense D435"), ("Serial Number", "000000000000"), ("Product Id", "0B07"))
#: Log time (ns) of the RealSense layout's static messages, as its recorder writes them: the
#: playback device takes a sensor's options (Depth Units) only from messages at the very
#: start (1 ns: yes; 1 ms: ignored, the option's default 0.01 m taken), and none at 0.
REALSENSE_STATIC_NS = 1


def bag_typestore(ros: int):
    """The rosbags typestore for writing a ROS ``ros`` (1 or 2) bag, with RealSense's StreamInfo."""
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    store = get_typestore(Stores.ROS1_NOETIC if ros == 1 else Stores.ROS2_HUMBLE)
    store.register(get_types_from_msg(STREAM_INFO_MSG, "realsense_msgs/msg/StreamInfo"))
    return store


def _header(store, stamp: float | int, frame_id: str):
    """A header stamped ``stamp``: seconds (float) or nanoseconds (int)."""
    Header, Time = store.types["std_msgs/msg/Header"], store.types["builtin_interfaces/msg/Time"]
    ns = stamp if isinstance(stamp, (int, np.integer)) else int(round(stamp * 1e9))
    time = Time(sec=int(ns // 10**9), nanosec=int(ns % 10**9))
    if "seq" in Header.__dataclass_fields__:  # ROS 1
        return Header(seq=0, stamp=time, frame_id=frame_id)
    return Header(stamp=time, frame_id=frame_id)


def image_message(store, pixels: np.ndarray, encoding: str, stamp: float, *, frame_id: str = "depth",
                  bigendian: bool = False, padding: int = 0):
    """A ``sensor_msgs/Image`` of ``pixels`` ((H, W) or (H, W, C) array whose dtype suits
    ``encoding``), stamped ``stamp`` (float seconds or int nanoseconds), samples big-endian if ``bigendian``, each row
    followed by ``padding`` bytes of 0xAB."""
    pixels = np.ascontiguousarray(pixels)
    if bigendian:
        pixels = pixels.astype(pixels.dtype.newbyteorder(">"))
    rows = pixels.reshape(pixels.shape[0], -1).view(np.uint8)
    data = np.concatenate([rows, np.full((rows.shape[0], padding), 0xAB, np.uint8)], axis=1)
    return store.types["sensor_msgs/msg/Image"](
        header=_header(store, stamp, frame_id), height=pixels.shape[0], width=pixels.shape[1], encoding=encoding,
        is_bigendian=int(bigendian), step=data.shape[1], data=data.ravel())


def camera_info_message(store, camera: Camera, *, frame_id: str = "depth"):
    """A ``sensor_msgs/CameraInfo`` with ``camera``'s size and intrinsics (no distortion)."""
    Info = store.types["sensor_msgs/msg/CameraInfo"]
    k = np.array([camera.fx, 0.0, camera.cx, 0.0, camera.fy, camera.cy, 0.0, 0.0, 1.0])
    p = np.array([camera.fx, 0.0, camera.cx, 0.0, 0.0, camera.fy, camera.cy, 0.0, 0.0, 0.0, 1.0, 0.0])
    matrices = dict(D=np.zeros(5), K=k, R=np.eye(3).ravel(), P=p)
    if "k" in Info.__dataclass_fields__:  # ROS 2 names them in lower case
        matrices = {name.lower(): value for name, value in matrices.items()}
    Roi = store.types["sensor_msgs/msg/RegionOfInterest"]
    return Info(header=_header(store, 0.0, frame_id), height=camera.height, width=camera.width,
                distortion_model="plumb_bob", **matrices, binning_x=0, binning_y=0,
                roi=Roi(x_offset=0, y_offset=0, height=0, width=0, do_rectify=False))


def write_bag(path: str | os.PathLike, messages, store, *, ros: int = 1, storage: str = "sqlite3") -> Path:
    """Write ``messages`` (an iterable of (topic, msgtype, log time in ns, message), in time
    order) to a ROS 1 ``.bag`` (``ros`` 1) or a ROS 2 bag folder (``ros`` 2, ``storage``
    ``sqlite3`` or ``mcap``), uncompressed, with rosbags' writers; returns ``path``."""
    from rosbags import rosbag1, rosbag2

    path = Path(path)
    if ros == 1:
        writer, serialize = rosbag1.Writer(path), store.serialize_ros1
    else:
        plugin = {"sqlite3": rosbag2.StoragePlugin.SQLITE3, "mcap": rosbag2.StoragePlugin.MCAP}[storage]
        writer, serialize = rosbag2.Writer(path, version=9, storage_plugin=plugin), store.serialize_cdr
    connections = {}
    with writer:
        for topic, msgtype, time, message in messages:
            if topic not in connections:
                connections[topic] = writer.add_connection(topic, msgtype, typestore=store)
            writer.write(connections[topic], time, serialize(message, msgtype))
    return path


def write_depth_bag(path: str | os.PathLike, depths, camera: Camera, *, ros: int = 1, storage: str = "sqlite3",
                    encoding: str = "16UC1", fps: float = 30.0, start: float = 100.0, realsense: bool = False,
                    bigendian: bool = False, padding: int = 0) -> Path:
    """A bag of the depth images ``depths`` (an iterable of (H, W) uint16 raw units, or
    float32 metres for ``32FC1``), stamped ``start + index / fps`` seconds, with the
    CameraInfo of ``camera``, in the common ROS layout (``/camera/depth/image_raw``,
    ``/camera/depth/camera_info``) or, with ``realsense``, in a RealSense recorder's
    (``/file_version``, the device's and sensor's info, ``/device_0/sensor_0/Depth_0/...``,
    its stream info with ``fps``, the ``Depth Units`` option set to ``camera.depth_scale``,
    frame numbers and metadata: a ROS 1 one plays in pyrealsense2's playback device with
    ``encoding="mono16"``; give a small ``start``, as the recorder's log times start near 0,
    since a real-time playback waits that long for the first frame). See :func:`write_bag`."""
    store = bag_typestore(ros)
    if realsense:
        ns = "/device_0/sensor_0/Depth_0"
        topic, info = f"{ns}/image/data", f"{ns}/info/camera_info"
    else:
        topic, info = "/camera/depth/image_raw", "/camera/depth/camera_info"
    first = int(round(start * 1e9))  # stamps in integer ns: exact at any epoch
    types = store.types
    key_value = types["diagnostic_msgs/msg/KeyValue"]

    def realsense_device(stamp: int):
        """The device, its sensor, the Depth Units option and the stream, before the frames."""
        yield "/file_version", "std_msgs/msg/UInt32", stamp, types["std_msgs/msg/UInt32"](data=3)
        for key, value in REALSENSE_DEVICE_INFO:
            yield "/device_0/info", "diagnostic_msgs/msg/KeyValue", stamp, key_value(key=key, value=value)
        yield ("/device_0/sensor_0/info", "diagnostic_msgs/msg/KeyValue", stamp,
               key_value(key="Name", value="Stereo Module"))
        yield ("/device_0/sensor_0/option/Depth Units/value", "std_msgs/msg/Float32", stamp,
               types["std_msgs/msg/Float32"](data=camera.depth_scale))
        yield ("/device_0/sensor_0/option/Depth Units/description", "std_msgs/msg/String", stamp,
               types["std_msgs/msg/String"](data="Number of meters represented by a single depth unit"))
        yield f"{ns}/info", "realsense_msgs/msg/StreamInfo", stamp, types["realsense_msgs/msg/StreamInfo"](
            fps=int(fps), encoding=encoding, is_recommended=True)
        vector, quaternion = types["geometry_msgs/msg/Vector3"], types["geometry_msgs/msg/Quaternion"]
        yield f"{ns}/tf/0", "geometry_msgs/msg/Transform", stamp, types["geometry_msgs/msg/Transform"](
            translation=vector(x=0.0, y=0.0, z=0.0), rotation=quaternion(x=0.0, y=0.0, z=0.0, w=1.0))

    def messages():
        static = REALSENSE_STATIC_NS if realsense else first
        if realsense:  # what librealsense's playback device needs to play it (ROS 1 only)
            yield from realsense_device(static)
        yield info, "sensor_msgs/msg/CameraInfo", static, camera_info_message(store, camera)
        for index, depth in enumerate(depths):
            stamp = first + int(round(index * 1e9 / fps))
            image = image_message(store, depth, encoding, stamp, bigendian=bigendian, padding=padding)
            if realsense and hasattr(image.header, "seq"):  # the frame number, from 1
                image.header.seq = index + 1
            yield topic, "sensor_msgs/msg/Image", stamp, image
            if realsense:
                for key, value in (("timestamp_domain", "Hardware Clock"), ("Frame Counter", str(index + 1)),
                                   ("Frame Timestamp", str(stamp // 1000))):
                    yield f"{ns}/image/metadata", "diagnostic_msgs/msg/KeyValue", stamp, key_value(key=key, value=value)

    return write_bag(path, messages(), store, ros=ros, storage=storage)


# ------------------------------------------------------------------------- Azure Kinect .mkv

#: The accelerometer extrinsics (``Rt.Rotation``, depth camera to accelerometer) of the
#: shared Azure Kinect's factory calibration, for :func:`azure_calibration`.
AZURE_ACCEL_ROTATION = ((0.0019369830843061209, 0.1084766760468483, -0.994097113609314),
                        (-0.9999940395355225, -0.0026388836558908224, -0.002236430300399661),
                        (-0.002865907270461321, 0.994095504283905, 0.10847091674804688))


def azure_calibration(camera: Camera, mode: str, *, accel_rotation=AZURE_ACCEL_ROTATION) -> dict:
    """A minimal Azure Kinect ``calibration.json`` (parsed) whose depth camera, taken to
    depth mode ``mode`` by :func:`occupose.io.mkv.camera_from_calibration`, has
    ``camera``'s intrinsics: the inverse of the SDK's crop and scale. No lens distortion;
    the accelerometer's ``Rt`` rotation is ``accel_rotation`` (3 x 3, depth to accelerometer)."""
    from occupose.io.mkv import DEPTH_MODES

    (binned_w, binned_h), (crop_x, crop_y), size = DEPTH_MODES[mode]
    if size != (camera.width, camera.height):
        raise ValueError(f"depth mode {mode} is {size[0]}x{size[1]}, the camera {camera.width}x{camera.height}")
    params = [(camera.cx + 0.5 + crop_x) / binned_w, (camera.cy + 0.5 + crop_y) / binned_h,
              camera.fx / binned_w, camera.fy / binned_h] + [0.0] * 10
    identity = {"Rotation": [1.0, 0, 0, 0, 1.0, 0, 0, 0, 1.0], "Translation": [0.0, 0.0, 0.0]}
    depth = {"Intrinsics": {"ModelParameterCount": 14, "ModelParameters": params,
                            "ModelType": "CALIBRATION_LensDistortionModelBrownConrady"},
             "Location": "CALIBRATION_CameraLocationD0", "Purpose": "CALIBRATION_CameraPurposeDepth",
             "MetricRadius": 1.74, "Rt": identity, "SensorHeight": 1024, "SensorWidth": 1024}
    accel = {"SensorType": "CALIBRATION_InertialSensorType_Accelerometer",
             "Rt": {"Rotation": [float(v) for v in np.ravel(accel_rotation)], "Translation": [0.0, 0.0, 0.0]}}
    return {"CalibrationInformation": {"Cameras": [depth], "InertialSensors": [accel],
                                       "Metadata": {"SerialId": "synthetic"}}}


def _set_vfw_compression(path: Path, track_title: bytes, fourcc: bytes) -> None:
    """Set the BITMAPINFOHEADER (``CodecPrivate``) of the track named ``track_title`` to
    ``fourcc`` and a positive (top-down as k4arecorder writes it) height, in place."""
    data = bytearray(path.read_bytes())
    name = data.find(b"\x53\x6e" + bytes([0x80 | len(track_title)]) + track_title)
    private = data.find(b"\x63\xa2\xa8", name)  # CodecPrivate, 40 bytes
    if name < 0 or private < 0:
        raise ValueError(f"{path}: no CodecPrivate for track {track_title!r}")
    header = private + 3
    if int.from_bytes(data[header:header + 4], "little") != 40:
        raise ValueError(f"{path}: the track {track_title!r} has no BITMAPINFOHEADER")
    height = int.from_bytes(data[header + 8:header + 12], "little", signed=True)
    data[header + 8:header + 12] = abs(height).to_bytes(4, "little")
    data[header + 16:header + 20] = fourcc
    path.write_bytes(bytes(data))


def write_depth_mkv(path: str | os.PathLike, depths, camera: Camera, *, mode: str | None = None,
                    fps: float = 30.0, start_offset_ns: int = 0, calibration: dict | bool = True,
                    accelerations=None, title: str = "DEPTH", accel_rotation=AZURE_ACCEL_ROTATION) -> Path:
    """An Azure Kinect style ``.mkv`` of the depth images ``depths`` ((H, W) uint16 mm each),
    written with PyAV, read back by :class:`occupose.io.mkv.MkvSource`.

    A ``rawvideo`` track titled ``title`` (``K4A_DEPTH_MODE`` ``mode``, default the one of
    the camera's size) whose packets are the images' big-endian bytes, stamped
    ``index / fps`` (Matroska's millisecond timecodes, as FFmpeg writes them); the file's
    ``K4A_START_OFFSET_NS`` tag; the ``calibration.json`` attachment
    (:func:`azure_calibration` of ``camera``, a dict of your own, or none for False); and
    with ``accelerations`` ((N, 3) m/s^2), a track titled ``IMU`` of N 40-byte
    ``S_K4A/IMU`` samples (a stand-in codec: FFmpeg cannot mux ``S_K4A/IMU``, and the reader
    finds the track by its name). FFmpeg writes a raw track's VFW header as BI_RGB: the
    depth track's is set to ``b16g`` (gray16be), as k4arecorder writes it.
    """
    import json
    from fractions import Fraction

    import av

    from occupose.io.mkv import DEPTH_MODES, IMU_SAMPLE

    path = Path(path)
    if mode is None:
        mode = next(n for n, (_, _, size) in DEPTH_MODES.items() if size == (camera.width, camera.height))
    microseconds = Fraction(1, 1_000_000)
    with av.open(str(path), "w", format="matroska", options={"allow_raw_vfw": "1", "write_crc32": "0"}) as out:
        out.metadata["title"] = "Azure Kinect"
        out.metadata["K4A_START_OFFSET_NS"] = str(int(start_offset_ns))
        stream = out.add_stream("rawvideo", rate=Fraction(fps).limit_denominator(1000))
        stream.width, stream.height, stream.pix_fmt = camera.width, camera.height, "gray16be"
        stream.metadata["title"] = title
        stream.metadata["K4A_DEPTH_MODE"] = mode
        imu = None
        if accelerations is not None:
            imu = out.add_stream("rawvideo", rate=1000)
            imu.width, imu.height, imu.pix_fmt = 20, 1, "gray16be"
            imu.metadata["title"] = "IMU"
        if calibration is not False:
            document = azure_calibration(camera, mode, accel_rotation=accel_rotation) if calibration is True \
                else calibration
            out.add_attachment("calibration.json", "application/octet-stream", json.dumps(document).encode())
        out.start_encoding()
        if imu is not None:
            for index, acc in enumerate(np.asarray(accelerations, np.float32).reshape(-1, 3)):
                sample = np.zeros(1, IMU_SAMPLE)
                sample["acc"], sample["gyro"] = acc, 0.0
                sample["acc_timestamp_ns"] = sample["gyro_timestamp_ns"] = start_offset_ns + index * 1_000_000
                packet = av.Packet(sample.tobytes())
                packet.stream, packet.time_base = imu, microseconds
                packet.pts = packet.dts = index * 1000
                out.mux(packet)
        for index, depth in enumerate(depths):
            depth = np.asarray(depth)
            if depth.shape != (camera.height, camera.width) or depth.dtype != np.uint16:
                raise ValueError(f"depth image {index} is {depth.dtype} {depth.shape}, expected uint16 "
                                 f"({camera.height}, {camera.width})")
            packet = av.Packet(depth.astype(">u2").tobytes())
            packet.stream, packet.time_base = stream, microseconds
            packet.pts = packet.dts = int(round(index * 1_000_000 / fps))
            out.mux(packet)
    _set_vfw_compression(path, title.encode(), b"b16g")
    return path


# ------------------------------------------------------------------------- TUM RGB-D folders

def write_tum_folder(path: str | os.PathLike, depths, *, fps: float = 30.0, start: float = 1305031102.175304,
                     stamps=None) -> Path:
    """A TUM RGB-D folder of the depth images ``depths`` ((H, W) uint16, metres * 5000 each):
    ``depth/<timestamp>.png`` (16-bit grayscale) and ``depth.txt`` listing them with the
    dataset's three comment lines, stamped ``stamps`` or ``start + index / fps`` seconds
    (6 decimals, as the dataset writes them); returns ``path``."""
    from PIL import Image

    path = Path(path)
    (path / "depth").mkdir(parents=True, exist_ok=True)
    lines = ["# depth maps", f"# file: '{path.name}.bag'", "# timestamp filename"]
    for index, depth in enumerate(depths):
        depth = np.asarray(depth)
        if depth.dtype != np.uint16 or depth.ndim != 2:
            raise ValueError(f"depth image {index} is {depth.dtype} {depth.shape}, expected (H, W) uint16")
        stamp = f"{(start + index / fps) if stamps is None else stamps[index]:.6f}"
        Image.fromarray(depth).save(path / "depth" / f"{stamp}.png")
        lines.append(f"{stamp} depth/{stamp}.png")
    (path / "depth.txt").write_text("\n".join(lines) + "\n")
    return path


def random_raw_depths(count: int, size: tuple[int, int], low: int, high: int, seed: int = 0) -> np.ndarray:
    """(count, H, W) uint16 raw depth images drawn uniformly from [low, high), a tenth of the
    pixels 0 (no measurement): frames for the readers' round-trip tests."""
    rng = np.random.default_rng(seed)
    depths = rng.integers(low, high, (count, *size), dtype=np.uint16)
    depths[rng.random(depths.shape) < 0.1] = 0
    return depths


def raw_frames(source) -> tuple[np.ndarray, list[float]]:
    """((T, H, W) uint16 raw images, T times in seconds) of every frame of ``source``'s first
    camera, back from the metres a frame source gives."""
    from occupose.camera import raw_depth_from_metres

    camera = source.cameras[0]
    frames = list(source.frames())
    return np.array([raw_depth_from_metres(f.depth[camera.name], camera) for f in frames]), [f.time for f in frames]
