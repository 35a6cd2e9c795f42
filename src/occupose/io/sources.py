"""Frame sources: every recording format behind one interface, chosen from the path.

A frame source is what the tracker, ``show`` and ``score`` read: ``path``, ``fps``,
``num_frames``, ``cameras`` (Camera list, world pose included), ``color_cameras``,
``has_groundtruth``, ``frames(color=...)`` (an iterator of :class:`Frame` in order, read as
it goes: memory stays flat however long the recording) and ``frame(index)``. The native
folder (:class:`occupose.io.recording.Recording`) is one; the other formats' readers are
registered in :data:`READERS` and subclass :class:`StreamSource`.

A recording from a real camera carries no world pose (z up, the floor at z = 0), which
the tracker needs: :func:`open_source` places its cameras, from a pose the user gives
(:class:`HeightTilt` or a JSON file, :func:`pose_from_file`), or from the floor seen in
its own frames.
"""

from __future__ import annotations

import importlib
import itertools
import json
import math
import os
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, Callable, Iterator, Mapping, Protocol, Sequence, runtime_checkable

import numpy as np

from occupose.camera import Camera, look_at, raw_depth_from_metres
from occupose.io.recording import Frame


class SourceError(ValueError):
    """A recording cannot be opened or read as any known format; the message names the file."""


class NoWorldPoseError(SourceError):
    """A recording has no world pose and none could be found from its frames."""


@runtime_checkable
class FrameSource(Protocol):
    """What every reader gives (see the module docstring); Recording is one."""

    path: Path
    fps: float
    num_frames: int
    cameras: list[Camera]

    @property
    def color_cameras(self) -> tuple[str, ...]: ...

    @property
    def has_groundtruth(self) -> bool: ...

    def frames(self, *, color: bool = True) -> Iterator[Frame]: ...

    def frame(self, index: int, *, color: bool = True) -> Frame: ...


class StreamSource:
    """Base of the readers of other formats: a recording read front to back.

    A subclass sets ``path``, ``fps``, ``num_frames`` and ``cameras`` (their world poses,
    the identity until placed, with ``pose_known`` False when the file has none) and
    implements ``_raw_frames(color)``: an iterator of (depth, colour, time) per frame,
    depth a dict camera name -> (H, W) uint16 raw units (metres = value *
    camera.depth_scale, 0 = none), colour a dict camera name -> (H, W, 3) uint8 RGB (empty
    when ``color`` is False), time the frame's device timestamp in seconds (any origin: the
    first frame's is subtracted) or None where the format has none (then index / fps).
    ``gravity`` : dict camera name -> (3,) camera-frame direction of gravity from
    the file's IMU, where it has one (the floor estimate uses it). ``reader_options`` :
    the reader options that open the same recording again, as plain data, with what the
    reader found for itself (a bag's topic when none was given), for ``summary.json``.
    """

    path: Path
    fps: float
    num_frames: int
    cameras: list[Camera]
    pose_known: bool = False
    gravity: Mapping[str, np.ndarray] = {}
    reader: str | None = None
    reader_options: Mapping[str, Any] = {}
    _color_names: tuple[str, ...] = ()

    def _raw_frames(self, color: bool) -> Iterator[tuple[dict[str, np.ndarray], dict[str, np.ndarray],
                                                          float | None]]:
        raise NotImplementedError

    def __repr__(self) -> str:
        return (f"{type(self).__name__}({str(self.path)!r}, {self.num_frames} frames at {self.fps:g} fps, "
                f"cameras {[c.name for c in self.cameras]})")

    @property
    def color_cameras(self) -> tuple[str, ...]:
        """Names of the cameras that have colour images."""
        return tuple(self._color_names)

    @property
    def has_groundtruth(self) -> bool:
        """Recordings of other formats carry no ground truth."""
        return False

    def groundtruth(self):
        """Recordings of other formats carry no ground truth: FileNotFoundError."""
        raise FileNotFoundError(f"{self.path}: a recording of this format has no ground truth")

    def camera(self, name: str) -> Camera:
        """The camera called ``name``."""
        for camera in self.cameras:
            if camera.name == name:
                return camera
        raise SourceError(f"{self.path}: no camera {name!r}; cameras are {[c.name for c in self.cameras]}")

    def frames(self, *, color: bool = True) -> Iterator[Frame]:
        """Every frame in order: depth in float32 metres per camera, colour where there is any."""
        scales = {c.name: c.depth_scale for c in self.cameras}
        start = None
        for index, (raw, colors, time) in enumerate(self._raw_frames(color)):
            if index >= self.num_frames:
                return
            if time is None:
                time = index / self.fps
            elif start is None:
                start = time
            depth = {name: (image * scales[name]).astype(np.float32) for name, image in raw.items()}
            yield Frame(index=index, depth=depth, color=colors if color else {},
                        time=float(time - (start or 0.0)))

    def frame(self, index: int, *, color: bool = True) -> Frame:
        """Frame ``index``, read by going through the frames before it."""
        if isinstance(index, bool) or not isinstance(index, (int, np.integer)) or not 0 <= index < self.num_frames:
            raise SourceError(f"{self.path}: frame index {index!r} out of range; the recording has frames "
                              f"0..{self.num_frames - 1}")
        for frame in self.frames(color=color):
            if frame.index == index:
                return frame
        raise SourceError(f"{self.path}: the recording ended before frame {index}")

    def placed(self, poses: Mapping[str, np.ndarray], origin: str = "given") -> StreamSource:
        """A copy whose cameras have the world poses ``poses`` (camera name -> (4, 4)),
        which came from ``origin`` (``given``, ``floor``; see :func:`placement`)."""
        copy = object.__new__(type(self))
        copy.__dict__.update(self.__dict__)
        copy.cameras = [replace(c, world_from_camera=poses[c.name]) for c in self.cameras]
        copy.pose_known = True
        copy.pose_from = origin
        return copy


@dataclass(frozen=True)
class Reader:
    """A registered recording format.

    name : its name (``--format``); description : one line for the docs and errors;
    extra : the install extra its libraries come in (None: none needed);
    matches : callable(Path) -> bool, whether a path is this format (cheap: the name,
    a few bytes); open : callable(Path, **options) -> FrameSource.
    """

    name: str
    description: str
    extra: str | None
    matches: Callable[[Path], bool]
    open: Callable[..., Any]


#: Readers by name, tried in this order when the format is not given.
READERS: dict[str, Reader] = {}


def register_reader(reader: Reader) -> Reader:
    """Add ``reader`` to :data:`READERS` (its name must be new)."""
    if reader.name in READERS:
        raise ValueError(f"a reader named {reader.name!r} is already registered")
    READERS[reader.name] = reader
    return reader


def require(module: str, extra: str, what: str):
    """Import ``module``, or raise ImportError naming the install extra that brings it."""
    try:
        return importlib.import_module(module)
    except ImportError as error:
        raise ImportError(f"{what} needs the {module!r} package ({error}); install it with "
                          f"pip install 'occupose[{extra}]'") from None


@dataclass(frozen=True)
class HeightTilt:
    """A camera pose given as height and tilt: the optical centre ``height`` metres above
    the floor, the optical axis ``tilt`` degrees below the horizontal (90: straight down),
    no roll; the camera looks along world +y from above the origin."""

    height: float
    tilt: float

    def __post_init__(self) -> None:
        if not (isinstance(self.height, (int, float)) and math.isfinite(self.height) and self.height > 0):
            raise ValueError(f"camera height must be a positive number of metres, got {self.height!r}")
        if not (isinstance(self.tilt, (int, float)) and -90.0 <= self.tilt <= 90.0):
            raise ValueError(f"tilt must be in degrees from -90 to 90 (below the horizontal), got {self.tilt!r}")

    def world_from_camera(self) -> np.ndarray:
        """(4, 4) float64 rigid transform, camera frame (OpenCV axes) to world."""
        tilt = math.radians(self.tilt)
        eye = np.array([0.0, 0.0, self.height])
        return look_at(eye, eye + (0.0, math.cos(tilt), -math.sin(tilt)))


def pose_from_file(path: str | os.PathLike, names: Sequence[str]) -> dict[str, np.ndarray]:
    """World poses from a JSON file: ``{"world_from_camera": 4x4}`` for every camera, or
    ``{"cameras": {name: {"world_from_camera": 4x4}}}`` per camera ``names``."""
    path = Path(path)
    try:
        data = json.loads(path.read_text(encoding="utf-8-sig"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as error:
        raise SourceError(f"{path}: not a readable JSON pose file ({error})") from None
    if isinstance(data, Mapping) and "cameras" in data and isinstance(data["cameras"], Mapping):
        entries = data["cameras"]
        missing = [n for n in names if n not in entries]
        if missing:
            raise SourceError(f"{path}: no pose for camera(s) {missing}; it has {sorted(entries)}")
        matrices = {n: entries[n].get("world_from_camera") if isinstance(entries[n], Mapping) else None
                    for n in names}
    elif isinstance(data, Mapping) and "world_from_camera" in data:
        matrices = dict.fromkeys(names, data["world_from_camera"])
    else:
        raise SourceError(f"{path}: expected {{\"world_from_camera\": [[...] x 4]}} or "
                          f"{{\"cameras\": {{name: {{\"world_from_camera\": ...}}}}}}")
    poses = {}
    for name, matrix in matrices.items():
        try:
            poses[name] = Camera(name=name, width=1, height=1, fx=1, fy=1, cx=0, cy=0,
                                 world_from_camera=matrix).world_from_camera
        except ValueError as error:
            raise SourceError(f"{path}: {error}") from None
    return poses


def reader_for(path: str | os.PathLike, format: str | None = None) -> Reader:
    """The reader of ``path``: the one named ``format``, or the first in :data:`READERS`
    that recognises it. SourceError listing the formats when none does."""
    path = Path(path)
    if format is not None:
        if format not in READERS:
            raise SourceError(f"unknown recording format {format!r}; valid: {', '.join(READERS)}")
        return READERS[format]
    if not path.exists():
        raise FileNotFoundError(f"{path}: no such recording")
    for reader in READERS.values():
        if reader.matches(path):
            return reader
    if path.is_dir():  # no recording.json: the folder reader says what is missing
        return READERS["folder"]
    formats = "; ".join(f"{r.name}: {r.description}" for r in READERS.values())
    raise SourceError(f"{path}: not a recording of any known format ({formats})")


def open_source(path: str | os.PathLike, *, format: str | None = None, pose: HeightTilt | str | os.PathLike |
                None = None, find_floor: bool = False, floor=None, **options) -> FrameSource:
    """Open the recording at ``path`` with its reader (:func:`reader_for`), its cameras placed.

    format : a :data:`READERS` name, or None to recognise it from the path
    pose : for a recording without a world pose: a :class:`HeightTilt` (every camera), a
        JSON pose file (:func:`pose_from_file`), or None to find the floor in its frames
        (:func:`place_from_floor`). A recording that has a pose keeps it; a pose given for
        one is an error.
    find_floor : place the cameras from the floor even when the recording has a pose
    floor : the :class:`occupose.config.FloorConfig` of the floor estimate (None: the default)
    options : the reader's own (``topic`` for bags, ``camera`` for TUM folders, ...)

    The source's ``reader`` is the name of the reader that opened it (:func:`source_of`).
    """
    reader = reader_for(path, format)
    source = reader.open(Path(path), **options)
    source.reader = reader.name
    if find_floor:
        if pose is not None:
            raise SourceError(f"{path}: give either a pose or find_floor, not both")
        return place_from_floor(without_pose(source), floor)
    if getattr(source, "pose_known", True):
        if pose is not None:
            raise SourceError(f"{path}: the recording has its own world pose; drop the pose option")
        return source
    names = [c.name for c in source.cameras]
    if isinstance(pose, HeightTilt):
        return source.placed(dict.fromkeys(names, pose.world_from_camera()), "given")
    if pose is not None:
        return source.placed(pose_from_file(pose, names), "given")
    return place_from_floor(source, floor)


def place_from_floor(source: StreamSource, config=None) -> StreamSource:
    """``source`` with its camera placed from the floor seen in its first frames
    (:func:`occupose.geometry.floor.find_floor`, gravity from ``source.gravity``).
    NoWorldPoseError when no floor is found, or for several cameras (their relative poses
    are not known)."""
    from occupose.config import FloorConfig
    from occupose.geometry.floor import find_floor

    config = FloorConfig() if config is None else config
    give = "give it with --camera-height H --tilt DEGREES or --world-from-camera FILE.json"
    if len(source.cameras) != 1:
        raise NoWorldPoseError(f"{source.path}: the recording has no world pose and {len(source.cameras)} cameras "
                               f"(the floor places one camera, not their poses to each other); {give}")
    camera = source.cameras[0]
    depths = (f.depth[camera.name] for f in itertools.islice(source.frames(color=False), config.frames))
    floor = find_floor(camera, depths, config, gravity=source.gravity.get(camera.name))
    if floor is None:
        raise NoWorldPoseError(f"{source.path}: the recording has no world pose (z up, the floor at z = 0) and no "
                               f"floor was found in its first {config.frames} frames (a plane with at least "
                               f"{config.min_share:.0%} of the points, nothing beyond it, the camera "
                               f"{config.min_height:g}-{config.max_height:g} m above it); {give}")
    return source.placed({camera.name: floor.world_from_camera()}, "floor")


def source_of(source: FrameSource) -> dict[str, Any]:
    """How ``source`` was read, for ``summary.json``: ``reader`` (its :data:`READERS` name,
    None when it was not opened by :func:`open_source`) and ``options`` (the reader options
    that open it again, ``StreamSource.reader_options``)."""
    return {"reader": getattr(source, "reader", None), "options": dict(getattr(source, "reader_options", {}))}


def placement(source: FrameSource) -> list[dict[str, Any]]:
    """Each camera's pose as a user reads it: ``name``, ``height_m`` (above the floor z = 0),
    ``tilt_deg`` (the optical axis below the horizontal), ``roll_deg`` and ``pose`` (where
    it came from: ``recording``, ``given`` or ``floor``) and ``world_from_camera`` (the (4, 4)
    pose as nested lists, so that a run's camera frame can be rebuilt from its summary)."""
    origin = getattr(source, "pose_from", "recording")
    entries = []
    for camera in source.cameras:
        pose = camera.world_from_camera
        entries.append({"name": camera.name, "height_m": round(float(pose[2, 3]), 4),
                        "tilt_deg": round(math.degrees(math.asin(np.clip(-pose[2, 2], -1, 1))), 3),
                        "roll_deg": round(math.degrees(math.asin(np.clip(pose[2, 0], -1, 1))), 3),
                        "pose": origin, "world_from_camera": pose.tolist()})
    return entries


class _Unplaced(StreamSource):
    """Any frame source's frames, its cameras' poses forgotten (:func:`without_pose`)."""

    def __init__(self, source: FrameSource):
        self.path, self.fps, self.num_frames = source.path, source.fps, source.num_frames
        self.cameras = [replace(c, world_from_camera=np.eye(4)) for c in source.cameras]
        self._color_names = tuple(source.color_cameras)
        self.gravity = dict(getattr(source, "gravity", {}))
        self.reader = getattr(source, "reader", None)
        self.reader_options = dict(getattr(source, "reader_options", {}))
        self._source = source

    def _raw_frames(self, color):
        for frame in self._source.frames(color=color):
            yield ({c.name: raw_depth_from_metres(frame.depth[c.name], c) for c in self.cameras}, frame.color,
                   frame.time)


def without_pose(source: FrameSource) -> StreamSource:
    """``source`` as a recording without a world pose (to place it from its floor)."""
    return _Unplaced(source)


def lazy(module: str, function: str) -> Callable[..., Any]:
    """A reader's ``open`` that imports ``module`` only when it is called."""
    def open_(path: Path, **options):
        return getattr(importlib.import_module(module), function)(path, **options)
    open_.__qualname__ = f"{module}.{function}"
    return open_


def _is_folder_recording(path: Path) -> bool:
    return path.is_dir() and (path / "recording.json").is_file()


def _open_folder(path: Path, **options):
    from occupose.io.recording import Recording

    if options:
        raise SourceError(f"{path}: a recording folder takes no reader options, got {sorted(options)}")
    return Recording(path)


register_reader(Reader("folder", "occupose's recording folder (recording.json, <camera>/depth/*.png)", None,
                       _is_folder_recording, _open_folder))
register_reader(Reader("bag", "a ROS 1 .bag (RealSense .bag too) or a ROS 2 bag (a folder with metadata.yaml, "
                       ".db3 or .mcap): one depth image topic", "ros", lazy("occupose.io.rosbag", "is_bag"),
                       lazy("occupose.io.rosbag", "open_bag")))
register_reader(Reader("mkv", "an Azure Kinect .mkv (k4arecorder): its DEPTH track, the calibration attachment's "
                       "intrinsics, the IMU's gravity", "kinect", lazy("occupose.io.mkv", "is_mkv"),
                       lazy("occupose.io.mkv", "open_mkv")))
register_reader(Reader("tum", "a TUM RGB-D folder (depth.txt, depth/*.png at 5000 units per metre; camera fr1, "
                       "fr2, fr3 or given)", None, lazy("occupose.io.tum", "is_tum"),
                       lazy("occupose.io.tum", "open_tum")))
