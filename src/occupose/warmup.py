"""Compile the tracker's kernels before a recording's first frame (issue 27: no compile stall).

numba compiles a kernel on its first call with each kind of argument, and caches the
machine code on disk (:mod:`occupose._numba`). On a machine whose cache is empty, the
first frames of the first run would stall for tens of seconds in the middle of tracking
(at the first person's start). :func:`warm_up` runs the tracker, with the settings of the
run to come, over the first frames of a small built-in scene with procedural motion (no
shared data), so that every kernel the run calls is compiled, or loaded from the cache,
before the run starts.

Once that is done for a set of settings, a marker file in the cache folder says so, keyed
by what decides which kernels exist and how they are compiled (numba's version, the
package's source files, the settings that choose code, the body model): later runs skip
the warm-up, and numba loads each kernel from its cache in a few milliseconds at its
first call. Measured in docs/notes/2026-12-06-compile-stall.md.
"""

from __future__ import annotations

import hashlib
import json
import os
from collections.abc import Callable, Sequence
from pathlib import Path

from occupose.camera import Camera
from occupose.config import TrackerConfig, as_config

#: The built-in scene tracked for each body model, and its frames: a person in view from
#: the first frames, started within a few frames, then tracked for a few frames more (a
#: second person calls no other kernel: measured in the note of the module docstring).
SCENES = {"full": ("no_occlusion", 24), "upper": ("top_view_arms", 24)}
#: The markers' folder in numba's cache folder.
MARKERS = "occupose-warm"


def model_of(config: TrackerConfig, cameras: Sequence[Camera]) -> str:
    """The body model a run with ``config`` on ``cameras`` tracks with (as the tracker
    chooses it)."""
    from occupose.tracker import model_for

    pose = config.pose
    return model_for(cameras, pose.steep_down_deg) if pose.model == "auto" else pose.model


def cache_folder() -> Path:
    """numba's cache folder (set by :func:`occupose._numba.configure`), where the markers go."""
    from numba.core.config import CACHE_DIR

    return Path(CACHE_DIR or os.environ.get("NUMBA_CACHE_DIR") or Path.home() / ".cache" / "occupose" / "numba")


def _strategy_settings(config: TrackerConfig) -> dict:
    """The settings that choose code rather than sizes: every one that is not a number
    (the strategies' names, the switches, the noise model). Numbers change the sizes of
    the arrays, not their types, so they call the same compiled kernels."""
    def chosen(value) -> bool:
        if isinstance(value, (list, tuple)):
            return all(map(chosen, value))
        return value is None or isinstance(value, (str, bool))

    return {f"{section}.{key}": value for section, values in config.to_dict().items()
            for key, value in values.items() if chosen(value) and value != []}


def marker_key(config: TrackerConfig, model: str) -> str:
    """SHA-1 of what decides the compiled kernels: numba's version, every source file of
    the package, the settings that choose code (:func:`_strategy_settings`) and the body
    model."""
    import numba

    import occupose

    settings = json.dumps(_strategy_settings(config), sort_keys=True)
    digest = hashlib.sha1(f"{numba.__version__}|{model}|{settings}".encode())
    for path in sorted(Path(occupose.__file__).parent.rglob("*.py")):
        digest.update(path.read_bytes())
    return digest.hexdigest()


def warm_up(config: TrackerConfig | str, cameras: Sequence[Camera], *,
            report: Callable[[str], None] | None = None, folder: str | os.PathLike | None = None,
            load: bool = False) -> bool:
    """Compile (or load) the kernels a run with ``config`` on ``cameras`` will call.

    Skipped when the marker of these settings and this body model exists in ``folder``
    (default: :func:`cache_folder`; it holds one empty file per :func:`marker_key`), unless
    ``load``: then the scene is tracked anyway, so that this process has every kernel
    loaded before its first frame (a live camera's frames do not wait for the cache, about
    0.3 s at the first frame and at a person's start). ``report(message)`` is called once,
    before a warm-up that compiles. Returns True when it ran.
    """
    config = as_config(config)
    model = model_of(config, cameras)
    marker = Path(cache_folder() / MARKERS if folder is None else folder) / marker_key(config, model)
    marked = marker.exists()
    if marked and not load:
        return False
    from occupose.run import track_frames
    from occupose.synth.generate import frames
    from occupose.synth.scenarios import build_scenario
    from occupose.tracker import Tracker

    if report is not None and not marked:
        report(f"compiling the tracker's kernels for this machine: once, about a minute (cached in {cache_folder()})")
    name, count = SCENES[model]
    scenario = build_scenario(name, use_mocap=False)
    tracker = Tracker(scenario.cameras, scenario.fps, config, seed=0)  # measured noise: it measures itself
    track_frames(tracker, frames(scenario, num_frames=count), count)
    marker.parent.mkdir(parents=True, exist_ok=True)
    marker.touch()
    return True
