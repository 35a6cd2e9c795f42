"""The generator's pose vector: its layout, forward kinematics, the stance, leg inverse kinematics.

A body is a :class:`occupose.body.dims.BodyDims` (segment lengths) and a pose is a vector
of ``POSE_SIZE`` numbers (root position and joint angles, layout in :data:`POSE_NAMES`);
:func:`joints_from_procedural` turns poses into the 15 canonical joints of
:mod:`occupose.joints`, (T, 15, 3) float64, world metres, z up, floor z = 0. (The
tracker's body models have poses of their own, :mod:`occupose.body.model`; these are the
generator's.) :func:`stance` is the relaxed upright start pose of every action.

Pose conventions (angles in radians):

- ``x, y, z``: pelvis (midpoint of the hips), world metres.
- ``heading``: facing direction about +z, 0 = facing +x, counterclockwise. The person's
  left is 90 deg counterclockwise from the facing direction, so facing = (left_hip -
  right_hip) x up. Headings are not wrapped (a chain of turns may leave (-pi, pi]).
- ``trunk_lean`` forward pitch of the trunk, ``trunk_side`` lean to the person's left,
  ``trunk_twist`` shoulders turned left of the pelvis, ``neck_flex`` head nodding forward.
- per side (``left_``/``right_``): ``hip_flex`` thigh forward (pi/2 = horizontal, as when
  sitting), ``hip_abd`` thigh out to the side, ``knee`` flexion (0 = straight);
  ``shoulder_flex`` arm forward (pi/2 = horizontal forward, pi = straight up),
  ``shoulder_abd`` arm out to the side (applied after flexion: pi/2 = horizontal sideways),
  ``shoulder_rot`` external rotation of the upper arm (turns a bent forearm outwards, or
  upwards when the arm is out to the side; negative = inwards across the body),
  ``elbow`` flexion (0 = straight). The same numbers on both sides give a mirror pose.
"""

from __future__ import annotations

import math

import numpy as np

from occupose.body.dims import DEFAULT_DIMS, BodyDims
from occupose.body.postures import ARM_REST
from occupose.joints import JOINT_INDEX, NUM_JOINTS

# ---------------------------------------------------------------------------------------
# Pose layout

#: Offsets of the per-side entries within a side's block of the pose vector.
HIP_FLEX, HIP_ABD, KNEE, SHOULDER_FLEX, SHOULDER_ABD, SHOULDER_ROT, ELBOW = range(7)
_SIDE_NAMES = ("hip_flex", "hip_abd", "knee", "shoulder_flex", "shoulder_abd", "shoulder_rot", "elbow")

X, Y, Z, HEADING, TRUNK_LEAN, TRUNK_SIDE, TRUNK_TWIST, NECK_FLEX = range(8)
#: Start of the left and right blocks: the left knee is ``pose[LEFT + KNEE]``.
LEFT, RIGHT = 8, 8 + len(_SIDE_NAMES)

POSE_NAMES: tuple[str, ...] = (
    ("x", "y", "z", "heading", "trunk_lean", "trunk_side", "trunk_twist", "neck_flex")
    + tuple(f"left_{n}" for n in _SIDE_NAMES) + tuple(f"right_{n}" for n in _SIDE_NAMES)
)
POSE_INDEX: dict[str, int] = {name: i for i, name in enumerate(POSE_NAMES)}
POSE_SIZE = len(POSE_NAMES)

_UPPER = np.r_[TRUNK_LEAN:NECK_FLEX + 1, LEFT + SHOULDER_FLEX:LEFT + ELBOW + 1,
               RIGHT + SHOULDER_FLEX:RIGHT + ELBOW + 1]
_SIDES = ((LEFT, 1.0), (RIGHT, -1.0))

#: Knee flexion of a relaxed upright stance (keeps the legs off the straight-knee singularity).
STAND_KNEE = 0.06


def pose_with(pose, **values) -> np.ndarray:
    """A copy of ``pose`` (D,) with the named entries (see :data:`POSE_NAMES`) replaced."""
    out = _check_pose(pose, "pose")
    for name, value in values.items():
        if name not in POSE_INDEX:
            raise ValueError(f"unknown pose entry {name!r}; valid names: {', '.join(POSE_NAMES)}")
        out[POSE_INDEX[name]] = float(value)
    return out


def stance(xy=(0.0, 0.0), heading: float = 0.0, dims: BodyDims = DEFAULT_DIMS) -> np.ndarray:
    """Relaxed upright pose (D,): pelvis above ``xy`` (metres), feet under the hips, arms down."""
    xy = np.asarray(xy, dtype=np.float64)
    if xy.shape != (2,) or not np.all(np.isfinite(xy)):
        raise ValueError(f"xy must be two finite numbers (x, y) in metres, got {xy!r}")
    if not math.isfinite(heading):
        raise ValueError(f"heading must be finite radians, got {heading!r}")
    pose = np.zeros(POSE_SIZE)
    pose[[X, Y]] = xy
    pose[Z] = dims.ankle_height + _reach(dims, STAND_KNEE)
    pose[HEADING] = heading
    for base, _ in _SIDES:
        pose[base + SHOULDER_FLEX:base + ELBOW + 1] = ARM_REST
    _set_legs(pose[None], _hips(pose[None], dims) * [1, 1, 0] + [0, 0, dims.ankle_height], dims)
    return pose


def _check_pose(pose, name: str = "start") -> np.ndarray:
    pose = np.array(pose, dtype=np.float64)
    if pose.shape != (POSE_SIZE,) or not np.all(np.isfinite(pose)):
        raise ValueError(f"{name} must be a finite pose vector of shape ({POSE_SIZE},), got shape {pose.shape}")
    return pose


# ---------------------------------------------------------------------------------------
# Forward and inverse kinematics


def _frame(heading):
    """Forward and left unit vectors (N, 3) of headings (N,)."""
    c, s, z = np.cos(heading), np.sin(heading), np.zeros_like(heading)
    return np.stack([c, s, z], -1), np.stack([-s, c, z], -1)


def _rotations(axis: int, angles) -> np.ndarray:
    """(N, 3, 3) rotations by ``angles`` (N,) about coordinate axis 0, 1 or 2 (right hand)."""
    c, s = np.cos(angles), np.sin(angles)
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    out = np.zeros(angles.shape + (3, 3))
    out[:, axis, axis] = 1.0
    out[:, i, i] = c
    out[:, j, j] = c
    out[:, i, j] = -s
    out[:, j, i] = s
    return out


def _limb(root, fwd, out, up, side, flex, abd, rot, bend, l1, l2, leg: bool):
    """Middle and end joints (N, 3) of a two-segment limb (see the module docstring).

    ``fwd``, ``out`` (away from the body's midline) and ``up`` (N, 3) are the frame the limb
    hangs in; at zero angles it points down and bends forward (arm) or backward (leg).
    """
    cf, sf = np.cos(flex)[:, None], np.sin(flex)[:, None]
    ca, sa = np.cos(abd)[:, None], np.sin(abd)[:, None]
    a = ca * (sf * fwd - cf * up) + sa * out  # upper segment: flexed forward, then swung out
    p = cf * fwd + sf * up  # bending direction, perpendicular to a and to out
    if leg:
        p = -p
    q = side * np.cross(p, a)  # p turned a quarter outwards about a (external rotation)
    p = np.cos(rot)[:, None] * p + np.sin(rot)[:, None] * q
    d = np.cos(bend)[:, None] * a + np.sin(bend)[:, None] * p
    mid = root + l1 * a
    return mid, mid + l2 * d


def _hips(poses, dims: BodyDims) -> np.ndarray:
    """(N, 2, 3) left and right hip joints of poses (N, D)."""
    _, left = _frame(poses[:, HEADING])
    half = 0.5 * dims.pelvis_width
    return poses[:, None, X:Z + 1] + np.array([half, -half])[None, :, None] * left[:, None, :]


def joints_from_procedural(poses, dims: BodyDims = DEFAULT_DIMS) -> np.ndarray:
    """Canonical joints of poses.

    poses : (..., D) float, pose vectors (layout :data:`POSE_NAMES`).
    Returns (..., 15, 3) float64, world metres, z up, joints in the order of
    :data:`occupose.joints.JOINTS`.
    """
    poses = np.asarray(poses, dtype=np.float64)
    if poses.ndim < 1 or poses.shape[-1] != POSE_SIZE:
        raise ValueError(f"poses must have shape (..., {POSE_SIZE}), got {poses.shape}")
    lead = poses.shape[:-1]
    p = poses.reshape(-1, POSE_SIZE)
    up = np.array([0.0, 0.0, 1.0])
    fwd, left = _frame(p[:, HEADING])
    trunk = (_rotations(2, p[:, HEADING]) @ _rotations(1, p[:, TRUNK_LEAN])
             @ _rotations(0, -p[:, TRUNK_SIDE]) @ _rotations(2, p[:, TRUNK_TWIST]))
    t_fwd, t_left, t_up = trunk[:, :, 0], trunk[:, :, 1], trunk[:, :, 2]
    out = np.empty((p.shape[0], NUM_JOINTS, 3))
    pelvis = p[:, X:Z + 1]
    neck = pelvis + dims.spine * t_up
    nf = p[:, NECK_FLEX][:, None]
    out[:, JOINT_INDEX["pelvis"]] = pelvis
    out[:, JOINT_INDEX["neck"]] = neck
    out[:, JOINT_INDEX["head"]] = neck + dims.neck_head * (np.cos(nf) * t_up + np.sin(nf) * t_fwd)
    hips = _hips(p, dims)
    for (base, s), name in zip(_SIDES, ("left", "right")):
        shoulder = neck + s * dims.shoulder_width * t_left - dims.shoulder_drop * t_up
        elbow, wrist = _limb(shoulder, t_fwd, s * t_left, t_up, s, *p[:, base + SHOULDER_FLEX:base + ELBOW + 1].T,
                             dims.upper_arm, dims.forearm, leg=False)
        hip = hips[:, 0 if s > 0 else 1]
        zeros = np.zeros(p.shape[0])
        knee, ankle = _limb(hip, fwd, s * left, up, s, p[:, base + HIP_FLEX], p[:, base + HIP_ABD], zeros,
                            p[:, base + KNEE], dims.thigh, dims.shin, leg=True)
        for joint, value in (("shoulder", shoulder), ("elbow", elbow), ("wrist", wrist),
                             ("hip", hip), ("knee", knee), ("ankle", ankle)):
            out[:, JOINT_INDEX[f"{name}_{joint}"]] = value
    return out.reshape(lead + (NUM_JOINTS, 3))


def _reach(dims: BodyDims, knee) -> float:
    """Hip-to-ankle distance with the knee flexed by ``knee`` radians, metres."""
    return math.sqrt(dims.thigh**2 + dims.shin**2 + 2.0 * dims.thigh * dims.shin * math.cos(knee))


def _leg_angles(hip, ankle, heading, side: float, dims: BodyDims) -> np.ndarray:
    """Hip flex, hip abd and knee (N, 3) that put the ankle at ``ankle`` (N, 3), or as near
    as the leg reaches; ``hip`` (N, 3), ``heading`` (N,), ``side`` +1 left / -1 right."""
    fwd, left = _frame(heading)
    v = ankle - hip
    th, sh = dims.thigh, dims.shin
    d = np.clip(np.linalg.norm(v, axis=-1), abs(th - sh) + 1e-9, th + sh)
    knee = np.arccos(np.clip((d**2 - th**2 - sh**2) / (2.0 * th * sh), -1.0, 1.0))
    c = th + sh * np.cos(knee)
    e = sh * np.sin(knee)
    abd = np.arcsin(np.clip(side * np.sum(v * left, -1) / np.maximum(c, 1e-9), -1.0, 1.0))
    flex = np.arctan2(np.sum(v * fwd, -1), -v[:, 2]) + np.arctan2(e, c * np.cos(abd))
    return np.stack([flex, abd, knee], -1)


def _set_legs(poses, ankles, dims: BodyDims) -> None:
    """Solve the legs of poses (N, D) in place so the ankles reach ``ankles`` (N, 2, 3)."""
    hips = _hips(poses, dims)
    for k, (base, s) in enumerate(_SIDES):
        poses[:, base + HIP_FLEX:base + KNEE + 1] = _leg_angles(hips[:, k], ankles[:, k], poses[:, HEADING], s, dims)


def _ankles(pose, dims: BodyDims) -> np.ndarray:
    """(2, 3) left and right ankles of one pose."""
    j = joints_from_procedural(pose, dims)
    return j[[JOINT_INDEX["left_ankle"], JOINT_INDEX["right_ankle"]]]


def _hip_height_limit(hips, ankles, dims: BodyDims) -> np.ndarray:
    """Highest pelvis z (N,) at which both ankles (N, 2, 3) stay within the legs' reach
    (knees bent at least :data:`STAND_KNEE`) from hips (N, 2, 3)."""
    r = _reach(dims, STAND_KNEE)
    flat = np.sum((hips[..., :2] - ankles[..., :2]) ** 2, -1)
    return np.min(ankles[..., 2] + np.sqrt(np.maximum(r * r - flat, 0.0)), axis=-1)
