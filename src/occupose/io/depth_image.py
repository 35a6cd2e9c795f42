"""Single depth images and a camera given on the command line (``occupose fit``).

A depth image is a 16-bit greyscale PNG, a ``.npy`` array, or a raw headerless file of
little-endian uint16 values whose byte count is the camera's ``2 * width * height`` (any
other name: the Kinect v1 frames of ``kinect_v1_person`` are such files). Integer values
are multiplied by the depth scale (default: the camera's, millimetres for a preset); a
floating-point ``.npy`` is metres unless a scale is given. 0 is no measurement.

The camera is a preset name (:data:`occupose.camera.CAMERA_PRESETS`) or a JSON file of an
object with ``width``, ``height``, ``fx``, ``fy``, ``cx``, ``cy`` and optionally ``name``,
``depth_scale`` and ``world_from_camera`` (4 x 4, camera to a world with z up and the floor
at 0: with it, the fit is in that world).
"""

from __future__ import annotations

import json
import os
import warnings
from pathlib import Path

import numpy as np
from PIL import Image, UnidentifiedImageError

from occupose.camera import CAMERA_PRESETS, Camera, camera_from_dict, camera_preset
from occupose.io._files import check_regular_file

#: Keys a camera JSON file must have, and those it may have.
REQUIRED_KEYS = ("width", "height", "fx", "fy", "cx", "cy")
OPTIONAL_KEYS = ("name", "depth_scale", "world_from_camera")


class DepthImageError(ValueError):
    """A depth image or camera file that cannot be read; the message names the file."""


def camera_from_option(text: str | os.PathLike) -> tuple[Camera, bool]:
    """(the camera, whether its world pose was given) of a preset name or a camera JSON
    file (module docstring)."""
    name = str(text)
    if name in CAMERA_PRESETS:
        return camera_preset(name), False
    path = Path(name)
    if not path.exists():
        raise DepthImageError(f"{name}: neither a camera preset ({', '.join(sorted(CAMERA_PRESETS))}) "
                              f"nor a camera JSON file")
    check_regular_file(path, DepthImageError, "a camera JSON file")
    try:
        entry = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as error:
        raise DepthImageError(f"{path}: not a readable JSON file ({error})") from None
    if not isinstance(entry, dict):
        raise DepthImageError(f"{path}: expected a JSON object with keys {list(REQUIRED_KEYS)}")
    missing = [key for key in REQUIRED_KEYS if key not in entry]
    unknown = sorted(set(entry) - set(REQUIRED_KEYS) - set(OPTIONAL_KEYS))
    if missing or unknown:
        raise DepthImageError(f"{path}: " + "; ".join(
            ([f"missing key(s) {missing}"] if missing else []) + ([f"unknown key(s) {unknown}"] if unknown else []))
            + f" (a camera has {list(REQUIRED_KEYS)}, and may have {list(OPTIONAL_KEYS)})")
    world = "world_from_camera" in entry
    full = {"name": "cam0", "depth_scale": 0.001, "world_from_camera": np.eye(4).tolist(), **entry}
    try:
        return camera_from_dict(full, source=str(path)), world
    except ValueError as error:
        raise DepthImageError(str(error)) from None


def read_depth_image(path: str | os.PathLike, camera: Camera, depth_scale: float | None = None) -> np.ndarray:
    """(H, W) float32 metres (0 = no measurement) of the depth image at ``path`` (module
    docstring) of ``camera``'s size. depth_scale : metres per unit (None: the camera's for
    integer images, 1 for a floating-point ``.npy``)."""
    path = Path(path)
    check_regular_file(path, DepthImageError, "a depth image")
    size = (camera.height, camera.width)
    suffix = path.suffix.lower()
    if suffix == ".png":
        values = _png(path)
    elif suffix == ".npy":
        try:
            values = np.load(path, allow_pickle=False)
        except (OSError, ValueError) as error:
            raise DepthImageError(f"{path}: not a readable .npy array ({error})") from None
    else:
        expected = 2 * camera.width * camera.height
        if path.stat().st_size != expected:
            raise DepthImageError(f"{path}: a raw depth image of camera {camera.name!r} ({camera.width}x"
                                  f"{camera.height} uint16) has {expected} bytes, this file has "
                                  f"{path.stat().st_size}")
        values = np.fromfile(path, "<u2").reshape(size)
    if values.shape != size:
        raise DepthImageError(f"{path}: the image is {values.shape}, camera {camera.name!r} is {size} (height, width)")
    if np.issubdtype(values.dtype, np.integer) and values.dtype != np.bool_:
        scale = camera.depth_scale if depth_scale is None else depth_scale
    elif np.issubdtype(values.dtype, np.floating):
        scale = 1.0 if depth_scale is None else depth_scale
    else:
        raise DepthImageError(f"{path}: expected integer or floating-point depth, got {values.dtype}")
    metres = values.astype(np.float64) * scale
    if not np.isfinite(metres).all() or (metres < 0).any():
        raise DepthImageError(f"{path}: depth must be finite and >= 0 (0 = no measurement)")
    return metres.astype(np.float32)


def _png(path: Path) -> np.ndarray:
    """The (H, W) uint16 of a 16-bit greyscale PNG."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error", Image.DecompressionBombWarning)
            with Image.open(path) as image:
                if image.format != "PNG" or image.mode not in ("I;16", "I;16B", "I"):
                    raise DepthImageError(f"{path}: expected a 16-bit greyscale PNG, got a {image.format} image of "
                                          f"mode {image.mode!r}")
                return np.asarray(image).astype(np.uint16)
    except (UnidentifiedImageError, Image.DecompressionBombWarning, Image.DecompressionBombError, OSError) as error:
        raise DepthImageError(f"{path}: not a readable PNG image ({error})") from None
