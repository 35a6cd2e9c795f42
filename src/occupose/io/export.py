"""Writing a run's tracks in another format, at the end of a run or afterwards from its
``tracks.csv`` (``occupose export``): the recording gives the frame count, the fps and,
for the camera frame, the camera's pose."""

from __future__ import annotations

import json
import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from occupose.io.writers import Tracks, tracks_from_table, tracks_in_camera, write_tracks, writer_for

#: Values of ``frame``: the world (z up, floor at z = 0) or a camera's (OpenCV axes).
FRAMES = ("world", "camera")


def check_frame(frame: str, camera: str | None, cameras: Sequence) -> str | None:
    """The camera whose frame the output is in for ``frame`` (:data:`FRAMES`) and an
    optional camera ``name`` among ``cameras`` (objects with ``.name``): None for the
    world, else the named camera or the first. ValueError for an unknown frame or camera,
    or a camera named for the world frame."""
    if frame not in FRAMES:
        raise ValueError(f"unknown frame {frame!r}; valid: {', '.join(FRAMES)}")
    names = [c.name for c in cameras]
    if frame == "world":
        if camera is not None:
            raise ValueError(f"a camera ({camera!r}) is named only for the camera frame (frame 'camera')")
        return None
    if camera is None:
        return names[0]
    if camera not in names:
        raise ValueError(f"no camera {camera!r} in the recording; its cameras are {', '.join(names)}")
    return camera


def tracks_for_output(table, recording, frame: str = "world", camera: str | None = None,
                      poses: dict[str, np.ndarray] | None = None) -> Tracks:
    """The joint table ``table`` ({id: (joints (T, 15, 3) metres, visible (T, 15) bool)}) of
    ``recording`` (a frame source: ``num_frames``, ``fps``, ``cameras``, ``path``) as
    :class:`Tracks` in ``frame`` (:func:`check_frame`). ``poses`` : camera name -> (4, 4)
    world_from_camera the tracks' world was made with, where it is not the recording's own
    (a pose given or found from the floor, :func:`poses_of_run`)."""
    name = check_frame(frame, camera, recording.cameras)
    tracks = tracks_from_table(table, recording.num_frames, recording.fps, str(recording.path))
    if name is None:
        return tracks
    pose = (poses or {}).get(name)
    if pose is None:
        pose = next(c.world_from_camera for c in recording.cameras if c.name == name)
    return tracks_in_camera(tracks, np.asarray(pose, dtype=float), name)


def summary_of_run(tracks_csv: Path) -> dict:
    """The ``summary.json`` beside a run's ``tracks.csv``. FileNotFoundError without one,
    ValueError for one that is not a run's summary."""
    summary = tracks_csv.parent / "summary.json"
    try:
        data = json.loads(summary.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise FileNotFoundError(f"{summary}: no summary.json beside {tracks_csv.name} to name its recording; "
                                "give the recording (--recording)") from None
    except (OSError, ValueError) as error:
        raise ValueError(f"{summary}: not a readable summary of a run ({error}); give the recording "
                         "(--recording)") from None
    if not isinstance(data, dict) or not isinstance(data.get("recording"), str):
        raise ValueError(f"{summary}: names no recording; give the recording (--recording)")
    return data


def reading_of_run(summary: dict) -> dict:
    """How a run's ``summary`` (as :func:`summary_of_run`) says its recording was read:
    ``{"reader": name or None, "options": {...}}`` (``{}`` for a summary from before it was
    recorded). ValueError for one that is not plain data of that shape."""
    read = summary.get("source")
    if read is None:
        return {}
    if (not isinstance(read, dict) or not isinstance(read.get("options", {}), dict)
            or not isinstance(read.get("reader"), (str, type(None)))):
        raise ValueError(f"summary.json: its source must be {{\"reader\": name, \"options\": {{...}}}}, got {read!r}")
    return {"reader": read.get("reader"), "options": read.get("options", {})}


def poses_of_run(summary: dict) -> dict[str, np.ndarray]:
    """Camera name -> (4, 4) world_from_camera of the cameras a run's ``summary`` (as
    :func:`summary_of_run`) lists as placed by the run (a pose given or found from the
    floor, not the recording's own)."""
    poses = {}
    for entry in summary.get("cameras") or ():
        if isinstance(entry, dict) and entry.get("pose") != "recording" and "world_from_camera" in entry:
            pose = np.asarray(entry["world_from_camera"], dtype=float)
            if pose.shape != (4, 4) or not np.all(np.isfinite(pose)):
                raise ValueError(f"summary.json: camera {entry.get('name')!r} has a world_from_camera that is not "
                                 "a finite 4x4 matrix")
            poses[str(entry.get("name"))] = pose
    return poses


def export_tracks(tracks_csv: str | os.PathLike, to: str, out: str | os.PathLike, *, frame: str = "world",
                  camera: str | None = None, recording: str | os.PathLike | None = None,
                  force: bool = False) -> Path:
    """Write the run's ``tracks_csv`` as ``to`` (:data:`occupose.io.writers.WRITERS`) to the
    file ``out`` in ``frame`` (:func:`check_frame`), whole or not at all (``force``: replace
    a file occupose wrote). ``recording`` : the recording the tracks are of (any format,
    read by its reader), by default the one the run's summary.json names. The camera frame
    is the one the run placed the camera in: the pose summary.json lists where the run gave
    or found it (:func:`poses_of_run`), else the recording's own. The recording is opened
    with the reader and reader options summary.json records (a bag's topic), if any.
    Returns ``out``."""
    from occupose.io.joint_table import read_tracks_csv
    from occupose.io.sources import reader_for

    writer_for(to).check_available()
    tracks_csv = Path(tracks_csv)
    if not tracks_csv.is_file():
        raise FileNotFoundError(f"{tracks_csv}: no such tracks file")
    has_summary = (tracks_csv.parent / "summary.json").is_file()
    summary = summary_of_run(tracks_csv) if recording is None or has_summary else {}
    path = Path(recording if recording is not None else summary["recording"])
    read = reading_of_run(summary) if summary and path == Path(summary["recording"]) else {}
    source = reader_for(path, read.get("reader")).open(path, **read.get("options", {}))
    name = check_frame(frame, camera, source.cameras)
    poses = poses_of_run(summary)
    if name is not None and name not in poses and not getattr(source, "pose_known", True):
        raise ValueError(f"{path}: the recording has no world pose and the run's summary.json gives none for "
                         f"camera {name!r}, so its camera frame is unknown; export in the world frame, or track "
                         "it again (summary.json then holds the pose)")
    table = read_tracks_csv(tracks_csv, source.num_frames)
    tracks = tracks_for_output(table, source, frame, camera, poses)
    return write_tracks(out, tracks, to, force=force, inputs=(tracks_csv, source.path))
