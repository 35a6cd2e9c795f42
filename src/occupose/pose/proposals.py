"""Data-driven limb proposals: a few particles try each arm and leg where its points are.

An annealed search turns a limb by a few tenths of a radian per frame. An arm the filter
has lost (left hanging while the person raised it, or left behind the torso where no
point says where it is) is not found again by diffusion: the poses in between lie in
space the camera sees as empty, which the free-space term penalises. The points tell where
it is, though: those farther than ``unexplained`` from the current estimate's surface and
within reach of a shoulder (nearer that shoulder than the other). When an arm has at least
``min_points`` of them, the point at their 90th percentile of distance from the shoulder
is taken as the hand, the arm reaches for it (:func:`reach_towards`: straight when the
hand is out of reach, else bent with the elbow where the points are), and the arm's
joint angles of that pose (the analytic inverse kinematics of
:func:`occupose.body.limb_angles`) replace those of a share of the particles before
the filter's step. The filter's weights decide: a proposal that does not explain the
points better dies at the first resampling.

Legs the same way, from their feet (:func:`feet`), for a person who stands (a walker's
foot leaves the floor): a leg behind furniture (a chair's back) whose foot shows below it
has few points of its own, and drifts where nothing is seen. The unexplained points less
than ``foot_height`` above the floor nearer one hip than the other (across the floor) and
within reach of it show that leg's foot, and the ankle lies behind the median of the
foot's points (the toes are ahead of it, and a camera sees the foot's near side): when it
is more than ``foot_lost`` from the leg's ankle, the leg reaches it, the knee bent
forwards (our legs have no feet, so the toes of a leg in the right place are unexplained
too: a foot found nearer its ankle is left to the filter).

The settings named here are fields of :class:`occupose.config.ProposalConfig`.

And a still person's legs as each other when they are bent (seated or crouching;
:func:`mirrored_legs`): a thigh with few points of its own (behind the other leg from one
camera, behind a table from the other) was left hanging while the person sat down, as
nothing seen pulls it forwards, until the other leg's angles were tried.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.distance import cdist

from occupose.body import LIMB_DOFS, BodyModel, capsules_from_poses, joints_from_pose, limb_angles
from occupose.config import ProposalConfig
from occupose.joints import JOINT_INDEX
from occupose.likelihood import Observation, point_distances

SIDES = ("left", "right")
#: Joints of each limb from its root: (root, middle, end).
LIMB_JOINTS = {"arm": ("shoulder", "elbow", "wrist"), "leg": ("hip", "knee", "ankle")}


def limb_dofs(model: BodyModel, side: str, limb: str = "arm") -> np.ndarray:
    """(4,) int64: the DOFs of ``side``'s ``limb`` that a proposal sets (an arm's shoulder
    flex, abd, rot and elbow, a forearm twist left to the filter; a leg's hip flex, abd,
    rot and knee)."""
    return np.array([model.dof_names.index(f"{side}_{name}") for name in LIMB_DOFS[limb]], np.int64)


def unexplained_points(model: BodyModel, pose: np.ndarray, observation: Observation,
                       unexplained: float = ProposalConfig.unexplained) -> np.ndarray:
    """(M, 3) the observation's points farther than ``unexplained`` metres from the surface
    of ``pose`` (D,)."""
    if len(observation.points) == 0:
        return observation.points
    a, b = capsules_from_poses(model, pose[None])
    distance, _ = point_distances(a, b, model.capsule_radii, observation)
    return observation.points[distance[0] > unexplained]


def limb_proposals(model: BodyModel, pose: np.ndarray, observation: Observation, *, legs: bool = True,
                   floor: float | None = 0.0, config: ProposalConfig | None = None
                   ) -> list[tuple[np.ndarray, np.ndarray]]:
    """The arm and leg poses that the points unexplained by ``pose`` suggest.

    model : the body model; pose : (D,) the current estimate; observation : the frame's
    Observation (its points, world metres, and their blocks, shared with the likelihood);
    legs : propose legs too (a model with legs and a ``floor``); floor : its height, metres
    config : the proposals' settings (default :class:`occupose.config.ProposalConfig`'s)
    Returns a list of (dofs (4,) int64, values (4,) float64), one per limb with evidence.
    """
    config = ProposalConfig() if config is None else config
    points = observation.points
    loose = unexplained_points(model, pose, observation, config.unexplained)
    if len(loose) < config.min_points:
        return []
    joints = joints_from_pose(model, pose)
    proposals = _arm_proposals(model, pose, joints, points, loose, config)
    if legs and floor is not None and "left_hip_flex" in model.dof_names:
        viewpoints = np.array([view.camera.position for view in observation.views]).reshape(-1, 3)
        for side, ankle in feet(model, pose, loose, floor, points=points, viewpoints=viewpoints,
                                config=config).items():
            hip, thigh, shin = _limb(joints, side, "leg")
            if np.linalg.norm(ankle[:2] - joints[JOINT_INDEX[f"{side}_ankle"], :2]) < config.foot_lost:
                continue
            within = points[np.linalg.norm(points - hip, axis=1) < config.reach * (thigh + shin)]
            knee, ankle = reach_towards(hip, ankle, thigh, shin, within, config.elbow_candidates,
                                        bend=forward(model, pose))
            proposals.append((limb_dofs(model, side, "leg"), limb_angles(model, pose, side, "leg", hip, knee, ankle)))
    return proposals


def mirrored_legs(model: BodyModel, pose: np.ndarray, active: np.ndarray | None, floor: float | None, *,
                  config: ProposalConfig | None = None) -> list[tuple[np.ndarray, np.ndarray]]:
    """Each leg set as the other one is: its hip flex, abd, rot and knee (the model's DOFs
    mirror left and right) that ``active`` (D,) bool allows (default all; a hidden shin's
    knee is frozen; None: all), when they differ from the other leg's of ``pose`` (D,) by
    more than ``config.mirror_differ`` radians in some DOF and the hips are more than
    ``config.mirror_bent`` metres below a straight leg's reach above the ``floor`` (its
    height, metres; seated or crouching). Returns a list of (dofs (n,) int64, values (n,)
    float64), at most one per leg ([] for a model without legs or without a floor).

    A thigh with few points of its own (behind the other leg from one camera, behind a
    table from the other) was left hanging while the person sat down, as nothing seen
    pulls it forwards: the other leg's angles are a guess the weights take or leave.
    Standing, the legs show themselves; proposed there too, the mirrored legs cost the
    torso's search particles behind a chair (8.4 -> 8.8 cm over 6 runs).
    """
    pose = np.asarray(pose, dtype=np.float64)
    if pose.shape != (model.num_dofs,):
        raise ValueError(f"pose must have shape ({model.num_dofs},), got {pose.shape}")
    if active is not None:
        active = np.asarray(active)
        if active.shape != (model.num_dofs,) or active.dtype != bool:
            raise ValueError(f"active must be a ({model.num_dofs},) bool array, got {active.dtype} {active.shape}")
    if "left_hip_flex" not in model.dof_names or floor is None:
        return []
    config = ProposalConfig() if config is None else config
    joints = joints_from_pose(model, pose)
    hips = min(joints[JOINT_INDEX[f"{side}_hip"], 2] for side in SIDES) - floor
    if hips > model.dims.hip_height - config.mirror_bent:
        return []
    proposals = []
    for side, other in (("left", "right"), ("right", "left")):
        dofs, source = limb_dofs(model, side, "leg"), limb_dofs(model, other, "leg")
        keep = np.ones(len(dofs), bool) if active is None else active[dofs]
        if keep.any() and np.max(np.abs(pose[dofs[keep]] - pose[source[keep]])) > config.mirror_differ:
            proposals.append((dofs[keep], pose[source[keep]].copy()))
    return proposals


def feet(model: BodyModel, pose: np.ndarray, loose: np.ndarray, floor: float, *,
         points: np.ndarray | None = None, viewpoints: np.ndarray | None = None,
         config: ProposalConfig | None = None) -> dict[str, np.ndarray]:
    """Where the feet that ``loose`` points (M, 3) show put the ankles: side -> (3,) metres.

    With ``config`` (:class:`occupose.config.ProposalConfig`, default its defaults): a leg's
    foot is its ``min_points`` or more loose points less than ``foot_height`` above
    ``floor``, nearer its hip than the other across the floor and within reach of it
    (``reach`` times the leg's length). The loose points of a foot are what ``pose``
    leaves unexplained, its toes for a leg in about the right place, so the foot is all of
    ``points`` (N, 3) (the person's, default ``loose``) below that height within
    ``foot_radius`` across the floor of their median. Its ankle is behind their median:
    by ``foot_ahead`` against the way ``pose`` faces (the toes reach some 0.2 m beyond the
    ankle, the heel 0.05 m behind it), and by the shin's radius at the
    ankle away from the nearest of ``viewpoints`` (V, 3) (the cameras' positions, world
    metres: a camera sees the near side of a foot), at the model's ankle height.
    model : a model with legs; pose : (D,) the current estimate.
    """
    config = ProposalConfig() if config is None else config
    low = loose[loose[:, 2] < floor + config.foot_height]
    if len(low) < config.min_points:
        return {}
    points = loose if points is None else points
    near_floor = points[points[:, 2] < floor + config.foot_height]
    viewpoints = np.zeros((0, 3)) if viewpoints is None else np.asarray(viewpoints, float).reshape(-1, 3)
    joints = joints_from_pose(model, pose)
    hips = np.array([joints[JOINT_INDEX[f"{side}_hip"]] for side in SIDES])
    nearer = np.argmin(np.linalg.norm(low[:, None, :2] - hips[None, :, :2], axis=2), axis=1)
    found = {}
    for s, side in enumerate(SIDES):
        hip, thigh, shin = _limb(joints, side, "leg")
        mine = (nearer == s) & (np.linalg.norm(low - hip, axis=1) < config.reach * (thigh + shin))
        if mine.sum() < config.min_points:
            continue
        centre = np.median(low[mine], axis=0)
        foot = near_floor[np.linalg.norm(near_floor[:, :2] - centre[:2], axis=1) < config.foot_radius]
        ankle = (np.median(foot, axis=0) if len(foot) else centre) - config.foot_ahead * forward(model, pose)
        if len(viewpoints):
            away = ankle[:2] - viewpoints[np.argmin(np.linalg.norm(viewpoints[:, :2] - ankle[:2], axis=1)), :2]
            radius = model.capsule_radii[model.capsule_part == model.part_names.index(f"{side}_shin"), 1].max()
            ankle[:2] += radius * away / max(float(np.linalg.norm(away)), 1e-9)
        ankle[2] = floor + model.dims.ankle_height
        found[side] = ankle
    return found


def forward(model: BodyModel, pose: np.ndarray) -> np.ndarray:
    """(3,) the horizontal unit vector ``pose`` (D,) faces (its heading)."""
    heading = pose[model.dof_names.index("heading")]
    return np.array([np.cos(heading), np.sin(heading), 0.0])


def _limb(joints: np.ndarray, side: str, limb: str) -> tuple[np.ndarray, float, float]:
    """The root joint (3,) of ``side``'s ``limb`` and its two segments' lengths, metres."""
    root, mid, end = (joints[JOINT_INDEX[f"{side}_{j}"]] for j in LIMB_JOINTS[limb])
    return root, float(np.linalg.norm(mid - root)), float(np.linalg.norm(end - mid))


def _arm_proposals(model, pose, joints, points, loose, config: ProposalConfig):
    shoulders = np.array([joints[JOINT_INDEX[f"{side}_shoulder"]] for side in SIDES])
    to_shoulder = np.linalg.norm(loose[:, None, :] - shoulders[None], axis=2)  # (M, 2)
    nearer = np.argmin(to_shoulder, axis=1)
    proposals = []
    for s, side in enumerate(SIDES):
        shoulder, upper, fore = _limb(joints, side, "arm")
        reach = to_shoulder[:, s]
        mine = (nearer == s) & (reach < config.reach * (upper + fore)) & (reach > upper)
        if mine.sum() < config.min_points:
            continue
        mine = np.flatnonzero(mine)
        hand = loose[mine[np.argsort(reach[mine])[int(0.9 * (len(mine) - 1))]]]
        within = points[np.linalg.norm(points - shoulder, axis=1) < config.reach * (upper + fore)]
        elbow, wrist = reach_towards(shoulder, hand, upper, fore, within, config.elbow_candidates)
        proposals.append((limb_dofs(model, side), limb_angles(model, pose, side, "arm", shoulder, elbow, wrist)))
    return proposals


def reach_towards(root: np.ndarray, end: np.ndarray, upper: float, lower: float, points: np.ndarray | None,
                  candidates: int = ProposalConfig.elbow_candidates, bend: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(middle, end) (3,) metres of a limb from ``root`` reaching for ``end``: an arm's
    elbow and wrist from its shoulder, a leg's knee and ankle from its hip.

    upper, lower : segment lengths, metres; points : (N, 3) the person's points, or None
    (nothing seen of the limb); bend : (3,) a direction the middle joint must lie along (a
    knee bends forwards), or None. Out of reach, the limb is straight towards the end.
    Within reach, its end is on ``end`` and the middle joint on its circle of possible
    places; of ``candidates`` places around it (those with a positive component along
    ``bend``, if any), the one whose two segments lie nearest the points (mean distance of
    5 samples along each to the nearest point) wins; without points, the one farthest
    along ``bend``.
    """
    offset = end - root
    distance = float(np.linalg.norm(offset))
    axis = offset / distance
    if distance >= upper + lower:
        return root + upper * axis, root + (upper + lower) * axis
    along = (upper ** 2 - lower ** 2 + distance ** 2) / (2 * distance)
    radius = np.sqrt(max(upper ** 2 - along ** 2, 0.0))
    side = np.cross(axis, [0.0, 0.0, 1.0] if abs(axis[2]) < 0.9 else [1.0, 0.0, 0.0])
    side /= np.linalg.norm(side)
    up = np.cross(side, axis)
    angles = np.linspace(0.0, 2 * np.pi, candidates, endpoint=False)
    around = np.cos(angles)[:, None] * side + np.sin(angles)[:, None] * up
    if bend is not None and (around @ np.asarray(bend, float) > 0.0).any():
        around = around[around @ np.asarray(bend, float) > 0.0]
    middles = root + along * axis + radius * around
    if points is None or len(points) == 0:
        return middles[np.argmax(around @ np.asarray(bend, float)) if bend is not None else 0], end
    t = np.linspace(0.1, 0.9, 5)[None, :, None]
    samples = np.concatenate([root + t * (middles[:, None] - root),
                              middles[:, None] + t * (end - middles[:, None])], axis=1)  # (E, 10, 3)
    squared = cdist(samples.reshape(-1, 3), points, "sqeuclidean").min(axis=1)  # quicker than a tree here
    nearest = np.sqrt(squared).reshape(samples.shape[:2])
    return middles[np.argmin(nearest.mean(axis=1))], end
