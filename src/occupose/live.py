"""Live tracking from a camera as it delivers frames (``occupose live --realsense``).

:class:`RealSenseCamera` opens an Intel RealSense depth camera with ``pyrealsense2`` (the
``realsense`` extra), or plays a RealSense ``.bag`` through its playback device in real
time, which is how it is tested: frames come at the recorded rate whether or not they are
taken. A bag can also be played at the tracker's pace (``real_time=False``,
``--every-frame``): every frame, none dropped, so what is tracked does not depend on the
machine's load. :func:`track_live` tracks them one after another, always the newest. When
the tracking falls behind, the frames it had no time for are dropped, counted from the gaps
in the device's frame numbers and reported. Every tracked frame gives one JSON line
(:func:`frame_record`), flushed at once, followed by late lines for the earlier frames the
look-back has just tracked a new person back into (:func:`late_records`; a line is never
rewritten), and a status line on stderr about every second says the frames, drops,
latency and people.

Latency is the time from a frame's capture to its JSON line. The capture time is the
frame's device timestamp placed on the host clock by the least delayed frame so far (the
least difference of arrival and device time): the figure leaves out that frame's own
transfer time, so it is a lower bound, and never less than the frame's tracking time. A camera has no world pose: it is given (:class:`occupose.io.sources.HeightTilt`
or a pose file), or found from the floor in the first ``floor.frames`` frames, which are
used only for that.
"""

from __future__ import annotations

import json
import math
import time
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO

import numpy as np

from occupose.camera import Camera
from occupose.config import TrackerConfig, as_config

#: The name of the live camera (the tracker's camera name, and in the JSON lines' layout).
CAMERA_NAME = "depth"
#: How long to wait for a frame before the camera (or the bag, once played) is taken as ended.
FRAME_TIMEOUT_MS = 2000
#: Seconds between status lines.
STATUS_EVERY_S = 1.0
#: Frames the camera's queue holds until they are taken (the oldest go first when it is full).
QUEUE_FRAMES = 64


@dataclass(frozen=True)
class LiveFrame:
    """One frame as the camera gave it: ``number`` its device frame number, ``time_ms`` its
    device timestamp (milliseconds), ``depth`` (H, W) float32 metres (0: no measurement),
    ``dropped`` the frames between it and the frame taken before it that were not taken,
    ``arrived`` the host's clock (``time.perf_counter``) when it was taken."""

    number: int
    time_ms: float
    depth: np.ndarray
    dropped: int
    arrived: float


class RealSenseCamera:
    """A RealSense depth stream: a camera (``serial``, or the first connected) or a ``bag``
    played in real time, or with ``real_time=False`` every frame of it, each when the one
    before has been taken. ``camera`` : its intrinsics as a :class:`Camera` (no world pose
    yet), ``fps`` : its frame rate. Use as a context manager, or :meth:`close`."""

    def __init__(self, *, serial: str | None = None, bag: str | Path | None = None, real_time: bool = True):
        from occupose.io.sources import require

        rs = require("pyrealsense2", "realsense", "a live RealSense camera")
        if serial is not None and bag is not None:
            raise ValueError("give a camera's serial number or a bag, not both")
        if not real_time and bag is None:
            raise ValueError("a live camera plays in real time: only a bag can be played frame by frame")
        config = rs.config()
        if bag is not None:
            if not Path(bag).is_file():
                raise FileNotFoundError(f"{bag}: no such bag file")
            config.enable_device_from_file(str(bag), repeat_playback=False)
        elif serial is not None:
            config.enable_device(serial)
        config.enable_stream(rs.stream.depth)
        self._rs = rs
        self._pipeline = rs.pipeline()
        # In real time every frame delivered goes to a queue of ours: the pipeline's own holds only the
        # newest, so a bag's first frames, played before it could be paused, would be lost on a busy
        # machine. Played frame by frame the pipeline's own is the one that waits for each frame to be
        # taken (a playback into a queue of ours stops after two frames).
        self._queue = rs.frame_queue(QUEUE_FRAMES, keep_frames=True) if real_time else None
        try:
            profile = self._pipeline.start(config, self._queue) if real_time else self._pipeline.start(config)
        except RuntimeError as error:
            what = f"{bag}: not a RealSense recording it can play" if bag is not None else "no RealSense camera"
            raise ValueError(f"{what} ({error})") from None
        device = profile.get_device()
        self._playback = device.as_playback() if bag is not None else None
        if self._playback is not None:
            self._playback.set_real_time(real_time)
            if real_time:
                self._playback.pause()  # until the first frame is asked for (frames)
        stream = profile.get_stream(rs.stream.depth).as_video_stream_profile()
        k = stream.get_intrinsics()
        self.fps = float(stream.fps())
        self.camera = Camera(name=CAMERA_NAME, width=k.width, height=k.height, fx=k.fx, fy=k.fy, cx=k.ppx, cy=k.ppy,
                             world_from_camera=np.eye(4), depth_scale=float(device.first_depth_sensor().get_depth_scale()))
        self._last = None

    def frames(self) -> Iterator[LiveFrame]:
        """The newest frame each time one is asked for, from which drops are counted (the
        first from a bag: the first it played), until none comes for
        :data:`FRAME_TIMEOUT_MS` (a bag played to its end, a camera unplugged)."""
        self.resume()
        while True:
            if self._queue is None:  # frame by frame
                ok, frame = self._pipeline.try_wait_for_frames(FRAME_TIMEOUT_MS)
            else:
                ok, frame = self._queue.try_wait_for_frame(FRAME_TIMEOUT_MS)
            if not ok:
                return
            while self._queue is not None and (self._last is not None or self._playback is None):  # the newest
                newer = self._queue.poll_for_frame()
                if not newer:
                    break
                frame = newer
            depth = frame.as_frameset().get_depth_frame() if frame.is_frameset() else frame.as_depth_frame()
            number = int(depth.get_frame_number())
            dropped = 0 if self._last is None else max(number - self._last - 1, 0)
            self._last = number
            metres = np.asanyarray(depth.get_data()).astype(np.float32) * np.float32(self.camera.depth_scale)
            yield LiveFrame(number, float(depth.get_timestamp()), metres, dropped, time.perf_counter())

    def pause(self) -> None:
        """Hold a bag played in real time where it is (a live camera cannot be held: its
        frames go on, and those not taken count as dropped; a bag played frame by frame
        waits anyway)."""
        if self._playback is not None and self._queue is not None:
            self._playback.pause()

    def resume(self) -> None:
        if self._playback is not None and self._queue is not None:
            self._playback.resume()

    def close(self) -> None:
        self._pipeline.stop()

    def __enter__(self) -> RealSenseCamera:
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def frame_record(index: int, frame: LiveFrame, estimates, latency_ms: float, dropped: int) -> dict:
    """One JSON line: ``frame`` (tracked frames from 0), ``device_frame``, ``time_ms`` (device
    timestamp), ``latency_ms``, ``dropped`` (frames dropped so far) and ``people``: per
    person ``track`` and ``joints`` (15 x [x, y, z] metres in the world frame, in the order
    of :data:`occupose.joints.JOINTS`, null where the model reports none) and ``visible``
    (15 booleans: estimated from this frame's data)."""
    return {"frame": index, "device_frame": frame.number, "time_ms": round(frame.time_ms, 3),
            "latency_ms": round(latency_ms, 2), "dropped": dropped, "people": _people(estimates)}


def late_records(index: int, looked_back, recent: Mapping[int, LiveFrame]) -> list[dict]:
    """The JSON lines of the look-back's estimates made at tracked frame ``index``
    (``FrameResult.looked_back``: {track: [(frames ago, PersonEstimate)]}): one per earlier
    frame, oldest first, with ``frame``, ``device_frame`` and ``time_ms`` of that frame (from
    ``recent``: tracked frame -> its LiveFrame), ``late`` true and the ``people`` tracked
    back in it, as in :func:`frame_record`. A reader that merges the lines of a frame gets
    what ``occupose track`` writes for it."""
    by_frame: dict[int, dict] = {}
    for track, earlier in looked_back.items():
        for ago, estimate in earlier:
            by_frame.setdefault(index - ago, {})[track] = estimate
    lines = []
    for earlier_index in sorted(by_frame):
        frame = recent[earlier_index]
        lines.append({"frame": earlier_index, "device_frame": frame.number, "time_ms": round(frame.time_ms, 3),
                      "late": True, "people": _people(by_frame[earlier_index])})
    return lines


def _people(estimates) -> list[dict]:
    """``people`` of a JSON line: {track: PersonEstimate} in track order."""
    people = []
    for track, estimate in sorted(estimates.items()):
        joints = [[round(float(c), 4) for c in j] if np.all(np.isfinite(j)) else None for j in estimate.joints]
        people.append({"track": int(track), "joints": joints, "visible": [bool(v) for v in estimate.visible]})
    return people


@dataclass
class LiveSummary:
    """What a live run did: frames tracked, frames dropped (including those taken for the
    floor), latencies (ms, one per tracked frame), the track ids seen, the pose used, the
    noise the grid assumed at the end (:meth:`occupose.grid.noise.CameraNoise.to_dict`)."""

    frames: int = 0
    dropped: int = 0
    latencies: list[float] = field(default_factory=list)
    tracks: set[int] = field(default_factory=set)
    pose: str = ""
    noise: dict = field(default_factory=dict)

    def latency(self, q: float) -> float:
        """The ``q`` quantile (0-1) of the latencies, ms (NaN before any frame)."""
        return float(np.quantile(self.latencies, q)) if self.latencies else math.nan

    def status(self) -> str:
        return (f"{self.frames} frames tracked, {self.dropped} dropped, latency "
                f"median {self.latency(0.5):.0f} ms, p95 {self.latency(0.95):.0f} ms, {len(self.tracks)} track(s)")


def _place(camera: Camera, frames: Iterator[LiveFrame], pose, config: TrackerConfig) -> tuple[Camera, str]:
    """The camera with its world pose (given, or from the floor in its next frames); returns
    (camera, where the pose came from: ``given`` or ``floor``)."""
    from dataclasses import replace

    from occupose.geometry.floor import find_floor
    from occupose.io.sources import HeightTilt, NoWorldPoseError, pose_from_file

    if isinstance(pose, HeightTilt):
        return replace(camera, world_from_camera=pose.world_from_camera()), "given"
    if pose is not None:
        return replace(camera, world_from_camera=pose_from_file(pose, [camera.name])[camera.name]), "given"
    depths = [f.depth for _, f in zip(range(config.floor.frames), frames)]
    floor = find_floor(camera, depths, config.floor) if depths else None
    if floor is None:
        raise NoWorldPoseError(f"no floor found in the camera's first {len(depths)} frames; give the pose with "
                               "--camera-height H --tilt DEGREES or --world-from-camera FILE.json")
    return replace(camera, world_from_camera=floor.world_from_camera()), "floor"


def track_live(source: RealSenseCamera, config: TrackerConfig | str = "ours", *, out: IO[str], pose=None,
               seed: int = 0, max_frames: int | None = None, status: Callable[[str], None] | None = None
               ) -> LiveSummary:
    """Track ``source``'s frames as they come, writing one JSON line per tracked frame to
    ``out`` (:func:`frame_record`), then a late line for each earlier frame the look-back
    tracked a new person back into (:func:`late_records`), flushed each time.

    pose : a HeightTilt, a pose file, or None (the floor in the first frames)
    max_frames : stop after this many tracked frames (None: until the source ends)
    status : called with a status line about every :data:`STATUS_EVERY_S` seconds and at the
        end (and once before a first warm-up, :mod:`occupose.warmup`)
    """
    from occupose import warmup
    from occupose.tracker import Tracker

    config = as_config(config)
    frames = source.frames()
    camera, origin = _place(source.camera, frames, pose, config)
    if config.grid.noise_model == "measured" and status is not None:  # the tracker measures it (Tracker)
        status(f"the camera's depth noise is measured on its first {config.grid.noise_frames} frames tracked")
    source.pause()  # a played bag waits for the warm-up; a camera's frames meanwhile are dropped
    warmup.warm_up(config, [camera], report=status, load=True)
    tracker = Tracker([camera], source.fps, config, seed=seed)
    source.resume()
    summary = LiveSummary(pose=origin)
    # the tracked frames the look-back may reach: their numbers and times for its late lines
    recent: dict[int, LiveFrame] = {}
    reach = round(config.start.look_back_s * source.fps) + config.start.look_back_from + 1
    offset = math.inf  # host clock minus device clock (s), least over the frames: the least delayed one's
    last_status = time.perf_counter()
    for frame in frames:
        if max_frames is not None and summary.frames >= max_frames:
            break
        offset = min(offset, frame.arrived - frame.time_ms / 1000.0)
        summary.dropped += frame.dropped  # the first: those that came during the floor estimate and warm-up
        result = tracker.update({camera.name: frame.depth})
        latency = 1000.0 * (time.perf_counter() - (frame.time_ms / 1000.0 + offset))
        recent[summary.frames] = frame
        recent.pop(summary.frames - reach, None)
        lines = [frame_record(summary.frames, frame, result.estimates, latency, summary.dropped)]
        lines += late_records(summary.frames, result.looked_back, recent)
        out.write("".join(json.dumps(line) + "\n" for line in lines))
        out.flush()
        summary.frames += 1
        summary.latencies.append(latency)
        summary.tracks.update(result.estimates)
        if status is not None and time.perf_counter() - last_status >= STATUS_EVERY_S:
            status(summary.status())
            last_status = time.perf_counter()
    summary.noise = tracker.noise[camera.name].to_dict()
    if status is not None:
        status(summary.status())
    return summary
