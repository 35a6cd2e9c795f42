"""The per-frame pipeline for any number of people and cameras (DESIGN.md, "The pipeline").

One :class:`Tracker` wires the stages and holds what lives across frames: the occupancy
grid (stage 1), the blob tracker (stage 2) and one :class:`occupose.pose.person.Person`
per tracked blob (stage 3). :meth:`Tracker.update` takes one frame of depth images and
returns a :class:`FrameResult`: every tracked person's 15 canonical joints, each flagged
visible (estimated from this frame's data) or not (carried from memory).

A frame:

1. the grid takes the depth images; cells inside a tracked person's body are *held*
   (no moving -> static transition), so a person standing or sitting still is not
   absorbed into the background;
2. moving cells are labelled into blobs, blobs tracked (ids persist); a new blob track
   near a lost person is that person's;
3. every tracked blob's pixels go to its person; where people touch, each pixel goes
   to the nearest predicted body (exclusion principle; a new person's body is made of
   its previous points, :func:`occupose.grid.pixels.predicted_from_tracks`);
4. per blob: a known person is updated (:meth:`occupose.pose.person.Person.update`), a
   new one started once its blob has been person-like for a few frames
   (:mod:`occupose.pose.start`) and later tracked back over the frames before its start
   (:mod:`occupose.pose.lookback`);
5. a person whose blob is gone is kept and carried; it ends when its blob has been gone
   for longer than ``blobs.max_gap_s``.

With ``upcoming`` frames, step 1 of the next frame runs on a second thread during step 4.
Every setting is a field of :class:`occupose.config.TrackerConfig`.
"""

from __future__ import annotations

import time
from collections.abc import Mapping, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field

import numpy as np

from occupose._validate import seed_value
from occupose.body import capsules_from_poses
from occupose.bounds import check_cameras, check_first_view, check_fps, check_reach
from occupose.camera import Camera
from occupose.config import TrackerConfig, as_config
from occupose.grid.blobs import blobs_from_mask
from occupose.grid.hold import cells_near_capsules
from occupose.grid.noise import camera_noise
from occupose.grid.occupancy import OccupancyGrid, spec_from_cameras
from occupose.grid.pixels import pixels_from_depth, predicted_from_tracks
from occupose.grid.tracking import BlobTracker
from occupose.pose.lookback import LookBack
from occupose.pose.person import Person, PersonEstimate
from occupose.pose.start import person_like, start_person, still_people
from occupose.sensors import NoiseEstimate

#: The stages timed in :attr:`FrameResult.seconds`.
STAGES = ("grid", "blobs", "observations", "pose")


@dataclass
class FrameResult:
    """What one :meth:`Tracker.update` gives.

    estimates : {track id: PersonEstimate} for every person tracked in this frame
    looked_back : {track id: [(frames ago, PersonEstimate)], newest first}: earlier frames
        of the people whose backward run this update made (the frames before their start)
    assigned : camera name -> (H, W) int32, the track id each pixel went to (0: nobody)
    seconds : seconds this update spent per stage (:data:`STAGES`)
    """

    estimates: dict[int, PersonEstimate]
    looked_back: dict[int, list[tuple[int, PersonEstimate]]] = field(default_factory=dict)
    assigned: dict[str, np.ndarray] = field(default_factory=dict)
    seconds: dict[str, float] = field(default_factory=dict)


def model_for(cameras: Sequence[Camera], steep_down_deg: float) -> str:
    """'upper' when every camera looks down more steeply than ``steep_down_deg`` degrees
    (ceiling cameras), else 'full'."""
    return "upper" if all(c.down_angle > np.deg2rad(steep_down_deg) for c in cameras) else "full"


class Tracker:
    """Skeletons of everyone in view, frame after frame (see the module docstring).

    cameras : Camera or sequence of Camera (unique names); fps : frames per second
    config : a TrackerConfig, or the name of a method of :data:`occupose.config.METHODS`
        (default ``ours``)
    seed : int, seeds every person's filter (person n gets a generator spawned from it)
    noise : None or camera name -> :class:`occupose.sensors.NoiseEstimate` (or the reason it
        could not be measured), each camera's measured depth noise
        (:func:`occupose.grid.noise.measure_noise` of the first
        ``grid.noise_frames`` frames; :func:`occupose.run.track_recording` measures it
        before the first frame), used with
        ``grid.noise_model`` measured. Without it, the tracker measures it itself on its
        first ``grid.noise_frames`` frames, which it tracks meanwhile with each camera's
        named noise model (as ``grid.noise_model`` preset); it then replays them through a
        grid made with the measured noise, and goes on with that grid (and the people it
        has). ``noise`` (after construction): camera name ->
        :class:`occupose.grid.noise.CameraNoise`, what the grid assumes of each camera.
    """

    def __init__(self, cameras, fps: float, config: TrackerConfig | str = "ours", *, seed: int = 0,
                 noise: Mapping[str, NoiseEstimate | str] | None = None):
        config = as_config(config)
        cameras = [cameras] if isinstance(cameras, Camera) else list(cameras)
        self.cameras = cameras
        limits = config.limits
        self.fps = check_fps(fps, limits)
        check_cameras(cameras, limits)
        self.config = config
        pose = config.pose
        self.model_name = model_for(cameras, pose.steep_down_deg) if pose.model == "auto" else pose.model
        grid = config.grid
        #: the frames the noise is being measured on, or None: (camera name -> depth, the
        #: capsules its grid update held, :meth:`_hold_capsules`)
        self._noise_frames = [] if grid.noise_model == "measured" and noise is None else None
        self.noise = camera_noise(cameras, grid, noise)  # measured, none given: named until measured
        self._make_grid()
        blobs = config.blobs
        self.blobs = BlobTracker(self.fps, blobs.max_gap_s, gate_m=blobs.gate_m, gate_growth=blobs.gate_growth,
                                 claim_share=blobs.claim_share, merge_margin_m=blobs.merge_margin_m,
                                 fragment_m=blobs.fragment_m, min_share=blobs.min_share,
                                 position_gain=blobs.position_gain, velocity_gain=blobs.velocity_gain)
        self.people: dict[int, Person] = {}
        self.seed = seed_value(seed)
        self._unviewed = {c.name for c in cameras}  # cameras whose first measured frame is not checked yet
        self._seeds = np.random.SeedSequence(seed)
        self._previous = {}
        self._pending: dict[int, list[np.ndarray]] = {}  # points of tracks not yet started
        self._fragments: set[int] = set()  # blob tracks that split off a tracked person's (see _start)
        self._look_back = LookBack(config, self.fps, cameras, self._seeds)
        self.frame = -1
        self._pool: ThreadPoolExecutor | None = None  # the grid's thread when updates overlap
        self._grid_job = None

    def _make_grid(self) -> None:
        """The grid (and its spec) for the cameras' noise and far range of ``self.noise``."""
        grid, far = self.config.grid, {name: c.max_range for name, c in self.noise.items()}
        check_reach(self.cameras, far, self.config.limits)
        self.spec = spec_from_cameras(self.cameras, cell=grid.cell, height=grid.height, max_range=far,
                                      max_cells=self.config.limits.grid_cells)
        self.grid = OccupancyGrid(self.spec, self.cameras, {name: c.model for name, c in self.noise.items()},
                                  alpha=grid.alpha, beta=grid.beta, gamma=grid.gamma, psi=grid.psi, p_occ=grid.p_occ,
                                  p_free=grid.p_free, tail_width=grid.tail_width, initial=grid.initial, max_range=far,
                                  no_return=grid.no_return, no_return_after=grid.no_return_after)

    def _seed_still(self, depths: Mapping[str, np.ndarray], frame: int) -> None:
        """After the grid's update with frame number ``frame``: people still from the first
        frame are no background (:func:`occupose.pose.start.still_people`)."""
        if frame < self.config.start.still_frames:
            self.grid.seed_moving(still_people(self.grid.states, self.spec, depths, self.cameras, self.config.start,
                                               self.config.size, self.config.blobs.join_m) & ~self.grid.moving_mask())

    def _measure_noise(self, depths: Mapping[str, np.ndarray], held) -> None:
        """Keep this frame, and the capsules ``held`` in its grid update, for the noise
        measurement (a Tracker given no ``noise`` with ``grid.noise_model`` measured); with
        ``grid.noise_frames`` of them, measure, make the grid again with the measured noise
        and replay them through it, each with its hold (without it, a person still from
        the first frame would fade into the background that much sooner)."""
        from occupose.grid.noise import measure_noise

        self._noise_frames.append(({name: np.array(d, np.float32) for name, d in depths.items()}, held))
        if len(self._noise_frames) < self.config.grid.noise_frames:
            return
        kept, self._noise_frames = self._noise_frames, None
        frames = [frame for frame, _ in kept]
        self.noise = camera_noise(self.cameras, self.config.grid,
                                  measure_noise(self.cameras, frames, self.config.grid, strict=False))
        self._make_grid()
        for index, (frame, held) in enumerate(kept):
            self.grid.update(frame, hold=self._hold_cells(held))
            self._seed_still(frame, index)
        for person in self.people.values():
            person.area = self._area()

    def _seen_depths(self, depths: Mapping[str, np.ndarray]) -> Mapping[str, np.ndarray]:
        """The depths the pose stage reads (camera name -> (H, W) float32 metres): ``depths``,
        or with ``pose.no_return_seen`` the pixels the grid counts as returning nothing
        (``OccupancyGrid.returnless``) at the camera's far range, so that a body part drawn
        over a background beyond the sensor's range is seen through."""
        if not self.config.pose.no_return_seen:
            return depths
        out = {}
        for cam in self.cameras:
            depth = np.asarray(depths[cam.name], np.float32)
            out[cam.name] = np.where(self.grid.returnless(cam.name), np.float32(self.grid.max_ranges[cam.name]), depth)
        return out

    def _area(self) -> tuple[np.ndarray, np.ndarray]:
        """(low (2,), high (2,)) world x, y metres: the grid's floor area (Person's ``area``)."""
        return np.asarray(self.spec.origin[:2], float), self.spec.high[:2]

    def _check_views(self, depths: Mapping[str, np.ndarray]) -> None:
        """Each camera's first frame with measurements (:func:`occupose.bounds.check_first_view`)."""
        for cam in [c for c in self.cameras if c.name in self._unviewed]:
            if check_first_view(cam, np.asarray(depths[cam.name]), self.noise[cam.name].max_range, self.config.limits):
                self._unviewed.discard(cam.name)

    def close(self) -> None:
        """Stop the grid's thread (when :meth:`update` was given ``upcoming`` frames)."""
        if self._pool is not None:
            self._pool.shutdown(wait=True)
            self._pool = None

    def update(self, depths: Mapping[str, np.ndarray], upcoming: Mapping[str, np.ndarray] | None = None
               ) -> FrameResult:
        """Take one frame: camera name -> (H, W) float32 depth, metres (0 = no measurement).

        Returns a FrameResult whose ``estimates`` hold every person tracked in this frame
        (seen, or kept through a short disappearance: then every joint has visible False).
        A person's track id is the id of the blob track that started it; it stays when the
        person comes back as another blob track (:meth:`_rejoin`).

        upcoming : the next frame's depths, or None. Given, the grid takes it on a second
        thread while stage 3 works on this frame (the paper's IV-B: the grid's kernel
        releases the GIL), and the next call must pass exactly that frame; its hold mask
        then comes from the bodies of the frame before this one.
        """
        self.frame += 1
        seconds = dict.fromkeys(STAGES, 0.0)
        clock = time.perf_counter()
        self._check_views(depths)
        held = None  # the capsules this frame's grid update holds, when it runs here
        if self._grid_job is not None:  # this frame's grid update ran during the last stage 3
            self._grid_job.result()
            self._grid_job = None
        else:
            held = self._hold_capsules()
            self.grid.update(depths, hold=self._hold_cells(held))
        self._seed_still(depths, self.frame)
        if self._noise_frames is not None:  # (no grid job meanwhile: held is this frame's)
            self._measure_noise(depths, held)
        seen_depths = self._seen_depths(depths)  # (before the next frame's grid job starts)
        clock = _tick(seconds, "grid", clock)
        blobs = self.config.blobs
        labels, found = blobs_from_mask(self.grid.moving_mask(), self.spec, min_cells=blobs.min_cells,
                                        min_height=blobs.min_height, min_top=blobs.min_top, join_m=blobs.join_m)
        seen = self.blobs.update(found)
        states = self.blobs.states
        for pid in [p for p, person in self.people.items() if person.blob not in states]:
            del self.people[pid]  # its blob has been gone for longer than the gap
        self._rejoin(seen, states)
        owner = {person.blob: pid for pid, person in self.people.items()}
        self._pending = {t: p for t, p in self._pending.items() if t in seen and t not in owner}
        self._fragments &= set(seen) - set(owner)
        clock = _tick(seconds, "blobs", clock)
        pixels_cfg = self.config.pixels
        bodies = {t: self.people[owner[t]].body_distance() for t in seen if t in owner}
        bodies |= predicted_from_tracks(states, self._previous, self.fps, ids=[t for t in seen if t not in bodies],
                                        body_points=pixels_cfg.body_points, reach=pixels_cfg.reach)
        pixels, assigned = pixels_from_depth(depths, self.cameras, self.spec, labels, seen, states=self.grid.states,
                                             centers={t: states[t].centroid for t in seen}, predicted=bodies,
                                             fallback=pixels_cfg.fallback)
        self._previous = pixels
        if upcoming is not None and self._noise_frames is None:  # (the grid may be made again while measuring)
            if self._pool is None:
                self._pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="occupose-grid")
            self._grid_job = self._pool.submit(self.grid.update, upcoming, self._hold_cells(self._hold_capsules()))
        clock = _tick(seconds, "observations", clock)
        out = {}
        for tid in seen:
            if tid in owner:
                pid = owner[tid]
                out[pid] = self.people[pid].update(pixels[tid], seen_depths, assigned, states[tid])
            else:
                person = self._start(tid, pixels[tid], seen_depths, seen[tid].centroid, states[tid].velocity)
                if person is not None:
                    out[tid] = person.estimate(True)
                    if self._look_back.enabled:
                        self._look_back.started(tid, self.frame)
        looked_back = {}
        if self._look_back.enabled:
            looked_back = self._look_back.remember(self.frame, self.people, seen, owner, self._fragments, states,
                                                   pixels, seen_depths, assigned)
        for pid, person in self.people.items():
            if pid not in out:  # gone (behind something): kept, not estimated
                person.carry(seen_depths)
                out[pid] = person.estimate(False)
        _tick(seconds, "pose", clock)
        return FrameResult(dict(sorted(out.items())), looked_back, assigned, seconds)

    def _start(self, tid: int, pixels, depths, centroid: np.ndarray, velocity: np.ndarray) -> Person | None:
        """A new person from blob track ``tid``, or None while its blob has not been
        person-like for ``start.frames`` frames (:mod:`occupose.pose.start`)."""
        start = self.config.start
        if not person_like(pixels, self.cameras, start, self.config.size.top_rank):
            self._pending.pop(tid, None)
            return None
        here = self.blobs.states[tid].centroid[:2]
        if any(np.hypot(*(p.pose[:2] - here)) < start.clearance for p in self.people.values() if not p.lost):
            self._pending.pop(tid, None)  # a piece of a tracked person's body split off its blob
            self._fragments.add(tid)
            return None
        pending = self._pending.setdefault(tid, [])
        pending.append(pixels.points)
        if len(pending) < start.frames:
            return None
        rng = np.random.default_rng(self._seeds.spawn(1)[0])
        person = start_person(np.concatenate(self._pending.pop(tid)), pixels, depths, centroid, velocity,
                              self.cameras, self.model_name, self.config, self.fps, rng,
                              area=self._area())
        person.blob = tid
        self.people[tid] = person
        return person

    def _rejoin(self, seen, states) -> None:
        """Give a new blob track to the nearest lost person (gone or suspended, whose own blob
        is not seen) whose carried pelvis is within ``carry.rejoin_m`` of the blob's centroid:
        a person coming out from behind a cabinet often comes back as a new blob track,
        because the blob's centroid stalls at the cabinet's edge while they disappear, so
        the blob tracker's prediction falls short of where they reappear. A blob that split
        off a person's (kept from starting by ``start.clearance``) may be taken at any age:
        the person whose blob went on without it may continue as it."""
        owned = {person.blob for person in self.people.values()}
        lost = {pid: person for pid, person in self.people.items() if person.lost and person.blob not in seen}
        for tid in seen:
            if tid in owned or tid in self._pending or not lost or (states[tid].age > 0 and tid not in self._fragments):
                continue
            pid, gap = min(((pid, float(np.hypot(*(p.pose[:2] - states[tid].centroid[:2])))) for pid, p in lost.items()),
                           key=lambda item: item[1])
            if gap < self.config.carry.rejoin_m:
                lost.pop(pid).blob = tid

    def _hold_capsules(self) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
        """The capsules (ends a, b (K, 3) world metres, radii (K,) metres) of the bodies of
        the people estimated in the last frame, which the grid holds, or None when there
        are none (or with ``grid.hold_people`` off)."""
        if not self.config.grid.hold_people:
            return None
        bodies = [capsules_from_poses(p.model, p.pose[None]) + (p.model.capsule_radii,)
                  for p in self.people.values() if not p.lost]
        if not bodies:
            return None
        a, b, radii = (np.concatenate([body[i][0] if i < 2 else body[i] for body in bodies]) for i in range(3))
        return a, b, radii

    def _hold_cells(self, capsules) -> np.ndarray | None:
        """(nx, ny, nz) bool, the cells within ``grid.hold_margin`` of ``capsules``
        (:meth:`_hold_capsules`), or None for None."""
        return None if capsules is None else cells_near_capsules(self.spec, *capsules, self.config.grid.hold_margin)


def _tick(seconds: dict[str, float], stage: str, start: float) -> float:
    now = time.perf_counter()
    seconds[stage] += now - start
    return now
