"""The per-frame pipeline for any number of people and cameras (DESIGN.md, "The pipeline").

One :class:`Tracker` holds everything that lives across frames: the occupancy grid
(stage 1), the blob tracker (stage 2) and one :class:`_Person` per tracked blob (stage 3:
a body model, a particle filter and, for methods with occlusion handling, the visible /
hidden state machine of :mod:`occupose.pose.occlusion`). :meth:`Tracker.update` takes one frame
of depth images and returns every tracked person's 15 canonical joints, each flagged
visible (estimated from this frame's data) or not (carried from memory).

A frame:

1. the grid takes the depth images; cells inside a tracked person's body are *held*
   (no moving -> static transition), so a person standing or sitting still is not
   absorbed into the background (with the paper's psi they would be after ~77 frames);
2. moving cells are labelled into blobs, blobs tracked (ids persist);
3. every tracked blob's pixels go to its person; where people touch, each pixel goes
   to the nearest predicted body (exclusion principle; a new person's body is made of
   its previous points, see :func:`occupose.grid.pixels.predicted_from_tracks`);
4. per person: a new track starts once its blob's own points have been tall enough and
   fully in view for a few frames (body size from their points, a search over headings
   facing where it walks or the camera, standing or sitting); a known one first runs the
   occlusion check (its previous estimate moved to the blob's new centre of mass), then
   the filter on the visible subtree, given only its points near that predicted body (not
   what it carries); hidden legs (and hidden shins under seen thighs) are placed with
   their feet on the floor, or, standing, reach the feet that show (a thigh seen over a
   hidden shin too); its stature is measured again over its first second upright
   and, once it has been seen from the front a few times, its neck height and shoulder
   width; its model is resized to them; LOOK_BACK_FROM frames after its start it is also
   tracked backwards from its estimate over the frames before the start (walking in from
   the image's edge; :attr:`Tracker.looked_back`), until its torso is out of view;
5. a person whose torso is hidden is kept (suspended): carried on at its walking speed if it
   walks (the speed of its last estimates in full view, while recent, or its blob's then)
   and is not at the image's edge, else moved with its blob; one whose blob is gone is kept and carried at
   that speed; either is placed back on its blob when seen again (where it was carried to,
   if it was carried at a walker's speed), keeping the way it walked (a new blob track near
   it is its); it ends when its blob has been gone for longer than ``max_gap_s``.

With ``upcoming`` frames, step 1 of the next frame runs on a second thread during step 4.

Methods (:data:`METHODS`) are named presets of filter, budget and occlusion handling;
every setting can be overridden.
"""

from __future__ import annotations

import itertools
import time
from collections import deque
from collections.abc import Mapping, Sequence
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field, replace

import numpy as np

from occupose.body import (
    BodyModel,
    body_model,
    capsules_from_poses,
    dims_from_observation,
    joints_from_poses,
    pose_from_joints,
    standing_pose,
)
from occupose.body.size import (
    TOP_BIAS,
    TOP_RANK,
    breadth_profile,
    dims_with_shoulders,
    neck_and_shoulders,
    top_height,
)
from occupose.camera import Camera
from occupose.filters.layered import spread_layers
from occupose.grid.blobs import blobs_from_mask
from occupose.grid.hold import cells_near_capsules
from occupose.grid.pixels import Observation as GridObservation
from occupose.grid.pixels import observations_from_depth, predicted_from_tracks
from occupose.grid.occupancy import OccupancyGrid, spec_from_cameras
from occupose.grid.tracking import BlobTracker, TrackState
from occupose.joints import NUM_JOINTS
from occupose.likelihood import Observation, View, observation_from_views, point_distances
from occupose.pose.occlusion import OcclusionState, hidden_parts_in_views, joint_parts, part_tree, planted_legs
from occupose.pose.problem import PoseEstimator, PoseProblem
from occupose.pose.proposals import feet, unexplained_points
from occupose.synth import motion as procedural


@dataclass(frozen=True)
class Method:
    """A tracking method: what runs in stage 3 for each person.

    filter : name in occupose.filters.FILTERS; particles : particles per person
    layers : annealing layers (an int, or one per partitioned-sampling stage; None for
        filters without layers); a model with another number of stages gets the same total
        spread from the root down (the upper model: (2, 1, 2) -> (3, 2))
    likelihood : name in occupose.likelihood.LIKELIHOODS
    occlusion : whether hidden parts are detected and left out (occupose.pose.occlusion; the
        full model only: the upper model is for ceiling cameras, where furniture hides
        no part of the upper body)
    model : "full", "upper" or "auto" (``upper`` for a camera looking steeply down)
    max_points : most observed points per person and frame given to the likelihood
    shape : measure each person's neck height and shoulder width on its first estimates
        seen from the front or the back, and resize its model once (the full model only;
        :meth:`_Person.learn_shape`)
    """

    filter: str
    particles: int
    layers: int | tuple[int, ...] | None = None
    likelihood: str = "points+free"
    occlusion: bool = False
    model: str = "auto"
    max_points: int = 1000
    shape: bool = True

    @property
    def filter_options(self) -> dict:
        return {} if self.layers is None else {"num_layers": self.layers}


#: The methods of the papers with their budgets. ``ours`` is the first paper's filter
#: (annealed layers within partitions, 200 particles; its "5 layers" read as 5 layers
#: spread over the 3 partitioned-sampling stages, 2 on the root, 1 on the head and arms,
#: 2 on the legs: 1000 likelihood evaluations per frame, also while the legs are hidden
#: (their layers then go to the other stages: 3 on the root, 2 on the head and arms); on
#: sit_behind_table, 300 frames, this split gave 8.3 cm against 11.0 cm for 3, 1, 1 and
#: 19.2 cm for 1, 1, 3) with occlusion handling; ``apf`` and ``ps`` its baselines (2000
#: and 6000 evaluations: 2000 particles x 3 stages; no occlusion handling);
#: ``part-based`` the second paper's upper-body filter (1000 evaluations). All use the
#: same likelihood.
METHODS: dict[str, Method] = {
    "ours": Method("apf+ps", 200, (2, 1, 2), occlusion=True),
    "apf": Method("apf", 200, 10),
    "ps": Method("ps", 2000),
    "part-based": Method("part-based", 1000, model="upper"),
}

#: A camera whose optical axis points down more steeply than this (radians below the
#: horizontal) is a ceiling camera: ``model="auto"`` picks the upper-body model.
STEEP_DOWN = np.deg2rad(60.0)
#: A blob starts a person once its own points (the pixels given to it, not those of the
#: people beside it) reach at least this high, metres (a seated adult's head; their top
#: as for the stature, occupose.body.size.top_height): a chair put down beside its carrier
#: shares the carrier's blob track but not the carrier's pixels,
MIN_INIT_TOP = 1.0
#: it has at least this many observed points,
MIN_INIT_POINTS = 200
#: and it has been so for this many frames in a row: the body size is measured on their
#: points pooled (the grid extracts a newly moving body over a few frames, so the first
#: frames' points fall short of the head).
INIT_FRAMES = 5
#: and some camera sees its pixels as a solid silhouette: they fill at least this share of
#: the image box between the FILL_QUANTILES of their columns and of their rows
#: (silhouette_fill). A person fills 0.55-0.8 of it (0.12 while cut by the image's edge); a
#: wall's noisy readings that a second camera's line of sight no longer overrules, in the
#: shadow a person casts from that camera, scatter over 0.01-0.08 of theirs and would
#: start a ghost (two_cameras_occlusion: a person's shadow from the side camera sweeping
#: the back wall, 300 of its pixels in the front camera over 0.7 x 1.3 m).
MIN_FILL = 0.25
FILL_QUANTILES = (5.0, 95.0)
#: A person whose pixels come within this many pixels of the left, right or top image edge
#: is not fully in view and does not start yet.
BORDER_PX = 3
#: Headings tried when a person starts, radians.
INIT_HEADINGS = np.linspace(-np.pi, np.pi, 12, endpoint=False)
#: Seat height of the sitting start, as a share of the stature (0.45 m for 1.75 m).
SEAT_SHARE = 0.26
#: Random perturbations of each start candidate scored at initialisation.
INIT_SAMPLES = 40
#: Filter steps run on a new person's first observation (to settle the start pose).
INIT_STEPS = 3
#: Spread (std) of a new person's particles around the chosen start: root x, y, z (m),
#: heading (rad), other angles (rad).
INIT_SPREAD = (0.05, 0.05, 0.05, 0.15, 0.1)
#: Seconds a track survives without its blob.
MAX_GAP_S = 3.0
#: A new person is also tracked backwards over the frames of its blob before its start
#: (walking in, cut by the image's edge, and the INIT_FRAMES its size is measured on), at
#: most this many seconds of them, until its torso is hidden (out of view; with occlusion
#: handling) or its blob was not seen, and those frames are reported (Tracker.looked_back).
#: A person walking in from the side is in view for 0.8 s before its start in
#: enter_exit_occlusion and sit_behind_table.
LOOK_BACK_S = 1.0
#: The backward run starts from the person's estimate this many frames after its start,
#: through the frames since: a start's legs may be a stride off, which the filter sets
#: right over the next frames but a backward run from the start pose would carry into the
#: frames before it (enter_exit_occlusion run 0: ankles 0.3-0.4 m off at the start, right
#: 5 frames later; from the start pose 0.55 m off before it).
LOOK_BACK_FROM = 10
#: A person gone or suspended walks on at the speed of its estimates in full view among
#: this many last ones, or at its blob's then, whichever is faster (else its pelvis's mean
#: velocity over them: _Person.step), at most CARRY_SPEED metres per frame (2 m/s at 30 fps).
CARRY_FRAMES = 15
CARRY_SPEED = 0.067
#: Largest horizontal offset between the pelvis and its blob's centroid kept for placing
#: a person that is back, metres.
MAX_ANCHOR = 0.25
#: A person faster than this walks, m/s: it starts facing the way it walks, and one who
#: walks more than BACKWARDS (radians) away from the way it faces is turned round.
WALKING_SPEED = 0.3
BACKWARDS = np.deg2rad(135.0)
#: A person is turned round at WALKING_SPEED in its first START_CHECK_S seconds, later only
#: at LATER_SPEED, m/s (one turning round to sit down still shows the way it came).
START_CHECK_S = 2.0
LATER_SPEED = 0.7
#: A walking person faces the way it walks: frames over which the way is taken, the nats
#: that facing backwards costs at full speed, and the speeds (m/s) from which the prior
#: starts and over which it ramps up to full weight (see _Person.walking). A person
#: standing still moves its estimated pelvis by a few centimetres per frame, which over
#: 0.5 s stays well below WALK_FROM.
WALK_FRAMES = 15
WALK_PRIOR = 1.0
WALK_FROM = 0.5
WALK_RAMP = 0.4
#: With Method.shape, a person's neck depth below the top of its head and its shoulder
#: breadth are measured (occupose.body.size.neck_and_shoulders) on SHAPE_FRAMES of its
#: estimates with the trunk, head and arms in view and upright (lean under SHAPE_LEAN
#: radians) that a camera looking at most SHAPE_LEVEL radians down sees from the front or
#: the back (facing within SHAPE_FRONTAL radians of its line of sight or away); their
#: medians then resize its model, once.
SHAPE_FRAMES = 6
SHAPE_LEAN = 0.3
SHAPE_LEVEL = np.deg2rad(35.0)
SHAPE_FRONTAL = np.deg2rad(37.0)
#: A person's stature is measured again on its first STATURE_FRAMES estimates with the
#: pelvis upright (at least STATURE_UPRIGHT of the legs' length above the floor), and its
#: model rescaled when their median differs from the start's by more than STATURE_CHANGE
#: metres: a ceiling camera's grid picks a person up over its first frames, and the start's
#: points may not reach the head yet (top_view_arms_flashy: 1.29 m, the shoulders, for a
#: head's top near 1.55; from the front the start's stature was within 2-3 cm).
STATURE_FRAMES = 30
STATURE_UPRIGHT = 0.8
STATURE_CHANGE = 0.05
#: The upper-body model sees only the points above this share of the person's stature
#: (the hips are at about 0.53).
UPPER_CUT = 0.5
#: A person's points farther than this from its predicted body (the last estimate moved
#: with its blob), metres, are left out of its likelihood (a validation gate): what a
#: person carries, or a piece of something else in its blob, is not its body. The points
#: term pulls the nearest part onto every point, so without the gate the legs reach into
#: a chair being carried (moved_chair: the left ankle 48 cm off for 4 s, in every method).
#: A limb that moved faster than the gate between two frames comes back over a few frames,
#: its points nearest the body first. A camera's points are all kept when the gate would
#: leave fewer than GATE_KEEP of them: the prediction itself is off (a person back from
#: behind a cabinet a step away from where it was carried), and would never be corrected.
GATE_M = 0.25
GATE_KEEP = 0.5
#: A new blob track within this distance of a lost person's carried pelvis is that
#: person's, metres (horizontal).
REJOIN_M = 1.0
#: A blob whose centroid is within this distance of a tracked person's pelvis does not
#: start a new person (it split off that person's blob), metres (horizontal).
START_CLEARANCE = 0.5
#: The DOFs of the legs (by name): a person carried at a walker's speed out of sight stands
#: (_Person.carry). The arms keep their last configuration: rested too, hanging, they fitted
#: the arm pixels after the cabinet worse (epsilon 10.8 -> 12.3 cm, `ours`, 3 runs).
LEG_DOFS = ("left_hip", "left_knee", "right_hip", "right_knee")


def _model_for(cameras: Sequence[Camera]) -> str:
    """'upper' when every camera looks down more steeply than STEEP_DOWN, else 'full'."""
    return "upper" if all(c.down_angle > STEEP_DOWN for c in cameras) else "full"


@dataclass
class PersonEstimate:
    """One tracked person in one frame.

    joints : (15, 3) float64, metres, world; NaN for joints the model does not report
    visible : (15,) bool, the joint was estimated from this frame's data (False: carried
        from memory while hidden or while the person's blob is gone)
    """

    joints: np.ndarray
    visible: np.ndarray


class _Person:
    """Stage 3 state of one tracked person: model, filter, occlusion state."""

    def __init__(self, model: BodyModel, method: Method, fps: float, rng: np.random.Generator,
                 backwards: bool = False):
        self.model = model
        self.backwards = backwards  # runs back in time (Tracker._look_back): it walks the other way
        self.method = method
        self.problem = PoseProblem(model, method.likelihood, fps=fps)
        options = method.filter_options
        layers = options.get("num_layers")
        stages = len(self.problem.partitions)
        if isinstance(layers, tuple) and len(layers) != stages:  # e.g. the upper model: 2 stages
            options["num_layers"] = spread_layers(sum(layers), stages)  # the same number, from the root down
        self.estimator = PoseEstimator(self.problem, method.filter, method.particles, rng, **options)
        self.occlusion = None
        if method.occlusion and model.name == "full":  # the upper body is for ceiling cameras,
            parents, dofs = part_tree(model)  # under which furniture hides no part of it
            self.occlusion = OcclusionState(parents, dofs, model.num_dofs)
        self.joint_parts = joint_parts(model)
        self.legs = np.array([n.startswith(LEG_DOFS) for n in model.dof_names])  # (D,) bool (carry)
        self.stance = standing_pose(model)  # (D,) standing at rest, feet under the hips
        self.pose: np.ndarray | None = None
        self.centroid: np.ndarray | None = None  # (3,) its blob's centroid when last seen
        self.anchor = np.zeros(2)  # pelvis x, y minus its blob's centroid x, y at the last estimate
        self.lost = False  # gone or suspended since the last estimate
        self.blob = 0  # id of its blob track (a person keeps its id when its blob's changes)
        self.path: list[np.ndarray] = []  # pelvis x, y of the last CARRY_FRAMES estimates
        # (estimate's number, pelvis x, y, its blob's velocity (2,) m/s) of those of them with
        # every part in view
        self.clear: list[tuple[int, np.ndarray, np.ndarray]] = []
        self.walked_on = False  # carried at a walker's speed since the last estimate (come_back)
        self.part_visible = np.ones(model.num_parts, bool)
        self.fps = fps
        self.since_turn = 0  # estimates since the last turn round (face_the_way_walked)
        self.estimates = 0  # estimates since the start (settle)
        self.shapes: list[tuple[float, float]] = []  # (neck depth, shoulder breadth) metres (learn_shape)
        self.shaped = not (method.shape and model.name == "full")  # resized, or never to be
        self.tops: list[float] = []  # statures measured on its first estimates (learn_stature)
        self.problem.stature_known = False  # until learn_stature has measured it again

    def settle(self, pose: np.ndarray, velocity: np.ndarray) -> None:
        """Take a new estimate (D,); velocity (2,) m/s: its blob's horizontal velocity."""
        self.pose = pose
        anchor = pose[:2] - self.centroid[:2]  # a partly hidden blob's centroid is off: clipped
        self.anchor = anchor * min(1.0, MAX_ANCHOR / max(float(np.hypot(*anchor)), 1e-12))
        self.path = (self.path + [pose[:2].copy()])[-CARRY_FRAMES:]
        self.estimates += 1
        if self.part_visible.all():
            self.clear = (self.clear + [(self.estimates, pose[:2].copy(), np.array(velocity, float))])[-CARRY_FRAMES:]

    def face_the_way_walked(self) -> None:
        """Turn the whole estimate round (heading + pi) when the person has walked faster
        than WALKING_SPEED (in its first START_CHECK_S seconds; later LATER_SPEED) over the
        last CARRY_FRAMES estimates in a direction more than BACKWARDS from the way it
        faces, at most once per CARRY_FRAMES. A body of round cones fits its points about
        as well facing either way, and the blob's velocity a person starts with can be off
        (the grid extracts a body over its first frames, and the centroid moves with it),
        so a person may start facing backwards; and an estimate may not follow a person who
        turns round on the spot (enter_exit_occlusion: facing the old way for 100 frames
        while walking back). Slower walks count only at the start: later, a person who
        turns round to sit down still shows the way it came in its recent path."""
        self.since_turn += 1
        if len(self.path) < CARRY_FRAMES or self.since_turn < CARRY_FRAMES:
            return
        velocity = (self.path[-1] - self.path[0]) / (len(self.path) - 1) * self.fps * self._time
        heading = self.problem.heading_dof
        facing = self.pose[heading]
        off = (np.arctan2(velocity[1], velocity[0]) - facing + np.pi) % (2 * np.pi) - np.pi
        fast = WALKING_SPEED if self.estimates <= START_CHECK_S * self.fps else LATER_SPEED
        if np.hypot(*velocity) > fast and abs(off) > BACKWARDS:
            turn = np.zeros(self.model.num_dofs)
            turn[heading] = np.pi
            self.estimator.shift(turn)
            self.pose = self.estimator.filter.estimate.copy()
            self.since_turn = 0

    def learn_shape(self, observation: Observation) -> None:
        """With Method.shape: measure the neck depth and shoulder breadth
        (occupose.body.size.neck_and_shoulders) in the first of ``observation``'s views
        that sees this estimate from the front or the back (SHAPE_FRONTAL, SHAPE_LEVEL;
        trunk, head and arms in view, upright); with SHAPE_FRAMES measurements, go on with
        a model of their medians (occupose.body.size.dims_with_shoulders; the particles
        moved so that the estimate keeps its joints)."""
        if self.shaped or abs(self.pose[self.model.dof("trunk_lean")]) > SHAPE_LEAN:
            return
        legs = np.array([name.endswith(("thigh", "shin")) for name in self.model.part_names])
        if not (self.part_visible | legs).all():
            return
        heading = self.pose[self.problem.heading_dof]
        for view in observation.views:
            ray = self.pose[:2] - view.camera.position[:2]
            square = abs(np.cos(heading) * ray[0] + np.sin(heading) * ray[1]) / max(float(np.hypot(*ray)), 1e-9)
            if view.camera.down_angle > SHAPE_LEVEL or square < np.cos(SHAPE_FRONTAL):
                continue
            points = view.points
            measured = neck_and_shoulders(breadth_profile(points)) if len(points) >= TOP_RANK else None
            if measured is not None:
                self.shapes.append(measured)
                break
        if len(self.shapes) < SHAPE_FRAMES:
            return
        depth, breadth = np.median(self.shapes, axis=0)
        self._resize(dims_with_shoulders(self.model.dims, self.model.girth, depth, breadth))
        self.shaped = True

    def learn_stature(self, observation: Observation) -> None:
        """Measure the stature again (the top of the person's points, as at the start) on
        its first STATURE_FRAMES estimates with the pelvis upright (at least
        STATURE_UPRIGHT of the legs' length above the floor); when their median differs
        from the model's by more than STATURE_CHANGE, go on with the model scaled to it
        (its proportions kept; the particles moved so that the estimate keeps its joints).
        Then the stature is known (PoseProblem.stature_known: the upper body's head may
        not rise above it)."""
        dims = self.model.dims
        if len(self.tops) >= STATURE_FRAMES or self.pose[self.model.dof("z")] < STATURE_UPRIGHT * dims.hip_height:
            return
        points = np.concatenate([view.points for view in observation.views])
        if len(points) < TOP_RANK:
            return
        self.tops.append(top_height(points[:, 2]) + TOP_BIAS)
        if len(self.tops) == STATURE_FRAMES:
            if abs(np.median(self.tops) - dims.height) > STATURE_CHANGE:
                self._resize(dims.scaled(float(np.clip(np.median(self.tops), 1.0, 2.2))))
            self.problem.stature_known = True

    def _resize(self, dims) -> None:
        """Go on with a model of ``dims`` (BodyDims; girth kept), the particles moved so
        that the estimate keeps its joints."""
        model = body_model(self.model.name, dims, self.model.girth)
        pose = pose_from_joints(model, joints_of(self.model, self.pose), refine=False)
        self.model = model
        self.problem.resize(model)
        self.estimator.shift(pose - self.pose)
        self.pose = pose
        self.stance = standing_pose(model)

    def walking(self) -> tuple[float, float] | None:
        """(direction, weight) of PoseProblem.walking: the way the pelvis moved over the last
        WALK_FRAMES estimates, weighted WALK_PRIOR nats from WALK_FROM + WALK_RAMP m/s up
        (linearly from 0 at WALK_FROM); None when slower or too new."""
        velocity = self._velocity()
        speed = 0.0 if velocity is None else float(np.hypot(*velocity))
        if speed <= WALK_FROM:
            return None
        return float(np.arctan2(velocity[1], velocity[0])), WALK_PRIOR * min(1.0, (speed - WALK_FROM) / WALK_RAMP)

    def standing(self) -> bool:
        """Whether the pelvis moved at most WALK_FROM m/s over the last WALK_FRAMES estimates
        (PoseProblem.standing: the feet are on the floor)."""
        velocity = self._velocity()
        return velocity is not None and float(np.hypot(*velocity)) <= WALK_FROM

    def _velocity(self) -> np.ndarray | None:
        """(2,) m/s of the pelvis over the last WALK_FRAMES estimates (forward in time, also
        for a person run backwards); None for fewer."""
        if len(self.path) < WALK_FRAMES:
            return None
        return (self.path[-1] - self.path[-WALK_FRAMES]) / (WALK_FRAMES - 1) * self.fps * self._time

    @property
    def _time(self) -> float:
        """-1 for a person run back in time (its path goes the way it walked from), else 1."""
        return -1.0 if self.backwards else 1.0

    def step(self) -> np.ndarray:
        """(2,) metres per frame: the faster of two measures of its walk over its last
        CARRY_FRAMES estimates with every part in view, when there are two of them: their
        mean step (from the first to the last; they need not follow one another) and their
        blob's median velocity; else the pelvis's mean step over its last CARRY_FRAMES
        estimates; at most CARRY_SPEED. A person walking behind a cabinet is estimated on
        what is left in view, which stalls at the cabinet's edge: those last estimates
        fall behind (0.6 against 1 m/s in enter_exit_occlusion). Each measure falls short
        where the other does not: the estimates just after a person starts are still
        settling (0.6-0.8 m/s for a 1 m/s walk in some runs, the blob 1.0), and the blob's
        velocity, smoothed by the blob tracker, lags a person speeding up (0.7 m/s for a
        walker reaching 1 m/s after turning round on the spot: the whole enter_exit scene
        FAILed in 3 of 3 runs with the blob's alone); the median leaves out the frames where
        the blob was already being cut."""
        recent = [(n, xy, velocity) for n, xy, velocity in self.clear if n > self.estimates - CARRY_FRAMES]
        if len(recent) > 1:
            (first, start, _), (last, end, _) = recent[0], recent[-1]
            walked = (end - start) / (last - first)
            blob = np.median([velocity for _, _, velocity in recent], axis=0) / self.fps
            step = max(walked, blob, key=lambda s: float(np.hypot(*s)))
        elif len(self.path) > 1:
            step = (self.path[-1] - self.path[0]) / (len(self.path) - 1)
        else:
            return np.zeros(2)
        return step * min(1.0, CARRY_SPEED / max(float(np.hypot(*step)), 1e-12))

    def carry(self) -> None:
        """A frame without an estimate (gone or suspended): the pose walks on at :meth:`step`;
        at a walker's speed (above WALK_FROM) it comes back where it was carried to
        (:meth:`come_back`), and its legs (and their occlusion memory) stand, the feet under
        the hips: a stride frozen while the walk goes on out of sight is a whole step off at
        every other step (the ankles 0.67 m behind the cabinet of enter_exit_occlusion),
        where the middle of a gait cycle is at most half a step off."""
        step = self.step()
        self.pose = self.pose.copy()
        self.pose[:2] += step
        self.lost = True
        self.walked_on = float(np.hypot(*step)) * self.fps > WALK_FROM
        if self.walked_on:
            self.pose[self.legs] = self.stance[self.legs]
            if self.occlusion is not None:
                self.occlusion.memory[self.legs] = self.stance[self.legs]

    def come_back(self, centroid: np.ndarray) -> None:
        """Back after being gone or suspended: start again at the blob's ``centroid`` (3,)
        plus the anchor, or where it was carried to if it was carried at a walker's speed
        (:meth:`carry`: the centroid of a body coming out from behind a cabinet lags at the
        cabinet's edge, whether its blob was kept or had gone). The particles are where the
        last estimate left them, not where the pose was carried since, so they are shifted
        from the estimate (the root's x, y, and the legs when they came to stand). The paths
        are moved along (the jump onto the blob is no step of the person's): the way it
        walked before goes on, so a person hidden again soon after is carried on that way."""
        place = self.pose[:2] if self.walked_on else centroid[:2] + self.anchor
        offset = np.zeros(self.model.num_dofs)
        offset[:2] = place - self.estimator.filter.estimate[:2]
        if self.walked_on:
            offset[self.legs] = (self.pose - self.estimator.filter.estimate)[self.legs]
        self.estimator.shift(offset)
        self.pose = self.pose.copy()
        self.pose[:2] = place
        self.centroid, self.lost, self.walked_on = centroid, False, False
        if self.path:
            moved = self.pose[:2] - self.path[-1]
            self.path = [p + moved for p in self.path]
            self.clear = [(n, p + moved, v) for n, p, v in self.clear]

    def estimate(self, fresh: bool) -> PersonEstimate:
        joints = joints_of(self.model, self.pose)
        visible = np.array([fresh and bool(len(p)) and bool(self.part_visible[p].all()) for p in self.joint_parts])
        return PersonEstimate(joints, visible & np.isfinite(joints[:, 0]))

    def body_distance(self, pose: np.ndarray | None = None):
        """f(points (N, 3)) -> (N,) metres to the surface of this person's body in ``pose``
        (D,) (default: its current pose)."""
        a, b = capsules_from_poses(self.model, (self.pose if pose is None else pose)[None])
        radii = self.model.capsule_radii

        def distance(points: np.ndarray) -> np.ndarray:
            return point_distances(a, b, radii, points, sort=False)[0][0].astype(np.float64)

        return distance


def joints_of(model: BodyModel, pose: np.ndarray) -> np.ndarray:
    """(15, 3) canonical joints of one pose (D,) of ``model``."""
    return joints_from_poses(model, np.asarray(pose, float)[None])[0]


def silhouette_fill(pixels: np.ndarray, width: int) -> float:
    """Share of the image box between the FILL_QUANTILES of the pixels' columns and rows
    that the pixels fill (0 for none).

    pixels : (N,) int, flat indices ``v * width + u`` of one camera's pixels, distinct
    """
    if len(pixels) == 0:
        return 0.0
    rows, columns = np.divmod(np.asarray(pixels), width)
    (u0, u1), (v0, v1) = np.percentile(columns, FILL_QUANTILES), np.percentile(rows, FILL_QUANTILES)
    inside = (columns >= u0) & (columns <= u1) & (rows >= v0) & (rows <= v1)
    return float(np.count_nonzero(inside) / ((np.floor(u1) - np.ceil(u0) + 1) * (np.floor(v1) - np.ceil(v0) + 1)))


def start_headings(velocity: np.ndarray, centroid: np.ndarray, camera: Camera) -> np.ndarray:
    """The headings of INIT_HEADINGS a person may start with, radians: those within 90
    degrees of where they walk (``velocity`` (2,) m/s, when faster than WALKING_SPEED),
    else of the direction towards ``camera`` from ``centroid`` (3,) metres.

    A body of round cones fits its points about as well facing either way (front and
    back differ little in depth), so the likelihood alone picks the wrong half turn about
    as often as the right one, which swaps left and right for good; people mostly face
    where they walk, and a person standing in view of a camera more often faces it.
    """
    if np.hypot(*velocity) > WALKING_SPEED:
        facing = np.arctan2(velocity[1], velocity[0])
    else:
        to_camera = camera.world_from_camera[:2, 3] - centroid[:2]
        facing = np.arctan2(to_camera[1], to_camera[0])
    off = (INIT_HEADINGS - facing + np.pi) % (2 * np.pi) - np.pi
    return INIT_HEADINGS[np.abs(off) < np.pi / 2 + 1e-9]


def start_candidates(model: BodyModel, centroid: np.ndarray, headings: np.ndarray = INIT_HEADINGS) -> np.ndarray:
    """(S, D) start poses for a person whose blob is centred at ``centroid`` (3,) metres:
    standing and (for models with legs) sitting, at every heading of ``headings``
    (radians), the pelvis above the centroid."""
    poses = []
    postures = [procedural.stance((0.0, 0.0), 0.0, model.dims)]
    if any("knee" in n for n in model.dof_names):
        standing = postures[0]
        postures.append(procedural.sit_down(standing, SEAT_SHARE * model.dims.height, dims=model.dims)[-1])
    for posture in postures:
        fitted = pose_from_joints(model, procedural.joints_from_procedural(posture[None], model.dims)[0])
        for heading in headings:
            pose = fitted.copy()
            pose[model.dof_names.index("heading")] = heading
            poses.append(pose)
    poses = np.array(poses)
    poses[:, 0:2] = centroid[:2]  # pelvis above the blob's centre; the filter settles the rest
    return poses


class Tracker:
    """Skeletons of everyone in view, frame after frame (see the module docstring).

    cameras : Camera or sequence of Camera (unique names); fps : frames per second
    method : a name of :data:`METHODS`; overrides : fields of :class:`Method` to change
        (filter, particles, layers, likelihood, occlusion, model, max_points)
    seed : int, seeds every person's filter (person n gets a generator spawned from it)
    cell : grid cell edge, metres; grid_options : passed to OccupancyGrid
    max_gap_s : seconds a track survives without its blob (a person walking behind a tall
        cabinet is gone for 1-2 s; while gone the pose moves with the blob track's velocity)
    hold_people : hold the grid cells of the people estimated in the last frame (no moving
        -> static transition there, :func:`occupose.grid.hold.cells_near_capsules`), so a
        person standing or sitting still is not absorbed into the background
    look_back_s : seconds of a new person's frames before its start tracked backwards
        (0: none; LOOK_BACK_FROM frames after its start); the tracker keeps a copy of the
        depth images of that many frames (and LOOK_BACK_FROM more) while some blob has no
        person yet or a person is that new. After each :meth:`update`, :attr:`looked_back`
        holds those estimates of the people whose backward run it made.
    """

    def __init__(self, cameras, fps: float, method: str = "ours", *, seed: int = 0, cell: float = 0.05,
                 grid_options: Mapping | None = None, max_gap_s: float = MAX_GAP_S, hold_people: bool = True,
                 look_back_s: float = LOOK_BACK_S, **overrides):
        if method not in METHODS:
            raise ValueError(f"unknown method {method!r}; valid names: {', '.join(METHODS)}")
        unknown = set(overrides) - set(Method.__dataclass_fields__)
        if unknown:
            raise ValueError(f"unknown method setting(s) {sorted(unknown)}; valid: {sorted(Method.__dataclass_fields__)}")
        self.method = replace(METHODS[method], **{k: v for k, v in overrides.items() if v is not None})
        self.method_name = method
        cameras = [cameras] if isinstance(cameras, Camera) else list(cameras)
        self.cameras = cameras
        self.fps = float(fps)
        if self.method.model not in ("auto", "full", "upper"):
            raise ValueError(f"model must be 'auto', 'full' or 'upper', got {self.method.model!r}")
        self.model_name = _model_for(cameras) if self.method.model == "auto" else self.method.model
        if not (np.isfinite(look_back_s) and look_back_s >= 0):
            raise ValueError(f"look_back_s must be a number of seconds >= 0, got {look_back_s!r}")
        self.spec = spec_from_cameras(cameras, cell=cell)
        self.grid = OccupancyGrid(self.spec, cameras, **dict(grid_options or {}))
        self.blobs = BlobTracker(self.fps, max_gap_s)
        self.people: dict[int, _Person] = {}
        self.hold_people = bool(hold_people)
        self._seeds = np.random.SeedSequence(seed)
        self._previous = {}
        self._pending: dict[int, list[np.ndarray]] = {}  # points of tracks not yet started
        self._fragments: set[int] = set()  # blob tracks that split off a tracked person's (see _start)
        # the last frames' data of the blobs without a person and of the people to be tracked
        # back (None for a frame without any)
        looked = round(look_back_s * self.fps)
        self._history: deque[_Recent | None] = deque(maxlen=looked + LOOK_BACK_FROM if looked else 0)
        self._new: dict[int, int] = {}  # people to be tracked back: id -> frame of their start
        #: {track id: [(frames ago, PersonEstimate)]}: the frames before a person's start
        #: tracked backwards, newest first (set by the update that ran the backward run)
        self.looked_back: dict[int, list[tuple[int, PersonEstimate]]] = {}
        self.frame = -1
        self.seconds = {"grid": 0.0, "blobs": 0.0, "observations": 0.0, "pose": 0.0}
        self.last_assigned: dict[str, np.ndarray] = {}
        self._pool: ThreadPoolExecutor | None = None  # the grid's thread when updates overlap
        self._grid_job = None

    def close(self) -> None:
        """Stop the grid's thread (when :meth:`update` was given ``upcoming`` frames)."""
        if self._pool is not None:
            self._pool.shutdown(wait=True)
            self._pool = None

    def update(self, depths: Mapping[str, np.ndarray], upcoming: Mapping[str, np.ndarray] | None = None
               ) -> dict[int, PersonEstimate]:
        """Take one frame: camera name -> (H, W) float32 depth, metres (0 = no measurement).

        Returns {track id: PersonEstimate} for every person tracked in this frame (seen,
        or kept through a short disappearance: then every joint has visible False). A
        person's track id is the id of the blob track that started it; it stays when the
        person comes back as another blob track (:meth:`_rejoin`).

        upcoming : the next frame's depths, or None. Given, the grid takes it on a second
        thread while stage 3 works on this frame (the paper's IV-B: the grid's kernel
        releases the GIL), and the next call must pass exactly that frame; its hold mask
        then comes from the bodies of the frame before this one.

        After the call, :attr:`looked_back` holds the estimates of earlier frames this call
        made (a new person tracked back over the frames before its start).
        """
        self.frame += 1
        self.looked_back = {}
        clock = time.perf_counter()
        if self._grid_job is not None:  # this frame's grid update ran during the last stage 3
            self._grid_job.result()
            self._grid_job = None
        else:
            self.grid.update(depths, hold=self._hold() if self.hold_people else None)
        clock = self._tick("grid", clock)
        labels, blobs = blobs_from_mask(self.grid.moving_mask(), self.spec)
        seen = self.blobs.update(blobs)
        states = self.blobs.states
        for pid in [p for p, person in self.people.items() if person.blob not in states]:
            del self.people[pid]  # its blob has been gone for longer than the gap
        self._rejoin(seen, states)
        owner = {person.blob: pid for pid, person in self.people.items()}
        self._pending = {t: p for t, p in self._pending.items() if t in seen and t not in owner}
        self._fragments &= set(seen) - set(owner)
        clock = self._tick("blobs", clock)
        bodies = {t: self.people[owner[t]].body_distance() for t in seen if t in owner}
        bodies |= predicted_from_tracks(states, self._previous, self.fps, ids=[t for t in seen if t not in bodies])
        observations, assigned = observations_from_depth(
            depths, self.cameras, self.spec, labels, seen, states=self.grid.states,
            centers={t: states[t].centroid for t in seen}, predicted=bodies)
        self._previous, self.last_assigned = observations, assigned
        if upcoming is not None:
            if self._pool is None:
                self._pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="occupose-grid")
            hold = self._hold() if self.hold_people else None
            self._grid_job = self._pool.submit(self.grid.update, upcoming, hold)
        clock = self._tick("observations", clock)
        out = {}
        for tid in seen:
            if tid in owner:
                pid = owner[tid]
                out[pid] = self._step(tid, self.people[pid], observations[tid], depths, assigned, states[tid])
            else:
                person = self._start(tid, observations[tid], depths, assigned, seen[tid])
                if person is not None:
                    out[tid] = person.estimate(True)
                    if self._history.maxlen:
                        self._new[tid] = self.frame
        if self._history.maxlen:
            self._remember(seen, owner, states, observations, depths, assigned)
        for pid, person in self.people.items():
            if pid not in out:  # gone (behind something): kept, not estimated
                person.carry()
                out[pid] = person.estimate(False)
        self._tick("pose", clock)
        return dict(sorted(out.items()))

    def _rejoin(self, seen, states) -> None:
        """Give a new blob track to the nearest lost person (gone or suspended, whose own blob
        is not seen) whose carried pelvis is within REJOIN_M of the blob's centroid: a person
        coming out from behind a cabinet often comes back as a new blob track, because the
        blob's centroid stalls at the cabinet's edge while they disappear, so the blob
        tracker's prediction falls short of where they reappear. A blob that split off a
        person's (kept from starting by START_CLEARANCE) may be taken at any age: the person
        whose blob went on without it may continue as it."""
        owned = {person.blob for person in self.people.values()}
        lost = {pid: person for pid, person in self.people.items() if person.lost and person.blob not in seen}
        for tid in seen:
            if tid in owned or tid in self._pending or not lost or (states[tid].age > 0 and tid not in self._fragments):
                continue
            pid, gap = min(((pid, float(np.hypot(*(p.pose[:2] - states[tid].centroid[:2])))) for pid, p in lost.items()),
                           key=lambda item: item[1])
            if gap < REJOIN_M:
                lost.pop(pid).blob = tid

    def _hold(self) -> np.ndarray | None:
        """(nx, ny, nz) bool, the cells within the grid's hold margin of the bodies of the
        people estimated in the last frame, or None when there are none."""
        bodies = [capsules_from_poses(p.model, p.pose[None]) + (p.model.capsule_radii,)
                  for p in self.people.values() if not p.lost]
        if not bodies:
            return None
        a, b, radii = (np.concatenate([body[i][0] if i < 2 else body[i] for body in bodies]) for i in range(3))
        return cells_near_capsules(self.spec, a, b, radii)

    def _tick(self, stage: str, start: float) -> float:
        now = time.perf_counter()
        self.seconds[stage] += now - start
        return now

    def _views(self, observation, depths, model: BodyModel, near=None) -> list[View]:
        """The likelihood's views of a person: its pixels in each camera, for the upper-body
        model only those above UPPER_CUT of its stature (as the second paper thresholds its
        top-view images: the model has no legs, and leg points pull its hanging arms down).

        near : f(points (N, 3) metres) -> (N,) metres to the person's predicted body, or None
            (a new person); given, only the pixels whose points are within GATE_M of it
            (all of a camera's when that leaves fewer than GATE_KEEP of them)
        """
        views = []
        for camera in self.cameras:
            pixels, points = observation.pixels[camera.name], observation.camera_points[camera.name]
            keep = np.ones(len(pixels), bool)
            if near is not None and len(pixels):
                gated = near(points) < GATE_M
                keep = gated if gated.mean() >= GATE_KEEP else keep
            if model.name == "upper":
                keep &= points[:, 2] >= UPPER_CUT * model.dims.height
            pixels = pixels[keep]
            mask = np.zeros(camera.height * camera.width, bool)
            mask[pixels] = True
            views.append(View(camera, depths[camera.name], mask.reshape(camera.height, camera.width)))
        return views

    def _start(self, tid, observation, depths, assigned, blob) -> _Person | None:
        """A new person from its blob, or None while the blob has not been person-like for
        INIT_FRAMES frames."""
        points = observation.points
        if (len(points) < MIN_INIT_POINTS or top_height(points[:, 2]) < MIN_INIT_TOP or self._at_border(observation)
                or max(silhouette_fill(observation.pixels[c.name], c.width) for c in self.cameras) < MIN_FILL):
            self._pending.pop(tid, None)
            return None
        centroid = self.blobs.states[tid].centroid[:2]
        if any(np.hypot(*(p.pose[:2] - centroid)) < START_CLEARANCE for p in self.people.values() if not p.lost):
            self._pending.pop(tid, None)  # a piece of a tracked person's body split off its blob
            self._fragments.add(tid)
            return None
        pending = self._pending.setdefault(tid, [])
        pending.append(points)
        if len(pending) < INIT_FRAMES:
            return None
        size = dims_from_observation(np.concatenate(self._pending.pop(tid)))
        rng = np.random.default_rng(self._seeds.spawn(1)[0])
        person = _Person(body_model(self.model_name, size.dims, size.girth), self.method, self.fps, rng)
        views = self._views(observation, depths, person.model)
        likelihood_obs = observation_from_views(views, self.method.max_points)
        problem = person.problem
        problem.set_observation(likelihood_obs)
        centre = np.mean(points, axis=0)
        headings = start_headings(self.blobs.states[tid].velocity, centre, self.cameras[0])
        candidates = start_candidates(person.model, centre, headings)
        spread = self._spread(person.model)
        samples = np.repeat(candidates, INIT_SAMPLES, axis=0)
        samples += rng.standard_normal(samples.shape) * spread
        samples = np.clip(samples, problem.limits[:, 0], problem.limits[:, 1])
        best = samples[int(np.argmax(problem.log_likelihood(samples).sum(axis=1)))]
        person.estimator.initialise(best, spread)
        for _ in range(INIT_STEPS):
            best = person.estimator.step(likelihood_obs)
        person.centroid = np.asarray(blob.centroid, float)
        person.blob = tid
        person.settle(best, self.blobs.states[tid].velocity)
        self.people[tid] = person
        return person

    def _at_border(self, observation) -> bool:
        """Whether the person's pixels touch the left, right or top edge (within BORDER_PX)
        of every camera's image that sees them: not fully in view of any camera, so its
        points would misjudge its size. (The bottom edge is allowed: a camera may cut the
        feet of a person who is near it. With several cameras, one that sees the whole
        person is enough: the pooled points hold the whole body.)"""
        cut = []
        for camera in self.cameras:
            pixels = observation.pixels[camera.name]
            if len(pixels) == 0:
                continue
            v, u = np.divmod(pixels, camera.width)
            cut.append(bool(u.min() < BORDER_PX or u.max() >= camera.width - BORDER_PX or v.min() < BORDER_PX))
        return all(cut)

    @staticmethod
    def _spread(model: BodyModel) -> np.ndarray:
        root_xyz, heading, angle = INIT_SPREAD[0], INIT_SPREAD[3], INIT_SPREAD[4]
        spread = np.where(model.angular, angle, root_xyz)
        spread[model.dof_names.index("heading")] = heading
        return spread

    def _remember(self, seen, owner, states, observations, depths, assigned) -> None:
        """Keep this frame's data of the blobs without a person and of the people to be
        tracked back (:meth:`_look_back`), and run the backward runs that are due."""
        for pid, start in list(self._new.items()):
            person = self.people.get(pid)
            if person is None or person.lost or self.frame - start >= LOOK_BACK_FROM:
                del self._new[pid]
                if person is not None and not person.lost:
                    self.looked_back[pid] = self._look_back(person, self.frame - start)
        kept = [t for t in seen if (t not in owner and t not in self._fragments) or owner.get(t) in self._new]
        self._history.append(_Recent({c: np.array(d) for c, d in depths.items()}, assigned,
                                     {t: (observations[t], states[t]) for t in kept}) if kept else None)

    def _look_back(self, person: _Person, since: int) -> list[tuple[int, PersonEstimate]]:
        """[(frames ago, PersonEstimate)], newest first: a person who started ``since``
        frames ago, tracked back in time from this frame's estimate over its blob's kept
        frames (while its blob was seen), by a person of its model run backwards
        (:class:`_Person`'s ``backwards``: the blob's velocity reversed, and it faces away
        from the way its path goes), until its torso is hidden (walking in from the image's
        edge) or it has nothing in view: the estimates of the frames before its start."""
        tid, out = person.blob, []
        back = _Person(person.model, self.method, self.fps, np.random.default_rng(self._seeds.spawn(1)[0]),
                       backwards=True)
        back.estimator.initialise(person.pose, self._spread(person.model))
        back.centroid, back.blob = person.centroid, tid
        back.settle(person.pose, -self.blobs.states[tid].velocity)
        for ago, frame in enumerate(reversed(self._history), start=1):
            if frame is None or tid not in frame.blobs:
                break
            observation, state = frame.blobs[tid]
            estimate = self._step(tid, back, observation, frame.depths, frame.assigned,
                                  replace(state, velocity=-state.velocity))
            if back.lost or not estimate.visible.any():
                break
            if ago > since:
                out.append((ago, estimate))
        return out

    def _step(self, tid, person: _Person, observation, depths, assigned, state) -> PersonEstimate:
        """One frame of a tracked person: ``state`` is its blob's TrackState in that frame."""
        active = scale = None
        centroid = np.asarray(state.centroid, float)
        if person.lost:
            person.come_back(centroid)
        moved = person.pose.copy()
        moved[:2] += centroid[:2] - person.centroid[:2]
        person.centroid = centroid
        if person.occlusion is not None:
            model = person.model

            def hidden(pose):
                a, b = capsules_from_poses(model, pose[None])
                return hidden_parts_in_views(a[0], b[0], model.capsule_radii, model.capsule_part, model.num_parts,
                                             depths, assigned, self.cameras, tid)

            person.part_visible = person.occlusion.update(moved, hidden)
            if person.occlusion.suspended:  # kept, not estimated: walks on, or stays with its blob
                # (at the image's edge it stays with its blob: the camera cannot show it walk on)
                if np.hypot(*person.step()) * self.fps > WALK_FROM and not self._at_border(observation):
                    person.carry()
                else:
                    person.pose, person.lost = moved, True
                return person.estimate(False)
            active, scale = person.occlusion.active_dofs(), person.occlusion.diffusion_scale()
            person.problem.hidden_parts = ~person.part_visible
        seen = observation_from_views(self._views(observation, depths, person.model, person.body_distance(moved)),
                                      self.method.max_points)
        if len(seen.points) == 0:  # e.g. the upper body's points all below its cut (crouching)
            return person.estimate(False)
        person.problem.walking, person.problem.standing = person.walking(), person.standing()
        pose = person.estimator.step(seen, active=active, diffusion_scale=scale)
        if person.occlusion is not None:
            person.occlusion.remember(pose)
            pose = person.occlusion.with_memory(pose)
            hidden = dict(zip(person.model.part_names, ~person.part_visible))
            legs = [side for side in ("left", "right") if hidden[f"{side}_thigh"]]
            shins = [side for side in ("left", "right") if hidden[f"{side}_shin"] and not hidden[f"{side}_thigh"]]
            if legs or shins:
                floor = person.problem.floor
                shown = feet(person.model, pose, unexplained_points(person.model, pose, seen), floor,
                             points=seen.points, viewpoints=np.array([c.position for c in self.cameras])) \
                    if floor is not None and person.problem.standing else {}
                # a standing leg whose foot shows reaches it whole: beside a chair's back
                # too few points of a thigh seen hold it (gesture_behind_chair 8.2 -> 6.9 cm)
                legs += [side for side in shins if side in shown]
                shins = [side for side in shins if side not in shown]
                pose = planted_legs(person.model, pose, legs, shins, shown)
                person.occlusion.memory = np.where(person.occlusion.active_dofs(), person.occlusion.memory, pose)
        person.settle(pose, state.velocity)
        person.face_the_way_walked()
        person.learn_stature(seen)
        person.learn_shape(seen)
        return person.estimate(True)


@dataclass
class _Recent:
    """One frame's data of the blobs without a person and of the people just started, kept
    for :meth:`Tracker._look_back`.

    depths : camera name -> (H, W) float32 metres (a copy); assigned : camera name -> (H, W)
    int32 track id of each pixel; blobs : {track id: (its occupose.grid.pixels
    Observation, its TrackState)}
    """

    depths: dict[str, np.ndarray]
    assigned: dict[str, np.ndarray]
    blobs: dict[int, tuple[GridObservation, TrackState]]


@dataclass
class TrackingResult:
    """The output of :func:`track_recording`.

    tracks : {track id: (joints (T, 15, 3) float64 metres, NaN where not tracked,
        visible (T, 15) bool)}
    seconds : seconds spent per stage (grid, blobs, observations, pose) and ``total``
        (all frames, reading excluded), ``startup`` (first frame, numba compilation included)
    fps : frames per second of tracking, the first frame (start-up) excluded
    num_frames : frames tracked; settings : the method's settings as run (for summaries)
    """

    tracks: dict[int, tuple[np.ndarray, np.ndarray]]
    seconds: dict[str, float] = field(default_factory=dict)
    fps: float = 0.0
    num_frames: int = 0
    settings: dict = field(default_factory=dict)


def track_frames(tracker: Tracker, frames, num_frames: int, progress=None, overlap: bool = False) -> TrackingResult:
    """Run ``tracker`` over ``frames`` (an iterable of objects with ``.index`` and
    ``.depth``, e.g. ``Recording.frames()``, indices from 0), the first ``num_frames`` of
    them. ``progress`` : callable(n) called after each frame, or None. ``overlap`` : update
    the grid with the next frame while the pose stage works on the current one
    (:meth:`Tracker.update`'s ``upcoming``)."""
    joints = {}
    visible = {}
    startup = 0.0
    total = 0.0
    frames = itertools.islice(frames, num_frames)
    upcoming = next(frames, None)
    indices = []  # of the frames taken so far
    while upcoming is not None:
        frame, upcoming = upcoming, next(frames, None)
        indices.append(frame.index)
        start = time.perf_counter()
        estimates = tracker.update(frame.depth, upcoming.depth if overlap and upcoming is not None else None)
        spent = time.perf_counter() - start
        if len(indices) == 1:
            startup = spent
        else:
            total += spent
        found = [(tid, frame.index, est) for tid, est in estimates.items()]
        found += [(tid, indices[-1 - ago], est) for tid, earlier in tracker.looked_back.items() for ago, est in earlier]
        for tid, index, est in found:
            if tid not in joints:
                joints[tid] = np.full((num_frames, NUM_JOINTS, 3), np.nan)
                visible[tid] = np.zeros((num_frames, NUM_JOINTS), bool)
            joints[tid][index] = est.joints
            visible[tid][index] = est.visible
        if progress is not None:
            progress(1)
    tracker.close()
    seconds = dict(tracker.seconds, total=total, startup=startup)
    fps = (num_frames - 1) / total if num_frames > 1 and total > 0 else 0.0
    return TrackingResult({t: (joints[t], visible[t]) for t in sorted(joints)}, seconds, fps, num_frames)


def track_recording(recording, method: str = "ours", *, seed: int = 0, progress=None, overlap: bool = False,
                    **settings) -> TrackingResult:
    """Track every person of an open :class:`occupose.io.recording.Recording`.

    method, seed, settings : as :class:`Tracker` (settings: Method fields, ``cell``,
    ``grid_options``, ``max_gap_s``); progress : callable(n) after each frame, or None;
    overlap : as :func:`track_frames`; off by default: on an idle 2-core machine the grid's
    thread competes with the likelihood kernels' two threads and one person ran at 62
    against 68 frames/s without it (it paid only on a busy machine: 13.5 against 10.7 at
    load 6; benchmarks/bench_speed.py).
    An empty recording (no frames) gives an empty result.
    """
    tracker = Tracker(recording.cameras, recording.fps, method, seed=seed, **settings)
    result = track_frames(tracker, recording.frames(), recording.num_frames, progress, overlap=overlap)
    result.settings = {"method": method, "seed": seed,
                       **{k: getattr(tracker.method, k) for k in Method.__dataclass_fields__},
                       "model": tracker.model_name}
    return result
