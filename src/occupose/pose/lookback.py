"""A new person tracked back over the frames before its start.

A person walking in from the image's edge starts only once one camera sees it whole and
its size is measured over ``start.frames`` frames; before that, its hand or shoulder may
show for a second. ``start.look_back_from`` frames after its start (the filter has set the
start's stride right by then), a person of the same model runs back in time from that
frame's estimate over the kept frames of its blob (its velocity reversed, its walking
prior and turn-round test flipped), at most ``start.look_back_s`` seconds of them, until
its torso is hidden (out of view) or its blob was not seen: those estimates are the frames
before its start. Set ``start.look_back_s = 0`` for none.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace

import numpy as np

from occupose.camera import Camera
from occupose.config import TrackerConfig
from occupose.grid.pixels import PersonPixels
from occupose.grid.tracking import TrackState
from occupose.pose.person import Person, PersonEstimate
from occupose.pose.search import start_spread


@dataclass
class _Recent:
    """One frame's data of the blobs without a person and of the people just started.

    depths : camera name -> (H, W) float32 metres (a copy); assigned : camera name -> (H, W)
    int32 track id of each pixel; blobs : {track id: (its pixels, its TrackState)}
    """

    depths: dict[str, np.ndarray]
    assigned: dict[str, np.ndarray]
    blobs: dict[int, tuple[PersonPixels, TrackState]]


class LookBack:
    """The kept frames and the people due to be tracked back (module docstring).

    config : the run's settings; fps : frames/s; cameras : the recording's cameras
    seeds : the tracker's SeedSequence, from which each backward run's generator is spawned
    """

    def __init__(self, config: TrackerConfig, fps: float, cameras: Sequence[Camera], seeds: np.random.SeedSequence):
        self.config, self.fps, self.cameras, self.seeds = config, fps, tuple(cameras), seeds
        kept = round(config.start.look_back_s * fps)
        self._history: deque[_Recent | None] = deque(maxlen=kept + config.start.look_back_from if kept else 0)
        self._new: dict[int, int] = {}  # people to be tracked back: id -> frame of their start

    @property
    def enabled(self) -> bool:
        return bool(self._history.maxlen)

    def started(self, pid: int, frame: int) -> None:
        """Person ``pid`` started at ``frame``: track it back once it is old enough."""
        self._new[pid] = frame

    def remember(self, frame: int, people: Mapping[int, Person], seen: Sequence[int], owner: Mapping[int, int],
                 fragments: set[int], states: Mapping[int, TrackState], pixels: Mapping[int, PersonPixels],
                 depths: Mapping[str, np.ndarray], assigned: Mapping[str, np.ndarray]
                 ) -> dict[int, list[tuple[int, PersonEstimate]]]:
        """Run the backward runs that are due at ``frame``, then keep this frame's data of the
        blobs without a person (``owner``: blob id -> person id, before this frame's starts;
        ``fragments``: blobs that split off a person) and of the people to be tracked back.
        Returns {person id: [(frames ago, PersonEstimate)], newest first}."""
        out = {}
        for pid, start in list(self._new.items()):
            person = people.get(pid)
            if person is None or person.lost or frame - start >= self.config.start.look_back_from:
                del self._new[pid]
                if person is not None and not person.lost:
                    out[pid] = self._run(person, frame - start, states[person.blob].velocity)
        kept = [t for t in seen if (t not in owner and t not in fragments) or owner.get(t) in self._new]
        self._history.append(_Recent({c: np.array(d) for c, d in depths.items()}, assigned,
                                     {t: (pixels[t], states[t]) for t in kept}) if kept else None)
        return out

    def _run(self, person: Person, since: int, velocity: np.ndarray) -> list[tuple[int, PersonEstimate]]:
        """[(frames ago, PersonEstimate)], newest first: ``person``, who started ``since``
        frames ago, tracked back from its estimate now over its blob's kept frames (its
        blob's ``velocity`` (2,) m/s now, reversed), the frames before its start only."""
        tid, out = person.blob, []
        back = Person(person.model, self.config, self.fps, np.random.default_rng(self.seeds.spawn(1)[0]),
                      self.cameras, backwards=True, area=person.area)
        back.estimator.initialise(person.pose, start_spread(person.model, self.config.start))
        back.centroid, back.blob = person.centroid, tid
        back.settle(person.pose, -velocity)
        for ago, recent in enumerate(reversed(self._history), start=1):
            if recent is None or tid not in recent.blobs:
                break
            pixels, state = recent.blobs[tid]
            estimate = back.update(pixels, recent.depths, recent.assigned, replace(state, velocity=-state.velocity))
            if back.lost or not estimate.visible.any():
                break
            if ago > since:
                out.append((ago, estimate))
        return out
