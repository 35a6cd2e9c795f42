"""C3D markers of every track (docs/outputs.md), written with the ``c3d`` package (extra ``c3d``).

One marker per track and joint, labelled ``t<id>_<joint>`` (``t3_left_knee``; labels up to
the format's 32 characters), track by track in increasing id, joints in
:data:`occupose.joints.JOINTS` order. Positions in millimetres (``POINT:UNITS`` ``mm``,
floating point), in the tracks' frame as it is: the world (z up, floor at z = 0) or a
camera's (OpenCV axes). Point rate = the recording's fps; frame t of the file is frame t
of the recording (the first frame numbered 1, as C3D counts).

Residual: 0 for a joint estimated from data in the frame, -1 (the format's invalid point)
for a hidden joint (carried from memory) and an unknown one; C3D readers drop the
position of an invalid point, so a hidden joint's carried position is only in tracks.csv
and the JSON output.
"""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import numpy as np

from occupose.io.writers import Tracks
from occupose.joints import JOINTS

_LABEL = re.compile(r"t-?[0-9]+_(" + "|".join(JOINTS) + r")")


def marker_labels(ids: np.ndarray) -> list[str]:
    """The P * 15 marker labels of tracks ``ids`` ((P,) int), in the file's order."""
    return [f"t{int(ident)}_{joint}" for ident in ids for joint in JOINTS]


def points_from_tracks(tracks: Tracks) -> np.ndarray:
    """(T, P * 15, 5) float32 C3D points: x, y, z mm (0 where invalid), residual (0 or -1),
    camera mask (0)."""
    num_frames = tracks.joints.shape[0]
    points = np.zeros((num_frames, tracks.joints.shape[1] * len(JOINTS), 5), np.float32)
    valid = tracks.visible.reshape(num_frames, -1)
    millimetres = np.nan_to_num(tracks.joints.reshape(num_frames, -1, 3) * 1000.0)
    points[..., :3] = np.where(valid[..., None], millimetres, 0.0)
    points[..., 3] = np.where(valid, 0.0, -1.0)
    return points


def write_c3d(path: Path, tracks: Tracks) -> None:
    """Write ``tracks`` as C3D to ``path`` (module docstring); ValueError without a track
    (a C3D file needs at least one marker)."""
    from occupose.io.sources import require

    if not len(tracks.ids):
        raise ValueError("no track to write: a C3D file needs at least one marker")
    c3d = require("c3d", "c3d", "writing C3D files")
    writer = c3d.Writer(point_rate=float(tracks.fps), point_units="mm  ")
    analog = np.zeros((0, 0), np.float32)
    writer.add_frames([(frame, analog) for frame in points_from_tracks(tracks)])
    writer.set_point_labels(marker_labels(tracks.ids))
    with open(path, "wb") as handle, warnings.catch_warnings():
        warnings.filterwarnings("ignore", "No analog data found", UserWarning)  # there is none, by design
        writer.write(handle)


def is_occupose_c3d(path: Path) -> bool:
    """Whether ``path`` is a C3D file whose markers are all labelled as this writer labels them."""
    from occupose.io.sources import require

    c3d = require("c3d", "c3d", "reading C3D files")
    try:
        with open(path, "rb") as handle, warnings.catch_warnings():
            warnings.simplefilter("ignore")
            labels = [label.strip() for label in c3d.Reader(handle).point_labels]
    except Exception:  # anything unreadable is not a file of ours
        return False
    return bool(labels) and all(_LABEL.fullmatch(label) for label in labels)
