"""occupose: occlusion-aware 3D skeleton tracking of people in depth-camera recordings.

    from occupose import TrackerConfig, track_recording

    config = TrackerConfig.from_dict({"method": "ours", "pose": {"particles": 300}})
    result = track_recording("path/to/recording", config, seed=0)
    for track, (joints, visible) in result.tracks.items():
        ...  # joints (T, 15, 3) metres, world frame; visible (T, 15) bool

The names below are loaded on first use, so ``import occupose`` is quick and sets nothing
up (numba's cache and thread settings belong to the command line and the evaluation
workers: :func:`occupose._numba.configure`).
"""

from __future__ import annotations

import importlib

__version__ = "0.1.0"

_EXPORTS = {
    "Tracker": "occupose.tracker",
    "FrameResult": "occupose.tracker",
    "TrackerConfig": "occupose.config",
    "METHODS": "occupose.config",
    "method_config": "occupose.config",
    "Recording": "occupose.io.recording",
    "open_recording": "occupose.io.recording",
    "track_recording": "occupose.run",
    "track_frames": "occupose.run",
    "write_run": "occupose.run",
    "TrackingResult": "occupose.run",
    "score": "occupose.evaluation.matching",
    "fit_frame": "occupose.pose.single",
    "FrameFit": "occupose.pose.single",
}

__all__ = ["__version__", *_EXPORTS]


def __getattr__(name: str):
    if name in _EXPORTS:
        value = getattr(importlib.import_module(_EXPORTS[name]), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module 'occupose' has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(__all__)
