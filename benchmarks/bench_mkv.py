"""Azure Kinect .mkv and TUM RGB-D reading speed: depth frames/s from generated files.

300 frames (a seeded random depth image, a tenth of it 0, different per frame) are written
to a temporary folder (so the files are in the page cache when read: decoding, not the
disk, is timed): Azure Kinect ``.mkv`` files in the NFOV unbinned (640x576) and WFOV
unbinned (1024x1024) modes with PyAV (``write_depth_mkv``), and a 640x480 TUM RGB-D folder
(``write_tum_folder``). Each is read through ``open_source`` three times; the median pass
is reported. ``raw frames/s``: the reader's uint16 images (``_raw_frames``: for the MKV,
PyAV's demuxer and the packets' big-endian bytes; for TUM, PNG decoding); ``frames/s``:
the float32 metres ``frames()`` gives the tracker. ``open s``: opening the file (the MKV
reader counts its depth packets, reads the calibration and the IMU's first samples).
"""

from __future__ import annotations

import os
import statistics
import tempfile
import time
from pathlib import Path

import numpy as np

from occupose.camera import Camera
from occupose.io.sources import HeightTilt, open_source
from occupose.testing import write_depth_mkv, write_tum_folder

TITLE = "Azure Kinect .mkv and TUM reading: depth frames/s from generated files (cached), median of 3 passes"

NUM_FRAMES = 300
CASES = [("mkv NFOV_UNBINNED", Camera("cam", 640, 576, 504.6, 504.7, 332.8, 348.8)),
         ("mkv WFOV_UNBINNED", Camera("cam", 1024, 1024, 504.6, 504.7, 524.8, 528.8)),
         ("tum", Camera("cam", 640, 480, 517.3, 516.5, 318.6, 255.3, 0.0002))]
POSE = HeightTilt(2.0, 30.0)


def _depths(camera: Camera, seed: int = 0):
    """NUM_FRAMES (H, W) uint16 images."""
    rng = np.random.default_rng(seed)
    base = rng.integers(500, 6000, (camera.height, camera.width), dtype=np.uint16)
    base[rng.random(base.shape) < 0.1] = 0
    for index in range(NUM_FRAMES):
        yield np.where(base > 0, base + index % 50, 0).astype(np.uint16)


def _frames_per_second(read) -> float:
    seconds = []
    for _ in range(3):
        start = time.perf_counter()
        count = sum(1 for _ in read())
        seconds.append(time.perf_counter() - start)
    assert count == NUM_FRAMES
    return NUM_FRAMES / statistics.median(seconds)


def run() -> list[dict]:
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        for name, camera in CASES:
            if name == "tum":
                path = write_tum_folder(Path(folder) / "tum", _depths(camera))
                options = {"camera": "fr1"}
            else:
                path = write_depth_mkv(Path(folder) / f"{name.split()[1]}.mkv", _depths(camera), camera)
                options = {}
            start = time.perf_counter()
            source = open_source(path, pose=POSE, **options)
            opened = time.perf_counter() - start
            rows.append({"file": name, "size": f"{camera.width}x{camera.height}", "frames": NUM_FRAMES,
                         "MB": round(sum(f.stat().st_size for f in [path, *path.rglob("*")] if f.is_file()) / 1e6),
                         "open s": round(opened, 3),
                         "raw frames/s": _frames_per_second(lambda: source._raw_frames(color=False)),
                         "frames/s": _frames_per_second(lambda: source.frames(color=False)),
                         "load": os.getloadavg()[0]})
    return rows


if __name__ == "__main__":
    from benchmarks import format_table

    table = format_table(TITLE, run())
    print(table)
    out = Path(__file__).parent / "results" / "mkv_reading.md"
    out.write_text(table + "\n")
    print(f"saved {out}")
