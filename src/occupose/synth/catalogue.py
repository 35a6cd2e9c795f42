"""A scenario of the catalogue rendered into a recording folder, the one way from a name to disk.

:func:`render_scenario` builds a scenario of :data:`occupose.synth.scenarios.SCENARIOS`
and writes its first frames as a recording folder with ground truth
(:func:`occupose.synth.generate.write_scenario`). ``occupose synth`` and ``occupose demo``
call it, and so does the evaluation for its renders under ``OUT/recordings/``.

The recording is made whole or not at all, beside ``out`` and swapped in
(:func:`occupose.io.output.staged_folder`). What happens to a folder already at ``out``
is the caller's choice, ``exists``:

- ``"refuse"``: ``out`` must not exist or be an empty folder, else
  :class:`occupose.io.output.OutputError`;
- ``"replace"``: as ``"refuse"``, but an earlier recording of occupose is replaced (the
  overwrite rule of :mod:`occupose.io.output`: only the files it wrote); anything else is
  still refused;
- ``"reuse"``: a folder rendered earlier with the same settings and the same ground-truth
  motion (as its :data:`RENDER_INFO` file records) is kept as it is; an earlier recording
  of occupose rendered otherwise is replaced as with ``"replace"``. Only this policy writes
  :data:`RENDER_INFO`.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from occupose.io.output import staged_folder
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
    listing the valid ones), the sensor, the frames, then the folder
    (:class:`occupose.io.output.OutputError`).
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
    with staged_folder(out, "recording", force=exists != "refuse") as folder:
        if progress is not None:
            progress(0, total)
        write_scenario(scenario, folder, seed=seed, num_frames=total,
                       progress=None if progress is None else lambda done: progress(done, total))
        if exists == "reuse":
            (folder / RENDER_INFO).write_text(json.dumps(info) + "\n")
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


__all__ = ["EXISTS", "RENDER_INFO", "FramesOutOfRange", "RenderedScenario", "render_scenario"]
