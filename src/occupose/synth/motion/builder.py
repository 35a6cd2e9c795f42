"""Chaining actions: :class:`MotionBuilder` runs them one after the other from a start pose
and keeps the frame range (:class:`Segment`) of each."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from occupose.body.dims import DEFAULT_DIMS, BodyDims
from occupose.synth.motion.actions import (
    _check_positive, gesture, keyframes, sit_down, sitting, stand, stand_up, turn, walk, wave,
)
from occupose.synth.motion.pose import POSE_SIZE, _check_pose, joints_from_procedural, stance

class Segment(NamedTuple):
    """Frames ``start`` (inclusive) to ``stop`` (exclusive) made by the action ``name``."""

    name: str
    start: int
    stop: int


class MotionBuilder:
    """Chains actions into one trajectory, each starting from the previous one's last pose.

    >>> b = MotionBuilder((0.0, 0.0), heading=0.0)
    >>> joints = b.walk([(2.0, 0.0)]).turn(np.pi).sit_down(0.45).wave("right").stand_up().joints()

    Frame 0 is the start pose (standing at ``start_xy`` facing ``heading``, or
    ``start_pose``); it belongs to the first action's :class:`Segment`. Methods mirror the
    actions of :mod:`occupose.synth.motion.actions` with ``dims`` and ``fps`` filled
    in, and return the builder.
    """

    def __init__(self, start_xy=(0.0, 0.0), heading: float = 0.0, dims: BodyDims = DEFAULT_DIMS,
                 fps: float = 30.0, start_pose=None):
        self.dims = dims
        self.fps = _check_positive("fps", fps, "frames per second")
        first = stance(start_xy, heading, dims) if start_pose is None else _check_pose(start_pose, "start_pose")
        self._chunks = [first[None]]
        self._segments: list[Segment] = []
        self._num_frames = 1

    @property
    def pose(self) -> np.ndarray:
        """The current (last) pose, (D,)."""
        return self._chunks[-1][-1].copy()

    @property
    def num_frames(self) -> int:
        return self._num_frames

    def append(self, name: str, poses) -> MotionBuilder:
        """Append poses (n, D) made elsewhere (e.g. by an action function) as action ``name``."""
        poses = np.asarray(poses, dtype=np.float64)
        if poses.ndim != 2 or poses.shape[1] != POSE_SIZE or poses.shape[0] < 1 or not np.all(np.isfinite(poses)):
            raise ValueError(f"poses must be finite with shape (n, {POSE_SIZE}), n >= 1, got {poses.shape}")
        begin = self._num_frames if self._segments else 0
        self._chunks.append(poses)
        self._num_frames += poses.shape[0]
        self._segments.append(Segment(name, begin, self._num_frames))
        return self

    def walk(self, path_xy, speed: float = 1.3) -> MotionBuilder:
        return self.append("walk", walk(self.pose, path_xy, speed, dims=self.dims, fps=self.fps))

    def turn(self, to_heading: float, duration: float | None = None) -> MotionBuilder:
        return self.append("turn", turn(self.pose, to_heading, duration, dims=self.dims, fps=self.fps))

    def stand(self, duration: float) -> MotionBuilder:
        return self.append("stand", stand(self.pose, duration, dims=self.dims, fps=self.fps))

    def sit_down(self, seat_height: float = 0.45, duration: float = 1.8) -> MotionBuilder:
        return self.append("sit_down", sit_down(self.pose, seat_height, duration, dims=self.dims, fps=self.fps))

    def sitting(self, duration: float) -> MotionBuilder:
        return self.append("sitting", sitting(self.pose, duration, dims=self.dims, fps=self.fps))

    def stand_up(self, duration: float = 1.8) -> MotionBuilder:
        return self.append("stand_up", stand_up(self.pose, duration, dims=self.dims, fps=self.fps))

    def wave(self, arm: str = "right", duration: float = 2.5, cycles: float = 3) -> MotionBuilder:
        return self.append("wave", wave(self.pose, arm, duration, cycles, fps=self.fps))

    def gesture(self, name: str = "raise", arm: str = "right", duration: float = 2.0) -> MotionBuilder:
        return self.append(f"gesture:{name}", gesture(self.pose, name, arm, duration, fps=self.fps))

    def keyframes(self, times, poses, interpolation: str = "smoothstep") -> MotionBuilder:
        return self.append("keyframes", keyframes(self.pose, times, poses, interpolation, fps=self.fps))

    def poses(self) -> np.ndarray:
        """All poses so far, (T, D)."""
        return np.concatenate(self._chunks)

    def joints(self) -> np.ndarray:
        """All frames as canonical joints, (T, 15, 3) float64, world metres."""
        return joints_from_procedural(self.poses(), self.dims)

    def segments(self) -> list[Segment]:
        """The frame range of each action so far, in order."""
        return list(self._segments)
