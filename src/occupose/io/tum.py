"""TUM RGB-D benchmark folders (``depth.txt`` and ``depth/*.png``) as frame sources.

What is read, and from where:

- depth: the 16-bit PNGs listed in ``depth.txt`` (``timestamp filename`` lines, ``#``
  comments), in its order; a value / :data:`DEPTH_FACTOR` (5000) is metres, 0 = none: the
  camera's ``depth_scale`` is 1 / 5000 = 0.0002 and the values are kept as they are.
- intrinsics: the dataset's published values of its three Kinects, by name
  (:data:`TUM_CAMERAS`: ``fr1``, ``fr2``, ``fr3``; the depth images are registered to the
  colour camera, so its intrinsics), or given. The ``camera`` option: a name, a JSON file
  ``{"fx": ..., "fy": ..., "cx": ..., "cy": ...}`` (pixels; the size is the images'), or
  None for the name in the folder's (``rgbd_dataset_freiburg2_desk`` is ``fr2``); a
  folder whose name says none is an error asking for one. Lens distortion is not used.
- time: the timestamps of ``depth.txt`` (seconds).
- fps: one over the median interval of the first :data:`FPS_FRAMES` timestamps, to 3
  decimals (:data:`DEFAULT_FPS` for a single frame).
- colour: none (``rgb.txt``'s images are not paired with the depth frames yet).
- gravity: none (the dataset's ``accelerometer.txt`` is not read).

Memory stays flat: one PNG at a time. The camera, ``cam0``, has no world pose
(``pose_known`` False): :func:`open_source` places it from a pose given or the floor.
"""

from __future__ import annotations

import json
import math
import re
import statistics
import warnings
from pathlib import Path
from typing import Iterator, Mapping

import numpy as np
from PIL import Image, UnidentifiedImageError

from occupose.camera import Camera
from occupose.io._files import check_regular_file
from occupose.io.sources import SourceError, StreamSource

#: Raw depth units per metre of the TUM RGB-D depth PNGs.
DEPTH_FACTOR = 5000.0
#: The published intrinsics (fx, fy, cx, cy; pixels of the 640 x 480 images) of the
#: dataset's cameras, Freiburg 1, 2 and 3 (the colour camera's: the depth is registered to it).
TUM_CAMERAS: dict[str, tuple[float, float, float, float]] = {
    "fr1": (517.3, 516.5, 318.6, 255.3),
    "fr2": (520.9, 521.0, 325.1, 249.7),
    "fr3": (535.4, 539.2, 320.1, 247.6),
}
#: The size (width, height) of the images the named cameras' intrinsics are for.
TUM_SIZE = (640, 480)
#: Frames per second of a one-frame folder.
DEFAULT_FPS = 30.0
#: First frames whose timestamps give the frame rate.
FPS_FRAMES = 31

LIST = "depth.txt"
_FREIBURG = re.compile(r"freiburg([123])", re.IGNORECASE)
_GIVE = "give it with --tum-camera fr1|fr2|fr3|FILE.json (Python: camera='fr1')"


def is_tum(path: Path) -> bool:
    """Whether ``path`` is a folder with a ``depth.txt`` (one name looked up, nothing read)."""
    path = Path(path)
    return path.is_dir() and (path / LIST).is_file()


def read_list(path: Path) -> list[tuple[float, str]]:
    """(timestamp seconds, file name) of each line of a TUM list file (``depth.txt``), in
    order; blank lines and ``#`` comments skipped. SourceError naming the line otherwise."""
    try:
        text = path.read_text(encoding="utf-8-sig")
    except (OSError, UnicodeDecodeError) as error:
        raise SourceError(f"{path}: cannot read it ({error})") from None
    entries = []
    for number, line in enumerate(text.splitlines(), 1):
        line = line.strip()
        if not line or line.startswith("#"):
            continue
        parts = line.split()
        try:
            stamp = float(parts[0])
            if len(parts) != 2 or not math.isfinite(stamp):
                raise ValueError
        except ValueError:
            raise SourceError(f"{path}, line {number}: expected 'timestamp filename', got {line!r}") from None
        entries.append((stamp, parts[1]))
    if not entries:
        raise SourceError(f"{path}: no 'timestamp filename' lines")
    return entries


def _named_camera(name: str) -> tuple[float, float, float, float]:
    key = name.lower().replace("freiburg", "fr")
    if key not in TUM_CAMERAS:
        raise SourceError(f"unknown TUM camera {name!r}; valid: {', '.join(TUM_CAMERAS)}, or a JSON file of "
                          f"fx, fy, cx, cy")
    return TUM_CAMERAS[key]


def intrinsics_for(folder: Path, camera: str | Path | Mapping[str, float] | None) -> tuple[float, float, float, float]:
    """(fx, fy, cx, cy) for a TUM folder: ``camera`` a :data:`TUM_CAMERAS` name, a JSON file
    or mapping of ``fx, fy, cx, cy``, or None for the name of the folder (``freiburg1`` ->
    ``fr1``). SourceError saying how to give one otherwise."""
    if camera is None:
        found = {m.group(1) for m in _FREIBURG.finditer(Path(folder).resolve().name)}
        if len(found) != 1:
            raise SourceError(f"{folder}: which TUM camera recorded it is not in the folder's name (freiburg1, "
                              f"freiburg2 or freiburg3); {_GIVE}")
        return TUM_CAMERAS[f"fr{found.pop()}"]
    if isinstance(camera, Mapping):
        values = camera
        where = "the camera given"
    elif isinstance(camera, str) and camera.lower().replace("freiburg", "fr") in TUM_CAMERAS:
        return _named_camera(camera)
    else:
        file = Path(camera)
        if not file.is_file():
            raise SourceError(f"unknown TUM camera {str(camera)!r}; valid: {', '.join(TUM_CAMERAS)}, or a JSON "
                              f"file of fx, fy, cx, cy")
        try:
            values = json.loads(file.read_text(encoding="utf-8-sig"))
        except (OSError, UnicodeDecodeError, json.JSONDecodeError) as error:
            raise SourceError(f"{file}: not a readable JSON camera file ({error})") from None
        where = str(file)
    try:
        return tuple(float(values[k]) for k in ("fx", "fy", "cx", "cy"))
    except (KeyError, TypeError, ValueError):
        raise SourceError(f"{where}: expected {{\"fx\": ..., \"fy\": ..., \"cx\": ..., \"cy\": ...}} (pixels), "
                          f"got {values!r}") from None


def _read_depth_png(file: Path) -> np.ndarray:
    """(H, W) uint16 of a 16-bit grayscale PNG; SourceError naming the file otherwise."""
    check_regular_file(file, SourceError, "a 16-bit depth PNG")
    try:
        with open(file, "rb") as handle, warnings.catch_warnings():
            warnings.simplefilter("ignore", Image.DecompressionBombWarning)
            image = Image.open(handle)
            if image.format != "PNG" or image.mode not in ("I;16", "I;16B"):
                raise SourceError(f"{file}: expected a 16-bit grayscale PNG, got a {image.format} image of mode "
                                  f"{image.mode!r}")
            return np.asarray(image).astype(np.uint16)
    except SourceError:
        raise
    except (UnidentifiedImageError, OSError, SyntaxError, ValueError, Image.DecompressionBombError) as error:
        raise SourceError(f"{file}: not a readable PNG image ({error})") from None


class TumSource(StreamSource):
    """A TUM RGB-D folder's depth images as one camera (see the module docstring).

    path : the folder; camera : its camera (:func:`intrinsics_for`). Attributes beyond
    StreamSource's: ``files`` (the depth PNGs), ``stamps`` (their timestamps, seconds).
    """

    def __init__(self, path: Path, camera: str | Path | Mapping[str, float] | None = None):
        self.path = Path(path)
        if not self.path.is_dir():
            raise FileNotFoundError(f"{self.path}: no such TUM RGB-D folder")
        listing = self.path / LIST
        if not listing.is_file():
            raise SourceError(f"{self.path}: no {LIST}; a TUM RGB-D folder lists its depth images there")
        entries = read_list(listing)
        fx, fy, cx, cy = intrinsics_for(self.path, camera)
        self.reader_options = {"camera": {"fx": fx, "fy": fy, "cx": cx, "cy": cy}}
        self.stamps = [stamp for stamp, _ in entries]
        self.files = [self.path / name for _, name in entries]
        first = _read_depth_png(self.files[0])
        missing = [str(f.relative_to(self.path)) for f in self.files if not f.is_file()]
        if missing:
            raise SourceError(f"{listing}: {len(missing)} listed file(s) missing: {', '.join(missing[:3])}"
                              f"{', ...' if len(missing) > 3 else ''}")
        height, width = first.shape
        named = camera is None or (isinstance(camera, str) and camera.lower().replace("freiburg", "fr") in TUM_CAMERAS)
        if named and (width, height) != TUM_SIZE:
            raise SourceError(f"{self.files[0]}: a {width}x{height} depth image; the TUM cameras' intrinsics are for "
                              f"{TUM_SIZE[0]}x{TUM_SIZE[1]}: give this folder's with --tum-camera FILE.json")
        try:
            self.cameras = [Camera("cam0", width, height, fx, fy, cx, cy, 1.0 / DEPTH_FACTOR)]
        except ValueError as error:
            raise SourceError(f"{self.path}: no usable intrinsics ({error})") from None
        self.num_frames = len(self.files)
        intervals = [b - a for a, b in zip(self.stamps[:FPS_FRAMES], self.stamps[1:FPS_FRAMES]) if b > a]
        self.fps = round(1.0 / statistics.median(intervals), 3) if intervals else DEFAULT_FPS

    def _raw_frames(self, color: bool) -> Iterator[tuple[dict[str, np.ndarray], dict[str, np.ndarray], float]]:
        """(depth {cam0: (H, W) uint16, metres * 5000}, {} (no colour), timestamp in seconds) per listed PNG."""
        camera = self.cameras[0]
        for file, stamp in zip(self.files, self.stamps):
            depth = _read_depth_png(file)
            if depth.shape != (camera.height, camera.width):
                raise SourceError(f"{file}: a {depth.shape[1]}x{depth.shape[0]} depth image in a folder of "
                                  f"{camera.width}x{camera.height}")
            yield {camera.name: depth}, {}, stamp


def open_tum(path: Path, *, camera: str | Path | Mapping[str, float] | None = None, **options) -> TumSource:
    """The TUM RGB-D folder at ``path`` as a frame source (:class:`TumSource`); ``camera``:
    its camera (a :data:`TUM_CAMERAS` name, a JSON file of fx, fy, cx, cy; None: from the
    folder's name). Other reader options are a SourceError naming them."""
    if options:
        raise SourceError(f"{path}: a TUM RGB-D folder takes only the reader option camera, got {sorted(options)}")
    return TumSource(Path(path), camera)
