"""The body fitted to one depth frame: no background model, no motion, maybe no floor.

:func:`fit_frame` finds the people of one frame and fits a body model to each from that
frame alone (``occupose fit``; the settings are the fields of
:class:`occupose.config.FitConfig`, ``fit``):

1. **Foreground.** Every measured pixel, less those of a ``background`` image of the empty
   scene where one is given (a pixel not ``background_m`` nearer than it, or not in a 3 x 3
   block of nearer pixels: noise), less the floor's (points within ``floor_m`` of it) where
   the floor is known.
2. **World.** The camera's world pose when it is given (z up, the floor at 0); else the
   floor fitted to the background image, or without one to the frame
   (:func:`occupose.geometry.floor.fit_floor`; its points must span ``floor_span`` across it
   in both directions: a chest seen from the front is a plane too), else none: the camera
   is taken as level (image up is up), and each person is placed so that their top is
   their stature above a floor of their own (a ceiling camera needs its pose or a floor).
3. **People.** The foreground's points that touch in a 3D grid of ``join_m`` cells (26
   neighbours) are one group; groups of at least ``min_points`` points and ``min_height``
   high are people (a hand is not; without a background image, the frame is taken to hold
   nothing but people, and the floor where it shows); the smaller groups of at least
   ``min_part`` points within ``reach_m`` of a person are theirs (a hand held out hides its
   forearm). Two people who touch are one.
4. **Size.** A person whose lowest point is below ``feet_height`` above a known floor
   has their legs in view and is measured as the tracker measures a new person
   (:func:`occupose.body.size.dims_from_observation`); otherwise the stature is not in the
   data, and ``stature`` (an average adult's) is taken; the neck and shoulders are measured
   from the points where they show (:func:`occupose.body.size.dims_with_shoulders`).
5. **Fit.** The body model (``full`` with legs in view, else ``upper``, unless one is
   asked for) starts as the tracker starts a person
   (:func:`occupose.pose.start.search_start`: standing and seated candidates facing the
   camera, perturbed and scored, then filter steps), and takes ``steps`` more steps of its
   filter on the same frame, whose limb proposals put the arms and legs where the points
   unexplained by the current estimate are.
6. **Visibility.** A fitted joint is visible when it projects inside the image and a point
   of its person lies within ``visible_m`` of it; the joints the model lacks (the upper
   model's hips, knees, ankles) are NaN and not visible.

Coordinates are the world's when the camera's pose was given, else the camera's (OpenCV
axes: x right, y down, z forward, metres).
"""

from __future__ import annotations

import dataclasses
from typing import NamedTuple

import numpy as np
from scipy import ndimage
from scipy.spatial import cKDTree

from occupose.body import body_model, dims_from_observation
from occupose.body.dims import DEFAULT_DIMS
from occupose.body.kinematics import joints_from_pose
from occupose.body.size import breadth_profile, dims_with_shoulders, neck_and_shoulders, top_height
from occupose.camera import Camera, pixels_from_points, points_from_depth
from occupose.config import TrackerConfig, as_config
from occupose.geometry.floor import Floor, fit_floor
from occupose.grid.pixels import PersonPixels
from occupose.joints import NUM_JOINTS
from occupose.pose.person import Person
from occupose.pose.start import search_start

#: The body models ``model`` may name; "auto" chooses per person (module docstring).
MODELS = ("auto", "full", "upper")
#: Frames per second the filter's motion model assumes between its steps on the frame.
_FPS = 30.0


class FittedPerson(NamedTuple):
    """One person of a frame, fitted.

    joints : (15, 3) float64 metres in :attr:`FrameFit.frame`, NaN where the model has no joint
    visible : (15,) bool; model : "full" or "upper"; pixels : (N,) int64 flat pixel indices
    ``v * W + u`` of the person's points; stature : metres, measured (legs in view) or taken
    """

    joints: np.ndarray
    visible: np.ndarray
    model: str
    pixels: np.ndarray
    stature: float


class FrameFit(NamedTuple):
    """The people of one frame: ``people`` (left to right in the image), ``frame`` ("world"
    or "camera", the frame of their joints) and ``floor``: (camera height m, tilt deg) of
    the floor fitted to the frame, or None (given with the pose, or not seen)."""

    people: list[FittedPerson]
    frame: str
    floor: tuple[float, float] | None


def _level_world() -> np.ndarray:
    """(4, 4) world_from_camera of a level camera at the origin: world x forward, y left, z up."""
    pose = np.eye(4)
    pose[:3, :3] = np.array([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]])
    return pose


def foreground(depth: np.ndarray, background: np.ndarray | None, margin: float) -> np.ndarray:
    """(H, W) bool: the measured pixels of ``depth`` (metres, 0 = none) not of the ``background``
    (H, W) metres image, if any: those at least ``margin`` metres nearer than it, or where it
    has no measurement, in 3 x 3 blocks of such pixels (a morphological opening: the sensor's
    noise makes scattered pixels of a far wall nearer than its background, not blocks)."""
    mask = np.isfinite(depth) & (depth > 0)
    if background is None:
        return mask
    ahead = mask & ~((background > 0) & (depth > background - margin))
    return ndimage.binary_opening(ahead, structure=np.ones((3, 3), bool))


def groups_of_points(points: np.ndarray, cell: float) -> np.ndarray:
    """(N,) int64 group of each point (N, 3) metres, from 0: the points whose cells of ``cell``
    metres touch (26 neighbours) are one group."""
    if len(points) == 0:
        return np.zeros(0, np.int64)
    index = np.floor((points - points.min(axis=0)) / cell).astype(np.int64)
    occupied = np.zeros(index.max(axis=0) + 1, bool)
    occupied[tuple(index.T)] = True
    labels, _ = ndimage.label(occupied, structure=np.ones((3, 3, 3), bool))
    return labels[tuple(index.T)].astype(np.int64) - 1


def _check_depth(depth, camera: Camera, what: str) -> np.ndarray:
    depth = np.asarray(depth)
    if depth.shape != (camera.height, camera.width) or not np.issubdtype(depth.dtype, np.floating):
        raise ValueError(f"{what} must be a ({camera.height}, {camera.width}) float array of metres for camera "
                         f"{camera.name!r}, got {depth.dtype} {depth.shape}")
    return depth.astype(np.float32, copy=False)


def fit_frame(depth, camera: Camera, *, model: str = "auto", world: bool = False, background=None,
              config: TrackerConfig | str = "ours", seed: int = 0) -> FrameFit:
    """Find and fit every person of one depth frame (module docstring).

    depth : (H, W) float metres of ``camera`` (0 = no measurement)
    model : "auto", "full" or "upper" (:data:`MODELS`)
    world : whether ``camera.world_from_camera`` is its pose in a world with z up and the
        floor at 0 (else it is ignored, the floor is looked for in the background image or
        the frame, and the joints come in the camera's frame)
    background : None or (H, W) float metres, the same camera's view of the empty scene
    config : a TrackerConfig or method name (``fit``, ``start``, ``pose``, ``size`` ... sections)
    seed : seeds the fit (the same seed, the same fit)
    """
    if model not in MODELS:
        raise ValueError(f"unknown model {model!r}; valid: {', '.join(MODELS)}")
    config = as_config(config)
    fit = config.fit
    depth = _check_depth(depth, camera, "depth")
    background = None if background is None else _check_depth(background, camera, "background")
    mask = foreground(depth, background, fit.background_m)
    floor = None
    if world:
        pose = camera.world_from_camera
    else:
        scene = np.where(mask, depth, 0) if background is None else background  # the empty scene shows it best
        seen = points_from_depth(scene, camera, frame="camera")[0]
        found = fit_floor(seen, config.floor)
        if found is not None and _span(seen, found, config) < fit.floor_span:
            found = None  # a person's chest or back, seen from the front
        pose = _level_world() if found is None else found.world_from_camera()
        floor = None if found is None else (found.height, found.tilt)
    floor_known = world or floor is not None
    placed = dataclasses.replace(camera, world_from_camera=pose)
    points, pixels = points_from_depth(np.where(mask, depth, 0), placed)
    if floor_known:
        keep = points[:, 2] >= fit.floor_m
        points, pixels = points[keep], pixels[keep]
    groups = people_of_points(points, groups_of_points(points, fit.join_m), config)
    rng = np.random.default_rng(seed)
    camera_from_world = placed.camera_from_world
    people = []
    for group in range(int(groups.max(initial=-1)) + 1):
        own = groups == group
        person = _fit_person(points[own], pixels[own], depth, placed, floor_known, model, config,
                             np.random.default_rng(rng.integers(2**63)))
        if not world:
            joints = person.joints @ camera_from_world[:3, :3].T + camera_from_world[:3, 3]
            person = person._replace(joints=joints)
        people.append(person)
    people.sort(key=lambda p: float(np.mean(p.pixels % camera.width)))
    return FrameFit(people, "world" if world else "camera", floor)


def _span(points: np.ndarray, floor: Floor, config: TrackerConfig) -> float:
    """Metres the ``points`` (N, 3) camera frame on the ``floor`` plane (within the floor
    fit's tolerance) span across it, the lesser of its two directions (5th to 95th percentile)."""
    tolerance = config.floor.tolerance_m + config.floor.tolerance_rel * points[:, 2]
    on = points[np.abs(points @ floor.normal + floor.height) <= tolerance]
    if len(on) < 2:
        return 0.0
    across = floor.world_from_camera()[:2, :3]  # the world's x and y axes in the camera frame
    lo, hi = np.percentile(on @ across.T, (5.0, 95.0), axis=0)
    return float(np.min(hi - lo))


def people_of_points(points: np.ndarray, groups: np.ndarray, config: TrackerConfig) -> np.ndarray:
    """(N,) int64 person of each point (N, 3) world metres, from 0, or -1, from their
    :func:`groups_of_points` ``groups`` (N,): a group of at least ``fit.min_points`` points
    ``fit.min_height`` high or more (1st to 99th percentile) is a person; a smaller group of
    at least ``fit.min_part`` points joins the person whose points come nearest it, when
    within ``fit.reach_m`` (a hand held out towards the camera hides its forearm, and is
    apart); the others are -1."""
    fit = config.fit
    counts = np.bincount(groups, minlength=1) if len(groups) else np.zeros(0, np.int64)
    people = [g for g in np.flatnonzero(counts >= fit.min_points)
              if np.ptp(np.percentile(points[groups == g, 2], (1.0, 99.0))) >= fit.min_height]
    out = np.full(len(points), -1, np.int64)
    for k, g in enumerate(people):
        out[groups == g] = k
    parts = [g for g in np.flatnonzero(counts >= fit.min_part) if g not in people]
    if not people or not parts:
        return out
    trees = [cKDTree(points[out == k]) for k in range(len(people))]  # 10-20 ms each for a close person
    for g in parts:
        own = groups == g
        gaps = [float(tree.query(points[own], distance_upper_bound=fit.reach_m)[0].min()) for tree in trees]
        if min(gaps) <= fit.reach_m:
            out[own] = int(np.argmin(gaps))
    return out


def _fit_person(points: np.ndarray, pixels: np.ndarray, depth: np.ndarray, camera: Camera, floor_known: bool,
                model: str, config: TrackerConfig, rng: np.random.Generator) -> FittedPerson:
    """One person's fit (module docstring, steps 4-6) from its points (N, 3) world metres
    and their flat ``pixels`` (N,) in ``camera`` (placed in the world); the joints come in
    that world, or, without a known floor, in ``camera``'s world frame."""
    fit = config.fit
    legs = floor_known and float(points[:, 2].min()) < fit.feet_height
    name = ("full" if legs else "upper") if model == "auto" else model
    offset = np.zeros(3)
    if legs:
        size = dims_from_observation(points, size=config.size)
        dims, girth = size.dims, size.girth
    else:
        dims, girth = DEFAULT_DIMS.scaled(fit.stature), 1.0
        if not floor_known:  # the person stands on a floor of their own, their top at the stature
            offset[2] = dims.height - config.size.top_bias - top_height(points[:, 2], config.size.top_rank)
    points = points + offset
    shape = neck_and_shoulders(breadth_profile(points, config.size), config.size)
    if shape is not None:
        dims = dims_with_shoulders(dims, girth, *shape, config.size)
    placed = dataclasses.replace(camera, world_from_camera=_shifted(camera.world_from_camera, offset))
    if not floor_known:
        config = config.with_values({"priors.floor": None})
    person = Person(body_model(name, dims, girth), config, _FPS, rng, [placed])
    person.problem.standing = legs
    seen_pixels = PersonPixels(0, {placed.name: pixels}, {placed.name: points})
    best, seen = search_start(person, seen_pixels, {placed.name: depth}, np.zeros(2), [placed], config.start.steps)
    for _ in range(fit.steps):
        best = person.estimator.step(seen)
    joints = joints_from_pose(person.model, best)
    return FittedPerson(joints - offset, _visible(joints, points, placed, fit.visible_m), name, pixels, dims.height)


def _shifted(world_from_camera: np.ndarray, offset: np.ndarray) -> np.ndarray:
    pose = np.array(world_from_camera, dtype=np.float64)
    pose[:3, 3] += offset
    return pose


def _visible(joints: np.ndarray, points: np.ndarray, camera: Camera, within: float) -> np.ndarray:
    """(15,) bool: the joints (15, 3) world metres (NaN: none) that project inside ``camera``'s
    image with one of the person's ``points`` (N, 3) within ``within`` metres."""
    known = np.isfinite(joints).all(axis=1)
    visible = np.zeros(NUM_JOINTS, bool)
    if not known.any():
        return visible
    uv, z = pixels_from_points(joints[known], camera)
    inside = (z > 0) & (uv[:, 0] >= 0) & (uv[:, 0] < camera.width) & (uv[:, 1] >= 0) & (uv[:, 1] < camera.height)
    near = cKDTree(points).query(joints[known], distance_upper_bound=within)[0] <= within
    visible[known] = inside & near
    return visible
