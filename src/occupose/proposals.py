"""Data-driven arm proposals: a few particles try each arm where its points are.

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
:func:`occupose.body.arm_angles`) replace those of a share of the particles before
the filter's step. The filter's weights decide: a proposal that does not explain the
points better dies at the first resampling.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from occupose.body import BodyModel, arm_angles, capsules_from_poses, joints_from_poses
from occupose.joints import JOINT_INDEX
from occupose.likelihood import Observation, point_distances

#: Default distance, metres, beyond which a point is not explained by the estimate.
UNEXPLAINED = 0.05
#: Default least number of unexplained points that make an arm proposal.
MIN_POINTS = 10
#: Reach of an arm beyond its upper arm + forearm (the hand), as a factor.
REACH = 1.25
SIDES = ("left", "right")
ARM_DOFS = ("shoulder_flex", "shoulder_abd", "shoulder_rot", "elbow")
#: Places tried for the elbow of an arm that reaches a hand within its length.
ELBOW_CANDIDATES = 8


def arm_dofs(model: BodyModel, side: str) -> np.ndarray:
    """(4,) int64: the DOFs of ``side``'s arm that a proposal sets (shoulder flex, abd, rot
    and elbow; a forearm twist is left to the filter)."""
    return np.array([model.dof_names.index(f"{side}_{name}") for name in ARM_DOFS], np.int64)


def arm_proposals(model: BodyModel, pose: np.ndarray, observation: Observation, *,
                  unexplained: float = UNEXPLAINED, min_points: int = MIN_POINTS) -> list[tuple[np.ndarray, np.ndarray]]:
    """The arm poses that the points unexplained by ``pose`` suggest.

    model : the body model; pose : (D,) the current estimate; observation : the frame's
    Observation (its points, world metres, and their blocks, shared with the likelihood)
    Returns a list of (dofs (n,) int64, values (n,) float64), one per arm with evidence.
    """
    points = observation.points
    if len(points) < min_points:
        return []
    a, b = capsules_from_poses(model, pose[None])
    distance, _ = point_distances(a, b, model.capsule_radii, observation)
    loose = points[distance[0] > unexplained]
    if len(loose) < min_points:
        return []
    joints = joints_from_poses(model, pose[None])[0]
    shoulders = np.array([joints[JOINT_INDEX[f"{side}_shoulder"]] for side in SIDES])
    to_shoulder = np.linalg.norm(loose[:, None, :] - shoulders[None], axis=2)  # (M, 2)
    nearer = np.argmin(to_shoulder, axis=1)
    proposals = []
    for s, side in enumerate(SIDES):
        shoulder, elbow, wrist = (joints[JOINT_INDEX[f"{side}_{j}"]] for j in ("shoulder", "elbow", "wrist"))
        upper, fore = np.linalg.norm(elbow - shoulder), np.linalg.norm(wrist - elbow)
        reach = to_shoulder[:, s]
        mine = (nearer == s) & (reach < REACH * (upper + fore)) & (reach > upper)
        if mine.sum() < min_points:
            continue
        mine = np.flatnonzero(mine)
        hand = loose[mine[np.argsort(reach[mine])[int(0.9 * (len(mine) - 1))]]]
        within = points[np.linalg.norm(points - shoulder, axis=1) < REACH * (upper + fore)]
        elbow, wrist = reach_towards(shoulder, hand, upper, fore, within)
        proposals.append((arm_dofs(model, side), arm_angles(model, pose, side, shoulder, elbow, wrist)))
    return proposals


def reach_towards(shoulder: np.ndarray, hand: np.ndarray, upper: float, fore: float, points: np.ndarray,
                  candidates: int = ELBOW_CANDIDATES) -> tuple[np.ndarray, np.ndarray]:
    """(elbow, wrist) (3,) metres of an arm from ``shoulder`` reaching for ``hand``.

    upper, fore : segment lengths, metres; points : (N, 3) the person's points. Out of
    reach, the arm is straight towards the hand. Within reach, the wrist is on the hand
    and the elbow on its circle of possible places; of ``candidates`` places around it,
    the one whose two segments lie nearest the points (mean distance of 5 samples along
    each to the nearest point) wins.
    """
    offset = hand - shoulder
    distance = float(np.linalg.norm(offset))
    axis = offset / distance
    if distance >= upper + fore:
        return shoulder + upper * axis, shoulder + (upper + fore) * axis
    along = (upper ** 2 - fore ** 2 + distance ** 2) / (2 * distance)
    radius = np.sqrt(max(upper ** 2 - along ** 2, 0.0))
    side = np.cross(axis, [0.0, 0.0, 1.0] if abs(axis[2]) < 0.9 else [1.0, 0.0, 0.0])
    side /= np.linalg.norm(side)
    up = np.cross(side, axis)
    angles = np.linspace(0.0, 2 * np.pi, candidates, endpoint=False)
    elbows = shoulder + along * axis + radius * (np.cos(angles)[:, None] * side + np.sin(angles)[:, None] * up)
    t = np.linspace(0.1, 0.9, 5)[None, :, None]
    samples = np.concatenate([shoulder + t * (elbows[:, None] - shoulder),
                              elbows[:, None] + t * (hand - elbows[:, None])], axis=1)  # (E, 10, 3)
    nearest = cKDTree(points).query(samples.reshape(-1, 3))[0].reshape(samples.shape[:2])
    return elbows[np.argmin(nearest.mean(axis=1))], hand
