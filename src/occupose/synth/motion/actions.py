"""Procedural actions: each maps a start pose (D,) to the poses of the frames that follow it.

An action returns (n, D) poses (layout :mod:`occupose.synth.motion.pose`) at a given frame
rate; each begins where the previous one ended, so they chain without jumps:
:func:`walk`, :func:`turn`, :func:`stand`, :func:`sit_down`, :func:`sitting`,
:func:`stand_up`, :func:`wave`, :func:`gesture`, :func:`keyframes`. Feet are planted by
solving the legs (:mod:`occupose.synth.motion.pose`'s inverse kinematics) for ankle tracks.
"""

from __future__ import annotations

import math
from typing import Callable, NamedTuple

import numpy as np

from occupose.body.dims import DEFAULT_DIMS, BodyDims
from occupose.body.postures import ARM_REST
from occupose.geometry.angles import wrap_angle
from occupose.synth.motion.pose import (
    ELBOW, HEADING, HIP_FLEX, LEFT, NECK_FLEX, POSE_SIZE, RIGHT, SHOULDER_ABD, SHOULDER_FLEX, SHOULDER_ROT,
    STAND_KNEE, TRUNK_LEAN, TRUNK_SIDE, TRUNK_TWIST, X, Y, Z, _ankles, _check_pose, _frame, _hip_height_limit, _hips,
    _reach, _set_legs, _SIDES, _UPPER,
)

# ---------------------------------------------------------------------------------------
# Time and stepping helpers


def _smoothstep(x):
    """Cubic ease 0 -> 1 on [0, 1] with zero slope at both ends (clipped outside)."""
    x = np.clip(x, 0.0, 1.0)
    return x * x * (3.0 - 2.0 * x)


def _smootherstep(x):
    """Quintic ease 0 -> 1 on [0, 1] with zero slope and curvature at both ends."""
    x = np.clip(x, 0.0, 1.0)
    return x**3 * (x * (6.0 * x - 15.0) + 10.0)


def _bump(x):
    """0 -> 1 -> 0 on [0, 1] (sin^2), zero slope at both ends."""
    return np.sin(np.pi * np.clip(x, 0.0, 1.0)) ** 2


def _check_positive(name: str, value, unit: str) -> float:
    if not (isinstance(value, (int, float, np.integer, np.floating)) and math.isfinite(value) and value > 0):
        raise ValueError(f"{name} must be a positive number of {unit}, got {value!r}")
    return float(value)


def _times(duration: float, fps: float) -> np.ndarray:
    """Times (n,) of the frames after a start frame: (1..n) / fps, n = round(duration * fps) >= 1."""
    n = max(1, int(round(_check_positive("duration", duration, "seconds") * _check_positive("fps", fps, "frames per second"))))
    return np.arange(1, n + 1) / fps


def _hold(start, n: int) -> np.ndarray:
    return np.repeat(start[None], n, axis=0)


def _is_sitting(pose) -> bool:
    return bool(min(pose[LEFT + HIP_FLEX], pose[RIGHT + HIP_FLEX]) > 1.0)


def _require(start, dims: BodyDims, action: str, sitting: bool) -> None:
    if sitting and not _is_sitting(start):
        raise ValueError(f"{action} needs a seated start pose (hips flexed over 1 rad); call sit_down first")
    if not sitting and start[Z] < dims.ankle_height + 0.85 * (dims.thigh + dims.shin):
        raise ValueError(f"{action} needs a standing start pose (pelvis at {start[Z]:.2f} m, standing is "
                         f"{dims.ankle_height + _reach(dims, STAND_KNEE):.2f} m); call stand_up first")


#: Fraction of a foot's heel-off to foot-flat time at which the heel strikes.
HEEL_STRIKE = 0.88
#: Height of the ankle above its stance height at heel strike, metres.
HEEL_ROCKER = 0.012


class _Step(NamedTuple):
    """One step of a foot (0 left, 1 right): the heel starts to rise at ``t_off`` and the
    foot is flat again at ``t_on`` (seconds) with the ankle at ``target`` (3,); ``lift`` is
    the ankle's greatest height above the straight line between the two, metres."""

    foot: int
    t_off: float
    t_on: float
    target: np.ndarray
    lift: float


def _ankle_tracks(times, starts, steps) -> np.ndarray:
    """Ankle positions (n, 2, 3) at ``times`` (n,) from their ``starts`` (2, 3) and ``steps``.

    Between heel-off and foot-flat (u from 0 to 1) the ankle moves forward on a quintic
    ease in warped time u^1.2 (a slow roll off the toes, then the swing) and rises and
    falls as sin^2, touching down (heel strike) at u = :data:`HEEL_STRIKE`, :data:`HEEL_ROCKER`
    above its stance height, then rolls down onto the flat foot.
    """
    tracks = np.repeat(starts[None], times.shape[0], axis=0)
    for foot in (0, 1):
        stance = starts[foot]
        for st in sorted((s for s in steps if s.foot == foot), key=lambda s: s.t_off):
            moving = (times >= st.t_off) & (times < st.t_on)
            u = (times[moving] - st.t_off) / (st.t_on - st.t_off)
            track = stance + (st.target - stance) * _smootherstep(u**1.2)[:, None]
            rocker = _smoothstep(u / HEEL_STRIKE) * (1.0 - _smoothstep((u - HEEL_STRIKE) / (1.0 - HEEL_STRIKE)))
            track[:, 2] += st.lift * _bump(u / HEEL_STRIKE) + HEEL_ROCKER * rocker
            tracks[moving, foot] = track
            tracks[times >= st.t_on, foot] = st.target
            stance = st.target
    return tracks


def _finish(poses, ankles, dims: BodyDims) -> np.ndarray:
    """Lower the pelvis where the legs cannot reach ``ankles`` (n, 2, 3), then solve the legs."""
    poses[:, Z] = np.minimum(poses[:, Z], _hip_height_limit(_hips(poses, dims), ankles, dims))
    _set_legs(poses, ankles, dims)
    return poses


# ---------------------------------------------------------------------------------------
# Walking and turning

#: Gait constants for a leg (hip to ankle) of 0.84 m; scaled with the leg length.
STEP_LENGTH = 0.70      # metres per step at 1.3 m/s; grows with the square root of speed
MIN_STEP_TIME = 0.4     # seconds; short walks slow down rather than step faster
FOOT_MOVING = 1.36      # heel-off to foot-flat time / step time (68 % of a stride)
FOOT_AHEAD = 0.27       # the pelvis passes over a planted foot this many step times after foot-flat
SWING_LIFT = 0.13       # ankle lift at mid-swing, metres
WALK_FOOT_OFFSET = 0.065  # ankle from the walking line, metres (standing: half the pelvis width)
PELVIS_DROP = 0.04      # mean pelvis lowering while walking, metres
PELVIS_BOB = 0.02       # vertical pelvis oscillation amplitude, metres (twice per stride)
PELVIS_SWAY = 0.02      # lateral pelvis shift towards the stance foot, metres
ARM_SWING = 0.3         # shoulder flexion amplitude of the arm swing, radians
CORNER_SMOOTHING = 0.4   # metres of arc length over which path corners are rounded (Gaussian sigma)
MAX_CORNER = math.radians(150.0)  # sharper turns in a path must be a separate turn()
TURN_BEFORE_WALK = 0.35  # radians; a larger start heading error turns on the spot first


class _Centreline(NamedTuple):
    """A smoothed walking path: arc length ``s`` (M,), points ``xy`` (M, 2), unwrapped tangent
    ``heading`` (M,)."""

    s: np.ndarray
    xy: np.ndarray
    heading: np.ndarray

    def at(self, s):
        s = np.clip(s, 0.0, self.s[-1])
        xy = np.stack([np.interp(s, self.s, self.xy[:, 0]), np.interp(s, self.s, self.xy[:, 1])], -1)
        return xy, np.interp(s, self.s, self.heading)


def _walk_points(start, path_xy) -> np.ndarray:
    """The walk's polyline (K, 2): the start position, then the waypoints of ``path_xy``."""
    path = np.asarray(path_xy, dtype=np.float64)
    if path.ndim != 2 or path.shape[1] != 2 or path.shape[0] < 1 or not np.all(np.isfinite(path)):
        raise ValueError(f"path_xy must be finite waypoints of shape (K, 2) with K >= 1, got shape {path.shape}")
    points = [start[[X, Y]]]
    for p in path:
        if np.linalg.norm(p - points[-1]) > (0.05 if len(points) == 1 else 1e-6):
            points.append(p)
    if len(points) < 2:
        raise ValueError("path_xy must lead away from the start position (its points are all within 5 cm of it)")
    points = np.array(points)
    seg = np.diff(points, axis=0)
    seg /= np.linalg.norm(seg, axis=1, keepdims=True)
    turns = np.arccos(np.clip(np.sum(seg[1:] * seg[:-1], axis=1), -1.0, 1.0))
    if np.any(turns > MAX_CORNER):
        k = int(np.argmax(turns))
        raise ValueError(f"path_xy turns by {math.degrees(turns[k]):.0f} deg at {points[k + 1].tolist()}; "
                         f"corners sharper than {math.degrees(MAX_CORNER):.0f} deg need walk, turn, walk")
    return points


def _centreline(points) -> _Centreline:
    from scipy.ndimage import gaussian_filter1d

    s_poly = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))])
    ds = 0.01
    s = np.linspace(0.0, s_poly[-1], max(2, int(math.ceil(s_poly[-1] / ds)) + 1))
    xy = np.stack([np.interp(s, s_poly, points[:, 0]), np.interp(s, s_poly, points[:, 1])], -1)
    if len(points) > 2:
        sigma = CORNER_SMOOTHING / (s[1] - s[0])
        pad = int(4 * sigma) + 1
        # odd reflection about the end points keeps the ends in place and straight
        padded = np.pad(xy, ((pad, pad), (0, 0)), mode="reflect", reflect_type="odd")
        xy = gaussian_filter1d(padded, sigma, axis=0, mode="nearest")[pad:-pad]
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(xy, axis=0), axis=1))])
    tangent = np.gradient(xy, axis=0)
    return _Centreline(s, xy, np.unwrap(np.arctan2(tangent[:, 1], tangent[:, 0])))


def walk(start, path_xy, speed: float = 1.3, *, dims: BodyDims = DEFAULT_DIMS, fps: float = 30.0) -> np.ndarray:
    """Walk from the start pose through the waypoints ``path_xy`` (K, 2), world metres.

    The pelvis follows the polyline (start position first; a first waypoint within 5 cm of
    it is dropped) with its corners rounded, at ``speed`` m/s once under way (paths too
    short for steps of :data:`MIN_STEP_TIME` are walked slower). It speeds up over the first
    step, brakes over the last but one and stops standing above the last waypoint, facing
    along the last segment; a last step brings the feet side by side. The walk takes about
    length / speed + 1.5 step times (0.52 s a step at 1.3 m/s). Steps are about 0.7 m long
    at 1.3 m/s (scaled with the leg length and the square root of the speed), planted feet
    stay put, arms swing in counter-phase to the legs and the pelvis bobs and sways. A start
    heading more than :data:`TURN_BEFORE_WALK` rad off the path turns on the spot first
    (:func:`turn`). Needs a standing start pose (D,).

    Returns (n, D) poses of the frames after ``start`` at ``fps``.
    """
    start = _check_pose(start)
    speed = _check_positive("speed", speed, "metres per second")
    if speed > 2.2:
        raise ValueError(f"speed must be a walking speed up to 2.2 m/s, got {speed}")
    fps = _check_positive("fps", fps, "frames per second")
    _require(start, dims, "walk", sitting=False)
    line = _centreline(_walk_points(start, path_xy))
    delta = float(wrap_angle(start[HEADING] - line.heading[0]))
    if abs(delta) > TURN_BEFORE_WALK:
        turned = turn(start, start[HEADING] - delta, dims=dims, fps=fps)
        return np.concatenate([turned, _walk(turned[-1], line, speed, 0.0, dims, fps)])
    return _walk(start, line, speed, delta, dims, fps)


def _walk(start, line: _Centreline, speed: float, delta: float, dims: BodyDims, fps: float) -> np.ndarray:
    length = float(line.s[-1])
    k = (dims.thigh + dims.shin) / 0.84
    # Step i lifts its heel at i * tau, strikes the floor at (i + HEEL_STRIKE * FOOT_MOVING) * tau
    # and is flat at (i + FOOT_MOVING) * tau. The pelvis speeds up over 1.5 tau (so the first
    # step is short), cruises, and brakes from the heel strike of the last but one step,
    # which lands at the end point, to a stop above it; the last step closes the feet.
    cruise = speed
    step_len = STEP_LENGTH * k * math.sqrt(cruise / 1.3)
    # braking covers what is left from that heel strike to the pelvis passing over the foot
    brake = 2.0 * ((1.0 - HEEL_STRIKE) * FOOT_MOVING + FOOT_AHEAD)  # braking time / tau
    extra = HEEL_STRIKE * FOOT_MOVING + 0.5 * brake - 2.75  # length / (cruise tau) = num_steps + extra
    num_steps = max(3, int(round(length / step_len - extra)))
    covered = num_steps + extra
    tau = length / (covered * cruise)
    if tau < MIN_STEP_TIME:
        tau = MIN_STEP_TIME
        cruise = length / (covered * tau)
    ramp_up, ramp_down = 1.5 * tau, brake * tau
    moving = (num_steps - 2.0 + HEEL_STRIKE * FOOT_MOVING + brake) * tau  # the pelvis stops
    n = int(math.ceil((num_steps - 1.0 + FOOT_MOVING) * tau * fps - 1e-9))

    def rate(t):  # speed / cruise speed
        return _smoothstep(t / ramp_up) * _smoothstep((moving - t) / ramp_down)

    def dist(t):  # arc length travelled by time t
        def area(x):  # integral of the smoothstep from 0 to x, for x in [0, 1]
            x = np.clip(x, 0.0, 1.0)
            return x**3 - 0.5 * x**4

        plateau = np.clip(np.minimum(t, moving - ramp_down) - ramp_up, 0.0, None)
        return cruise * (ramp_up * area(t / ramp_up) + plateau
                         + ramp_down * (0.5 - area((moving - np.clip(t, None, moving)) / ramp_down)))

    def heading(t):
        _, h = line.at(dist(t))
        return start[HEADING] + (h - line.heading[0]) - delta * _smoothstep(t / ramp_up)

    ankles0 = _ankles(start, dims)
    ahead = float((ankles0[0, :2] - ankles0[1, :2]) @ [math.cos(line.heading[0]), math.sin(line.heading[0])])
    first = 1 if ahead > -0.01 else 0  # the trailing foot steps first; the right one from a square stance
    steps = []
    for i in range(num_steps):
        foot = first if i % 2 == 0 else 1 - first
        t_off, t_on = i * tau, (i + FOOT_MOVING) * tau
        if i >= num_steps - 2:
            centre, h, width = line.xy[-1], heading(moving), 0.5 * dims.pelvis_width
        else:
            t_under = t_on + FOOT_AHEAD * tau
            centre, h, width = line.at(dist(t_under))[0], heading(t_under), WALK_FOOT_OFFSET * k
        side = 1.0 if foot == 0 else -1.0
        target = np.array([centre[0] - side * width * math.sin(h), centre[1] + side * width * math.cos(h),
                           dims.ankle_height])
        lift = SWING_LIFT * k * (0.3 + 0.7 * float(rate(0.5 * (t_off + t_on))))
        steps.append(_Step(foot, t_off, t_on, target, lift))

    t = np.arange(1, n + 1) / fps
    r = rate(t)
    xy, _ = line.at(dist(t))
    h = heading(t)
    _, left = _frame(h)
    # heel strikes of the first foot: (HEEL_STRIKE FOOT_MOVING + 2 i) tau; the pelvis is
    # lowest just after every heel strike and highest half a step later
    t_strike = HEEL_STRIKE * FOOT_MOVING * tau
    t_high = t_strike + 0.6 * tau
    stance_side = 1.0 if first == 1 else -1.0  # the foot that does not step first
    sway = PELVIS_SWAY * k * r * np.cos(np.pi * (t - t_high) / tau) * stance_side
    poses = _hold(start, n)
    poses[:, X:Y + 1] = xy + sway[:, None] * left[:, :2]
    poses[:, Z] = start[Z] - k * r * (PELVIS_DROP - PELVIS_BOB * np.cos(2.0 * np.pi * (t - t_high) / tau))
    poses[:, HEADING] = h
    _finish(poses, _ankle_tracks(t, ankles0, steps), dims)

    # upper body: from the start pose into the walking pattern over the first half second
    # each arm is furthest forward as the opposite heel strikes
    walking = poses.copy()
    swing = np.cos(np.pi * (t - t_strike) / tau)  # +1 at the first foot's heel strikes
    first_side = 1.0 if first == 0 else -1.0  # +1 when the left foot steps first
    walking[:, TRUNK_LEAN] = 0.05 * r
    walking[:, TRUNK_SIDE] = 0.0
    walking[:, TRUNK_TWIST] = 0.08 * r * swing * first_side
    walking[:, NECK_FLEX] = 0.0
    for base, s in _SIDES:
        flex = r * (0.05 - ARM_SWING * swing * s * first_side)
        walking[:, base + SHOULDER_FLEX] = flex
        walking[:, base + SHOULDER_ABD] = ARM_REST[1] + 0.03 * r
        walking[:, base + SHOULDER_ROT] = ARM_REST[2]
        walking[:, base + ELBOW] = ARM_REST[3] + 0.15 * r + 0.4 * np.maximum(flex, 0.0)
    w = _smoothstep(t / 0.5)[:, None]
    poses[:, _UPPER] = (1.0 - w) * start[_UPPER] + w * walking[:, _UPPER]
    return poses


def turn(start, to_heading: float, duration: float | None = None, *, dims: BodyDims = DEFAULT_DIMS,
         fps: float = 30.0) -> np.ndarray:
    """Turn on the spot to face ``to_heading`` (rad, the nearer way round), stepping around.

    ``duration`` defaults to 0.5 s + 0.6 s per radian. Needs a standing start pose (D,).
    Returns (n, D) poses of the frames after ``start``.
    """
    start = _check_pose(start)
    if not math.isfinite(to_heading):
        raise ValueError(f"to_heading must be finite radians, got {to_heading!r}")
    _require(start, dims, "turn", sitting=False)
    delta = float(wrap_angle(to_heading - start[HEADING]))
    t = _times(0.5 + 0.6 * abs(delta) if duration is None else duration, fps)
    total = t[-1]
    k = (dims.thigh + dims.shin) / 0.84
    poses = _hold(start, t.shape[0])
    poses[:, HEADING] = start[HEADING] + delta * _smoothstep(t / total)
    poses[:, Z] -= 0.01 * k * _bump(t / total)
    num_steps = 0 if abs(delta) < 0.02 else max(2, int(math.ceil(abs(delta) / (np.pi / 4))))
    slot = total / max(num_steps, 1)
    steps = []
    for i in range(num_steps):
        foot = (0 if delta > 0 else 1) if i % 2 == 0 else (1 if delta > 0 else 0)  # lead with the inner foot
        t_off, t_on = (i + 0.05) * slot, (i + 0.95) * slot
        h = start[HEADING] + delta * (1.0 if i >= num_steps - 2 else float(_smoothstep((i + 1) / num_steps)))
        side = 0.5 * dims.pelvis_width * (1.0 if foot == 0 else -1.0)
        target = np.array([start[X] - side * math.sin(h), start[Y] + side * math.cos(h), dims.ankle_height])
        steps.append(_Step(foot, t_off, t_on, target, 0.05 * k))
    return _finish(poses, _ankle_tracks(t, _ankles(start, dims), steps), dims)


# ---------------------------------------------------------------------------------------
# Standing, sitting


def stand(start, duration: float, *, dims: BodyDims = DEFAULT_DIMS, fps: float = 30.0) -> np.ndarray:
    """Stand idle for ``duration`` seconds: feet planted, a little sway of the pelvis, trunk
    and head that fades in and out (the last frame equals the start pose).
    Needs a standing start pose (D,). Returns (n, D)."""
    start = _check_pose(start)
    _require(start, dims, "stand", sitting=False)
    t = _times(duration, fps)
    env = _smoothstep(t / 0.6) * _smoothstep((t[-1] - t) / 0.6)
    fwd, left = _frame(np.full(t.shape, start[HEADING]))
    shift = env[:, None] * (0.012 * np.sin(2 * np.pi * t / 5.1)[:, None] * left
                            + 0.006 * np.sin(2 * np.pi * t / 7.3)[:, None] * fwd)
    poses = _hold(start, t.shape[0])
    poses[:, X:Y + 1] += shift[:, :2]
    poses[:, TRUNK_SIDE] -= env * 0.015 * np.sin(2 * np.pi * t / 5.1)
    poses[:, NECK_FLEX] += env * 0.04 * np.sin(2 * np.pi * t / 6.7)
    return _finish(poses, _hold(_ankles(start, dims), t.shape[0]), dims)


#: Trunk lean and arms (shoulder flex, abd, rot, elbow: hands resting on the thighs) when seated.
SIT_LEAN = 0.0
SIT_ARMS = np.array([0.35, 0.15, 0.0, 0.7])


def pelvis_offset_from_seat(seat_height: float, dims: BodyDims = DEFAULT_DIMS) -> tuple[float, float]:
    """Where :func:`sit_down` puts the pelvis: (back, z), metres.

    ``back`` is the horizontal distance behind the ankles (the pelvis starts above them)
    and ``z`` the height, ``seat_height + dims.seat_clearance``, with the shins vertical
    and the thighs, of length ``dims.thigh``, reaching from the knee to the hip (so they lie
    on a seat of that height: horizontal when the seat is at knee height).
    """
    if not (isinstance(seat_height, (int, float, np.integer, np.floating)) and math.isfinite(seat_height)):
        raise ValueError(f"seat_height must be a number of metres, got {seat_height!r}")
    knee = dims.ankle_height + dims.shin
    low = knee - 0.6 * dims.thigh - dims.seat_clearance
    high = min(knee + 0.6 * dims.thigh, dims.ankle_height + dims.thigh + dims.shin - 0.1) - dims.seat_clearance
    if not low <= seat_height <= high:
        raise ValueError(f"seat_height must be in [{low:.2f}, {high:.2f}] m for this body, got {seat_height}")
    z = seat_height + dims.seat_clearance
    return math.sqrt(dims.thigh**2 - (z - knee) ** 2), z


def sit_down(start, seat_height: float = 0.45, duration: float = 1.8, *, dims: BodyDims = DEFAULT_DIMS,
             fps: float = 30.0) -> np.ndarray:
    """Sit down on a seat ``seat_height`` metres high behind the person.

    Feet stay planted; the pelvis moves back and down to :func:`pelvis_offset_from_seat`
    (behind the midpoint of the ankles), the trunk leans forward on the way and comes
    upright again, the hands come to rest on the thighs. Needs a standing start pose (D,).
    Returns (n, D).
    """
    start = _check_pose(start)
    _require(start, dims, "sit_down", sitting=False)
    back, z = pelvis_offset_from_seat(seat_height, dims)
    t = _times(duration, fps)
    u = t / t[-1]
    ankles = _ankles(start, dims)
    fwd, _ = _frame(np.array([start[HEADING]]))
    end = np.append(ankles[:, :2].mean(axis=0) - back * fwd[0, :2], z)
    m = _smootherstep(u)[:, None]
    poses = _hold(start, t.shape[0])
    poses[:, X:Z + 1] = (1.0 - m) * start[X:Z + 1] + m * end
    upright = start.copy()
    upright[_UPPER] = 0.0
    upright[TRUNK_LEAN] = SIT_LEAN
    for base, _ in _SIDES:
        upright[base + SHOULDER_FLEX:base + ELBOW + 1] = SIT_ARMS
    poses[:, _UPPER] = (1.0 - m) * start[_UPPER] + m * upright[_UPPER]
    b = _bump(u)
    poses[:, TRUNK_LEAN] += 0.6 * b
    poses[:, NECK_FLEX] -= 0.2 * b  # keep looking ahead while leaning
    for base, _ in _SIDES:
        poses[:, base + SHOULDER_FLEX] += 0.4 * b
    return _finish(poses, _hold(ankles, t.shape[0]), dims)


def stand_up(start, duration: float = 1.8, *, dims: BodyDims = DEFAULT_DIMS, fps: float = 30.0) -> np.ndarray:
    """Stand up from a seat: lean forward, then rise with the pelvis coming forward over the
    planted feet, ending in a relaxed upright pose. Needs a seated start pose (D,).
    Returns (n, D)."""
    start = _check_pose(start)
    _require(start, dims, "stand_up", sitting=True)
    t = _times(duration, fps)
    u = t / t[-1]
    ankles = _ankles(start, dims)
    end = np.append(ankles[:, :2].mean(axis=0), ankles[:, 2].mean() + _reach(dims, STAND_KNEE))
    m = _smootherstep((u - 0.2) / 0.8)[:, None]
    poses = _hold(start, t.shape[0])
    poses[:, X:Z + 1] = (1.0 - m) * start[X:Z + 1] + m * end
    upright = start.copy()
    upright[_UPPER] = 0.0
    for base, _ in _SIDES:
        upright[base + SHOULDER_FLEX:base + ELBOW + 1] = ARM_REST
    poses[:, _UPPER] = (1.0 - m) * start[_UPPER] + m * upright[_UPPER]
    b = _bump(u**0.75)
    poses[:, TRUNK_LEAN] += 0.65 * b
    poses[:, NECK_FLEX] -= 0.2 * b
    for base, _ in _SIDES:
        poses[:, base + SHOULDER_FLEX] += 0.4 * b
    return _finish(poses, _hold(ankles, t.shape[0]), dims)


def sitting(start, duration: float, *, dims: BodyDims = DEFAULT_DIMS, fps: float = 30.0) -> np.ndarray:
    """Sit idle for ``duration`` seconds with a little trunk and head motion that fades in and
    out (the last frame equals the start pose). Needs a seated start pose (D,). Returns (n, D)."""
    start = _check_pose(start)
    _require(start, dims, "sitting", sitting=True)
    t = _times(duration, fps)
    env = _smoothstep(t / 0.6) * _smoothstep((t[-1] - t) / 0.6)
    poses = _hold(start, t.shape[0])
    poses[:, TRUNK_LEAN] += env * 0.03 * np.sin(2 * np.pi * t / 4.7)
    poses[:, TRUNK_SIDE] += env * 0.015 * np.sin(2 * np.pi * t / 5.3)
    poses[:, NECK_FLEX] += env * 0.05 * np.sin(2 * np.pi * t / 6.1)
    return poses


# ---------------------------------------------------------------------------------------
# Arm motions

#: Arm poses of :func:`gesture` (shoulder flex, abd, rot, elbow) and the arms each uses
#: (None = the ``arm`` argument).
GESTURES: dict[str, tuple[np.ndarray, str | None]] = {
    "raise": (np.array([2.9, 0.15, 0.0, 0.15]), None),   # arm straight up
    "point": (np.array([1.45, 0.2, 0.0, 0.05]), None),   # arm forward, horizontal
    "side": (np.array([0.0, 1.5, 0.0, 0.05]), None),     # arm out to the side, horizontal
    "reach": (np.array([0.9, 0.1, 0.0, 0.3]), None),     # forward and down, as to a table
    "cross": (np.array([0.45, 0.0, -1.3, 1.8]), "both"),  # arms folded in front of the chest
}
_ARMS = {"left": (LEFT,), "right": (RIGHT,), "both": (LEFT, RIGHT)}
#: Waving: upper arm out to the side, forearm up; the wave swings the forearm side to side
#: (elbow flexion) in the body's frontal plane.
WAVE_ARM = np.array([0.3, 1.45, 1.27, 1.45])


def _arm_bases(arm: str) -> tuple[int, ...]:
    if arm not in _ARMS:
        raise ValueError(f"arm must be one of {', '.join(_ARMS)}, got {arm!r}")
    return _ARMS[arm]


def gesture(start, name: str = "raise", arm: str = "right", duration: float = 2.0, *,
            fps: float = 30.0) -> np.ndarray:
    """Move an arm (``"left"``, ``"right"`` or ``"both"``) to a gesture of :data:`GESTURES`
    (``raise``, ``point``, ``side``, ``reach``, ``cross``: both arms), hold it and bring it
    back, over ``duration`` seconds. Only the arms move, so it works standing or seated.
    Returns (n, D) poses of the frames after ``start`` (D,); the last equals the start pose."""
    start = _check_pose(start)
    if name not in GESTURES:
        raise ValueError(f"unknown gesture {name!r}; valid names: {', '.join(GESTURES)}")
    target, forced = GESTURES[name]
    bases = _arm_bases(forced or arm)
    t = _times(duration, fps)
    ramp = min(0.7, 0.35 * t[-1])
    w = (_smoothstep(t / ramp) * _smoothstep((t[-1] - t) / ramp))[:, None]
    poses = _hold(start, t.shape[0])
    for base in bases:
        block = slice(base + SHOULDER_FLEX, base + ELBOW + 1)
        poses[:, block] = (1.0 - w) * start[block] + w * target
    return poses


def wave(start, arm: str = "right", duration: float = 2.5, cycles: float = 3, *,
         fps: float = 30.0) -> np.ndarray:
    """Raise a hand (``"left"``, ``"right"`` or ``"both"``) beside the head, wave ``cycles``
    times and lower it, over ``duration`` seconds; only the arms move. Returns (n, D) poses
    of the frames after ``start`` (D,); the last equals the start pose."""
    start = _check_pose(start)
    bases = _arm_bases(arm)
    cycles = _check_positive("cycles", cycles, "waves")
    t = _times(duration, fps)
    ramp = min(0.6, 0.25 * t[-1])
    w = (_smoothstep(t / ramp) * _smoothstep((t[-1] - t) / ramp))[:, None]
    u = np.clip((t - ramp) / (t[-1] - 2.0 * ramp), 0.0, 1.0)
    swing = np.sin(2.0 * np.pi * cycles * u)
    target = np.repeat(WAVE_ARM[None], t.shape[0], axis=0)
    target[:, 2] += 0.1 * swing
    target[:, 3] += 0.35 * swing
    poses = _hold(start, t.shape[0])
    for base in bases:
        block = slice(base + SHOULDER_FLEX, base + ELBOW + 1)
        poses[:, block] = (1.0 - w) * start[block] + w * target
    return poses


# ---------------------------------------------------------------------------------------
# Keyframes


def _interp_smoothstep(knots, values, t):
    i = np.clip(np.searchsorted(knots, t, side="right") - 1, 0, knots.shape[0] - 2)
    w = _smoothstep((t - knots[i]) / (knots[i + 1] - knots[i]))[:, None]
    return (1.0 - w) * values[i] + w * values[i + 1]


def _interp_pchip(knots, values, t):
    from scipy.interpolate import PchipInterpolator

    return PchipInterpolator(knots, values, axis=0)(t)


#: Interpolations of :func:`keyframes`: ``smoothstep`` eases in and out of every key (the
#: motion stops at each), ``pchip`` passes through the keys without overshoot.
INTERPOLATIONS: dict[str, Callable] = {"smoothstep": _interp_smoothstep, "pchip": _interp_pchip}


def keyframes(start, times, poses, interpolation: str = "smoothstep", *, fps: float = 30.0) -> np.ndarray:
    """Interpolate from the start pose (D,) through keyframe ``poses`` (K, D) at ``times``
    (K,) seconds after it (strictly increasing, > 0). Interpolation: a name of
    :data:`INTERPOLATIONS`. Every entry is interpolated as a number (headings unwrapped as
    given); feet are not held in place. Returns (n, D), n = round(times[-1] * fps) frames
    evenly spaced up to times[-1], the last equal to the last keyframe."""
    start = _check_pose(start)
    times = np.asarray(times, dtype=np.float64)
    poses = np.asarray(poses, dtype=np.float64)
    if times.ndim != 1 or times.shape[0] < 1 or not np.all(np.isfinite(times)):
        raise ValueError(f"times must be a finite (K,) array with K >= 1, got shape {times.shape}")
    if times[0] <= 0 or np.any(np.diff(times) <= 0):
        raise ValueError(f"times must be strictly increasing and > 0 seconds, got {times.tolist()}")
    if poses.shape != (times.shape[0], POSE_SIZE) or not np.all(np.isfinite(poses)):
        raise ValueError(f"poses must be finite with shape ({times.shape[0]}, {POSE_SIZE}), got {poses.shape}")
    if interpolation not in INTERPOLATIONS:
        raise ValueError(f"unknown interpolation {interpolation!r}; valid names: {', '.join(INTERPOLATIONS)}")
    n = max(1, int(round(times[-1] * _check_positive("fps", fps, "frames per second"))))
    t = times[-1] * np.arange(1, n + 1) / n
    return INTERPOLATIONS[interpolation](np.concatenate([[0.0], times]), np.vstack([start, poses]), t)
