"""Writers of a tracker's skeletons in other tools' formats (docs/outputs.md), by name.

Every writer is a function ``write(path, tracks)`` of a :class:`Tracks` to one file,
registered in :data:`WRITERS` with the file suffix it gives and its test that a file is
one occupose wrote (the overwrite rule of :mod:`occupose.io.output`):

``json``  Azure Kinect Body Tracking's offline-processor layout (:mod:`.k4abt_json`)
``bvh``   one BVH of every track, positions in 6 channels per joint (:mod:`.bvh`)
``c3d``   markers in millimetres, residual -1 where a joint is hidden or unknown (:mod:`.c3d`)

:func:`write_tracks` writes one whole or not at all; :func:`tracks_in_camera` turns the
tracks into a camera's frame first.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from occupose._validate import bool_array, float_array
from occupose.joints import NUM_JOINTS


@dataclass(frozen=True)
class Tracks:
    """Every track of a run, frame-major.

    ids : (P,) int64 track ids
    joints : (T, P, 15, 3) float64 metres, NaN where a joint is unknown (not tracked)
    visible : (T, P, 15) bool, False where hidden (carried from memory) or unknown
    fps : frames per second of the recording; frame t is at t / fps seconds
    frame : "world" (z up, floor at z = 0) or "camera:<name>" (OpenCV: x right, y down, z forward)
    source : the recording (or tracks.csv) the tracks came from, as written into the files
    """

    ids: np.ndarray
    joints: np.ndarray
    visible: np.ndarray
    fps: float
    frame: str = "world"
    source: str = ""

    @property
    def known(self) -> np.ndarray:
        """(T, P, 15) bool: where a joint has a position."""
        return np.isfinite(self.joints).all(axis=-1)

    @property
    def times(self) -> np.ndarray:
        """(T,) float64 seconds of each frame, index / fps."""
        return np.arange(self.joints.shape[0]) / self.fps

    @property
    def in_camera(self) -> bool:
        return self.frame.startswith("camera")


def tracks_from_table(table: Mapping[int, tuple[np.ndarray, np.ndarray]], num_frames: int, fps: float,
                      source: str = "") -> Tracks:
    """A joint table (:data:`occupose.io.joint_table.JointTable`: {id: (joints (T, 15, 3)
    metres, visible (T, 15) bool)}, as ``read_tracks_csv`` or a TrackingResult gives) as
    :class:`Tracks` in the world frame, ids in increasing order. ``num_frames`` : T (the
    table may be empty); ``fps`` > 0."""
    if not (isinstance(fps, (int, float, np.number)) and not isinstance(fps, bool) and np.isfinite(fps) and fps > 0):
        raise ValueError(f"fps must be a positive finite number, got {fps!r}")
    ids = sorted(int(i) for i in table)
    joints = np.full((num_frames, len(ids), NUM_JOINTS, 3), np.nan)
    visible = np.zeros((num_frames, len(ids), NUM_JOINTS), bool)
    for p, ident in enumerate(ids):
        joints[:, p] = float_array(table[ident][0], f"track {ident} joints", (num_frames, NUM_JOINTS, 3))
        visible[:, p] = bool_array(table[ident][1], f"track {ident} visible", (num_frames, NUM_JOINTS))
    return Tracks(np.array(ids, np.int64), joints, visible & np.isfinite(joints).all(axis=-1), float(fps),
                  "world", source)


def tracks_in_camera(tracks: Tracks, world_from_camera: np.ndarray, name: str) -> Tracks:
    """``tracks`` (world frame) in the frame of the camera ``name`` whose pose is
    ``world_from_camera`` ((4, 4) rigid, metres): p_camera = R^T (p_world - t)."""
    if tracks.frame != "world":
        raise ValueError(f"the tracks are already in the {tracks.frame} frame")
    pose = float_array(world_from_camera, "world_from_camera", (4, 4))
    rotation, origin = pose[:3, :3], pose[:3, 3]
    return replace(tracks, joints=(tracks.joints - origin) @ rotation, frame=f"camera:{name}")


@dataclass(frozen=True)
class Writer:
    """A registered output format.

    name : its name (``--format``, ``--to``); suffix : the file suffix it is written with
    summary : one line for help texts
    write : callable(path, tracks) writing the whole file at ``path`` (a temporary name)
    is_ours : callable(path) -> bool, whether a file there is one occupose wrote
    needs : (module, install extra) of an optional package the writer imports, or None
    """

    name: str
    suffix: str
    summary: str
    write: Callable[[Path, Tracks], None]
    is_ours: Callable[[Path], bool]
    needs: tuple[str, str] | None = None

    def check_available(self) -> None:
        """Raise the ImportError naming the extra to install when the package it needs is missing."""
        if self.needs is not None:
            from occupose.io.sources import require

            require(*self.needs, f"writing {self.name.upper()} files")


WRITERS: dict[str, Writer] = {}


def register_writer(writer: Writer) -> Writer:
    if writer.name in WRITERS:
        raise ValueError(f"a writer named {writer.name!r} is already registered")
    WRITERS[writer.name] = writer
    return writer


def writer_for(name: str) -> Writer:
    """The writer ``name`` (:data:`WRITERS`); ValueError listing the valid names otherwise."""
    try:
        return WRITERS[name]
    except (KeyError, TypeError):
        raise ValueError(f"unknown output format {name!r}; valid: {', '.join(WRITERS)}") from None


def write_tracks(path: str | os.PathLike, tracks: Tracks, format: str, *, force: bool = False,
                 inputs: Iterable[str | os.PathLike] = ()) -> Path:
    """Write ``tracks`` as ``format`` (:data:`WRITERS`) to the file ``path``, whole or not at
    all; an existing file is replaced only with ``force`` and only if occupose wrote it
    (:func:`occupose.io.output.staged_file`). Returns the path."""
    from occupose.io.output import staged_file

    writer = writer_for(format)
    with staged_file(path, writer.is_ours, f"{writer.name} file", force=force, inputs=inputs) as temporary:
        writer.write(temporary, tracks)
    return Path(path)


def _register() -> None:
    from occupose.io.writers import bvh, c3d, k4abt_json

    register_writer(Writer("json", ".json", "Azure Kinect Body Tracking offline-processor JSON (mm)",
                           k4abt_json.write_k4abt_json, k4abt_json.is_occupose_json))
    register_writer(Writer("bvh", ".bvh", "BVH, positions in 6 channels per joint (cm, y up)",
                           bvh.write_bvh, bvh.is_occupose_bvh))
    register_writer(Writer("c3d", ".c3d", "C3D markers (mm, z up; residual -1 hidden)",
                           c3d.write_c3d, c3d.is_occupose_c3d, needs=("c3d", "c3d")))


_register()

__all__ = ["WRITERS", "Tracks", "Writer", "register_writer", "tracks_from_table", "tracks_in_camera",
           "write_tracks", "writer_for"]
