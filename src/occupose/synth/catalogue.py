"""A scenario of the catalogue rendered into a recording folder, the one way from a name to disk.

:func:`render_scenario` builds a scenario of :data:`occupose.synth.scenarios.SCENARIOS`
and writes its first frames as a recording folder with ground truth
(:func:`occupose.synth.generate.write_scenario`). ``occupose synth`` and ``occupose demo``
call it, and so does the evaluation for its renders under ``OUT/recordings/``.

What happens to a folder already at ``out`` is the caller's choice, ``exists``:

- ``"refuse"``: ``out`` must not exist or be an empty folder, else :class:`OutputInTheWay`;
- ``"replace"``: as ``"refuse"``, but an earlier recording (a folder with
  ``recording.json``) is removed first; anything else is still refused;
- ``"reuse"``: a folder rendered earlier with the same settings and the same ground-truth
  motion (as its :data:`RENDER_INFO` file records) is kept as it is; whatever else is
  there is removed and rendered again. :data:`RENDER_INFO` is written last, so a
  half-written folder is never reused. Only this policy writes it.
"""

from __future__ import annotations

import hashlib
import json
import shutil
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from occupose.synth import scenarios
from occupose.synth.generate import write_scenario
from occupose.synth.scenarios import Scenario

#: File of a reusable render (policy ``"reuse"``): what was rendered, as JSON (scenario,
#: seed, frames, motion_source, events, and "truth", the SHA-1 of the ground-truth joints).
RENDER_INFO = "render.json"
#: The policies for a folder already at ``out`` (module docstring).
EXISTS = ("refuse", "replace", "reuse")

Progress = Callable[[int, int], None]


class FramesOutOfRange(ValueError):
    """More frames asked for than the scenario has (or fewer than one)."""

    def __init__(self, name: str, frames: int, available: int):
        super().__init__(f"frames must be in 1..{available} for {name}, got {frames}")
        self.name, self.frames, self.available = name, frames, available


class OutputInTheWay(FileExistsError):
    """Something at ``path`` that a new recording may not replace. ``reason``:
    ``"not a folder"``, ``"not empty"`` (policy ``"refuse"``) or ``"not a recording"``
    (policy ``"replace"``: a folder without ``recording.json`` is never removed)."""

    def __init__(self, path: Path, reason: str):
        message = {"not a folder": "exists and is not a folder",
                   "not empty": "exists and is not empty (exists='replace' replaces an earlier recording)",
                   "not a recording": "is not a recording folder (no recording.json): not removing it"}[reason]
        super().__init__(f"{path} {message}")
        self.path, self.reason = path, reason


@dataclass(frozen=True)
class RenderedScenario:
    """A recording folder made (or kept) by :func:`render_scenario`.

    path : the folder; scenario : the scenario as built (all its frames);
    num_frames : frames in the folder; reused : True when an earlier render was kept.
    """

    path: Path
    scenario: Scenario
    num_frames: int
    reused: bool


def render_scenario(name: str, out, *, seed: int = 0, frames: int | None = None, sensor: str | None = None,
                    procedural: bool = False, exists: str = "refuse", clip_frames: bool = False,
                    progress: Progress | None = None) -> RenderedScenario:
    """Render the scenario ``name`` into the recording folder ``out``.

    seed : the scene's seed (body sizes, clothes) and the sensor noise's
    frames : render the first ``frames`` frames (None: all of them); more than the scenario
        has raise :class:`FramesOutOfRange`, unless ``clip_frames`` (then it renders at
        most that many)
    sensor : a camera preset for every camera instead of the scenario's own (None: its own)
    procedural : procedural motion even when the shared mocap clips are present
    exists : what to do with a folder already at ``out``: ``"refuse"``, ``"replace"`` or
        ``"reuse"`` (module docstring)
    progress : ``progress(done, total)`` is called with ``done = 0`` once the number of
        frames is known and nothing has been written yet, then after every frame rendered
        (``done = 1``), or once with ``done = total`` when an earlier render is reused

    Everything is checked before anything at ``out`` is touched: the name (ValueError
    listing the valid ones), the sensor, the frames, then the folder (:class:`OutputInTheWay`).
    """
    if exists not in EXISTS:
        raise ValueError(f"exists must be one of {', '.join(EXISTS)}, got {exists!r}")
    out = Path(out)
    scenario = scenarios.build_scenario(name, seed=seed, sensor=sensor, use_mocap=not procedural)
    available = scenario.num_frames
    total = available if frames is None else min(frames, available) if clip_frames else frames
    if not 0 < total <= available:
        raise FramesOutOfRange(name, frames, available)
    if exists == "reuse":
        info = _render_info(scenario, seed, total, sensor)
        if _rendered_as(out, info):
            if progress is not None:
                progress(0, total)
                progress(total, total)
            return RenderedScenario(out, scenario, total, reused=True)
        if out.exists():
            shutil.rmtree(out)
    else:
        _make_room(out, replace=exists == "replace")
    if progress is not None:
        progress(0, total)
    write_scenario(scenario, out, seed=seed, num_frames=total,
                   progress=None if progress is None else lambda done: progress(done, total))
    if exists == "reuse":
        (out / RENDER_INFO).write_text(json.dumps(info) + "\n")
    return RenderedScenario(out, scenario, total, reused=False)


def _render_info(scenario: Scenario, seed: int, total: int, sensor: str | None) -> dict:
    """What a reusable render records about itself (the content of :data:`RENDER_INFO`)."""
    # the ground truth's digest: a recording of motion the scenario no longer makes is stale
    truth = hashlib.sha1(b"".join(np.ascontiguousarray(p.joints[:total]).tobytes() for p in scenario.people))
    info = {"scenario": scenario.name, "seed": seed, "frames": total, "motion_source": scenario.motion_source,
            "events": {k: list(v) for k, v in scenario.events.items()}, "truth": truth.hexdigest()}
    if sensor is not None:
        info["sensor"] = sensor
    return info


def _rendered_as(out: Path, info: dict) -> bool:
    """Whether ``out`` is a whole recording whose :data:`RENDER_INFO` equals ``info``."""
    marker = out / RENDER_INFO
    if not (marker.is_file() and (out / "recording.json").is_file()):
        return False
    try:
        return json.loads(marker.read_text()) == info
    except ValueError:
        return False  # unreadable: render again


def _make_room(out: Path, replace: bool) -> None:
    """Make ``out`` ready for a new recording: it must not exist, be empty, or (with
    ``replace``) be an earlier recording, which is removed. Anything else is refused."""
    if not out.exists():
        return
    if not out.is_dir():
        raise OutputInTheWay(out, "not a folder")
    if not any(out.iterdir()):
        return
    if not replace:
        raise OutputInTheWay(out, "not empty")
    if not (out / "recording.json").is_file():
        raise OutputInTheWay(out, "not a recording")
    shutil.rmtree(out)


__all__ = ["EXISTS", "RENDER_INFO", "FramesOutOfRange", "OutputInTheWay", "RenderedScenario", "render_scenario"]
