"""Bag reading speed: depth frames/s decoded from generated ROS 1 and ROS 2 bags.

300 frames of 640x480 (a seeded random depth image, a tenth of it 0, different per frame)
are written uncompressed with rosbags' writers to a temporary folder (so the file is in
the page cache when read: decoding, not the disk, is timed), then read through
``open_source`` three times; the median pass is reported. ``raw frames/s``: the reader's
uint16 images (``_raw_frames``: rosbags' deserialisation, byte order, row padding,
``32FC1`` quantisation); ``frames/s``: the float32 metres ``frames()`` gives the tracker.
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
from occupose.testing import write_depth_bag

TITLE = "Bag reading: depth frames/s of 640x480 from a generated bag (file cached), median of 3 passes"

NUM_FRAMES = 300
CAMERA = Camera("cam", 640, 480, 525.0, 525.0, 319.5, 239.5, 0.001)
CASES = [("ROS 1 .bag", 1, "sqlite3", "16UC1"), ("ROS 1 .bag", 1, "sqlite3", "32FC1"),
         ("ROS 2 sqlite3", 2, "sqlite3", "16UC1"), ("ROS 2 mcap", 2, "mcap", "16UC1")]


def _depths(encoding: str, seed: int = 0):
    """NUM_FRAMES (480, 640) images: uint16 mm, or float32 metres for 32FC1."""
    rng = np.random.default_rng(seed)
    base = rng.integers(500, 6000, (480, 640), dtype=np.uint16)
    base[rng.random(base.shape) < 0.1] = 0
    for index in range(NUM_FRAMES):
        depth = np.where(base > 0, base + index % 50, 0).astype(np.uint16)
        yield depth * np.float32(0.001) if encoding == "32FC1" else depth


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
        for name, ros, storage, encoding in CASES:
            path = Path(folder) / f"{ros}_{storage}_{encoding}{'.bag' if ros == 1 else ''}"
            write_depth_bag(path, _depths(encoding), CAMERA, ros=ros, storage=storage, encoding=encoding)
            source = open_source(path, pose=HeightTilt(2.0, 30.0))
            rows.append({"bag": name, "encoding": encoding, "frames": NUM_FRAMES,
                         "MB": round(sum(f.stat().st_size for f in [path, *path.rglob("*")] if f.is_file()) / 1e6),
                         "raw frames/s": _frames_per_second(lambda: source._raw_frames(color=False)),
                         "frames/s": _frames_per_second(lambda: source.frames(color=False)),
                         "load": os.getloadavg()[0]})
    return rows


if __name__ == "__main__":
    from benchmarks import format_table

    table = format_table(TITLE, run())
    print(table)
    out = Path(__file__).parent / "results" / "bag_reading.md"
    out.write_text(table + "\n")
    print(f"saved {out}")
