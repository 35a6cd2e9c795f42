"""``occupose convert``: any recording format written as occupose's recording folder.

The folder holds every frame's depth (and colour where the source has it, registered to
the depth) in the source's own raw units, the cameras as placed (the world pose the
recording had, was given or was found from the floor), and in ``recording.json``'s
``origin`` where it came from and each camera's height, tilt and roll, and the frames'
times in ``times.csv`` where they are not evenly spaced at the fps (dropped frames).
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path

from occupose.camera import raw_depth_from_metres
from occupose.io.output import staged_folder
from occupose.io.recording import RecordingWriter
from occupose.io.sources import FrameSource, placement


def convert(source: FrameSource, out: str | os.PathLike, *, reader: str | None = None, color: bool = True,
            force: bool = False, progress: Callable[[int], None] | None = None) -> Path:
    """Write ``source`` into the recording folder ``out``, whole or not at all (the overwrite
    rule of :mod:`occupose.io.output`); returns ``out``. ``reader`` : the format's name, for
    ``origin``; ``color`` : write colour where there is any; ``progress`` : callable(n)
    after each frame. Depth is stored in each camera's raw units (bit-exact for a uint16
    source)."""
    origin = {"source": str(source.path), "reader": reader, "cameras": placement(source)}
    with staged_folder(out, "recording", force=force, inputs=(source.path,)) as folder:
        with RecordingWriter(folder, source.cameras, source.fps, origin=origin) as writer:
            for frame in source.frames(color=color):
                writer.write_frame({c.name: raw_depth_from_metres(frame.depth[c.name], c) for c in source.cameras},
                                   frame.color or None, time=frame.time)
                if progress is not None:
                    progress(1)
    return Path(out)
