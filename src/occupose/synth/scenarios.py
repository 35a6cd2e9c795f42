"""The catalogue of synthetic scenarios (each about 10-20 s at 30 fps).

They mirror the papers' sequences: the first paper's front-view sequences with furniture
hiding legs or most of the body (Seq1/Seq10 sitting behind a table, Seq12 no occlusion),
a chair that is moved and must become background again, two people crossing, and the
second paper's ceiling-camera sequences S1 (dark clothes), S2 (flashy clothes) and S3
(two people whose arms cross).

Motion comes from the real mocap clips of the shared data when they are present (walks
and in-place arm motions from the Bandai-Namco clips) and from :mod:`occupose.synth.motion`
otherwise, and always for what the clips lack (sitting, carrying a chair, walks that must
end at an exact spot). ``Scenario.motion_source`` says which was used.

World frame: metres, z up, floor at z = 0. Front-view scenes look from y = 0 towards +y
into a 6 m wide room whose back wall stands at y = 4.2 (inside a Kinect v1's range).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from occupose.body.dims import BodyDims, DEFAULT_DIMS, dims_from_joints
from occupose.camera import Camera, camera_preset, look_at, sensor_spec
from occupose.joints import JOINT_INDEX as J
from occupose.io.mocap import canonical_from_clip, find_clip, load_clip
from occupose.synth import motion as pm
from occupose.synth.body import BodyShape, random_body_shape
from occupose.synth.retarget import facing_from_joints as facing, place, resample
from occupose.geometry.primitives import Primitives, concat
from occupose.synth.scene import chair, cabinet, couch, room, table
from occupose.synth.sequence import chain

FPS = 30.0
FACING_CAMERA = -math.pi / 2  # front-view cameras look along +y; a person facing them faces -y


@dataclass(frozen=True)
class Person:
    """One synthetic person: joints (T, 15, 3) world metres and a body shape."""

    joints: np.ndarray
    shape: BodyShape


@dataclass(frozen=True)
class Scenario:
    """A scene ready to render.

    cameras : the depth cameras; noise : camera name -> (noise model name, its options:
        the sensor's measuring range)
    static : furniture and room that never move; moving : per frame, furniture that moves
        (empty batches where nothing moves), or None
    events : named frame intervals [start, stop) worth knowing (e.g. "sitting")
    conditions : what a randomized scene drew (occupose.synth.random_scenes; JSON-ready),
        empty for the catalogue's scenes
    """

    name: str
    description: str
    fps: float
    cameras: tuple[Camera, ...]
    noise: dict[str, tuple[str, dict]]
    static: Primitives
    people: tuple[Person, ...]
    motion_source: str
    moving: tuple[Primitives, ...] | None = None
    events: dict[str, tuple[int, int]] = field(default_factory=dict)
    conditions: dict = field(default_factory=dict)

    @property
    def num_frames(self) -> int:
        return int(self.people[0].joints.shape[0])

    def moving_at(self, t: int) -> Primitives:
        """Furniture that moves, posed at frame ``t`` (an empty batch when none)."""
        return concat([]) if self.moving is None else self.moving[t]


# ------------------------------------------------------------------------------ motion


class _Motion:
    """Chains motion segments for one person, from real clips where allowed and present.

    Segments are joint trajectories (T, 15, 3); :func:`occupose.synth.sequence.chain`
    joins them. Procedural segments use body dimensions measured on the real clips when
    these are used, so a person's size does not change between segments: the first real
    clip sets them, and the procedural segments before it are built again with them (each
    is kept as its actions on a builder that starts where the segment before it ends).
    """

    def __init__(self, use_mocap: bool, start_xy, heading: float, dims: BodyDims):
        self.use_mocap = use_mocap
        self.dims = dims
        self.start = (start_xy, heading)
        self.segments: list[np.ndarray] = [pm.joints_from_procedural(pm.stance(start_xy, heading, dims)[None], dims)]
        #: per segment, the procedural actions that build it (None: a clip or given joints)
        self.actions: list[Callable[[pm.MotionBuilder], pm.MotionBuilder] | None] = [None]
        self.headings: list[float | None] = [None]
        self.sources: set[str] = set()

    def _clip(self, name: str, start_s: float, seconds: float | None) -> np.ndarray | None:
        path = find_clip(name) if self.use_mocap else None
        if path is None:
            return None
        clip = load_clip(path)
        joints = resample(canonical_from_clip(clip), clip.fps, FPS)
        first = int(round(start_s * FPS))
        last = None if seconds is None else first + int(round(seconds * FPS))
        joints = place(joints[first:last], fps=FPS)
        if not any(source.startswith("mocap:") for source in self.sources):
            self._resize(dims_from_joints(joints))  # the first real clip sets this person's body size
        self.sources.add(f"mocap:{path.stem}")
        return joints

    def _resize(self, dims: BodyDims) -> None:
        """Go on with ``dims``: the start pose and every procedural segment so far rebuilt."""
        self.dims = dims
        self.segments[0] = pm.joints_from_procedural(pm.stance(*self.start, dims)[None], dims)
        for i, actions in enumerate(self.actions):
            if actions is not None:
                self.segments[i] = actions(self._builder(self.segments[i - 1])).joints()[1:]

    def _builder(self, before: np.ndarray | None = None) -> pm.MotionBuilder:
        """A builder that starts where ``before`` (default: the last segment) ends."""
        last = (self.segments[-1] if before is None else before)[-1]
        return pm.MotionBuilder(last[J["pelvis"], :2], float(facing(last)), self.dims, FPS)

    def add(self, joints: np.ndarray, heading: float | None = None,
            actions: Callable[[pm.MotionBuilder], pm.MotionBuilder] | None = None) -> _Motion:
        self.segments.append(joints)
        self.headings.append(heading)
        self.actions.append(actions)
        return self

    def clip_or(self, name: str, procedural: Callable[[pm.MotionBuilder], pm.MotionBuilder],
                heading: float | None = None, start_s: float = 0.0, seconds: float | None = None) -> _Motion:
        """Add a slice of the real clip ``name``, or the procedural actions when absent."""
        joints = self._clip(name, start_s, seconds)
        if joints is not None:
            return self.add(joints, heading)

        def actions(builder: pm.MotionBuilder) -> pm.MotionBuilder:
            if heading is not None and abs(math.remainder(heading - builder.pose[pm.HEADING], math.tau)) > 0.05:
                builder.turn(heading)
            return procedural(builder)

        return self.procedural(actions)

    def procedural(self, actions: Callable[[pm.MotionBuilder], pm.MotionBuilder]) -> _Motion:
        """Add procedural actions that start from the current pose (exact positions)."""
        self.sources.add("procedural")
        return self.add(actions(self._builder()).joints()[1:], actions=actions)

    def joints(self, num_frames: int, skip: int = 0) -> np.ndarray:
        """The chained trajectory without its first ``skip`` frames, cut or held (last
        pose) to exactly ``num_frames`` frames."""
        joints = chain(self.segments, self.headings)[skip:]
        if len(joints) < num_frames:
            joints = np.concatenate([joints, np.repeat(joints[-1:], num_frames - len(joints), axis=0)])
        return joints[:num_frames]


def _walk(m: _Motion, heading: float, seconds: float, clip: str = "dataset-1_walk_normal_001") -> _Motion:
    """Walk straight ahead along ``heading`` for ``seconds`` (a real walk clip, or procedural)."""
    def procedural(b: pm.MotionBuilder) -> pm.MotionBuilder:
        xy = b.pose[[pm.X, pm.Y]]
        return b.walk([xy + 1.3 * seconds * np.array([math.cos(heading), math.sin(heading)])])

    return m.clip_or(clip, procedural, heading=heading, start_s=0.5, seconds=seconds)


def _source(*motions: _Motion) -> str:
    return ", ".join(sorted(set().union(*(m.sources for m in motions))))


def _dims(rng: np.random.Generator) -> BodyDims:
    return DEFAULT_DIMS.scaled(float(np.clip(rng.normal(1.74, 0.07), 1.58, 1.92)))


# ----------------------------------------------------------------------------- cameras


def _cameras(sensor: str | None, specs) -> tuple[tuple[Camera, ...], dict[str, str]]:
    """Cameras from (name, default sensor, eye, target) with an optional sensor override."""
    cams, noise = [], {}
    for name, default, eye, target in specs:
        preset = sensor or default
        spec = sensor_spec(preset)
        cams.append(camera_preset(preset, world_from_camera=look_at(eye, target), camera_name=name))
        noise[name] = (spec.noise, {"min_range": spec.near, "max_range": spec.far})
    return tuple(cams), noise


def _front(sensor: str | None):
    return _cameras(sensor, [("front", "kinect_v1", (0.0, 0.0, 1.6), (0.0, 3.0, 0.9))])


def _top(sensor: str | None):
    return _cameras(sensor, [("top", "kinect_v1", (0.0, 0.0, 2.9), (0.0, 0.0, 0.0))])


def _front_room() -> Primitives:
    return room(width=6.0, depth=4.7, height=2.8, center_xy=(0.0, 1.85), walls=("+x", "-x", "+y", "-y"),
                ceiling=True)


def _shop_room() -> Primitives:
    """Floor and two supermarket shelves at the edges of a ceiling camera's view."""
    return concat([room(width=6.0, depth=6.0, walls=()),
                   cabinet((-1.45, 0.0), width=3.0, depth=0.5, height=1.8, color=(200, 200, 205)),
                   cabinet((1.45, 0.0), width=3.0, depth=0.5, height=1.8, color=(200, 200, 205))])


# --------------------------------------------------------------------------- scenarios


def _no_occlusion(rng, use_mocap, sensor):
    # in view and already walking at frame 0 (the recording starts 1 s into the walk): the
    # grid tells a person from the background only by their motion
    m = _Motion(use_mocap, (2.1, 3.0), math.pi, _dims(rng))
    _walk(m, math.pi, 2.6)
    m.procedural(lambda b: b.turn(FACING_CAMERA))
    m.clip_or("dataset-2_wave-right-hand_active_001", lambda b: b.wave("right", 4.0, 5), seconds=4.0)
    _walk(m, 0.0, 2.2)
    m.procedural(lambda b: b.turn(FACING_CAMERA))
    m.clip_or("dataset-2_wave-both-hands_active_001", lambda b: b.wave("both", 3.0, 4), seconds=3.5)
    cams, noise = _front(sensor)
    return dict(cameras=cams, noise=noise, static=_front_room(),
                people=(Person(m.joints(390, skip=30), random_body_shape(rng)),), motion_source=_source(m))


def _sit_frames(segments, name):
    found = [s for s in segments if s.name == name]
    return found[0].start, found[-1].stop


def _sit_behind_table_parts(rng, use_mocap):
    furniture = concat([table((0.0, 2.5), heading=FACING_CAMERA, panel=True), couch((0.0, 3.6), heading=FACING_CAMERA)])
    dims = _dims(rng)
    b = pm.MotionBuilder((2.9, 3.05), math.pi, dims, FPS)
    b.walk([(0.0, 3.05)], speed=1.1).turn(FACING_CAMERA).sit_down(0.45)
    b.gesture("point", "right", 2.0).wave("both", 2.5, 3).gesture("raise", "left", 2.0).sitting(1.0)
    b.stand_up().turn(0.0).walk([(2.9, 3.05)], speed=1.1)
    segments = b.segments()
    events = {"sitting": (_sit_frames(segments, "sit_down")[0], _sit_frames(segments, "stand_up")[1])}
    m = _Motion(use_mocap, (2.9, 3.05), math.pi, dims).add(b.joints())
    return furniture, m, events


def _sit_behind_table(rng, use_mocap, sensor):
    furniture, m, events = _sit_behind_table_parts(rng, use_mocap)
    cams, noise = _front(sensor)
    return dict(cameras=cams, noise=noise, static=concat([_front_room(), furniture]),
                people=(Person(m.joints(600), random_body_shape(rng)),), motion_source="procedural",
                events=events)


def _two_cameras_occlusion(rng, use_mocap, sensor):
    furniture, m, events = _sit_behind_table_parts(rng, use_mocap)
    cams, noise = _cameras(sensor, [("front", "kinect_v1", (0.0, 0.0, 1.6), (0.0, 3.0, 0.9)),
                                    ("side", "kinect_v2", (2.8, 2.2, 2.0), (0.0, 3.2, 0.7))])
    return dict(cameras=cams, noise=noise, static=concat([_front_room(), furniture]),
                people=(Person(m.joints(600), random_body_shape(rng)),), motion_source="procedural",
                events=events)


def _walk_behind_couch(rng, use_mocap, sensor):
    # back and forth behind the couch, turning inside the view (|x| < 1.8 m at y = 3.3):
    # the same person throughout (leaving the view would end the track)
    m = _Motion(use_mocap, (-2.4, 3.3), 0.0, _dims(rng))
    _walk(m, 0.0, 2.9)
    m.procedural(lambda b: b.turn(math.pi / 2).stand(0.3))
    _walk(m, math.pi, 1.9, clip="dataset-1_walk_happy_001")
    m.procedural(lambda b: b.turn(FACING_CAMERA))
    m.clip_or("dataset-1_bye_normal_001", lambda b: b.wave("right", 2.5, 3))
    cams, noise = _front(sensor)
    static = concat([_front_room(), couch((0.0, 2.4), heading=FACING_CAMERA)])
    return dict(cameras=cams, noise=noise, static=static,
                people=(Person(m.joints(390, skip=30), random_body_shape(rng)),), motion_source=_source(m))


def _enter_exit_occlusion(rng, use_mocap, sensor):
    # walks in, behind the cabinet, turns inside the view (|x| < 1.75 m at y = 3.2), back
    # behind it, and waves: the same person throughout (leaving the view would end the track)
    m = _Motion(use_mocap, (-2.4, 3.2), 0.0, _dims(rng))
    m.procedural(lambda b: b.walk([(1.5, 3.2)], speed=1.0).turn(math.pi).stand(0.5)
                 .walk([(-1.5, 3.2)], speed=1.0).turn(FACING_CAMERA))
    m.clip_or("dataset-2_wave-left-hand_active_001", lambda b: b.wave("left", 2.0, 3))
    cams, noise = _front(sensor)
    static = concat([_front_room(), cabinet((0.0, 2.4), heading=FACING_CAMERA, width=1.1, height=1.9)])
    return dict(cameras=cams, noise=noise, static=static,
                people=(Person(m.joints(420), random_body_shape(rng)),), motion_source=_source(m))


def _gesture_behind_chair(rng, use_mocap, sensor):
    m = _Motion(use_mocap, (2.6, 3.0), math.pi, _dims(rng))
    m.procedural(lambda b: b.walk([(0.2, 3.0)], speed=1.1).turn(FACING_CAMERA))
    m.clip_or("dataset-1_byebye_normal_001", lambda b: b.wave("both", 2.5, 3))
    m.clip_or("dataset-2_raise-up-right-hand_elderly_021", lambda b: b.gesture("raise", "right", 2.5))
    m.clip_or("dataset-2_wave-left-hand_elderly_005", lambda b: b.wave("left", 3.0, 4))
    cams, noise = _front(sensor)
    static = concat([_front_room(), chair((0.2, 2.6), heading=FACING_CAMERA)])
    return dict(cameras=cams, noise=noise, static=static,
                people=(Person(m.joints(390, skip=30), random_body_shape(rng)),), motion_source=_source(m))


def _moved_chair(rng, use_mocap, sensor):
    dims = _dims(rng)
    start, pick, drop = (2.3, 3.4), (0.3, 3.4), (-1.2, 2.6)
    b = pm.MotionBuilder(start, math.pi, dims, FPS)
    b.walk([(pick[0] + 0.6, pick[1])], speed=1.2).stand(0.5)
    carry_from = b.num_frames
    b.walk([(drop[0] + 0.6, drop[1])], speed=0.8)
    carry_to = b.num_frames
    b.stand(0.5).turn(0.0).walk([(2.9, 1.9)], speed=1.2).stand(14.0)
    poses = b.poses()
    # arms forward holding the chair while carrying it, eased in and out over 0.4 s
    ramp = np.zeros(len(poses))
    ramp[carry_from:carry_to] = 1.0
    ramp = np.convolve(ramp, np.ones(12) / 12, mode="same")
    for base in (pm.LEFT, pm.RIGHT):
        for dof, angle in ((pm.SHOULDER_FLEX, 0.55), (pm.SHOULDER_ABD, 0.1), (pm.ELBOW, 0.4)):
            poses[:, base + dof] += ramp * (angle - poses[:, base + dof])
    joints = pm.joints_from_procedural(poses, dims)
    n = 600
    chair_xy = np.empty((n, 2))
    chair_heading = np.full(n, math.pi)  # its back rest towards the person coming from +x
    chair_xy[:carry_from] = pick
    for t in range(carry_from, min(carry_to, n)):
        fwd = facing(joints[t])
        # held by its back rest, which is nearest the person
        chair_xy[t] = joints[t, J["pelvis"], :2] + 0.6 * np.array([math.cos(fwd), math.sin(fwd)])
        chair_heading[t] = fwd
    chair_xy[carry_to:] = chair_xy[carry_to - 1]
    chair_heading[carry_to:] = chair_heading[carry_to - 1]
    lift = np.zeros(n)
    lift[carry_from:carry_to] = 0.08
    moving = tuple(_lifted(chair(tuple(chair_xy[t]), chair_heading[t]), lift[t]) for t in range(n))
    m = _Motion(use_mocap, start, math.pi, dims).add(joints)
    cams, noise = _front(sensor)
    return dict(cameras=cams, noise=noise, static=_front_room(),
                people=(Person(m.joints(n), random_body_shape(rng)),), motion_source="procedural",
                moving=moving, events={"carried": (carry_from, carry_to)})


def _lifted(prims: Primitives, dz: float) -> Primitives:
    center = prims.center.copy()
    center[:, 2] += dz
    return Primitives(prims.kind, center, prims.axes, prims.size, prims.end, prims.person, prims.part, prims.color)


def _two_people_crossing(rng, use_mocap, sensor):
    # both in view and walking at frame 0 (the recording starts 1 s into the walks, as in
    # no_occlusion), B passing in front of A at about frame 50; the walks end inside the
    # front camera's view (it spans |x| < 1.9 m at y = 3.5 and 1.35 m at y = 2.5), so both
    # stay in full view while they turn to the camera, wave, and then stand still. The
    # walks are procedural: they must end at exact spots.
    a = _Motion(use_mocap, (-1.75, 3.5), 0.0, _dims(rng))
    a.procedural(lambda b: b.walk([(1.15, 3.5)], speed=0.7).turn(FACING_CAMERA))
    a.clip_or("dataset-2_wave-right-hand_active_001", lambda b: b.wave("right", 3.0, 4))
    b_ = _Motion(use_mocap, (1.15, 2.5), math.pi, _dims(rng))
    b_.procedural(lambda b: b.walk([(-0.4, 2.5)], speed=0.6).turn(FACING_CAMERA))
    b_.clip_or("dataset-2_wave-both-hands_active_001", lambda b: b.wave("both", 3.0, 4))
    cams, noise = _front(sensor)
    people = (Person(a.joints(330, skip=30), random_body_shape(rng)),
              Person(b_.joints(330, skip=30), random_body_shape(rng)))
    return dict(cameras=cams, noise=noise, static=_front_room(), people=people, motion_source=_source(a, b_))


def _top_arms(rng, use_mocap, sensor, clothing: str, clips: tuple[str, ...]):
    # steps in from the edge of the view, walking at frame 0 (the grid tells a person from
    # the background by their motion: one who stands still from the first frame is floor)
    m = _Motion(use_mocap, (0.25, -0.95), math.pi / 2, _dims(rng))
    m.procedural(lambda b: b.walk([(0.25, -0.2)], speed=0.8))
    procedural = [lambda b: b.wave("right", 3.0, 4), lambda b: b.gesture("point", "left", 2.5),
                  lambda b: b.wave("both", 3.0, 4), lambda b: b.gesture("cross", "both", 2.5),
                  lambda b: b.gesture("side", "right", 2.5), lambda b: b.wave("left", 3.0, 4)]
    for clip, actions in zip(clips, procedural):
        m.clip_or(clip, actions)
    cams, noise = _top(sensor)
    return dict(cameras=cams, noise=noise, static=_shop_room(),
                people=(Person(m.joints(450, skip=15), random_body_shape(rng, clothing)),), motion_source=_source(m))


def _top_view_arms(rng, use_mocap, sensor):
    clips = ("dataset-2_wave-right-hand_active_001", "dataset-2_raise-up-left-hand_elderly_017",
             "dataset-2_wave-both-hands_active_001", "dataset-1_byebye_normal_001",
             "dataset-2_raise-up-right-hand_elderly_021", "dataset-2_wave-left-hand_active_001")
    return _top_arms(rng, use_mocap, sensor, "dark", clips)


def _top_view_arms_flashy(rng, use_mocap, sensor):
    clips = ("dataset-2_wave-left-hand_feminine_027", "dataset-2_raise-up-both-hands_elderly_019",
             "dataset-2_wave-right-hand_elderly_007", "dataset-1_bye_active_001",
             "dataset-2_wave-both-hands_feminine_026", "dataset-2_raise-up-left-hand_elderly_017")
    return _top_arms(rng, use_mocap, sensor, "flashy", clips)


def _top_view_two_people(rng, use_mocap, sensor):
    # both step in towards each other, walking at frame 0 (a person standing still from the
    # first frame is background to the grid), and stop face to face 0.84 m apart
    a = _Motion(use_mocap, (-1.1, 0.0), 0.0, _dims(rng))
    b_ = _Motion(use_mocap, (1.1, 0.05), math.pi, _dims(rng))
    # facing each other, A's right arm and B's left arm are on the same side: they overlap
    a.procedural(lambda b: b.walk([(-0.42, 0.0)], speed=0.8).gesture("reach", "right", 3.0).wave("both", 2.5, 3)
                 .gesture("reach", "both", 2.5))
    a.clip_or("dataset-2_wave-right-hand_active_001", lambda b: b.wave("right", 3.0, 4))
    b_.procedural(lambda b: b.walk([(0.42, 0.05)], speed=0.8).gesture("reach", "left", 3.0)
                  .gesture("cross", "both", 2.5).gesture("reach", "both", 2.5))
    b_.clip_or("dataset-2_wave-both-hands_active_001", lambda b: b.wave("both", 3.0, 4))
    cams, noise = _top(sensor)
    people = (Person(a.joints(300, skip=15), random_body_shape(rng)),
              Person(b_.joints(300, skip=15), random_body_shape(rng)))
    return dict(cameras=cams, noise=noise, static=_shop_room(), people=people, motion_source=_source(a, b_))


@dataclass(frozen=True)
class ScenarioEntry:
    summary: str
    build: Callable


#: Scenario builders by name, with a one-line summary each.
SCENARIOS: dict[str, ScenarioEntry] = {
    "no_occlusion": ScenarioEntry(
        "one person in the open, walking from the first frame: walks, waves, walks back, waves (Seq12)",
        _no_occlusion),
    "sit_behind_table": ScenarioEntry(
        "walks in, sits on a couch behind a table (legs hidden), gestures, stands up, leaves (Seq1/Seq10)",
        _sit_behind_table),
    "walk_behind_couch": ScenarioEntry(
        "walks behind a couch that hides the legs, back and forth, then waves", _walk_behind_couch),
    "enter_exit_occlusion": ScenarioEntry(
        "walks behind a tall cabinet and back, turning in view: most of the body hidden for 1-2 s each time", _enter_exit_occlusion),
    "gesture_behind_chair": ScenarioEntry(
        "walks in and gestures standing behind a chair whose back hides hips and thighs", _gesture_behind_chair),
    "moved_chair": ScenarioEntry(
        "carries a chair to a new place, leaves it and walks away: the background must update", _moved_chair),
    "two_people_crossing": ScenarioEntry(
        "two people cross the room in opposite directions, one passing in front of the other, then wave; "
        "both in full view throughout",
        _two_people_crossing),
    "top_view_arms": ScenarioEntry(
        "ceiling camera at 2.9 m, one person in dark clothes steps in and moves the arms (second paper's S1)",
        _top_view_arms),
    "top_view_arms_flashy": ScenarioEntry(
        "ceiling camera at 2.9 m, one person in flashy clothes steps in and moves the arms (second paper's S2)",
        _top_view_arms_flashy),
    "top_view_two_people": ScenarioEntry(
        "ceiling camera, two people step in face to face, their arms reach across and overlap (S3)",
        _top_view_two_people),
    "two_cameras_occlusion": ScenarioEntry(
        "sit_behind_table seen by a front and a side camera (the side one sees the legs)",
        _two_cameras_occlusion),
}


def build_scenario(name: str, seed: int = 0, sensor: str | None = None, use_mocap: bool = True) -> Scenario:
    """Build the scenario ``name`` of :data:`SCENARIOS`, or the random scene ``random-<N>``
    (:func:`occupose.synth.random_scenes.random_scenario` of seed N).

    seed : seeds the people's body sizes, girth and clothes (a random scene is drawn from N)
    sensor : a camera preset name used for every camera instead of the scenario's own
    use_mocap : use real mocap clips when the shared data is present (False: always procedural)
    """
    from occupose.synth import random_scenes  # it builds on this module's Scenario

    if sensor is not None:
        sensor_spec(sensor)  # raises with the valid names
    if random_scenes.is_random_name(name):
        return random_scenes.random_scenario(random_scenes.seed_of(name), use_mocap=use_mocap, sensor=sensor)
    if name not in SCENARIOS:
        raise ValueError(f"unknown scenario {name!r}; valid names: {', '.join(SCENARIOS)}, "
                         f"or {random_scenes.PREFIX}<seed>")
    entry = SCENARIOS[name]
    parts = entry.build(np.random.default_rng(seed), use_mocap, sensor)
    return Scenario(name=name, description=entry.summary, fps=FPS, **parts)
