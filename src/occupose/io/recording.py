"""The native recording folder: write it, open it, iterate its frames (DESIGN.md "Recording folder").

::

    <recording>/
      recording.json               format, version, fps, num_frames, cameras
      <camera>/depth/000000.png    16-bit PNG; depth = value * depth_scale metres; 0 = no measurement
      <camera>/color/000000.png    optional 8-bit RGB, registered to the depth image
      groundtruth.csv              optional: frame,person,joint,x,y,z[,visible] (world metres)
      times.csv                    optional: frame,time (seconds since the first frame)

A camera has colour when its ``color`` folder exists; it then has a colour image for
every frame. Ground truth has one row per frame, person and known joint; joints with
no row are unknown (NaN); `occupose.io.joint_table` reads and writes it. ``times.csv``
holds each frame's time where the frames were not evenly spaced at ``fps`` (a converted
recording whose device dropped frames); without it frame i is at i / fps.

Opening a recording checks ``recording.json`` and every frame file's PNG header (mode and
size; no image is decoded before its header is checked), and refuses frame files past
``num_frames``. Everything wrong with a recording, an OS error reading it (permission
denied, a folder or a device where a file should be) included, is reported as a
RecordingError (a ValueError) or FileNotFoundError whose message names the file.
"""

from __future__ import annotations

import json
import os
import re
import sys
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Iterator, Mapping, Sequence

import numpy as np
from PIL import Image, UnidentifiedImageError

from occupose._validate import positive_float
from occupose.camera import Camera, camera_from_dict
from occupose.io._files import check_regular_file, read_file_bytes
from occupose.io.joint_table import JointTableError, read_joint_table, write_joint_table
from occupose.io.output import write_text
from occupose.joints import NUM_JOINTS

FORMAT = "occupose-recording"
VERSION = 1
SUPPORTED_VERSIONS: tuple[int, ...] = (1,)
RECORDING_KEYS: tuple[str, ...] = ("format", "version", "fps", "num_frames", "cameras")
#: Keys a recording.json may have besides: ``origin``, what a converted recording was made
#: from (``{"source": path, "reader": name, "cameras": [height, tilt, roll, pose of each]}``).
OPTIONAL_KEYS: tuple[str, ...] = ("origin",)

_JSON_NAME = "recording.json"
_GROUNDTRUTH_NAME = "groundtruth.csv"
_TIMES_NAME = "times.csv"
#: Seconds by which a frame's time may differ from index / fps before times.csv is written;
#: times.csv keeps microseconds.
_TIME_TOLERANCE_S = 1e-6


#: Synthetic label images a recording may carry beside depth and colour.
LABEL_KINDS = ("person", "part")

# The images of a recording by kind: their PIL mode and what the messages call them.
_IMAGES = {"depth": ("I;16", "a 16-bit grayscale depth"), "color": ("RGB", "an 8-bit RGB colour"),
           **{kind: ("L", f"an 8-bit {kind} label") for kind in LABEL_KINDS}}
# The name of a frame's image file (`frame_filename`), any frame number.
_FRAME_NAME = re.compile(r"[0-9]{6,}\.png")


class RecordingError(ValueError):
    """A recording folder or one of its files is malformed; the message names the file."""


def frame_filename(index: int) -> str:
    """Name of frame ``index``'s image file: zero-padded to six digits, ``000042.png``."""
    return f"{index:06d}.png"


@dataclass(frozen=True)
class Frame:
    """One time step of a recording.

    index : int, frame number from 0
    depth : dict camera name -> (H, W) float32, metres; 0 where there is no measurement
    color : dict camera name -> (H, W, 3) uint8 RGB, for the cameras that have colour
    time : float, seconds since the recording's first frame: the device's timestamps
        where the format has them, else ``index / fps``
    """

    index: int
    depth: dict[str, np.ndarray]
    color: dict[str, np.ndarray]
    time: float = 0.0


@dataclass(frozen=True)
class GroundTruth:
    """Ground-truth skeletons of a recording.

    joints : (T, P, 15, 3) float64, metres, world frame; NaN where unknown (person absent)
    visible : (T, P, 15) bool; False where unknown
    person_ids : tuple of P ints, increasing; person p of the arrays has id person_ids[p]
    """

    joints: np.ndarray
    visible: np.ndarray
    person_ids: tuple[int, ...]


# ----------------------------------------------------------------------------- writing


class RecordingWriter:
    """Write a recording folder frame by frame.

    ``path`` must not exist or be an empty folder. Every ``write_frame`` call gives a
    depth image for every camera; the first call decides which cameras have colour and
    later calls must give colour for the same cameras. ``close()`` (or leaving the
    ``with`` block without an exception) writes ``recording.json``; a block left by an
    exception leaves the folder without it, i.e. not a readable recording.
    """

    def __init__(self, path: str | os.PathLike, cameras: Sequence[Camera], fps: float, *,
                 origin: Mapping | None = None):
        self.path = Path(path)
        self.origin = None if origin is None else dict(origin)  # recording.json's optional "origin"
        cameras = list(cameras)
        if not cameras or not all(isinstance(c, Camera) for c in cameras):
            raise ValueError(f"cameras must be a non-empty list of Camera, got {cameras!r}")
        names = [c.name for c in cameras]
        if len(set(names)) != len(names):
            raise ValueError(f"camera names must be unique, got {names}")
        fps = positive_float(fps, "fps")
        if self.path.exists() and (not self.path.is_dir() or any(self.path.iterdir())):
            raise FileExistsError(f"{self.path}: recording folder must not exist or be empty")
        self.cameras = cameras
        self.fps = fps
        self.num_frames = 0
        self._color_names: frozenset[str] | None = None
        self._groundtruth_frames: int | None = None
        self._times: list[float] = []
        self._closed = False
        for camera in cameras:
            (self.path / camera.name / "depth").mkdir(parents=True, exist_ok=True)

    def __enter__(self) -> RecordingWriter:
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        if exc_type is None:
            self.close()

    def _check_open(self) -> None:
        if self._closed:
            raise ValueError(f"{self.path}: recording writer is closed")

    def write_frame(
        self,
        depths: Mapping[str, np.ndarray],
        colors: Mapping[str, np.ndarray] | None = None,
        labels: Mapping[str, Mapping[str, np.ndarray]] | None = None,
        time: float | None = None,
    ) -> None:
        """Append one frame.

        depths : dict camera name -> (H, W) uint16 raw depth (metres / depth_scale), every camera
        colors : dict camera name -> (H, W, 3) uint8 RGB, or None for no colour
        labels : optional synthetic label images, dict camera name -> {kind: (H, W) uint8}
            with kind in LABEL_KINDS ("person": person id, 0 = none; "part": body-part label)
        time : seconds since the first frame (given for every frame or for none; not
            decreasing); times that are not index / fps are written into times.csv
        """
        self._check_open()
        if (time is None) != (not self._times) and self.num_frames:
            raise ValueError(f"time must be given for every frame or for none (frame {self.num_frames})")
        if time is not None:
            time = float(time)
            if not np.isfinite(time) or (self._times and time < self._times[-1]):
                raise ValueError(f"frame {self.num_frames}'s time must be finite and not before the previous "
                                 f"frame's, got {time!r}")
        colors = {} if colors is None else dict(colors)
        labels = {} if labels is None else dict(labels)
        expected = [c.name for c in self.cameras]
        if set(depths) != set(expected):
            raise ValueError(f"depths must have one image per camera {expected}, got {sorted(depths)}")
        unknown = sorted(set(colors) - set(expected))
        if unknown:
            raise ValueError(f"colors given for unknown camera(s) {unknown}; cameras are {expected}")
        if self._color_names is not None and set(colors) != self._color_names:
            raise ValueError(
                f"colors must be given for the same cameras in every frame: "
                f"{sorted(self._color_names)} before, {sorted(colors)} in frame {self.num_frames}"
            )
        images = []
        for camera in self.cameras:
            size = (camera.height, camera.width)
            depth = np.asarray(depths[camera.name])
            if depth.dtype != np.uint16 or depth.shape != size:
                raise ValueError(
                    f"depth for camera {camera.name!r} must be uint16 {size} raw values "
                    f"(see camera.raw_depth_from_metres), got {depth.dtype} {depth.shape}"
                )
            images.append((camera.name, "depth", np.ascontiguousarray(depth)))
            if camera.name in colors:
                color = np.asarray(colors[camera.name])
                if color.dtype != np.uint8 or color.shape != size + (3,):
                    raise ValueError(
                        f"color for camera {camera.name!r} must be uint8 {size + (3,)} RGB, "
                        f"got {color.dtype} {color.shape}"
                    )
                images.append((camera.name, "color", np.ascontiguousarray(color)))
            for kind, label in labels.get(camera.name, {}).items():
                label = np.asarray(label)
                if kind not in LABEL_KINDS or label.dtype != np.uint8 or label.shape != size:
                    raise ValueError(
                        f"label image {kind!r} for camera {camera.name!r} must be one of {LABEL_KINDS} "
                        f"as uint8 {size}, got {label.dtype} {label.shape}"
                    )
                images.append((camera.name, kind, np.ascontiguousarray(label)))
        name = frame_filename(self.num_frames)
        for camera_name, kind, image in images:
            folder = self.path / camera_name / kind
            if kind != "depth":
                folder.mkdir(exist_ok=True)
            Image.fromarray(image).save(folder / name, compress_level=1)
        self._color_names = frozenset(colors)
        if time is not None:
            self._times.append(time)
        self.num_frames += 1

    def write_groundtruth(
        self, joints: np.ndarray, visible: np.ndarray, person_ids: Sequence[int]
    ) -> None:
        """Write ``groundtruth.csv`` (once). Its frame count must match the recording's at close.

        joints : (T, P, 15, 3) float, metres, world frame; NaN where unknown (person absent);
            each joint is either fully finite or fully NaN
        visible : (T, P, 15) bool
        person_ids : P distinct ints (rows are written by frame, then increasing id, then joint)
        """
        self._check_open()
        if self._groundtruth_frames is not None:
            raise ValueError(f"{self.path / _GROUNDTRUTH_NAME}: ground truth was already written")
        joints = np.asarray(joints, dtype=np.float64)
        visible = np.asarray(visible)
        ids = [int(i) for i in person_ids]
        if joints.ndim != 4 or joints.shape[2:] != (NUM_JOINTS, 3):
            raise ValueError(f"joints must have shape (T, P, {NUM_JOINTS}, 3), got {joints.shape}")
        if visible.dtype != bool or visible.shape != joints.shape[:3]:
            raise ValueError(f"visible must be bool of shape {joints.shape[:3]}, got {visible.dtype} {visible.shape}")
        if len(ids) != joints.shape[1] or len(set(ids)) != len(ids):
            raise ValueError(f"person_ids must be {joints.shape[1]} distinct ints, got {list(person_ids)}")
        write_joint_table(self.path / _GROUNDTRUTH_NAME,
                          {ids[p]: (joints[:, p], visible[:, p]) for p in range(len(ids))}, "groundtruth")
        self._groundtruth_frames = joints.shape[0]

    def close(self) -> None:
        """Write ``recording.json`` (and ``times.csv`` when a frame's time is not its
        index / fps). Calling it again does nothing."""
        if self._closed:
            return
        if self._groundtruth_frames is not None and self._groundtruth_frames != self.num_frames:
            raise ValueError(
                f"{self.path / _GROUNDTRUTH_NAME}: ground truth has {self._groundtruth_frames} frames, "
                f"the recording {self.num_frames}"
            )
        even = np.arange(self.num_frames) / self.fps
        if self._times and np.abs(np.asarray(self._times) - even).max() > _TIME_TOLERANCE_S:
            rows = "".join(f"{i},{t:.6f}\n" for i, t in enumerate(self._times))
            write_text(self.path / _TIMES_NAME, "frame,time\n" + rows)
        # one camera per line, as in DESIGN.md, rather than one number per line
        head = {"format": FORMAT, "version": VERSION, "fps": self.fps, "num_frames": self.num_frames}
        head = json.dumps(head if self.origin is None else dict(head, origin=self.origin))
        cameras = ",\n  ".join(json.dumps(c.to_dict()) for c in self.cameras)
        write_text(self.path / _JSON_NAME, f'{head[:-1]},\n "cameras": [\n  {cameras}\n ]}}\n')
        self._closed = True


# ----------------------------------------------------------------------------- reading


def _read_header(file: Path) -> tuple[float, int, list[Camera]]:
    try:
        data = read_file_bytes(file, RecordingError, "the recording's JSON header")
    except FileNotFoundError:
        raise FileNotFoundError(f"{file}: no such file; a recording folder needs a {_JSON_NAME}") from None
    try:
        header = json.loads(data.decode("utf-8-sig"))
    except UnicodeDecodeError as error:
        raise RecordingError(f"{file}: not a UTF-8 text file ({error.reason})") from None
    except json.JSONDecodeError as error:
        raise RecordingError(
            f"{file}: not valid JSON ({error.msg} at line {error.lineno} column {error.colno})"
        ) from None
    except RecursionError:
        raise RecordingError(f"{file}: JSON nested too deeply to be a recording header") from None
    except ValueError as error:  # an integer of more digits than Python converts (its advice cut)
        raise RecordingError(f"{file}: not a readable recording header ({str(error).split(';')[0]})") from None
    if not isinstance(header, dict):
        raise RecordingError(f"{file}: expected a JSON object, got {type(header).__name__}")
    if header.get("format") != FORMAT:
        raise RecordingError(f"{file}: \"format\" must be {FORMAT!r}, got {header.get('format')!r}")
    version = header.get("version")
    if isinstance(version, bool) or version not in SUPPORTED_VERSIONS:
        raise RecordingError(
            f"{file}: unsupported version {version!r}; this occupose reads versions {list(SUPPORTED_VERSIONS)}"
        )
    missing = [k for k in RECORDING_KEYS if k not in header]
    if missing:
        raise RecordingError(f"{file}: missing key(s) {missing}; a recording needs {list(RECORDING_KEYS)}")
    unknown = sorted(set(header) - set(RECORDING_KEYS) - set(OPTIONAL_KEYS))
    if unknown:
        raise RecordingError(f"{file}: unknown key(s) {unknown}; a recording has {list(RECORDING_KEYS)} "
                             f"and may have {list(OPTIONAL_KEYS)}")
    fps, num_frames, entries = header["fps"], header["num_frames"], header["cameras"]
    if isinstance(fps, bool) or not isinstance(fps, (int, float)) or not 0 < fps <= sys.float_info.max:
        raise RecordingError(f"{file}: \"fps\" must be a positive number, got {fps!r}")
    if isinstance(num_frames, bool) or not isinstance(num_frames, int) or num_frames < 0:
        raise RecordingError(f"{file}: \"num_frames\" must be a non-negative integer, got {num_frames!r}")
    if not isinstance(entries, list) or not entries:
        raise RecordingError(f"{file}: \"cameras\" must be a non-empty list, got {entries!r}")
    cameras = []
    for i, entry in enumerate(entries):
        try:
            cameras.append(camera_from_dict(entry, source=f"{file}: cameras[{i}]"))
        except ValueError as error:
            raise RecordingError(str(error)) from None
    names = [c.name for c in cameras]
    if len(set(names)) != len(names):
        raise RecordingError(f"{file}: camera names must be unique, got {names}")
    return float(fps), num_frames, cameras


def _check_frame_files(folder: Path, num_frames: int, kind: str, camera: Camera) -> None:
    """Check that ``folder`` holds frames 0 .. num_frames - 1 of ``kind`` ("depth" or
    "color", `_IMAGES`), each a regular file whose PNG header has the kind's mode and the
    camera's size (nothing decoded), and no frame file numbered num_frames or more."""
    try:
        names = os.listdir(folder)
    except FileNotFoundError:
        raise FileNotFoundError(f"{folder}: no such folder; it should hold the camera's {num_frames} frames") from None
    except OSError as problem:
        raise RecordingError(
            f"{folder}: cannot list it ({problem.strerror or problem}); it should hold the camera's {num_frames} frames"
        ) from None
    extra = sorted(n for n in names if _FRAME_NAME.fullmatch(n) and int(n[:-4]) >= num_frames)
    if extra:
        raise RecordingError(
            f"{folder}: {len(extra)} frame file(s) past the recording's \"num_frames\" {num_frames} "
            f"({extra[0]}{' .. ' + extra[-1] if len(extra) > 1 else ''}); set num_frames in "
            f"{_JSON_NAME} to the frames there are, or remove the files after the last frame"
        )
    present = set(names)
    for i in range(num_frames):
        file = folder / frame_filename(i)
        if file.name not in present:
            raise FileNotFoundError(f"{file}: missing frame file (recording has {num_frames} frames)")
        _read_png(file, kind, camera, decode=False)


def _read_png(file: Path, kind: str, camera: Camera, *, decode: bool = True) -> np.ndarray | None:
    """The image of ``file``, a PNG of ``kind`` (a key of `_IMAGES`) of ``camera``'s size.

    Mode and size are checked from the PNG header before anything is decoded (an image
    over twice PIL's decompression-bomb limit is refused without its size). Returns (H, W) uint16,
    (H, W, 3) uint8 or (H, W) uint8 as the kind's mode says, or None when ``decode`` is
    False (the header checked only).
    """
    mode, what = _IMAGES[kind]
    height, width = camera.height, camera.width
    expected = f"{what} PNG (mode {mode!r}) of {width}x{height}"
    try:
        check_regular_file(file, RecordingError, expected)
    except FileNotFoundError:
        raise FileNotFoundError(f"{file}: missing frame file") from None
    try:
        handle = open(file, "rb")
    except OSError as problem:  # permission denied, a link loop
        raise RecordingError(f"{file}: cannot read it ({problem.strerror or problem}); expected {expected}") from None
    try:
        with handle, warnings.catch_warnings():  # the size is checked below, before anything is decoded
            warnings.simplefilter("ignore", Image.DecompressionBombWarning)
            image = Image.open(handle)
            if image.format != "PNG" or image.mode != mode:
                raise RecordingError(
                    f"{file}: expected {what} PNG (mode {mode!r}), got a {image.format} image of mode {image.mode!r}"
                )
            if image.size != (width, height):
                raise RecordingError(
                    f"{file}: image is {image.size[0]}x{image.size[1]}, the camera is {width}x{height}"
                )
            return np.asarray(image) if decode else None
    except RecordingError:
        raise
    except Image.DecompressionBombError as error:
        raise RecordingError(f"{file}: far too large an image for a frame; expected {expected} ({error})") from None
    except UnidentifiedImageError:
        raise RecordingError(f"{file}: not a readable PNG image (cannot identify image file)") from None
    except (OSError, SyntaxError, ValueError) as error:
        raise RecordingError(f"{file}: not a readable PNG image ({error})") from None


def _read_times(file: Path, num_frames: int) -> np.ndarray | None:
    """(num_frames,) float64 seconds of ``times.csv`` (a ``frame,time`` header, then frames
    0 .. num_frames - 1 in order, times finite and not decreasing), or None without one."""
    if not file.exists():
        return None
    try:
        text = read_file_bytes(file, RecordingError, "the frames' times").decode("utf-8-sig")
    except UnicodeDecodeError as error:
        raise RecordingError(f"{file}: not a UTF-8 text file ({error.reason})") from None
    lines = text.splitlines()
    if not lines or lines[0].strip() != "frame,time":
        raise RecordingError(f"{file}: the first line must be 'frame,time'")
    rows = lines[1:]
    if len(rows) != num_frames:
        raise RecordingError(f"{file}: {len(rows)} frame time(s), the recording has {num_frames} frames")
    times = np.empty(num_frames)
    for i, row in enumerate(rows):
        fields = row.split(",")
        try:
            if len(fields) != 2 or int(fields[0]) != i:
                raise ValueError
            times[i] = float(fields[1])
        except ValueError:
            raise RecordingError(f"{file}: line {i + 2} must be '{i},<seconds>', got {row[:60]!r}") from None
        if not np.isfinite(times[i]) or (i and times[i] < times[i - 1]):
            raise RecordingError(f"{file}: line {i + 2}: frame {i}'s time {fields[1]!r} is not finite or is before "
                                 "the previous frame's")
    return times


class Recording:
    """An open recording folder (read-only; images are read on demand).

    Attributes: ``path`` (Path), ``fps`` (float), ``num_frames`` (int), ``cameras``
    (list of Camera). Opening checks ``recording.json``, that every frame file exists and
    that its PNG header gives the right mode and size (nothing is decoded), that no
    camera has frame files past ``num_frames``, and ``times.csv`` where there is one.
    """

    def __init__(self, path: str | os.PathLike):
        self.path = Path(path)
        if not self.path.is_dir():
            raise FileNotFoundError(f"{self.path}: no such recording folder")
        self.fps, self.num_frames, self.cameras = _read_header(self.path / _JSON_NAME)
        self._times = _read_times(self.path / _TIMES_NAME, self.num_frames)
        self._by_name = {c.name: c for c in self.cameras}
        self._color_names = []
        for camera in self.cameras:
            _check_frame_files(self.path / camera.name / "depth", self.num_frames, "depth", camera)
            if (self.path / camera.name / "color").exists():
                _check_frame_files(self.path / camera.name / "color", self.num_frames, "color", camera)
                self._color_names.append(camera.name)

    def __repr__(self) -> str:
        return (
            f"Recording({str(self.path)!r}, {self.num_frames} frames at {self.fps:g} fps, "
            f"cameras {list(self._by_name)})"
        )

    def camera(self, name: str) -> Camera:
        """The camera called ``name``."""
        try:
            return self._by_name[name]
        except KeyError:
            raise RecordingError(f"{self.path}: no camera {name!r}; cameras are {list(self._by_name)}") from None

    @property
    def color_cameras(self) -> tuple[str, ...]:
        """Names of the cameras that have colour images."""
        return tuple(self._color_names)

    def _check_index(self, index: int) -> int:
        if isinstance(index, bool) or not isinstance(index, (int, np.integer)) or not 0 <= index < self.num_frames:
            raise RecordingError(
                f"{self.path}: frame index {index!r} out of range; the recording has frames 0..{self.num_frames - 1}"
            )
        return int(index)

    def depth_raw(self, index: int, name: str) -> np.ndarray:
        """(H, W) uint16 raw depth of camera ``name`` at frame ``index`` (metres = value * depth_scale)."""
        camera = self.camera(name)
        file = self.path / name / "depth" / frame_filename(self._check_index(index))
        return _read_png(file, "depth", camera)

    def color(self, index: int, name: str) -> np.ndarray:
        """(H, W, 3) uint8 RGB image of camera ``name`` at frame ``index``."""
        camera = self.camera(name)
        if name not in self._color_names:
            raise RecordingError(f"{self.path / name}: camera {name!r} has no color folder")
        file = self.path / name / "color" / frame_filename(self._check_index(index))
        return _read_png(file, "color", camera)

    def label(self, index: int, name: str, kind: str) -> np.ndarray:
        """(H, W) uint8 synthetic label image (``kind`` in LABEL_KINDS) of camera ``name``.

        Only synthetic recordings have them: ``<camera>/person/`` holds the person id of
        every pixel (0 = none), ``<camera>/part/`` its body-part label (occupose.joints.PARTS).
        """
        camera = self.camera(name)
        if kind not in LABEL_KINDS:
            raise ValueError(f"unknown label kind {kind!r}; valid: {', '.join(LABEL_KINDS)}")
        file = self.path / name / kind / frame_filename(self._check_index(index))
        if not file.parent.is_dir():
            raise RecordingError(f"{file.parent}: this recording has no {kind!r} label images (only synthetic ones do)")
        return _read_png(file, kind, camera)

    def has_labels(self, kind: str) -> bool:
        """Whether every camera has ``kind`` label images (LABEL_KINDS; synthetic recordings)."""
        if kind not in LABEL_KINDS:
            raise ValueError(f"unknown label kind {kind!r}; valid: {', '.join(LABEL_KINDS)}")
        return all((self.path / c.name / kind).is_dir() for c in self.cameras)

    def frame(self, index: int, *, color: bool = True) -> Frame:
        """Frame ``index``: depth in float32 metres for every camera, colour where there is
        any (none read when ``color`` is False: ``Frame.color`` is then empty)."""
        index = self._check_index(index)
        depth = {
            c.name: (self.depth_raw(index, c.name) * c.depth_scale).astype(np.float32) for c in self.cameras
        }
        colors = {name: self.color(index, name) for name in self._color_names} if color else {}
        time = index / self.fps if self._times is None else float(self._times[index])
        return Frame(index=index, depth=depth, color=colors, time=time)

    def frames(self, *, color: bool = True) -> Iterator[Frame]:
        """Iterate over all frames in order, reading each when it is reached (`frame`)."""
        for index in range(self.num_frames):
            yield self.frame(index, color=color)

    @property
    def has_groundtruth(self) -> bool:
        """Whether the recording has a ``groundtruth.csv``."""
        return (self.path / _GROUNDTRUTH_NAME).is_file()

    def groundtruth(self) -> GroundTruth:
        """Read ``groundtruth.csv`` into arrays over all ``num_frames`` frames.

        A missing ``visible`` column means every listed joint is visible. Persons are
        those with at least one row, in increasing id order.
        """
        file = self.path / _GROUNDTRUTH_NAME
        if not file.exists():
            raise FileNotFoundError(f"{file}: no such file; this recording has no ground truth")
        try:
            table = read_joint_table(file, self.num_frames, "groundtruth")
        except JointTableError as error:
            raise RecordingError(str(error)) from None
        person_ids = tuple(sorted(table))
        joints = np.full((self.num_frames, len(person_ids), NUM_JOINTS, 3), np.nan)
        visible = np.zeros(joints.shape[:3], dtype=bool)
        for p, person in enumerate(person_ids):
            joints[:, p], visible[:, p] = table[person]
        return GroundTruth(joints=joints, visible=visible, person_ids=person_ids)


def open_recording(path: str | os.PathLike) -> Recording:
    """Open the recording folder at ``path`` (same as ``Recording(path)``)."""
    return Recording(path)
