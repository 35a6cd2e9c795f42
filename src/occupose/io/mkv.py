"""Azure Kinect recordings (``.mkv``, written by ``k4arecorder``) as frame sources, read with PyAV.

What is read, and from where:

- depth: the video track whose title is ``DEPTH`` (never chosen by index: a recording
  without colour has it first), ``rawvideo`` samples ``b16g`` (16-bit big-endian,
  millimetres, 0 = none). The packets' bytes are the pixels: they are read as they are,
  not decoded (bit-identical, and several times faster).
- intrinsics: the ``calibration.json`` attachment (the device's factory calibration). Its
  depth camera's principal point and focal lengths are normalised to the 1024 x 1024
  sensor; :func:`camera_from_calibration` takes them to the recorded depth mode with the
  Azure Kinect SDK's per-mode crop and scale (``transformation_get_mode_specific_camera_calibration``,
  :data:`DEPTH_MODES`). Lens distortion is not used. The mode is the track's
  ``K4A_DEPTH_MODE`` tag, else the one of the track's size.
- time: the device timestamp, packet pts (µs) + ``K4A_START_OFFSET_NS`` // 1000 (the
  recording's first timestamp), in seconds.
- fps: the track's frame rate (``K4A`` writes the camera rate), else one over the median
  interval of the first :data:`FPS_FRAMES` timestamps.
- gravity: the mean accelerometer sample of the first :data:`IMU_SAMPLES` samples of the
  ``IMU`` track, turned into the depth camera's frame with the calibration's accelerometer
  extrinsics (:func:`gravity_from_accelerations`). FFmpeg does not deliver that track's
  blocks, so a small Matroska (EBML) walk reads them (:func:`imu_samples`).
- colour: none. The ``COLOR`` track (MJPEG) is another camera with its own intrinsics and
  pose, not registered to the depth; the tracker uses depth only.

Memory stays flat: one packet at a time. Opening the file reads the depth track through
once to count its frames (at disk speed: the other tracks' blocks are skipped). A file cut
short gives the whole frames before the cut.
The camera, ``cam0``, has no world pose (``pose_known`` False): :func:`open_source` places
it from a pose given or the floor (the IMU's gravity helps choose the floor plane).
"""

from __future__ import annotations

import json
import statistics
from pathlib import Path
from typing import Any, BinaryIO, Iterator, Mapping

import numpy as np

from occupose.camera import Camera
from occupose.io.sources import SourceError, StreamSource, require

#: Depth modes of the Azure Kinect: the calibration image (binned sensor) size, the crop
#: offset in it and the output image size, as the SDK's
#: ``transformation_get_mode_specific_depth_camera_calibration`` uses them.
DEPTH_MODES: dict[str, tuple[tuple[int, int], tuple[int, int], tuple[int, int]]] = {
    "NFOV_2X2BINNED": ((512, 512), (96, 90), (320, 288)),
    "NFOV_UNBINNED": ((1024, 1024), (192, 180), (640, 576)),
    "WFOV_2X2BINNED": ((512, 512), (0, 0), (512, 512)),
    "WFOV_UNBINNED": ((1024, 1024), (0, 0), (1024, 1024)),
}
#: The depth sensor's size the calibration's intrinsics are normalised to.
SENSOR_SIZE = (1024, 1024)
#: Metres per raw depth unit (the Azure Kinect's depth is in millimetres).
DEPTH_SCALE = 0.001
#: Frames per second of a one-frame recording whose track gives no rate.
DEFAULT_FPS = 30.0
#: First frames whose timestamps give the frame rate where the track does not.
FPS_FRAMES = 31
#: First IMU samples averaged for gravity (the IMU runs at about 1.6 kHz: 0.1 s).
IMU_SAMPLES = 160

DEPTH_TITLE, IMU_TITLE = "DEPTH", "IMU"
CALIBRATION = "calibration.json"
EBML_MAGIC = b"\x1a\x45\xdf\xa3"
SUFFIXES = (".mkv",)

#: One IMU sample in a ``S_K4A/IMU`` block (the SDK's packed ``matroska_imu_sample_t``).
IMU_SAMPLE = np.dtype([("acc_timestamp_ns", "<u8"), ("acc", "<f4", 3), ("gyro_timestamp_ns", "<u8"),
                       ("gyro", "<f4", 3)])

# Matroska element IDs (with their length marker, as written)
_SEGMENT, _TRACKS, _TRACK_ENTRY, _TRACK_NUMBER, _NAME, _CODEC = 0x18538067, 0x1654AE6B, 0xAE, 0xD7, 0x536E, 0x86
_CLUSTER, _SIMPLE_BLOCK, _BLOCK_GROUP, _BLOCK = 0x1F43B675, 0xA3, 0xA0, 0xA1
_LEVEL1 = {0x114D9B74, 0x1549A966, _TRACKS, _CLUSTER, 0x1C53BB6B, 0x1941A469, 0x1254C367, 0x1043A770}


def camera_from_calibration(calibration: Mapping[str, Any], mode: str, name: str = "cam0") -> Camera:
    """The depth camera of an Azure Kinect ``calibration.json`` (parsed) in depth mode ``mode``.

    calibration : the parsed JSON (``CalibrationInformation.Cameras``, the one with
    ``Purpose`` ``CALIBRATION_CameraPurposeDepth``: ``ModelParameters[0:4]`` = cx, cy, fx,
    fy normalised to the 1024 x 1024 sensor, the origin at the top left pixel's corner);
    mode : a :data:`DEPTH_MODES` name.

    Returns a Camera (pixels, the origin at the top left pixel's centre): fx, fy scaled to
    the binned sensor; cx, cy scaled, less the mode's crop offset and half a pixel.
    ValueError for an unknown mode or a calibration without a usable depth camera.
    """
    if mode not in DEPTH_MODES:
        raise ValueError(f"unknown Azure Kinect depth mode {mode!r}; valid: {', '.join(DEPTH_MODES)}")
    try:
        cameras = calibration["CalibrationInformation"]["Cameras"]
        depth = [c for c in cameras if c.get("Purpose") == "CALIBRATION_CameraPurposeDepth"]
        if len(depth) != 1:
            raise ValueError(f"{len(depth)} depth cameras (Purpose CALIBRATION_CameraPurposeDepth)")
        depth = depth[0]
        size = (int(depth["SensorWidth"]), int(depth["SensorHeight"]))
        cx, cy, fx, fy = (float(v) for v in depth["Intrinsics"]["ModelParameters"][:4])
    except (KeyError, TypeError, IndexError, AttributeError) as error:
        raise ValueError(f"not an Azure Kinect calibration ({type(error).__name__}: {error})") from None
    if size != SENSOR_SIZE:
        raise ValueError(f"the depth camera's sensor is {size[0]}x{size[1]}, expected "
                         f"{SENSOR_SIZE[0]}x{SENSOR_SIZE[1]}")
    (binned_w, binned_h), (crop_x, crop_y), (width, height) = DEPTH_MODES[mode]
    return Camera(name, width, height, fx * binned_w, fy * binned_h, cx * binned_w - crop_x - 0.5,
                  cy * binned_h - crop_y - 0.5, DEPTH_SCALE)


def gravity_from_accelerations(accelerations: np.ndarray, calibration: Mapping[str, Any]) -> np.ndarray:
    """The direction of gravity in the depth camera's frame from accelerometer samples.

    accelerations : (N, 3) float, m/s^2, the accelerometer's frame (an accelerometer at rest
    measures the support's push: up); calibration : the parsed ``calibration.json``, whose
    accelerometer ``Rt`` rotates depth-camera directions into the accelerometer's frame.

    Returns (3,) float64 unit vector, depth camera frame (OpenCV axes: x right, y down, z
    forward), pointing down. ValueError for no samples or no accelerometer calibration.
    """
    accelerations = np.asarray(accelerations, np.float64).reshape(-1, 3)
    if not len(accelerations):
        raise ValueError("no accelerometer samples")
    try:
        sensors = calibration["CalibrationInformation"]["InertialSensors"]
        accel = [s for s in sensors if s.get("SensorType") == "CALIBRATION_InertialSensorType_Accelerometer"]
        rotation = np.array(accel[0]["Rt"]["Rotation"], np.float64).reshape(3, 3)
    except (KeyError, TypeError, IndexError, ValueError, AttributeError) as error:
        raise ValueError(f"no accelerometer extrinsics in the calibration ({type(error).__name__}: {error})") \
            from None
    up = rotation.T @ accelerations.mean(axis=0)
    norm = np.linalg.norm(up)
    if not np.isfinite(norm) or norm < 1.0:  # m/s^2: a stationary camera measures about 9.8
        raise ValueError(f"the accelerometer's mean is {norm:.3g} m/s^2, no direction of gravity")
    return -up / norm


# ----------------------------------------------------------------------------- Matroska walk

def _vint(file: BinaryIO, marker: bool) -> tuple[int, int]:
    """An EBML variable-length integer at the file's position: (value, bytes); with
    ``marker`` its length marker is kept (element IDs). EOFError at the end of the file."""
    head = file.read(1)
    if not head:
        raise EOFError
    length = 1
    while length <= 8 and not head[0] & (0x80 >> (length - 1)):
        length += 1
    if length > 8:
        raise ValueError(f"an invalid EBML number at byte {file.tell() - 1}")
    rest = file.read(length - 1)
    if len(rest) < length - 1:
        raise EOFError
    value = head[0] if marker else head[0] & (0xFF >> length)
    for byte in rest:
        value = value << 8 | byte
    return value, length


def _elements(file: BinaryIO, end: int | None) -> Iterator[tuple[int, int, int, int | None]]:
    """(id, header start, data start, data size or None for unknown) of the elements from
    the file's position to ``end`` (None: the end of the file); the caller reads or skips
    the data and this seeks past it (an element of unknown size is entered)."""
    while end is None or file.tell() < end:
        header = file.tell()
        try:
            element, _ = _vint(file, True)
            size, length = _vint(file, False)
        except EOFError:
            return
        start = file.tell()
        unknown = size == (1 << 7 * length) - 1
        yield element, header, start, None if unknown else size
        if not unknown:
            file.seek(start + size)


def _tracks(file: BinaryIO, end: int | None) -> dict[str, tuple[int, str]]:
    """Track name -> (track number, codec id) from a Tracks element's data."""
    tracks = {}
    for element, _, start, size in _elements(file, end):
        if element != _TRACK_ENTRY or size is None:
            continue
        fields = {}
        for field, _, _, field_size in _elements(file, start + size):
            if field in (_TRACK_NUMBER, _NAME, _CODEC) and field_size is not None:
                fields[field] = file.read(field_size)
        if _TRACK_NUMBER in fields:
            tracks[fields.get(_NAME, b"").decode("utf-8", "replace")] = (
                int.from_bytes(fields[_TRACK_NUMBER], "big"), fields.get(_CODEC, b"").decode("ascii", "replace"))
    return tracks


def _block_payload(file: BinaryIO, size: int, track: int) -> bytes | None:
    """A (Simple)Block's frame data if it belongs to ``track`` (unlaced), else None."""
    number, length = _vint(file, False)
    if number != track:
        return None
    header = file.read(3)  # timecode (2), flags
    if len(header) < 3:
        raise EOFError
    if header[2] & 0x06:
        raise ValueError("laced IMU blocks are not read")
    return file.read(size - length - 3)


def _blocks(file: BinaryIO, end: int | None) -> Iterator[int]:
    """The data sizes of a Cluster's (Simple)Blocks, the file positioned at each one's data."""
    for element, header, start, size in _elements(file, end):
        if element in _LEVEL1:  # the end of a cluster of unknown size
            file.seek(header)
            return
        if size is None:
            continue
        if element == _SIMPLE_BLOCK:
            yield size
        elif element == _BLOCK_GROUP:
            for inner, _, _, inner_size in _elements(file, start + size):
                if inner == _BLOCK and inner_size is not None:
                    yield inner_size


def imu_samples(path: str | Path, count: int = IMU_SAMPLES, title: str = IMU_TITLE) -> np.ndarray:
    """The first ``count`` samples of an Azure Kinect recording's IMU track.

    path : the ``.mkv``; title : the track's name. Walks the Matroska (EBML) elements to the
    track's blocks, reading the headers of the clusters' blocks and the IMU blocks' data.

    Returns (n,) :data:`IMU_SAMPLE` records, n <= count (0 when the file has no such track);
    ``acc`` in m/s^2, accelerometer frame; timestamps in ns of the device clock.
    ValueError for a file that is not Matroska or a laced IMU block.
    """
    chunks: list[bytes] = []
    wanted = count * IMU_SAMPLE.itemsize
    with open(path, "rb") as file:
        if file.read(4) != EBML_MAGIC:
            raise ValueError(f"{path}: not a Matroska file (no EBML header)")
        file.seek(0)
        try:
            segment = next(((start, size) for element, _, start, size in _elements(file, None)
                            if element == _SEGMENT), None)
            if segment is None:
                raise ValueError(f"{path}: no Matroska segment")
            file.seek(segment[0])
            track = None
            for element, _, start, size in _elements(file, None if segment[1] is None else sum(segment)):
                end = None if size is None else start + size
                if element == _TRACKS:
                    found = _tracks(file, end)
                    if title not in found:
                        return np.zeros(0, IMU_SAMPLE)
                    track = found[title][0]
                elif element == _CLUSTER and track is not None:
                    for block_size in _blocks(file, end):
                        payload = _block_payload(file, block_size, track)
                        if payload is not None:
                            chunks.append(payload)
                            wanted -= len(payload)
                            if wanted <= 0:
                                break
                    if wanted <= 0:
                        break
        except EOFError:
            pass  # a file cut short: the samples read so far
    data = b"".join(chunks)
    data = data[: len(data) // IMU_SAMPLE.itemsize * IMU_SAMPLE.itemsize]
    return np.frombuffer(data, IMU_SAMPLE)[:count].copy()


# ----------------------------------------------------------------------------- the reader

def is_mkv(path: Path) -> bool:
    """Whether ``path`` looks like a Matroska file: a ``.mkv`` file, or a file starting with
    the EBML magic (4 bytes read, no more)."""
    path = Path(path)
    if not path.is_file():
        return False
    if path.suffix.lower() in SUFFIXES:
        return True
    try:
        with path.open("rb") as file:
            return file.read(4) == EBML_MAGIC
    except OSError:
        return False


class MkvSource(StreamSource):
    """An Azure Kinect ``.mkv``'s depth track as one camera (see the module docstring).

    Attributes beyond StreamSource's: ``depth_mode`` (a :data:`DEPTH_MODES` name),
    ``calibration`` (the parsed ``calibration.json``), ``start_offset_us`` (the device
    timestamp of pts 0), ``gravity`` ({"cam0": (3,) depth camera frame, down} where the
    file has IMU samples, else {}).
    """

    def __init__(self, path: Path):
        self._av = require("av", "kinect", "reading Azure Kinect .mkv files")
        self.path = Path(path)
        if not self.path.is_file():
            raise FileNotFoundError(f"{self.path}: no such .mkv file")
        try:
            with self._av.open(str(self.path)) as container:
                self._read_header(container)
        except SourceError:
            raise
        except (self._av.FFmpegError, OSError, UnicodeDecodeError) as error:
            raise self._fail(f"not a readable Matroska file ({type(error).__name__}: {error})") from None
        self.gravity = self._gravity()

    def _fail(self, message: str) -> SourceError:
        return SourceError(f"{self.path}: {message}")

    def _depth_stream(self, container):
        streams = [s for s in container.streams if s.type == "video" and s.metadata.get("title") == DEPTH_TITLE]
        if len(streams) != 1:
            titles = [f"{s.type} {s.metadata.get('title', '(untitled)')!r}" for s in container.streams]
            raise self._fail(f"{len(streams)} video tracks titled {DEPTH_TITLE!r} (an Azure Kinect recording has "
                             f"one, with depth on); its tracks: {', '.join(titles) or 'none'}")
        return streams[0]

    def _read_header(self, container) -> None:
        stream = self._depth_stream(container)
        context = stream.codec_context
        pix_fmt = context.format.name if context.format is not None else None
        if context.name != "rawvideo" or pix_fmt != "gray16be":
            raise self._fail(f"the {DEPTH_TITLE} track is {context.name} {pix_fmt}, not rawvideo gray16be (b16g)")
        width, height = context.width, context.height
        sizes = {size: name for name, (_, _, size) in DEPTH_MODES.items()}
        self.depth_mode = stream.metadata.get("K4A_DEPTH_MODE") or sizes.get((width, height))
        if self.depth_mode not in DEPTH_MODES or DEPTH_MODES[self.depth_mode][2] != (width, height):
            raise self._fail(f"a {width}x{height} {DEPTH_TITLE} track of depth mode {self.depth_mode!r}: not an "
                             f"Azure Kinect depth mode ({', '.join(f'{n} {w}x{h}' for (w, h), n in sizes.items())})")
        self.calibration = self._calibration(container)
        try:
            camera = camera_from_calibration(self.calibration, self.depth_mode)
        except ValueError as error:
            raise self._fail(f"{CALIBRATION}: {error}") from None
        try:
            self.start_offset_us = int(container.metadata.get("K4A_START_OFFSET_NS", "0")) // 1000
        except ValueError:
            raise self._fail(f"K4A_START_OFFSET_NS is {container.metadata['K4A_START_OFFSET_NS']!r}, not an "
                             f"integer") from None
        self._stream_index, self._time_base = stream.index, stream.time_base
        self._frame_bytes = width * height * 2
        stamps = []
        count = 0
        for packet in container.demux(stream):
            if packet.size == 0 or packet.pts is None:
                continue  # the demuxer's flush packet
            if count < FPS_FRAMES:
                stamps.append(self._seconds(packet.pts))
            count += 1
        if count == 0:
            raise self._fail(f"the {DEPTH_TITLE} track has no frames")
        self.num_frames = count
        rate = stream.average_rate or stream.guessed_rate
        intervals = [b - a for a, b in zip(stamps, stamps[1:]) if b > a]
        if rate:
            self.fps = float(rate)
        elif intervals:
            self.fps = round(1.0 / statistics.median(intervals), 3)
        else:
            self.fps = DEFAULT_FPS
        self.cameras = [camera]

    def _calibration(self, container) -> dict:
        attachments = [s for s in container.streams if s.type == "attachment"]
        found = [s for s in attachments if s.metadata.get("filename") == CALIBRATION]
        if not found:
            names = [s.metadata.get("filename", "?") for s in attachments]
            raise self._fail(f"no {CALIBRATION} attachment to give the depth camera's intrinsics (attachments: "
                             f"{', '.join(names) or 'none'})")
        try:
            return json.loads(bytes(found[0].data).rstrip(b"\0").decode("utf-8"))
        except (UnicodeDecodeError, json.JSONDecodeError) as error:
            raise self._fail(f"its {CALIBRATION} attachment is not JSON ({error})") from None

    def _seconds(self, pts: int) -> float:
        """The device timestamp of a packet pts, seconds: the pts in µs plus the start offset."""
        return (int(round(pts * self._time_base * 1_000_000)) + self.start_offset_us) * 1e-6

    def _gravity(self) -> dict[str, np.ndarray]:
        try:
            samples = imu_samples(self.path)
        except (ValueError, OSError):
            return {}
        if not len(samples):
            return {}
        try:
            return {self.cameras[0].name: gravity_from_accelerations(samples["acc"], self.calibration)}
        except ValueError:
            return {}

    def _raw_frames(self, color: bool) -> Iterator[tuple[dict[str, np.ndarray], dict[str, np.ndarray], float]]:
        """(depth {cam0: (H, W) uint16 mm}, {} (no colour), device timestamp in seconds) per depth packet."""
        camera = self.cameras[0]
        try:
            with self._av.open(str(self.path)) as container:
                stream = container.streams[self._stream_index]
                for packet in container.demux(stream):
                    if packet.size == 0 or packet.pts is None:
                        continue
                    if packet.size != self._frame_bytes:
                        raise self._fail(f"a {DEPTH_TITLE} frame of {packet.size} bytes at "
                                         f"{self._seconds(packet.pts):.6f} s; {camera.width}x{camera.height} "
                                         f"16-bit frames have {self._frame_bytes}")
                    depth = np.frombuffer(packet, ">u2").astype(np.uint16).reshape(camera.height, camera.width)
                    yield {camera.name: depth}, {}, self._seconds(packet.pts)
        except SourceError:
            raise
        except (self._av.FFmpegError, OSError) as error:
            raise self._fail(f"the {DEPTH_TITLE} track could not be read ({type(error).__name__}: {error})") from None


def open_mkv(path: Path, **options) -> MkvSource:
    """The Azure Kinect recording at ``path`` as a frame source (:class:`MkvSource`); it
    takes no reader options (SourceError naming any given)."""
    if options:
        raise SourceError(f"{path}: an Azure Kinect .mkv takes no reader options, got {sorted(options)}")
    return MkvSource(Path(path))
