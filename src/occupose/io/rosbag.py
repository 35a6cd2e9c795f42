"""ROS 1 and ROS 2 bags as frame sources: one depth image topic, read with ``rosbags``.

Formats: a ROS 1 ``.bag`` (RealSense ``.bag`` files are ROS 1 bags), a ROS 2 bag folder
(``metadata.yaml`` with its ``.db3`` or ``.mcap``), or a ROS 2 ``.db3`` / ``.mcap`` file
(or a folder holding them without ``metadata.yaml``).

What is read, and from where:

- depth: the ``sensor_msgs/Image`` topic given as ``topic``, or else the only one whose
  encoding is a depth encoding (:data:`DEPTH_ENCODINGS`); of several, the only one with
  ``depth`` in its name; otherwise a SourceError lists them. ``16UC1`` / ``mono16`` are
  kept as they are (raw units, millimetres unless the bag says otherwise: a RealSense
  ``<sensor>/option/Depth Units/value``); ``32FC1`` (float metres, NaN, 0 or negative =
  no measurement) is quantised to uint16 at :data:`FLOAT_DEPTH_SCALE` metres (0 = none;
  beyond 65.535 m = none). ``is_bigendian`` and ``step`` (row padding) are honoured.
- intrinsics: the ``sensor_msgs/CameraInfo`` topic nearest the image topic in the topic
  tree among those that fit it (the same size and ``frame_id``; ``K`` in ROS 1, ``k`` in
  ROS 2; lens distortion is not used); none is an error.
- time: the image header's stamp (the bag's receive time where the stamp is zero).
- fps: a RealSense stream's ``<stream>/info`` (``realsense_msgs/StreamInfo``), else one over
  the median interval of the first :data:`FPS_FRAMES` stamps, to 3 decimals
  (:data:`DEFAULT_FPS` for a single frame).
- colour: none. A RealSense bag's ``Color_0`` stream is a different sensor with its own
  intrinsics and pose, not registered to the depth, and an ordinary bag does not say
  whether an RGB topic is registered to its depth, so no colour is read from bags.
- gravity: none (a RealSense IMU's accelerometer is in its own frame; not used yet).

The camera, ``cam0``, has no world pose (``pose_known`` False): :func:`open_source` places
it from a pose given or the floor.
"""

from __future__ import annotations

import math
import sqlite3
import statistics
from pathlib import Path
from typing import Iterator

import numpy as np

from occupose.camera import Camera, raw_depth_from_metres
from occupose.io.sources import SourceError, StreamSource, require

#: Depth encodings of ``sensor_msgs/Image`` read, and their sample types (little-endian).
DEPTH_ENCODINGS: dict[str, np.dtype] = {"16UC1": np.dtype("<u2"), "mono16": np.dtype("<u2"),
                                        "32FC1": np.dtype("<f4")}
#: Metres per raw unit of the uint16 images made from ``32FC1`` (float metres) images.
FLOAT_DEPTH_SCALE = 0.001
#: Metres per raw unit of ``16UC1`` / ``mono16`` images when the bag does not say.
DEFAULT_DEPTH_SCALE = 0.001
#: Frames per second of a one-frame bag without a RealSense stream info.
DEFAULT_FPS = 30.0
#: First frames whose stamps give the frame rate.
FPS_FRAMES = 31

IMAGE = "sensor_msgs/msg/Image"
CAMERA_INFO = "sensor_msgs/msg/CameraInfo"
STREAM_INFO = "realsense_msgs/msg/StreamInfo"
DEPTH_UNITS = "option/Depth Units/value"

ROSBAG1_MAGIC = b"#ROSBAG V2.0"
MCAP_MAGIC = b"\x89MCAP0\r\n"
SUFFIXES = (".bag", ".db3", ".mcap")


def depth_from_image(data, height: int, width: int, step: int, encoding: str, is_bigendian: bool,
                     depth_scale: float = FLOAT_DEPTH_SCALE) -> np.ndarray:
    """A ``sensor_msgs/Image``'s pixels as raw depth.

    data : (step * height,) uint8 or bytes, the message's ``data``; height, width : pixels;
    step : bytes per row (>= width * bytes per sample; the rest of a row is padding);
    encoding : one of :data:`DEPTH_ENCODINGS`; is_bigendian : byte order of the samples;
    depth_scale : metres per raw unit of the result, used for ``32FC1`` only.

    Returns (height, width) uint16, a new array: the samples of ``16UC1`` / ``mono16``, or
    ``round(metres / depth_scale)`` of ``32FC1`` with 0 where NaN, inf, <= 0 or beyond
    65535 units. ValueError for another encoding or too little data.
    """
    if encoding not in DEPTH_ENCODINGS:
        raise ValueError(f"image encoding {encoding!r} is not a depth encoding ({', '.join(DEPTH_ENCODINGS)})")
    dtype = DEPTH_ENCODINGS[encoding].newbyteorder(">" if is_bigendian else "<")
    row = width * dtype.itemsize
    buffer = np.frombuffer(data, np.uint8)
    if step < row or buffer.size < step * height:
        raise ValueError(f"a {width}x{height} {encoding} image needs step >= {row} and {step} * {height} bytes; "
                         f"it has step {step} and {buffer.size} bytes")
    samples = buffer[: step * height].reshape(height, step)[:, :row].view(dtype)
    if encoding == "32FC1":
        camera = Camera("depth", width, height, 1.0, 1.0, 0.0, 0.0, depth_scale)
        return raw_depth_from_metres(samples.astype(np.float32), camera)
    return samples.astype(np.uint16)


def is_bag(path: Path) -> bool:
    """Whether ``path`` looks like a ROS bag: a ``.bag`` / ``.db3`` / ``.mcap`` file, a file
    starting with a ROS 1 or MCAP magic, or a folder with ``metadata.yaml`` or a ``.db3`` /
    ``.mcap`` (a few bytes and names read, no more)."""
    path = Path(path)
    if path.is_dir():
        return (path / "metadata.yaml").is_file() or any(next(path.glob(f"*{s}"), None) for s in SUFFIXES[1:])
    if not path.is_file():
        return False
    if path.suffix.lower() in SUFFIXES:
        return True
    try:
        with path.open("rb") as file:
            head = file.read(len(ROSBAG1_MAGIC))
    except OSError:
        return False
    return head == ROSBAG1_MAGIC or head.startswith(MCAP_MAGIC)


def _bag_paths(path: Path) -> list[Path]:
    """What ``AnyReader`` opens for ``path``: the file, the bag folder, or the ``.db3`` /
    ``.mcap`` files of a folder without ``metadata.yaml`` or named ``*.bag`` (AnyReader
    takes any path ending in ``.bag`` for a ROS 1 file)."""
    if path.is_dir() and (path.suffix.lower() == ".bag" or not (path / "metadata.yaml").is_file()):
        files = sorted(p for s in SUFFIXES[1:] for p in path.glob(f"*{s}"))
        if not files:
            raise SourceError(f"{path}: a folder without metadata.yaml or a .db3 / .mcap file is not a ROS bag")
        return files
    return [path]


def _errors() -> tuple[type[BaseException], ...]:
    """The exceptions by which rosbags says a file is not a readable bag."""
    from rosbags.highlevel import AnyReaderError
    from rosbags.rosbag1 import ReaderError as Reader1Error
    from rosbags.rosbag2 import ReaderError as Reader2Error
    from rosbags.serde import SerdeError

    return AnyReaderError, Reader1Error, Reader2Error, SerdeError, sqlite3.Error, OSError, KeyError, ValueError


def _stamp(message, log_time: int) -> float:
    """Seconds of a message's header stamp, or of its log time (ns) where the stamp is 0."""
    stamp = message.header.stamp
    if stamp.sec == 0 and stamp.nanosec == 0:
        return log_time * 1e-9
    return stamp.sec + stamp.nanosec * 1e-9


def _namespaces(topic: str) -> list[str]:
    """The namespaces above ``topic``, nearest first, the root ("") last."""
    parts = topic.split("/")
    return ["/".join(parts[:k]) for k in range(len(parts) - 1, 0, -1)]


def _nearest(topic: str, candidates: list[str]) -> list[str]:
    """The candidate topics in the namespace nearest ``topic`` that holds any."""
    for namespace in _namespaces(topic):
        found = [c for c in candidates if c.startswith(namespace + "/")]
        if found:
            return found
    return []


class BagSource(StreamSource):
    """A ROS 1 / ROS 2 bag's depth image topic as one camera (see the module docstring).

    path : the bag (file or folder); topic : its depth ``sensor_msgs/Image`` topic (None:
    found). Attributes beyond StreamSource's: ``topic``, ``info_topic`` (the CameraInfo
    used), ``encoding``.
    """

    def __init__(self, path: Path, topic: str | None = None):
        require("rosbags", "ros", "reading ROS bags")
        from rosbags.highlevel import AnyReader
        from rosbags.typesys import Stores, get_typestore

        self.path = Path(path)
        if not self.path.exists():
            raise FileNotFoundError(f"{self.path}: no such bag")
        self._paths = _bag_paths(self.path)
        self._typestore = get_typestore(Stores.LATEST)  # for ROS 2 bags that carry no message definitions
        self._any_reader = AnyReader
        try:
            with self._open() as reader:
                self._read_header(reader, topic)
        except SourceError:
            raise
        except _errors() as error:
            raise SourceError(f"{self.path}: not a readable ROS bag ({type(error).__name__}: {error})") from None

    def _open(self):
        return self._any_reader(self._paths, default_typestore=self._typestore)

    def _fail(self, message: str) -> SourceError:
        return SourceError(f"{self.path}: {message}")

    def _first(self, reader, topic: str, count: int = 1) -> list[tuple[object, int]]:
        """The first ``count`` messages of ``topic``, deserialised, with their log times (ns)."""
        connections = [c for c in reader.connections if c.topic == topic]
        messages = []
        for connection, time, raw in reader.messages(connections=connections):
            messages.append((reader.deserialize(raw, connection.msgtype), time))
            if len(messages) == count:
                break
        return messages

    def _read_header(self, reader, topic: str | None) -> None:
        topics: dict[str, str] = {}
        counts: dict[str, int] = {}
        for connection in reader.connections:
            topics[connection.topic] = connection.msgtype
            counts[connection.topic] = counts.get(connection.topic, 0) + connection.msgcount
        images = [t for t, kind in topics.items() if kind == IMAGE and counts[t] > 0]
        self.topic = self._choose(reader, images, topic, topics)
        self.reader_options = {"topic": self.topic}
        first = self._first(reader, self.topic, FPS_FRAMES)
        image = first[0][0]
        self.encoding = image.encoding
        if self.encoding not in DEPTH_ENCODINGS:
            raise self._fail(f"topic {self.topic} has images of encoding {self.encoding!r}, not a depth encoding "
                             f"({', '.join(DEPTH_ENCODINGS)})")
        self.num_frames = counts[self.topic]
        self.fps = self._frame_rate(reader, topics, [_stamp(m, t) for m, t in first])
        depth_scale = FLOAT_DEPTH_SCALE if self.encoding == "32FC1" else self._depth_units(reader, topics)
        self.cameras = [self._camera(reader, topics, image, depth_scale)]

    def _choose(self, reader, images: list[str], topic: str | None, topics: dict[str, str]) -> str:
        if topic is not None:
            if topic not in topics:
                raise self._fail(f"no topic {topic!r}; its image topics are {images or 'none'}")
            if topics[topic] != IMAGE:
                raise self._fail(f"topic {topic!r} is a {topics[topic]}, not a {IMAGE}; its image topics are "
                                 f"{images or 'none'}")
            if topic not in images:
                raise self._fail(f"topic {topic!r} has no messages")
            return topic
        if not images:
            raise self._fail(f"no {IMAGE} topic with messages (topics: {', '.join(sorted(topics)) or 'none'})")
        encodings = {t: self._first(reader, t)[0][0].encoding for t in images}
        depths = [t for t in images if encodings[t] in DEPTH_ENCODINGS]
        if not depths:
            listed = ", ".join(f"{t} ({e})" for t, e in encodings.items())
            raise self._fail(f"no depth image topic (encodings {', '.join(DEPTH_ENCODINGS)}); image topics: {listed}")
        if len(depths) > 1:
            named = [t for t in depths if "depth" in t.lower()]
            if len(named) == 1:
                return named[0]
            listed = ", ".join(f"{t} ({encodings[t]})" for t in depths)
            raise self._fail(f"several depth image topics: {listed}; choose one with --topic (topic=...)")
        return depths[0]

    def _frame_rate(self, reader, topics: dict[str, str], stamps: list[float]) -> float:
        for info in _nearest(self.topic, [t for t, kind in topics.items() if kind == STREAM_INFO])[:1]:
            fps = float(self._first(reader, info)[0][0].fps)
            if fps > 0:
                return fps
        intervals = [b - a for a, b in zip(stamps, stamps[1:]) if b > a]
        if not intervals:
            return DEFAULT_FPS
        return round(1.0 / statistics.median(intervals), 3)  # stamps in ns: 30 fps, not 29.99999997

    def _depth_units(self, reader, topics: dict[str, str]) -> float:
        units = _nearest(self.topic, [t for t in topics if t.endswith("/" + DEPTH_UNITS)])
        if not units:
            return DEFAULT_DEPTH_SCALE
        value = np.float32(self._first(reader, units[0])[0][0].data)
        if not (math.isfinite(value) and value > 0):
            raise self._fail(f"{units[0]} is {value}, not a positive number of metres per depth unit")
        return float(str(value))  # the shortest decimal of the float32 (0.001, not 0.0010000000474974513)

    def _camera(self, reader, topics: dict[str, str], image, depth_scale: float) -> Camera:
        """cam0 from the CameraInfo of the image topic: of the CameraInfo topics whose first
        message fits the image (the same size, or 0 x 0; the same ``frame_id`` where both
        have one), the one nearest the image topic in the topic tree."""
        infos = {t: self._first(reader, t) for t, kind in topics.items() if kind == CAMERA_INFO}
        infos = {t: messages[0][0] for t, messages in infos.items() if messages}
        frame = image.header.frame_id
        fitting = [t for t, info in infos.items()
                   if (info.width, info.height) in ((image.width, image.height), (0, 0))
                   and (not frame or not info.header.frame_id or info.header.frame_id == frame)]
        found = _nearest(self.topic, fitting)
        if not found:
            listed = ", ".join(f"{t} ({i.width}x{i.height}, frame_id {i.header.frame_id!r})" for t, i in infos.items())
            raise self._fail(f"no {CAMERA_INFO} topic for {self.topic} ({image.width}x{image.height}, frame_id "
                             f"{frame!r}) to give its intrinsics; CameraInfo topics: {listed or 'none'}")
        if len(found) > 1:
            raise self._fail(f"several {CAMERA_INFO} topics fit {self.topic}: {', '.join(found)}")
        self.info_topic = found[0]
        info = infos[self.info_topic]
        k = np.asarray(info.K if hasattr(info, "K") else info.k, np.float64)
        try:
            return Camera("cam0", image.width, image.height, k[0], k[4], k[2], k[5], depth_scale)
        except ValueError as error:
            raise self._fail(f"{self.info_topic}: no usable intrinsics K = {k.tolist()} ({error})") from None

    def _raw_frames(self, color: bool) -> Iterator[tuple[dict[str, np.ndarray], dict[str, np.ndarray], float]]:
        """(depth {cam0: (H, W) uint16}, {} (no colour), stamp in seconds) per image, in bag order."""
        camera = self.cameras[0]
        try:
            with self._open() as reader:
                connections = [c for c in reader.connections if c.topic == self.topic]
                for connection, time, raw in reader.messages(connections=connections):
                    image = reader.deserialize(raw, connection.msgtype)
                    if (image.width, image.height, image.encoding) != (camera.width, camera.height, self.encoding):
                        raise self._fail(f"{self.topic}: a {image.width}x{image.height} {image.encoding} image at "
                                         f"{_stamp(image, time):.6f} s in a stream of {camera.width}x"
                                         f"{camera.height} {self.encoding}")
                    depth = depth_from_image(image.data, image.height, image.width, image.step, image.encoding,
                                             bool(image.is_bigendian), camera.depth_scale)
                    yield {camera.name: depth}, {}, _stamp(image, time)
        except SourceError:
            raise
        except _errors() as error:
            raise self._fail(f"{self.topic} could not be read ({type(error).__name__}: {error})") from None


def open_bag(path: Path, *, topic: str | None = None, **options) -> BagSource:
    """The bag at ``path`` as a frame source (:class:`BagSource`); ``topic``: its depth image
    topic. Other reader options are a SourceError naming them."""
    if options:
        raise SourceError(f"{path}: a ROS bag takes only the reader option topic, got {sorted(options)}")
    return BagSource(Path(path), topic)
