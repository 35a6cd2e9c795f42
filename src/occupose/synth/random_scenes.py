"""Randomized scenes: a distribution of scenes rather than a catalogue.

:func:`random_scenario` draws one scene from a seed (the scenario name ``random-<seed>``;
``docs/robustness.md`` lists every drawn quantity with its range and source):

- a camera among all presets (:data:`occupose.camera.CAMERA_PRESETS`), its focal lengths
  and principal point jittered as real calibrations differ from the nominal ones; mounted
  at the room's edge (front view: :data:`FRONT_HEIGHT_RANGE`, tilted down by
  :data:`FRONT_TILT_RANGE`) or on the ceiling looking straight down (top view);
- a room of several sizes whose back wall stands inside or beyond the camera's range;
- furniture of one kind (:data:`FURNITURE_KINDS`) between the camera and the first person,
  or none;
- 1-3 people (:data:`PEOPLE_WEIGHTS`) with their own proportions
  (:mod:`occupose.synth.anthropometry`), some in clothes of low reflectivity; each walks
  in, or stands still in view from the first frame, or (the first person) stands partly
  hidden behind the furniture from the first frame, then moves: a real mocap clip of a
  family of :data:`CLIP_FAMILIES` (when the shared clips are there) or procedural motion
  (walking, gestures, sitting down on a chair or couch);
- sensor noise from the nominal model up to the sensor's specified worst case
  (:data:`WORST_CASE`), with a systematic depth bias.

Every person is placed where, after the lead-in, at least :data:`IN_VIEW_SHARE` of the
frames show all their joints in the image and in range, where no joint comes near the
furniture and where people keep apart (:mod:`occupose.synth.placement`); a draw that
cannot be placed is drawn again from the same random stream, so a seed always gives the
same scene. ``Scenario.conditions`` records what was drawn (JSON-ready).
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from occupose.camera import CAMERA_PRESETS, Camera, look_at, sensor_spec
from occupose.geometry.primitives import Primitives, concat
from occupose.io.mocap import canonical_from_clip, list_clips, load_clip
from occupose.joints import JOINT_INDEX as J
from occupose.paths import mocap_dir
from occupose.synth import motion as pm
from occupose.synth import placement
from occupose.synth.anthropometry import Anthropometry, draw_anthropometry
from occupose.synth.retarget import facing_from_joints, place, resample, retarget_lengths
from occupose.synth.scenarios import FPS, Person, Scenario
from occupose.synth.scene import cabinet, chair, couch, counter, room, shelf, table
from occupose.synth.sequence import chain

#: Scenario names of random scenes: this prefix and the seed.
PREFIX = "random-"
#: Frames of a random scene when none are asked for (7 s at 30 fps).
DEFAULT_FRAMES = 210

# ------------------------------------------------------------------ camera
#: Share of top views (ceiling camera looking down); the rest are front views.
TOP_SHARE = 0.35
#: Front-view camera height above the floor, metres (uniform).
FRONT_HEIGHT_RANGE = (0.8, 2.6)
#: Front-view downward tilt, degrees (uniform).
FRONT_TILT_RANGE = (0.0, 40.0)
#: Top-view camera height (on the ceiling), metres (uniform).
TOP_HEIGHT_RANGE = (2.5, 3.5)
#: Focal lengths fx, fy scaled by 1 + U(-j, j) each: real calibrations differ from the
#: nominal by a few percent (the Kinect v2 calibrations of the shared data: fx 366.95 vs
#: the nominal 365.5, 0.4 %).
FOCAL_JITTER = 0.03
#: Principal point moved by U(-j, j) times the image width (cx) and height (cy); the
#: shared Kinect v2 calibration's cx is 243.0 against a nominal 254.9 (2.3 % of 512 px).
PRINCIPAL_JITTER = 0.025

# ------------------------------------------------------------------ room
#: Room width across the front camera's view (top view: both sides), metres (uniform).
ROOM_WIDTH_RANGE = (3.5, 8.0)
#: Front view: distance of the back wall from the camera, metres (uniform); beyond the
#: sensor's range it returns no depth.
BACK_WALL_RANGE = (2.8, 7.0)
#: Room height of front views, metres (uniform; at least the camera height + 0.2 m).
ROOM_HEIGHT_RANGE = (2.5, 3.2)
#: Walls stay at least this far from people and furniture, metres.
WALL_MARGIN = 0.4

# ------------------------------------------------------------------ furniture
#: Furniture kinds between the camera and the first person (uniform).
FURNITURE_KINDS = ("none", "table", "counter", "couch", "chair", "cabinet", "shelf")
#: Gap between the furniture's far side and the first person's pelvis, metres (uniform);
#: a person who sits down keeps at least :data:`SITTING_GAP` (the knees come forward).
FURNITURE_GAP_RANGE = (0.2, 0.7)
SITTING_GAP = 0.55
#: Joints keep this far from any furniture box, metres (about a limb's radius).
FURNITURE_MARGIN = 0.08

# ------------------------------------------------------------------ people
#: Probability of 1, 2 and 3 people.
PEOPLE_WEIGHTS = {1: 0.5, 2: 0.3, 3: 0.2}
#: Start modes (uniform for the first person; later people walk in or stand still).
START_MODES = ("walk_in", "still", "hidden")
#: Start "hidden": the share of the first person's joints whose line of sight from the
#: camera crosses the furniture in the first frame (partly hidden: the upper body stays seen).
HIDDEN_SHARE = (0.15, 0.6)
#: Standing still before moving (starts "still" and "hidden"), seconds (uniform).
STILL_RANGE = (0.5, 1.5)
#: Walking in: speed in m/s, and the walk's length in metres (uniform).
WALK_SPEED_RANGE = (0.9, 1.3)
WALK_IN_RANGE = (1.8, 3.0)
#: Front views: people face the camera within +-this many degrees (walk clips: any heading).
FACING_SPREAD_DEG = 60.0
#: Share of people in clothes of low reflectivity, and the share of their pixels lost.
DARK_SHARE = 0.25
BODY_DROPOUT_RANGE = (0.1, 0.4)
#: After the lead-in, this share of frames must show every joint in view.
IN_VIEW_SHARE = 0.9
#: People keep their pelvises this far apart horizontally, and every joint this far, metres.
MIN_PELVIS_GAP = 0.7
MIN_JOINT_GAP = 0.25
#: Mocap clips move the pelvis at most this far from where they start, metres (longer
#: clips are cut and their last pose held).
MAX_CLIP_TRAVEL = 3.0
#: Placements tried per person before the scene's geometry is drawn again; geometry draws
#: per design (:func:`_draw_design`), and designs drawn before giving up.
PLACEMENT_TRIES = 40
SCENE_TRIES = 20
DESIGN_TRIES = 10

#: Mocap clip families (by the clip's content label) and the weight of each, with the
#: procedural sitting (always procedural: no clip sits down).
CLIP_FAMILIES = {
    "walk": ("walk", "walk-back", "walk-left", "walk-right", "walk-turn-left", "walk-turn-right"),
    "run": ("run", "dash"),
    "gesture": ("bye", "byebye", "guide", "respond", "call", "wave-left-hand", "wave-right-hand",
                "wave-both-hands", "raise-up-left-hand", "raise-up-right-hand", "raise-up-both-hands"),
    "bow": ("bow",),
    "fight": ("punch", "kick", "slash", "cmu-kick"),
    "dance": ("dance-short",),
    "jump": ("cmu-jump",),
}
FAMILY_WEIGHTS = {"walk": 0.18, "run": 0.07, "gesture": 0.25, "bow": 0.12, "fight": 0.12, "dance": 0.05,
                  "jump": 0.06, "sit": 0.15}
#: CMU takes by file stem: their content label.
CMU_CONTENT = {"01_01": "cmu-jump", "11_01": "cmu-kick"}
#: Procedural actions when there are no clips (uniform).
PROCEDURAL_ACTIONS = ("walk", "gesture", "sit")

# ------------------------------------------------------------------ noise
#: Noise levels (uniform) and the share of the worst case each draws, uniform in the range.
NOISE_LEVELS = {"nominal": (0.0, 0.0), "high": (0.3, 0.7), "worst": (0.85, 1.0)}
#: Per preset, the specified worst case beyond the nominal model: (random std metres,
#: systematic error metres, systematic error as a share of depth). Azure Kinect DK hardware
#: specification: random error std <= 17 mm, systematic < 11 mm + 0.1 % of distance.
#: Kinect v1 and v2 have no manufacturer figure: the Azure Kinect's is used. RealSense
#: D435 datasheet: absolute depth error < 2 % at 2 m (taken as the share), random as Azure.
WORST_CASE = {
    "azure_nfov": (0.017, 0.011, 0.001),
    "kinect_v2": (0.017, 0.011, 0.001),
    "kinect_v1": (0.017, 0.011, 0.001),
    "realsense_d435": (0.017, 0.0, 0.02),
}


class _Redraw(Exception):
    """This draw cannot be placed: draw the scene again."""


def is_random_name(name: str) -> bool:
    """Whether ``name`` is ``random-<seed>`` with a non-negative integer seed."""
    return name.startswith(PREFIX) and name[len(PREFIX):].isdigit()


def seed_of(name: str) -> int:
    """The seed of a ``random-<seed>`` name (ValueError otherwise)."""
    if not is_random_name(name):
        raise ValueError(f"not a random scene name: {name!r} (expected {PREFIX}<seed>, e.g. {PREFIX}0)")
    return int(name[len(PREFIX):])


def suite(count: int) -> list[str]:
    """Names of the random scenes of seeds 0..count-1."""
    if isinstance(count, bool) or not isinstance(count, (int, np.integer)) or count < 1:
        raise ValueError(f"a random suite needs a count >= 1, got {count!r}")
    return [f"{PREFIX}{seed}" for seed in range(int(count))]


# ---------------------------------------------------------------------- camera


@dataclass(frozen=True)
class _View:
    camera: Camera
    preset: str
    view: str          # "front" | "top"
    height: float      # metres
    tilt: float        # degrees below the horizon (top views: 90)
    near: float
    far: float


def _draw_view(rng: np.random.Generator, preset: str, view: str) -> _View:
    """The camera of a ``view`` ("front" | "top") scene: intrinsics of ``preset``
    jittered, height and tilt drawn."""
    spec = sensor_spec(preset)
    fx, fy = (f * (1.0 + rng.uniform(-FOCAL_JITTER, FOCAL_JITTER)) for f in (spec.fx, spec.fy))
    cx = spec.cx + rng.uniform(-PRINCIPAL_JITTER, PRINCIPAL_JITTER) * spec.width
    cy = spec.cy + rng.uniform(-PRINCIPAL_JITTER, PRINCIPAL_JITTER) * spec.height
    if view == "top":
        height, tilt = float(rng.uniform(*TOP_HEIGHT_RANGE)), 90.0
        yaw = rng.uniform(-math.pi, math.pi)
        pose = look_at((0.0, 0.0, height), (0.0, 0.0, 0.0), up=(math.cos(yaw), math.sin(yaw), 0.0))
    else:
        height, tilt = float(rng.uniform(*FRONT_HEIGHT_RANGE)), float(rng.uniform(*FRONT_TILT_RANGE))
        t = math.radians(tilt)
        pose = look_at((0.0, 0.0, height), (0.0, math.cos(t), height - math.sin(t)))
    camera = Camera(name=view, width=spec.width, height=spec.height, fx=float(fx), fy=float(fy), cx=float(cx),
                    cy=float(cy), world_from_camera=pose)
    return _View(camera, preset, view, height, tilt, spec.near, spec.far)


def _draw_noise(rng: np.random.Generator, view: _View, dark_people: tuple[int, ...]) -> tuple[str, dict, dict]:
    """The camera's noise entry: (level name, options, what to record)."""
    spec = sensor_spec(view.preset)
    levels = list(NOISE_LEVELS)
    level = levels[rng.integers(len(levels))]
    share = float(rng.uniform(*NOISE_LEVELS[level]))
    random_std, systematic, relative = WORST_CASE[view.preset]
    signs = np.where(rng.random(2) < 0.5, -1.0, 1.0)
    options = {"min_range": spec.near, "max_range": spec.far, "extra_std": share * random_std,
               "bias": float(signs[0] * share * systematic), "bias_scale": float(signs[1] * share * relative)}
    dropout = float(rng.uniform(*BODY_DROPOUT_RANGE)) if dark_people else 0.0
    if dark_people:
        options.update(body_dropout=dropout, dark_people=dark_people)
    record = {"noise_share_of_worst": share, "extra_std_m": options["extra_std"], "bias_m": options["bias"],
              "bias_scale": options["bias_scale"], "body_dropout": dropout}
    return level, options, record


# ---------------------------------------------------------------------- motion


@dataclass(frozen=True)
class _Plan:
    """What a person does after the lead-in: a clip (``clip`` set) or procedural ``action``."""

    family: str                 # a CLIP_FAMILIES key, or "procedural"
    action: str                 # the clip's stem, or "walk" | "gesture" | "sit"
    clip: Path | None = None
    start: float = 0.0          # share of the clip skipped
    params: dict = field(default_factory=dict)


def _content(path: Path) -> str:
    """A clip's content label: ``dataset-1_bow_active_001`` -> ``bow``; CMU by :data:`CMU_CONTENT`."""
    return CMU_CONTENT.get(path.stem, path.stem.split("_")[1] if path.stem.startswith("dataset-") else path.stem)


def _clips_by_family() -> dict[str, tuple[Path, ...]]:
    """The shared clips by family (each CMU take once, its BVH preferred); {} without them."""
    return _clips_under(mocap_dir())


@functools.lru_cache(maxsize=4)
def _clips_under(root: Path | None) -> dict[str, tuple[Path, ...]]:
    """:func:`_clips_by_family` for the mocap folder ``root`` (None: no clips)."""
    takes: dict[str, Path] = {}
    for path in list_clips() if root is not None else []:
        if path.stem not in takes or path.suffix == ".bvh":
            takes[path.stem] = path
    families: dict[str, list[Path]] = {}
    for path in sorted(takes.values()):
        for family, contents in CLIP_FAMILIES.items():
            if _content(path) in contents:
                families.setdefault(family, []).append(path)
    return {family: tuple(paths) for family, paths in families.items()}


@functools.lru_cache(maxsize=64)
def _clip_joints(path: Path) -> np.ndarray:
    """A clip's canonical joints at the scene's frame rate, on the floor, (T, 15, 3)."""
    clip = load_clip(path)
    joints = resample(canonical_from_clip(clip), clip.fps, FPS)
    joints.setflags(write=False)
    return joints


def _draw_gestures(rng: np.random.Generator) -> list[tuple]:
    """Two arm actions: ("wave", arm, seconds, cycles) or ("gesture", name, arm, seconds)."""
    arms = ("left", "right", "both")
    out = []
    for _ in range(2):
        if rng.random() < 0.5:
            out.append(("wave", arms[rng.integers(3)], float(rng.uniform(2.0, 3.0)), int(rng.integers(3, 5))))
        else:
            names = sorted(pm.GESTURES)
            out.append(("gesture", names[rng.integers(len(names))], arms[rng.integers(3)], float(rng.uniform(1.8, 2.5))))
    return out


def _draw_family(rng: np.random.Generator, use_mocap: bool) -> str:
    """A person's motion: a clip family or "sit" (:data:`FAMILY_WEIGHTS`) when the clips
    are there, else a procedural action (:data:`PROCEDURAL_ACTIONS`)."""
    clips = _clips_by_family() if use_mocap else {}
    if not clips:
        return PROCEDURAL_ACTIONS[rng.integers(len(PROCEDURAL_ACTIONS))]
    families = [f for f in FAMILY_WEIGHTS if f == "sit" or f in clips]
    weights = np.array([FAMILY_WEIGHTS[f] for f in families])
    return families[rng.choice(len(families), p=weights / weights.sum())]


def _draw_plan(rng: np.random.Generator, family: str, use_mocap: bool) -> _Plan:
    """A motion of ``family`` (:func:`_draw_family`): a clip of it, or (no clips, or
    ``use_mocap`` False) the procedural action of that name."""
    clips = _clips_by_family().get(family, ()) if use_mocap else ()
    if clips:
        path = clips[rng.integers(len(clips))]
        return _Plan(family, path.stem, path, float(rng.uniform(0.0, 0.5)))
    action = family
    params: dict = {"gestures": _draw_gestures(rng)}
    if action == "walk":
        params.update(distance=float(rng.uniform(1.2, 2.5)), turn=float(rng.uniform(-1.0, 1.0)),
                      speed=float(rng.uniform(*WALK_SPEED_RANGE)))
    elif action == "sit":
        seat = "chair" if rng.random() < 0.5 else "couch"
        params.update(seat=seat, seat_height=float(rng.uniform(0.42, 0.48)), stand_up=bool(rng.random() < 0.5))
    return _Plan("procedural", action, params=params)


def _arm_actions(b: pm.MotionBuilder, gestures: list[tuple]) -> pm.MotionBuilder:
    for kind, *args in gestures:
        if kind == "wave":
            arm, seconds, cycles = args
            b.wave(arm, seconds, cycles)
        else:
            name, arm, seconds = args
            b.gesture(name, arm, seconds)
    return b


def _procedural(b: pm.MotionBuilder, plan: _Plan, heading: float) -> pm.MotionBuilder:
    """Continue ``b`` with the plan's procedural action; ``heading``: where to face."""
    p = plan.params
    if plan.action == "walk":
        way = heading + p["turn"]
        xy = b.pose[[pm.X, pm.Y]] + p["distance"] * np.array([math.cos(way), math.sin(way)])
        b.walk([xy], speed=p["speed"]).turn(heading)
        return _arm_actions(b, p["gestures"][:1])
    if plan.action == "sit":
        b.sit_down(p["seat_height"]).sitting(0.4)
        _arm_actions(b, p["gestures"]).sitting(0.5)
        return b.stand_up() if p["stand_up"] else b
    return _arm_actions(b, p["gestures"])


def _turn_if_needed(b: pm.MotionBuilder, heading: float) -> pm.MotionBuilder:
    if abs(math.remainder(heading - b.pose[pm.HEADING], math.tau)) > 0.05:
        b.turn(heading)
    return b


def _trajectory(plan: _Plan, body: Anthropometry, spot, heading: float, start: str, lead: dict,
                frames: int) -> tuple[np.ndarray, int]:
    """The person's joints (frames, 15, 3) and the lead-in's length in frames.

    The lead-in walks from ``lead["entry"]`` to ``spot`` (start "walk_in") or stands at
    ``spot`` for ``lead["still"]`` seconds; then the plan runs, facing ``heading``."""
    dims = body.motion_dims()
    spot = np.asarray(spot, np.float64)
    if start == "walk_in":
        entry = np.asarray(lead["entry"], np.float64)
        d = spot - entry
        b = pm.MotionBuilder(entry, math.atan2(d[1], d[0]), dims, FPS).walk([spot], speed=lead["speed"])
    else:
        b = pm.MotionBuilder(spot, heading, dims, FPS).stand(lead["still"])
    _turn_if_needed(b, heading)
    lead_frames = b.num_frames
    if plan.clip is None:
        joints = _procedural(b, plan, heading).joints()
    else:
        clip = _clip_joints(plan.clip)
        first = int(plan.start * max(len(clip) - 30, 0))
        piece = place(clip[first:first + max(frames - lead_frames, 2)], fps=FPS)
        travel = np.linalg.norm(piece[:, J["pelvis"], :2] - piece[:1, J["pelvis"], :2], axis=-1)
        piece = piece[: max(2, int(np.argmax(travel > MAX_CLIP_TRAVEL)) or len(piece))]
        piece = retarget_lengths(piece, body.bone_lengths(), body.ankle_height, fps=FPS)
        joints = chain([b.joints(), piece], [None, heading])
        # a clip that travels is moved back by half its way, so that it centres on the spot
        joints[..., :2] -= 0.5 * (joints[-1, J["pelvis"], :2] - joints[lead_frames, J["pelvis"], :2])
    if len(joints) < frames:
        joints = np.concatenate([joints, np.repeat(joints[-1:], frames - len(joints), axis=0)])
    return joints[:frames], lead_frames


# ---------------------------------------------------------------------- furniture


def _draw_furniture(rng: np.random.Generator, kind: str, xy, heading: float) -> Primitives:
    """Furniture of ``kind`` centred at ``xy`` with its front (local +x) along ``heading``."""
    if kind == "table":
        return table(xy, heading, size=(float(rng.uniform(0.9, 1.6)), float(rng.uniform(0.6, 0.9))),
                     height=float(rng.uniform(0.70, 0.78)), panel=bool(rng.random() < 0.5))
    if kind == "counter":
        return counter(xy, heading, width=float(rng.uniform(1.2, 2.4)), depth=float(rng.uniform(0.55, 0.65)),
                       height=float(rng.uniform(0.86, 0.95)))
    if kind == "couch":
        return couch(xy, heading, width=float(rng.uniform(1.6, 2.2)), back_height=float(rng.uniform(0.75, 0.95)))
    if kind == "chair":
        return chair(xy, heading, back_height=float(rng.uniform(0.85, 1.0)))
    if kind == "cabinet":
        return cabinet(xy, heading, width=float(rng.uniform(0.6, 1.2)), depth=float(rng.uniform(0.4, 0.6)),
                       height=float(rng.uniform(1.6, 2.1)))
    if kind == "shelf":
        return shelf(xy, heading, width=float(rng.uniform(0.8, 1.6)), depth=float(rng.uniform(0.3, 0.4)),
                     height=float(rng.uniform(1.2, 2.0)), boards=int(rng.integers(2, 5)), back=bool(rng.random() < 0.5))
    raise ValueError(f"unknown furniture kind {kind!r}; valid: {', '.join(FURNITURE_KINDS[1:])}")


#: Depth of each furniture kind's footprint along its front, metres (for placing it).
_DEPTH = {"table": 0.9, "counter": 0.7, "couch": 0.85, "chair": 0.46, "cabinet": 0.6, "shelf": 0.4}


def _toward_camera(view: _View, xy: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """Unit floor direction from ``xy`` towards the camera's foot (random under a top camera)."""
    d = view.camera.world_from_camera[:2, 3] - xy
    n = np.linalg.norm(d)
    if n < 0.2:
        a = rng.uniform(-math.pi, math.pi)
        return np.array([math.cos(a), math.sin(a)])
    return d / n


# ---------------------------------------------------------------------- people


def _draw_spot(rng: np.random.Generator, view: _View) -> np.ndarray:
    cam = view.camera
    half = math.atan(min(cam.cx, cam.width - cam.cx) / cam.fx)
    if view.view == "top":
        r = max(view.height - 1.2, 0.3) * math.tan(half)
        return rng.uniform(-r, r, size=2)
    depth = rng.uniform(view.near + 0.8, max(view.far - 0.3, view.near + 1.0))
    return np.array([rng.uniform(-1.0, 1.0) * 0.75 * math.tan(half) * depth, depth])


def _travel_angle(plan: _Plan) -> float:
    """Direction a clip travels in relative to the way it faces at its start, radians
    (its first 3 s from where the plan starts it)."""
    clip = _clip_joints(plan.clip)
    first = int(plan.start * max(len(clip) - 30, 0))
    pelvis = clip[first:first + 90, J["pelvis"], :2]
    way = pelvis[-1] - pelvis[0]
    return math.atan2(way[1], way[0]) - float(facing_from_joints(clip[first]))


def _draw_heading(rng: np.random.Generator, view: _View, spot: np.ndarray, plan: _Plan) -> float:
    """Where the person faces when the plan starts: towards a front camera within
    +-:data:`FACING_SPREAD_DEG`, any way under a top camera; a walk or run clip in a front
    view travels across the image (within 30 degrees of its horizontal)."""
    if view.view == "top":
        return float(rng.uniform(-math.pi, math.pi))
    if plan.family in ("walk", "run"):
        across = (0.0 if rng.random() < 0.5 else math.pi) + math.radians(rng.uniform(-30.0, 30.0))
        return across - _travel_angle(plan)
    d = view.camera.world_from_camera[:2, 3] - spot
    return math.atan2(d[1], d[0]) + math.radians(rng.uniform(-FACING_SPREAD_DEG, FACING_SPREAD_DEG))


def _draw_lead(rng: np.random.Generator, view: _View, start: str, spot: np.ndarray) -> dict:
    """How the person gets to ``spot``: walking in (front views: from either side, within
    45 degrees of the image's horizontal) or standing still there."""
    if start == "walk_in":
        a = rng.uniform(-math.pi, math.pi)
        if view.view == "front":
            a = rng.uniform(-math.pi / 4, math.pi / 4) + (math.pi if rng.random() < 0.5 else 0.0)
        entry = spot + rng.uniform(*WALK_IN_RANGE) * np.array([math.cos(a), math.sin(a)])
        return {"entry": entry, "speed": float(rng.uniform(*WALK_SPEED_RANGE))}
    return {"still": float(rng.uniform(*STILL_RANGE))}


@dataclass
class _Placed:
    joints: np.ndarray
    lead_frames: int
    plan: _Plan
    start: str
    body: Anthropometry
    spot: np.ndarray
    seat: Primitives | None


def _seat(rng: np.random.Generator, plan: _Plan, spot: np.ndarray, heading: float, body: Anthropometry) -> Primitives | None:
    """The chair or couch a sitting person sits on, behind ``spot``."""
    if plan.action != "sit":
        return None
    kind = plan.params["seat"]
    back, _ = pm.pelvis_offset_from_seat(plan.params["seat_height"], body.motion_dims())
    depth = 0.46 if kind == "chair" else 0.85
    fwd = np.array([math.cos(heading), math.sin(heading)])
    xy = spot - fwd * (back - 0.12 + depth / 2)
    if kind == "chair":
        return chair(tuple(xy), heading, seat_height=plan.params["seat_height"], size=depth)
    return couch(tuple(xy), heading, width=float(rng.uniform(1.6, 2.0)), seat_height=plan.params["seat_height"])


def _place_person(rng: np.random.Generator, view: _View, start: str, body: Anthropometry, family: str,
                  use_mocap: bool, frames: int, furniture: dict, others: list[_Placed]) -> _Placed:
    """Draw a motion of ``family`` and a spot until the person fits (module docstring);
    ``furniture`` holds ``kind`` and, once placed (by the first person), ``prims``."""
    for attempt in range(PLACEMENT_TRIES):
        if attempt % 10 == 0:
            plan = _draw_plan(rng, family, use_mocap)
        spot = _draw_spot(rng, view)
        heading = _draw_heading(rng, view, spot, plan)
        if plan.action == "sit" and view.view == "front":  # sitting faces the camera within 25 degrees
            d = view.camera.world_from_camera[:2, 3] - spot
            heading = math.atan2(d[1], d[0]) + math.radians(rng.uniform(-25.0, 25.0))
        lead = _draw_lead(rng, view, start, spot)
        dims = body.motion_dims()
        standing = pm.joints_from_procedural(pm.stance(spot, heading, dims)[None], dims)
        if not placement.in_view(standing, view.camera, view.near, view.far)[0]:
            continue  # a quick test first: someone standing at the spot must be in view
        try:
            joints, lead_frames = _trajectory(plan, body, spot, heading, start, lead, frames)
        except ValueError:  # e.g. a seat too high or low for this body
            continue
        seat = _seat(rng, plan, spot, heading, body)
        new_furniture = None
        if "prims" not in furniture and furniture["kind"] != "none":
            toward = _toward_camera(view, spot, rng)
            kind = furniture["kind"]
            gap = max(float(rng.uniform(*FURNITURE_GAP_RANGE)), SITTING_GAP if plan.action == "sit" else 0.0)
            xy = spot + toward * (gap + _DEPTH[kind] / 2)
            new_furniture = _draw_furniture(rng, kind, tuple(xy), math.atan2(toward[1], toward[0]))
        occluder = furniture.get("prims", new_furniture)
        checked = min(lead_frames, frames - 1) if start == "walk_in" else 0  # a short scene: its last frame
        seen = placement.in_view(joints[checked:], view.camera, view.near, view.far)
        if seen.mean() < IN_VIEW_SHARE:
            continue
        obstacles = [p for p in [occluder] + [o.seat for o in others] if p is not None]
        if obstacles and np.any(placement.inside_boxes(joints.reshape(-1, 3), concat(obstacles), FURNITURE_MARGIN)):
            continue
        if seat is not None and (
                np.any(placement.inside_boxes(joints.reshape(-1, 3), seat))  # walking through one's own seat
                or any(np.any(placement.inside_boxes(o.joints.reshape(-1, 3), seat, FURNITURE_MARGIN)) for o in others)
                or (obstacles and np.any(placement.inside_boxes(placement.box_corners(seat), concat(obstacles))))):
            continue
        if not placement.clear_of_people(joints, [o.joints for o in others], MIN_PELVIS_GAP, MIN_JOINT_GAP):
            continue
        if start == "hidden":
            hidden = placement.hidden_from(view.camera, joints[0], occluder).mean()
            if not HIDDEN_SHARE[0] <= hidden <= HIDDEN_SHARE[1]:
                continue
        if new_furniture is not None:
            furniture["prims"] = new_furniture
        return _Placed(joints, lead_frames, plan, start, body, spot, seat)
    raise _Redraw


# ---------------------------------------------------------------------- the scene


def _room(rng: np.random.Generator, view: _View, occupied: np.ndarray) -> tuple[Primitives, dict]:
    """Walls around the camera and everything placed (``occupied``: (N, 2) floor points)."""
    width = float(rng.uniform(*ROOM_WIDTH_RANGE))
    lo, hi = occupied.min(axis=0) - WALL_MARGIN, occupied.max(axis=0) + WALL_MARGIN
    if view.view == "front":
        back = float(rng.uniform(*BACK_WALL_RANGE))
        x0, x1 = min(-width / 2, lo[0]), max(width / 2, hi[0])
        y0, y1 = min(-0.3, lo[1]), max(back, hi[1])
        height = max(float(rng.uniform(*ROOM_HEIGHT_RANGE)), view.height + 0.2)
        ceiling = True
    else:
        depth = float(rng.uniform(*ROOM_WIDTH_RANGE))
        x0, x1 = min(-width / 2, lo[0]), max(width / 2, hi[0])
        y0, y1 = min(-depth / 2, lo[1]), max(depth / 2, hi[1])
        back, height, ceiling = y1, view.height + 0.02, False
    prims = room(width=x1 - x0, depth=y1 - y0, height=height, center_xy=((x0 + x1) / 2, (y0 + y1) / 2),
                 ceiling=ceiling)
    record = {"room_m": [round(x1 - x0, 3), round(y1 - y0, 3), round(height, 3)],
              "back_wall_m": round(y1, 3),
              "back_wall": "in_range" if view.view == "front" and y1 < view.far else "beyond_range"}
    if view.view == "top":
        record["back_wall"] = "top_view"
    return prims, record


def _draw_design(rng: np.random.Generator, use_mocap: bool, sensor: str | None) -> dict:
    """The scene's categorical draws: camera preset and view, people, their start modes and
    motion families, the furniture kind. They are kept while the geometry is drawn again,
    so that placing a person does not favour the motions and views that are easy to place."""
    presets = sorted(CAMERA_PRESETS)
    preset = presets[rng.integers(len(presets))]
    view = "top" if rng.random() < TOP_SHARE else "front"
    counts = list(PEOPLE_WEIGHTS)
    count = counts[rng.choice(len(counts), p=np.array(list(PEOPLE_WEIGHTS.values())))]
    start = START_MODES[rng.integers(len(START_MODES))]
    starts = [start] + [("walk_in", "still")[rng.integers(2)] for _ in range(count - 1)]
    kinds = FURNITURE_KINDS[1:] if start == "hidden" else FURNITURE_KINDS
    return {"preset": sensor or preset, "view": view, "count": count, "starts": starts, "use_mocap": use_mocap,
            "families": [_draw_family(rng, use_mocap) for _ in range(count)],
            "furniture": kinds[rng.integers(len(kinds))]}


def _draw_scene(rng: np.random.Generator, seed: int, design: dict, view: _View, frames: int) -> Scenario:
    """The scene of ``design`` seen by ``view``: people, furniture, room and noise drawn
    (:class:`_Redraw` when a person cannot be placed)."""
    count, start = design["count"], design["starts"][0]
    furniture = {"kind": design["furniture"]}
    placed: list[_Placed] = []
    for i in range(count):
        body = draw_anthropometry(rng)
        placed.append(_place_person(rng, view, design["starts"][i], body, design["families"][i],
                                    design["use_mocap"], frames, furniture, placed))
    dark = tuple(i + 1 for i in range(count) if rng.random() < DARK_SHARE)
    people = tuple(Person(p.joints, p.body.body_shape(rng, "dark" if i + 1 in dark else "normal"))
                   for i, p in enumerate(placed))
    pieces = [furniture["prims"]] if "prims" in furniture else []
    pieces += [p.seat for p in placed if p.seat is not None]
    occupied = np.concatenate([view.camera.world_from_camera[None, :2, 3]]
                              + [p.joints[..., :2].reshape(-1, 2) for p in placed]
                              + [placement.box_corners(piece)[:, :2] for piece in pieces])
    walls, room_record = _room(rng, view, occupied)
    level, options, noise_record = _draw_noise(rng, view, dark)
    first = placed[0]
    conditions = {
        "view": view.view, "people": count, "furniture": furniture["kind"], "start": start,
        "camera": view.preset, "noise": level,
        "motion": first.plan.family,
        "camera_height_m": round(view.height, 4), "tilt_deg": round(view.tilt, 3),
        "focal_scale": [round(view.camera.fx / sensor_spec(view.preset).fx, 5),
                        round(view.camera.fy / sensor_spec(view.preset).fy, 5)],
        "principal_shift_px": [round(view.camera.cx - sensor_spec(view.preset).cx, 3),
                               round(view.camera.cy - sensor_spec(view.preset).cy, 3)],
        **room_record,
        **{k: round(v, 5) for k, v in noise_record.items()},
        "dark_clothes": len(dark),
        "persons": [{"stature_m": round(p.body.stature, 4), "motion": p.plan.family, "action": p.plan.action,
                     "start": p.start, "clothes": "dark" if i + 1 in dark else "normal",
                     "seat": p.plan.params.get("seat", "none"), "lead_in_frames": p.lead_frames}
                    for i, p in enumerate(placed)],
    }
    sources = sorted({f"mocap:{p.plan.action}" if p.plan.clip is not None else "procedural" for p in placed}
                     | {"procedural"})
    events = {"lead_in": (0, first.lead_frames)}
    description = (f"random scene {seed}: {view.view} view, {view.preset}, {count} person(s), "
                   f"furniture {furniture['kind']}, start {start}, motion {first.plan.family} "
                   f"({first.plan.action}), noise {level}")
    return Scenario(name=f"{PREFIX}{seed}", description=description, fps=FPS, cameras=(view.camera,),
                    noise={view.camera.name: (sensor_spec(view.preset).noise, options)},
                    static=concat([walls] + pieces), people=people, motion_source=", ".join(sources),
                    events=events, conditions=conditions)


@dataclass(frozen=True)
class RandomDraw:
    """A random scene and the draws given up on before it (:func:`draw_random_scenario`).

    scenario : the scene
    rejected : one record per geometry draw that could not be placed, in order: ``design``
        (how many designs were given up on before its own; 0: the first design), its
        design's ``view``, ``camera``, ``people``, ``start`` (the first person's),
        ``furniture`` and ``motion`` (the first person's motion family, "sit" for the
        procedural sitting), and its camera's ``camera_height_m`` and ``tilt_deg``
    designs : designs drawn, the kept one included (1: the first design was placed)
    """

    scenario: Scenario
    rejected: tuple[dict, ...]
    designs: int


def _rejected_record(design_index: int, design: dict, view: _View) -> dict:
    """What :attr:`RandomDraw.rejected` keeps of a geometry draw that could not be placed."""
    return {"design": design_index, "view": design["view"], "camera": design["preset"], "people": design["count"],
            "start": design["starts"][0], "furniture": design["furniture"], "motion": design["families"][0],
            "camera_height_m": round(view.height, 4), "tilt_deg": round(view.tilt, 3)}


def draw_random_scenario(seed: int, use_mocap: bool = True, frames: int | None = None,
                         sensor: str | None = None) -> RandomDraw:
    """Draw the random scene of ``seed`` (:func:`random_scenario`, same arguments) and keep
    a record of the draws that could not be placed on the way (:class:`RandomDraw`)."""
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise ValueError(f"seed must be an integer >= 0, got {seed!r}")
    frames = DEFAULT_FRAMES if frames is None else frames
    if isinstance(frames, bool) or not isinstance(frames, (int, np.integer)) or frames < 2:
        raise ValueError(f"frames must be an integer >= 2, got {frames!r}")
    if sensor is not None:
        sensor_spec(sensor)
    rng = np.random.default_rng(np.random.SeedSequence(int(seed)))
    rejected: list[dict] = []
    for design_index in range(DESIGN_TRIES):
        design = _draw_design(rng, use_mocap, sensor)
        for _ in range(SCENE_TRIES):
            view = _draw_view(rng, design["preset"], design["view"])
            try:
                scenario = _draw_scene(rng, int(seed), design, view, int(frames))
            except _Redraw:
                rejected.append(_rejected_record(design_index, design, view))
                continue
            return RandomDraw(scenario, tuple(rejected), design_index + 1)
    raise RuntimeError(f"random scene {seed}: no placement found in {DESIGN_TRIES} x {SCENE_TRIES} draws")


def random_scenario(seed: int, use_mocap: bool = True, frames: int | None = None,
                    sensor: str | None = None) -> Scenario:
    """Draw the random scene of ``seed`` (module docstring).

    use_mocap : use the shared mocap clips when present (False: procedural motion only)
    frames : the scene's length (None: :data:`DEFAULT_FRAMES`)
    sensor : a camera preset instead of the drawn one (the design's other choices stay;
        the geometry, placed for this camera, and the noise come out differently)

    The draws come from ``np.random.SeedSequence(seed)``: the same arguments give the same
    scene, array for array. A design (the categorical draws) is kept for up to
    :data:`SCENE_TRIES` geometry draws, then drawn again, up to :data:`DESIGN_TRIES` times
    (:func:`draw_random_scenario` records the draws given up on).
    """
    return draw_random_scenario(seed, use_mocap, frames, sensor).scenario


__all__ = ["DEFAULT_FRAMES", "PREFIX", "RandomDraw", "draw_random_scenario", "is_random_name", "random_scenario",
           "seed_of", "suite"]
