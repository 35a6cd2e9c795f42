"""Rerun recordings (``.rrd``) of a recording and its tracks, for the rerun viewer
(rerun-sdk, extra ``rerun``; docs/outputs.md).

:func:`write_rerun` logs, with a :class:`rerun.RecordingStream` of its own (no global
state, no viewer) saved to a file, whole or not at all:

- ``world``: the world frame, z up (``ViewCoordinates.RIGHT_HAND_Z_UP``), metres;
- ``world/cameras/<name>``: each camera's pose (``Transform3D``, world_from_camera) and, at
  ``.../image``, its intrinsics (``Pinhole``, OpenCV axes RDF); at ``.../image/depth`` its
  depth image in every frame (``DepthImage`` of raw units, ``meter`` = 1 / depth_scale,
  the turbo colormap over :func:`occupose.viz.depth_range` of the first frame), which the
  viewer also shows as a point cloud in 3D;
- ``world/tracks/<id>``: each track's skeleton in every frame where it has a joint:
  ``bones`` (``LineStrips3D``, one strip per bone) and ``joints`` (``Points3D``, the 15
  joints in canonical order, those not known left out), in the track's colour
  (:func:`occupose.viz.track_color`), hidden joints and the bones to them dimmed
  (:data:`HIDDEN_SHADE`); cleared in a frame without a joint;

all on two timelines: ``frame`` (the frame index, a sequence) and ``time`` (seconds since
the first frame, the frames' own times); not on rerun's ``log_time`` (the wall clock).
"""

from __future__ import annotations

import os
from collections.abc import Callable, Mapping
from pathlib import Path

import numpy as np

from occupose.camera import raw_depth_from_metres
from occupose.io.output import SOFTWARE, OutputError, staged_file
from occupose.io.writers import tracks_from_table
from occupose.joints import BONES
from occupose.viz import DEPTH_COLORMAP, depth_range, track_color

#: The file suffix of rerun recordings.
RRD_SUFFIX = ".rrd"
#: The rerun application id of every recording occupose writes: how --force tells one of ours.
APPLICATION_ID = SOFTWARE
#: The timelines: the frame index (sequence) and the time since the first frame (seconds).
FRAME_TIMELINE = "frame"
TIME_TIMELINE = "time"
#: Radii, metres, of a joint's point and a bone's line.
JOINT_RADIUS_M = 0.025
BONE_RADIUS_M = 0.012
#: A hidden joint (carried from memory) and a bone to one are drawn in the track's colour
#: times this shade.
HIDDEN_SHADE = 0.45


def rrd_path(out: str | os.PathLike) -> Path:
    """The file a rerun recording asked for at ``out`` is written to: ``out`` with ``.rrd``
    appended when it has no suffix. A folder or another suffix is an :class:`OutputError`."""
    out = Path(out)
    if out.is_dir():
        raise OutputError(f"{out} is a folder; give the rerun recording's file name")
    if not out.suffix:
        return out.with_name(out.name + RRD_SUFFIX)
    if out.suffix.lower() != RRD_SUFFIX:
        raise OutputError(f"{out}: rerun recordings are written as {RRD_SUFFIX}; give a name ending in {RRD_SUFFIX}")
    return out


def _rerun(what: str):
    from occupose.io.sources import require

    return require("rerun", "rerun", what)


def is_occupose_rrd(path: str | os.PathLike) -> bool:
    """Whether ``path`` is a rerun recording whose application id is :data:`APPLICATION_ID`."""
    rr = _rerun("reading rerun recordings")
    try:
        stores = rr.chunk.RrdReader(path).recordings()
    except Exception:  # anything unreadable is not a recording of ours
        return False
    return bool(stores) and all(store.application_id == APPLICATION_ID for store in stores)


def skeleton_strips(joints: np.ndarray, visible: np.ndarray, color) -> tuple[list[np.ndarray], np.ndarray]:
    """The bones of one skeleton as line strips.

    joints : (15, 3) float metres, NaN where unknown; visible : (15,) bool; color : 8-bit RGB
    Returns (strips: a (2, 3) array per bone whose two joints are known, colours (S, 3)
    uint8: ``color``, times :data:`HIDDEN_SHADE` where either joint is hidden).
    """
    known = np.isfinite(joints).all(axis=1)
    bones = [(a, b) for a, b in BONES if known[a] and known[b]]
    shaded = np.array([not (visible[a] and visible[b]) for a, b in bones], bool)
    return [joints[[a, b]] for a, b in bones], _colors(color, shaded)


def _colors(color, shaded: np.ndarray) -> np.ndarray:
    """(N, 3) uint8: ``color`` where not ``shaded``, times HIDDEN_SHADE where it is."""
    base = np.asarray(color, np.float64)
    return np.rint(np.where(shaded[:, None], base * HIDDEN_SHADE, base)).astype(np.uint8).reshape(-1, 3)


def _log_cameras(stream, rr, cameras) -> None:
    stream.log("world", rr.ViewCoordinates.RIGHT_HAND_Z_UP, static=True)
    for camera in cameras:
        pose = camera.world_from_camera
        stream.log(f"world/cameras/{camera.name}", rr.Transform3D(translation=pose[:3, 3], mat3x3=pose[:3, :3]),
                   static=True)
        stream.log(f"world/cameras/{camera.name}/image",
                   rr.Pinhole(image_from_camera=camera.intrinsic_matrix, resolution=[camera.width, camera.height],
                              camera_xyz=rr.ViewCoordinates.RDF), static=True)


def write_rerun(source, tracks: Mapping[int, tuple[np.ndarray, np.ndarray]], out: str | os.PathLike, *,
                force: bool = False, progress: Callable[[int], None] | None = None) -> Path:
    """Write a rerun recording of every frame of ``source`` and the tracks (module docstring).

    source : a frame source (:func:`occupose.io.sources.open_source`) with a world pose
    tracks : {track id: (joints (T, 15, 3) metres world frame, visible (T, 15) bool)} over
        the source's T frames, as read from a tracks.csv
    out : the ``.rrd`` file (the suffix is appended to a name without one); an existing
        file is replaced only with ``force`` and only if occupose wrote it
        (:func:`is_occupose_rrd`); never one inside the recording
    progress : called with 1 after each frame is logged
    Returns the path written.
    """
    rr = _rerun("writing rerun recordings")
    if source.num_frames == 0:
        raise ValueError(f"{source.path}: the recording has no frames, nothing to write")
    table = tracks_from_table(tracks, source.num_frames, source.fps)
    colors = {int(track): track_color(track) for track in table.ids}
    out = rrd_path(out)
    with staged_file(out, is_occupose_rrd, "rerun recording", force=force, inputs=(source.path,)) as temporary:
        stream = rr.RecordingStream(APPLICATION_ID)
        stream.set_log_time_enabled(False)  # the recording's own timelines only, not the wall clock of writing
        stream.save(temporary)
        try:
            _log_cameras(stream, rr, source.cameras)
            limits = {}
            shown = set()
            for frame in source.frames(color=False):
                t = frame.index
                stream.set_time(FRAME_TIMELINE, sequence=t)
                stream.set_time(TIME_TIMELINE, duration=frame.time)
                for camera in source.cameras:
                    depth = frame.depth[camera.name]
                    limits.setdefault(camera.name, depth_range(depth))
                    stream.log(f"world/cameras/{camera.name}/image/depth",
                               rr.DepthImage(raw_depth_from_metres(depth, camera), meter=1.0 / camera.depth_scale,
                                             colormap=DEPTH_COLORMAP, depth_range=limits[camera.name]))
                for p, track in enumerate(int(i) for i in table.ids):
                    joints, visible = table.joints[t, p], table.visible[t, p]
                    known = np.isfinite(joints).all(axis=1)
                    entity = f"world/tracks/{track}"
                    if not known.any():
                        if track in shown:
                            stream.log(entity, rr.Clear(recursive=True))
                            shown.discard(track)
                        continue
                    strips, strip_colors = skeleton_strips(joints, visible, colors[track])
                    stream.log(f"{entity}/bones", rr.LineStrips3D(strips, colors=strip_colors, radii=BONE_RADIUS_M))
                    stream.log(f"{entity}/joints", rr.Points3D(joints[known], radii=JOINT_RADIUS_M,
                                                               colors=_colors(colors[track], ~visible[known])))
                    shown.add(track)
                if progress is not None:
                    progress(1)
            stream.flush()
        finally:
            stream.disconnect()  # closes the file (its footer written) before it is renamed or removed
    return out


__all__ = ["APPLICATION_ID", "RRD_SUFFIX", "is_occupose_rrd", "rrd_path", "skeleton_strips", "write_rerun"]
