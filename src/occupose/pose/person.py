"""Stage 3 for one tracked person: its model, filter and occlusion state, and its policies.

A :class:`Person` is made when its blob starts it (:mod:`occupose.pose.start`); each frame
:meth:`Person.update` runs the occlusion check (its previous estimate moved to the blob's
new centre of mass), then the filter on the visible subtree, given only its points near
that predicted body; hidden legs are placed with their feet on the floor, or, standing,
reach the feet that show. Over its first estimates it measures its stature again and,
seen from the front, its neck and shoulders, and resizes its model. A person whose torso
is hidden is suspended: carried on at its walking speed if it walks and is not at the
image's edge, else moved with its blob; one whose blob is gone is carried too
(:meth:`Person.carry`); either is placed back when seen again (:meth:`Person.come_back`).
The settings are the fields of :class:`occupose.config.TrackerConfig` (sections pose,
carry, shape, size, occlusion, priors, proposals, likelihood, diffusion).
"""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from occupose.body import (
    BodyModel,
    body_model,
    capsules_from_poses,
    diffusion_scales,
    joints_from_pose,
    pose_from_joints,
    standing_pose,
    twin_pose,
)
from occupose.body.size import breadth_profile, dims_with_shoulders, neck_and_shoulders, top_height
from occupose.camera import Camera
from occupose.config import TrackerConfig
from occupose.filters import filter_options
from occupose.filters.layered import spread_layers
from occupose.geometry.angles import wrap_angle
from occupose.grid.pixels import PersonPixels
from occupose.grid.tracking import TrackState
from occupose.likelihood import Observation, observation_from_views, point_distances
from occupose.pose.estimator import PoseEstimator
from occupose.pose.occlusion import (OcclusionState, hidden_parts_in_views, joint_parts, part_tree, parts_out_of_view,
                                     parts_seen_through, planted_legs)
from occupose.pose.problem import PoseProblem
from occupose.pose.proposals import feet, unexplained_points
from occupose.pose.search import best_sample, explained_share, start_candidates, start_spread
from occupose.pose.views import at_border, modelled, views_from_pixels


@dataclass
class PersonEstimate:
    """One tracked person in one frame.

    joints : (15, 3) float64, metres, world; NaN for joints the model does not report
    visible : (15,) bool, the joint was estimated from this frame's data (False: carried
        from memory while hidden or while the person's blob is gone)
    """

    joints: np.ndarray
    visible: np.ndarray


class Person:
    """Stage 3 state of one tracked person: model, filter, occlusion state (module docstring).

    model : its body model (sized at its start); config : the run's settings; fps : frames/s
    rng : its own random generator; cameras : the recording's cameras
    backwards : it runs back in time (the look-back, :mod:`occupose.pose.lookback`): it
        walks the other way, so its walking prior and turn-round test flip
    area : None or (low (2,), high (2,)), world x, y metres: the floor area the cameras
        watch (the occupancy grid's), out of which it is not carried (:meth:`carry`)
    """

    def __init__(self, model: BodyModel, config: TrackerConfig, fps: float, rng: np.random.Generator,
                 cameras: Sequence[Camera], *, backwards: bool = False,
                 area: tuple[np.ndarray, np.ndarray] | None = None):
        self.model = model
        self.config = config
        self.cameras = tuple(cameras)
        self.backwards = backwards
        self.area = None if area is None else (np.asarray(area[0], float), np.asarray(area[1], float))
        pose = config.pose
        self.problem = PoseProblem(model, pose.likelihood, fps=fps,
                                   diffusion=diffusion_scales(model, fps, per_kind=dataclasses.asdict(config.diffusion)),
                                   likelihood_options=config.likelihood.options_for(pose.likelihood),
                                   part_weights=pose.part_weights, floor=config.priors.floor, priors=config.priors)
        layers = pose.layers
        stages = len(self.problem.partitions)
        if isinstance(layers, tuple) and len(layers) != stages:  # e.g. the upper model: 2 stages
            layers = spread_layers(sum(layers), stages)  # the same number, from the root down
        given = {"num_layers": layers, "survival": pose.survival, "resampling": pose.resampling,
                 "shuffle": pose.shuffle}
        accepted = filter_options(pose.filter)
        options = {k: v for k, v in given.items() if k in accepted and v is not None}
        self.estimator = PoseEstimator(self.problem, pose.filter, pose.particles, rng, pose.velocity_damping,
                                       pose.proposal_share, proposal_config=config.proposals, **options)
        self.occlusion = None
        if config.occlusion.enabled and model.name == "full":  # the upper body is for ceiling cameras,
            parents, dofs = part_tree(model)  # under which furniture hides no part of it
            self.occlusion = OcclusionState(parents, dofs, model.num_dofs, config.occlusion.resume_frames,
                                            config.occlusion.resume_scale)
        self.joint_parts = joint_parts(model)
        self.legs = np.array([n.startswith(config.carry.stand_dofs) for n in model.dof_names])  # (D,) bool (carry)
        self.stance = standing_pose(model)  # (D,) standing at rest, feet under the hips
        self.pose: np.ndarray | None = None
        self.centroid: np.ndarray | None = None  # (3,) its blob's centroid when last seen
        self.anchor = np.zeros(2)  # pelvis x, y minus its blob's centroid x, y at the last estimate
        self.lost = False  # gone or suspended since the last estimate
        self.blob = 0  # id of its blob track (a person keeps its id when its blob's changes)
        self.path: list[np.ndarray] = []  # pelvis x, y of the last carry.frames estimates
        self.heights: list[float] = []  # ... and its height above the floor (metres)
        # (estimate's number, pelvis x, y, its blob's velocity (2,) m/s) of those of them with
        # every part in view
        self.clear: list[tuple[int, np.ndarray, np.ndarray]] = []
        self.walked_on = False  # carried at a walker's speed since the last estimate (come_back)
        self.part_visible = np.ones(model.num_parts, bool)
        self.fps = fps
        self.since_turn = 0  # estimates since the last turn round (face_the_way_walked)
        self.twin_better: list[bool] = []  # whether its twin explained the points better (face_the_better_way)
        # its twin's gains (nats) in its first seconds (settle_facing; None once decided; a person run back
        # starts from an estimate)
        self.start_twins: list[float] | None = None if backwards or config.carry.start_twin_s <= 0 else []
        self.settled: float | None = None  # heading (rad) settled by settle_facing, while the estimate keeps it
        self.estimates = 0  # estimates since the start (settle)
        self.shapes: list[tuple[float, float]] = []  # (neck depth, shoulder breadth) metres (learn_shape)
        self.shaped = not (config.shape.learn and model.name == "full")  # resized, or never to be
        self.tops: list[float] = []  # statures measured on its first estimates (learn_stature)
        self.problem.stature_known = False  # until learn_stature has measured it again
        self.doubtful = 0  # doubtful estimates in a row (recheck)
        self.since_search = 0  # estimates since the last search again (recheck)
        self.searches = self.recoveries = 0  # searches again, and those taken (recheck)

    def update(self, pixels: PersonPixels, depths: Mapping[str, np.ndarray], assigned: Mapping[str, np.ndarray],
               state: TrackState) -> PersonEstimate:
        """One frame of a tracked person.

        pixels : its pixels this frame; depths : camera name -> (H, W) float32 metres;
        assigned : camera name -> (H, W) int32 track id of each pixel; state : its blob's
        TrackState this frame
        """
        config = self.config
        active = scale = None
        centroid = np.asarray(state.centroid, float)
        if self.lost:
            self.come_back(centroid)
        moved = self.pose.copy()
        moved[:2] += centroid[:2] - self.centroid[:2]
        self.centroid = centroid
        if self.occlusion is not None:
            model = self.model

            def hidden(pose):
                a, b = capsules_from_poses(model, pose[None])
                return hidden_parts_in_views(a[0], b[0], model.capsule_radii, model.capsule_part, model.num_parts,
                                             depths, assigned, self.cameras, self.blob, config.occlusion.spheres,
                                             config.occlusion.margin)

            self.part_visible = self.occlusion.update(moved, hidden)
            if self.occlusion.suspended:  # kept, not estimated: walks on, or stays with its blob
                # (at the image's edge it stays with its blob: the camera cannot show it walk on)
                start = config.start
                if not (np.hypot(*self.step()) * self.fps > config.carry.walk_from
                        and not at_border(pixels, self.cameras, start.border_px, start.border_count)
                        and self.carry(depths)):
                    self.pose, self.lost = moved, True
                return self.estimate(False)
            active, scale = self.occlusion.active_dofs(), self.occlusion.diffusion_scale()
            self.problem.hidden_parts = ~self.part_visible
        seen = observation_from_views(views_from_pixels(pixels, depths, self.cameras, self.model, config.pose,
                                                        self.body_distance(moved)), config.pose.max_points)
        if len(seen.points) == 0:  # e.g. the upper body's points all below its cut (crouching)
            return self.estimate(False)
        self.problem.walking, self.problem.standing = self.walking(), self.standing()
        pose = self.estimator.step(seen, active=active, diffusion_scale=scale)
        if self.occlusion is not None:
            pose = self._place_hidden_legs(pose, seen)
        self.settle(pose, state.velocity)
        self.settle_facing()
        self.face_the_way_walked()
        self.face_the_better_way()
        self.learn_stature(seen)
        self.learn_shape(seen)
        self.recheck(pixels, depths)
        return self.estimate(True)

    def _place_hidden_legs(self, pose: np.ndarray, seen: Observation) -> np.ndarray:
        """The estimate ``pose`` (D,) with hidden parts at their memory, and hidden legs (and
        hidden shins under seen thighs) placed with their feet on the floor, or, standing,
        reaching the feet that show (a thigh seen over a hidden shin too: beside a chair's
        back too few points of a thigh seen hold it)."""
        self.occlusion.remember(pose)
        pose = self.occlusion.with_memory(pose)
        hidden = dict(zip(self.model.part_names, ~self.part_visible))
        legs = [side for side in ("left", "right") if hidden[f"{side}_thigh"]]
        shins = [side for side in ("left", "right") if hidden[f"{side}_shin"] and not hidden[f"{side}_thigh"]]
        if legs or shins:
            floor = self.problem.floor
            shown = feet(self.model, pose, unexplained_points(self.model, pose, seen, self.config.proposals.unexplained),
                         floor, points=seen.points, viewpoints=np.array([c.position for c in self.cameras]),
                         config=self.config.proposals) if floor is not None and self.problem.standing else {}
            legs += [side for side in shins if side in shown]
            shins = [side for side in shins if side not in shown]
            pose = planted_legs(self.model, pose, legs, shins, shown, self.config.occlusion)
            self.occlusion.memory = np.where(self.occlusion.active_dofs(), self.occlusion.memory, pose)
        return pose

    def settle(self, pose: np.ndarray, velocity: np.ndarray) -> None:
        """Take a new estimate (D,); velocity (2,) m/s: its blob's horizontal velocity."""
        carry = self.config.carry
        self.pose = pose
        anchor = pose[:2] - self.centroid[:2]  # a partly hidden blob's centroid is off: clipped
        self.anchor = anchor * min(1.0, carry.max_anchor / max(float(np.hypot(*anchor)), 1e-12))
        self.path = (self.path + [pose[:2].copy()])[-carry.frames:]
        self.heights = (self.heights + [float(pose[2])])[-carry.frames:]
        self.estimates += 1
        if self.part_visible.all():
            self.clear = (self.clear + [(self.estimates, pose[:2].copy(), np.array(velocity, float))])[-carry.frames:]

    def face_the_way_walked(self) -> None:
        """Turn the whole estimate round (heading + pi) when the person has walked faster
        than ``carry.walking_speed`` (in its first ``carry.start_check_s`` seconds; later
        ``carry.later_speed``) over the last ``carry.frames`` estimates in a direction more
        than ``carry.backwards_deg`` from the way it faces, at most once per ``carry.frames``.
        A body of round cones fits its points about as well facing either way, and the
        blob's velocity a person starts with can be off (the grid extracts a body over its
        first frames), so a person may start facing backwards; and an estimate may not
        follow a person who turns round on the spot. Slower walks count only at the start:
        later, a person who turns round to sit down still shows the way it came. A move
        counts only while the person stays upright (:meth:`_upright`): a person sitting down
        steps backwards, and was turned round to face the couch it sat on."""
        carry = self.config.carry
        self.since_turn += 1
        if len(self.path) < carry.frames or self.since_turn < carry.frames:
            return
        if self._walks_against(self.pose[self.problem.heading_dof]) and not self._keeps_settled():
            turn = np.zeros(self.model.num_dofs)
            turn[self.problem.heading_dof] = np.pi
            self.estimator.shift(turn)
            self.pose = self.estimator.filter.estimate.copy()
            self._turned()

    def _walks_against(self, facing: float) -> bool:
        """Whether the person has walked faster than ``carry.walking_speed`` (in its first
        ``carry.start_check_s`` seconds; later ``carry.later_speed``) over the last
        ``carry.frames`` estimates in a direction more than ``carry.backwards_deg`` from
        ``facing`` (rad, the heading dof)."""
        carry = self.config.carry
        if len(self.path) < carry.frames or not self._upright(carry.frames):
            return False
        velocity = (self.path[-1] - self.path[0]) / (len(self.path) - 1) * self.fps * self._time
        off = wrap_angle(np.arctan2(velocity[1], velocity[0]) - facing)
        fast = carry.walking_speed if self.estimates <= carry.start_check_s * self.fps else carry.later_speed
        return bool(np.hypot(*velocity) > fast and abs(off) > np.deg2rad(carry.backwards_deg))

    def settle_facing(self) -> None:
        """Settle the way a new person faces by its limbs: over its first
        ``carry.start_twin_s`` seconds, until it walks faster than
        ``carry.walking_speed`` (over its last ``carry.walk_frames`` estimates), compare
        its estimate with the estimate's twin every ``carry.twin_every`` estimates
        (:meth:`_twin_gain`); then, with at least ``carry.start_twin_count``
        comparisons, go on with the twin when the t statistic of its gains (their mean
        over its standard error) is at least ``carry.start_twin_t``, and keep the
        estimate when it is at most minus that (the comparisons start again when the
        estimate is turned meanwhile, :meth:`_turned`). The heading so settled is kept
        (:meth:`_keeps_settled`) against the walk: neither the turn round
        (:meth:`face_the_way_walked`) nor the walking prior act on a walk against it, so
        a person who stood, and then walks backwards, is not turned to face the way it
        walks. A person who does not walk may start facing either way
        (:func:`occupose.pose.start.start_headings` keeps the half facing the camera),
        and walking says nothing about one who walks backwards: on the randomized
        benchmark's walk-back clips the start faced the wrong way and the twin explained
        better in 7 of 8 to 9 of 9 comparisons before the walk began. A share of wins
        does not tell those from a gesturing person faced the right way, whose twin won
        9 of 15 by as much, but more noisily; their gains' t statistic does (about 3 and
        1; notes/2026-12-07-start-twin.md)."""
        carry = self.config.carry
        if self.start_twins is None:
            return
        velocity = self._velocity()
        moving = velocity is not None and float(np.hypot(*velocity)) > carry.walking_speed
        if not moving and self.estimates <= carry.start_twin_s * self.fps:
            if self.estimates % carry.twin_every == 0:
                self.start_twins.append(self._twin_gain()[0])
            return
        gains, self.start_twins = np.array(self.start_twins), None
        if len(gains) < carry.start_twin_count:
            return
        t = gains.mean() / max(float(gains.std(ddof=1)), 1e-12) * np.sqrt(len(gains))
        if t >= carry.start_twin_t:
            self._take_twin(twin_pose(self.model, self.pose))
        elif t > -carry.start_twin_t:
            return
        self.settled = float(self.pose[self.problem.heading_dof])

    def _keeps_settled(self) -> bool:
        """Whether the estimate still faces within a quarter turn of the heading settled by
        :meth:`settle_facing` (else that heading is dropped: the person turned)."""
        if self.settled is not None and abs(wrap_angle(self.pose[self.problem.heading_dof] - self.settled)) > np.pi / 2:
            self.settled = None
        return self.settled is not None

    def _twin_gain(self) -> tuple[float, np.ndarray]:
        """(nats by which the estimate's twin explains its points better than the estimate,
        negative when worse, the twin (D,)): the difference of their summed log-likelihoods
        (the walking prior's included)."""
        twin = twin_pose(self.model, self.pose)
        estimate, mirrored = self.problem.log_likelihood(np.stack([self.pose, twin])).sum(axis=1)
        return float(mirrored - estimate), twin

    def _take_twin(self, twin: np.ndarray) -> None:
        """Go on with ``twin`` (D,) of the estimate (the particles moved with it)."""
        self.estimator.shift(twin - self.pose)
        self.pose = twin
        self._turned()

    def _turned(self) -> None:
        """The estimate was turned round: the comparisons with its twin made so far were of
        another estimate."""
        self.twin_better = []
        if self.start_twins is not None:
            self.start_twins = []
        self.since_turn = 0

    def face_the_better_way(self) -> None:
        """With ``carry.twin``: go on with the estimate's twin (its joints relabelled left for
        right, :func:`occupose.body.twin_pose`) when the twin explained the person's points
        better than the estimate in at least ``carry.twin_share`` of the comparisons (one
        every ``carry.twin_every`` estimates) of the last ``carry.twin_window_s`` seconds.
        A person who does not walk faces either way as far as the walking prior knows, and
        a body turned round fits its points about as well: what tells the halves apart is
        the limbs, whose joint limits bend them only one way (knees back, elbows and raised
        arms forward), so the wrong half's estimate explains its points a little worse most
        of the time. Measured on a still person
        seen from the front, the back and the side (notes/2026-12-04-twin-test.md): the twin
        of an estimate facing the wrong way explains better in 78-98 % of frames, of one
        facing the right way in 10-34 %. While the person walks, a twin that would face
        against the way walked (:meth:`face_the_way_walked`'s test) is not even made:
        walking says more."""
        carry = self.config.carry
        if not carry.twin or self.estimates % carry.twin_every:
            return
        heading = self.problem.heading_dof
        if self._walks_against(self.pose[heading] + np.pi):
            self.twin_better = []
            return
        gain, twin = self._twin_gain()
        window = max(1, int(round(carry.twin_window_s * self.fps / carry.twin_every)))
        self.twin_better = (self.twin_better + [gain > 0])[-window:]
        if len(self.twin_better) == window and np.mean(self.twin_better) >= carry.twin_share:
            self._take_twin(twin)

    def recheck(self, pixels: PersonPixels, depths: Mapping[str, np.ndarray]) -> None:
        """With ``recover.enabled``: search again from scratch every ``recover.every``
        estimates, and at once (but not within ``recover.cooldown`` estimates of the last
        search) after ``recover.frames`` doubtful estimates in a row: estimates that explain
        less than ``recover.min_explained`` of the person's points (``recover.points`` of its
        pixels' points, explained within ``recover.explained_m`` of the body). The search is a
        start's (:func:`occupose.pose.search.start_candidates` at ``start.headings`` headings
        round the circle, the estimate itself, and the estimate moved onto the points'
        centre; ``recover.samples`` perturbations of each),
        settled by ``recover.steps`` filter steps on all the person's points; it is taken,
        the person keeping its id, when it is both more likely and explains more of the
        points than the estimate, else the filter goes back to where it was. The filter
        follows its points only near its last estimate (:meth:`body_distance`), and the
        walking prior and the occlusion memory hold it where it went, so an estimate gone
        wrong does not always come back by itself; neither test alone is safe: the
        likelihood prefers a body turned round about as often as not, and a body off its
        points may still cover most of them."""
        recover, start = self.config.recover, self.config.start
        self.since_search += 1
        if not recover.enabled:
            return
        points = pixels.points
        points = points[modelled(points, self.model, self.config.pose)]
        if len(points) == 0:
            return
        points = points[np.linspace(0, len(points) - 1, min(recover.points, len(points))).astype(int)]
        share = explained_share(self.body_distance(), points, recover.explained_m)
        self.doubtful = self.doubtful + 1 if share < recover.min_explained else 0
        if self.since_search < recover.every and (self.doubtful < recover.frames
                                                  or self.since_search <= recover.cooldown):
            return
        self.doubtful = self.since_search = 0
        self.searches += 1
        seen = observation_from_views(views_from_pixels(pixels, depths, self.cameras, self.model, self.config.pose),
                                      self.config.pose.max_points)
        before = self.estimator.state()
        self.problem.set_observation(seen)
        centre = np.mean(points, axis=0)
        headings = np.linspace(-np.pi, np.pi, start.headings, endpoint=False)
        moved = self.pose.copy()
        moved[:2] = centre[:2] + self.anchor
        candidates = np.vstack([start_candidates(self.model, centre, headings, start.seat_share),
                                self.pose[None], moved[None]])
        spread = start_spread(self.model, start)
        self.estimator.initialise(best_sample(self.problem, candidates, spread, recover.samples,
                                              self.estimator.filter.rng), spread)
        for _ in range(recover.steps):
            pose = self.estimator.step(seen)
        old, new = self.problem.log_likelihood(np.stack([self.pose, pose])).sum(axis=1)
        if new <= old or explained_share(self.body_distance(pose), points, recover.explained_m) <= share:
            self.estimator.restore(before)
            return
        self.recoveries += 1
        self.pose = pose
        if self.start_twins is not None:  # they compared another estimate (settle_facing)
            self.start_twins = []
        self.path[-1], self.heights[-1] = pose[:2].copy(), float(pose[2])
        if self.occlusion is not None:
            self.occlusion.memory = pose.copy()

    def learn_shape(self, observation: Observation) -> None:
        """With ``shape.learn``: measure the neck depth and shoulder breadth
        (:func:`occupose.body.size.neck_and_shoulders`) in the first of ``observation``'s
        views that sees this estimate from the front or the back (``shape.frontal_deg``,
        ``shape.level_deg``; trunk, head and arms in view, upright); with ``shape.frames``
        measurements, go on with a model of their medians
        (:func:`occupose.body.size.dims_with_shoulders`; the particles moved so that the
        estimate keeps its joints)."""
        shape, size = self.config.shape, self.config.size
        if self.shaped or abs(self.pose[self.model.dof("trunk_lean")]) > shape.lean:
            return
        legs = np.array([name.endswith(("thigh", "shin")) for name in self.model.part_names])
        if not (self.part_visible | legs).all():
            return
        heading = self.pose[self.problem.heading_dof]
        for view in observation.views:
            ray = self.pose[:2] - view.camera.position[:2]
            square = abs(np.cos(heading) * ray[0] + np.sin(heading) * ray[1]) / max(float(np.hypot(*ray)), 1e-9)
            if view.camera.down_angle > np.deg2rad(shape.level_deg) or square < np.cos(np.deg2rad(shape.frontal_deg)):
                continue
            points = view.points
            measured = neck_and_shoulders(breadth_profile(points, size), size) if len(points) >= size.top_rank \
                else None
            if measured is not None:
                self.shapes.append(measured)
                break
        if len(self.shapes) < shape.frames:
            return
        depth, breadth = np.median(self.shapes, axis=0)
        self._resize(dims_with_shoulders(self.model.dims, self.model.girth, depth, breadth, size))
        self.shaped = True

    def learn_stature(self, observation: Observation) -> None:
        """Measure the stature again (the top of the person's points, as at the start) on
        its first ``shape.stature_frames`` estimates with the pelvis upright (at least
        ``shape.stature_upright`` of the legs' length above the floor); when their median
        differs from the model's by more than ``shape.stature_change``, go on with the
        model scaled to it (its proportions kept; the particles moved so that the estimate
        keeps its joints). Then the stature is known (PoseProblem.stature_known: the upper
        body's head may not rise above it)."""
        shape, size = self.config.shape, self.config.size
        dims = self.model.dims
        if len(self.tops) >= shape.stature_frames or self.pose[self.model.dof("z")] < shape.stature_upright * dims.hip_height:
            return
        points = np.concatenate([view.points for view in observation.views])
        if len(points) < size.top_rank:
            return
        self.tops.append(top_height(points[:, 2], size.top_rank) + size.top_bias)
        if len(self.tops) == shape.stature_frames:
            if abs(np.median(self.tops) - dims.height) > shape.stature_change:
                self._resize(dims.scaled(float(np.clip(np.median(self.tops), 1.0, 2.2))))
            self.problem.stature_known = True

    def _resize(self, dims) -> None:
        """Go on with a model of ``dims`` (BodyDims; girth kept), the particles moved so
        that the estimate keeps its joints."""
        model = body_model(self.model.name, dims, self.model.girth)
        pose = pose_from_joints(model, joints_from_pose(self.model, self.pose), refine=False)
        self.model = model
        self.problem.resize(model)
        self.estimator.shift(pose - self.pose)
        self.pose = pose
        self.stance = standing_pose(model)

    def walking(self) -> tuple[float, float] | None:
        """(direction, weight) of PoseProblem.walking: the way the pelvis moved over the last
        ``carry.walk_frames`` estimates, weighted ``carry.walk_prior`` nats from
        ``walk_from + walk_ramp`` m/s up (linearly from 0 at ``walk_from``); None when
        slower, too new, or not upright (:meth:`_upright`)."""
        carry = self.config.carry
        velocity = self._velocity()
        speed = 0.0 if velocity is None else float(np.hypot(*velocity))
        if speed <= carry.walk_from or not self._upright(carry.walk_frames):
            return None
        direction = float(np.arctan2(velocity[1], velocity[0]))
        if self._keeps_settled() and abs(wrap_angle(direction - self.pose[self.problem.heading_dof])) > np.deg2rad(
                carry.backwards_deg):
            return None
        return direction, carry.walk_prior * min(1.0, (speed - carry.walk_from) / carry.walk_ramp)

    def _upright(self, frames: int) -> bool:
        """Whether the pelvis stayed at least ``carry.upright`` of its standing height (the
        body's :func:`occupose.body.standing_pose`) above the floor over the last ``frames``
        estimates: a walk keeps it there, while a person sitting down (or getting up) moves
        backwards (forwards) as it drops (rises), and is not walking the way it faces. On
        the mocap walks of the randomized benchmark the pelvis stays above 0.89 of the
        walker's standing height in every half second of walking faster than 0.3 m/s."""
        floor = 0.0 if self.problem.floor is None else self.problem.floor
        return min(self.heights[-frames:]) - floor >= self.config.carry.upright * self.stance[2]

    def standing(self) -> bool:
        """Whether the pelvis moved at most ``carry.walk_from`` m/s over the last
        ``carry.walk_frames`` estimates (PoseProblem.standing: the feet are on the floor)."""
        velocity = self._velocity()
        return velocity is not None and float(np.hypot(*velocity)) <= self.config.carry.walk_from

    def _velocity(self) -> np.ndarray | None:
        """(2,) m/s of the pelvis over the last ``carry.walk_frames`` estimates (forward in
        time, also for a person run backwards); None for fewer."""
        frames = self.config.carry.walk_frames
        if len(self.path) < frames:
            return None
        return (self.path[-1] - self.path[-frames]) / (frames - 1) * self.fps * self._time

    @property
    def _time(self) -> float:
        """-1 for a person run back in time (its path goes the way it walked from), else 1."""
        return -1.0 if self.backwards else 1.0

    def step(self) -> np.ndarray:
        """(2,) metres per frame: the faster of two measures of its walk over its last
        ``carry.frames`` estimates with every part in view, when there are two of them: their
        mean step (from the first to the last; they need not follow one another) and their
        blob's median velocity; else the pelvis's mean step over its last ``carry.frames``
        estimates; at most ``carry.max_speed``. A person walking behind a cabinet is
        estimated on what is left in view, which stalls at the cabinet's edge, so those last
        estimates fall behind; the blob's velocity, smoothed by the blob tracker, lags a
        person speeding up; each measure falls short where the other does not, and the
        median leaves out the frames where the blob was already being cut."""
        carry = self.config.carry
        recent = [(n, xy, velocity) for n, xy, velocity in self.clear if n > self.estimates - carry.frames]
        if len(recent) > 1:
            (first, start, _), (last, end, _) = recent[0], recent[-1]
            walked = (end - start) / (last - first)
            blob = np.median([velocity for _, _, velocity in recent], axis=0) / self.fps
            step = max(walked, blob, key=lambda s: float(np.hypot(*s)))
        elif len(self.path) > 1:
            step = (self.path[-1] - self.path[0]) / (len(self.path) - 1)
        else:
            return np.zeros(2)
        return step * min(1.0, carry.max_speed / max(float(np.hypot(*step)), 1e-12))

    def carry(self, depths: Mapping[str, np.ndarray]) -> bool:
        """A frame without an estimate (gone or suspended): the pose walks on at :meth:`step`;
        at a walker's speed (above ``carry.walk_from``) it comes back where it was carried to
        (:meth:`come_back`), and its legs (``carry.stand_dofs``, and their occlusion memory)
        stand, the feet under the hips: a stride frozen while the walk goes on out of sight
        is a whole step off at every other step, where the middle of a gait cycle is at most
        half a step off. Unless a camera sees through where its torso would walk to
        (:func:`occupose.pose.occlusion.parts_seen_through` in this frame's ``depths``, camera
        name -> (H, W) float32 metres): nobody is there, so the walk out of sight has
        stopped; the pose then stays where it is. Nor out of every camera's image (beside it
        or behind the camera, :func:`occupose.pose.occlusion.parts_out_of_view`), nor out of
        the watched ``area`` (beyond the cameras' range): out of sight there is not hidden,
        and nothing would ever stop the walk (an estimate that slid off a person standing
        still was carried out of the room, and on behind the camera, for 140 frames while
        its blob stayed; another on through the back wall). Returns whether it walked on (a
        step of 0 is a walk)."""
        step = self.step()
        pose = self.pose.copy()
        pose[:2] += step
        self.lost = True
        model = self.model
        a, b = capsules_from_poses(model, pose[None])
        torso, spheres = model.part_names.index("torso"), self.config.occlusion.spheres
        outside = self.area is not None and not np.all((pose[:2] >= self.area[0]) & (pose[:2] <= self.area[1]))
        if np.any(step) and (outside or parts_seen_through(a[0], b[0], model.capsule_radii, model.capsule_part, model.num_parts,
                                                depths, self.cameras, spheres, self.config.occlusion.margin)[torso]
                             or parts_out_of_view(a[0], b[0], model.capsule_radii, model.capsule_part,
                                                  model.num_parts, self.cameras, spheres)[torso]):
            self.walked_on = False
            return False
        self.pose = pose
        self.walked_on = float(np.hypot(*step)) * self.fps > self.config.carry.walk_from
        if self.walked_on:
            self.pose[self.legs] = self.stance[self.legs]
            if self.occlusion is not None:
                self.occlusion.memory[self.legs] = self.stance[self.legs]
        return True

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
        """This frame's joints; ``fresh``: estimated from this frame's data (else carried)."""
        joints = joints_from_pose(self.model, self.pose)
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
