"""Postures of the body models in their own DOFs: standing at rest, and seated.

These are the tracker's own guesses of how a person stands or sits (a new person's start
candidates, the legs of a person carried out of sight). They are built from the model's
DOF conventions and its body dimensions alone (:mod:`occupose.body.model`: x forward, y to
the left, z up at the zero pose; hip flexion swings the thigh forward, knee flexion the
shin back), not from the scene generator's motion, so the synthetic people do not sit the
way the tracker expects them to.
"""

from __future__ import annotations

import math

import numpy as np

from occupose.body.model import BodyModel
from occupose.geometry.angles import wrap_angle

#: Arms hanging relaxed: shoulder flex, abd, rot, elbow (radians).
ARM_REST = np.array([0.0, 0.12, 0.0, 0.15])
#: Knee flexion of a relaxed upright stance, radians (keeps the legs off the straight-knee
#: singularity).
STAND_KNEE = 0.06

_ARM = ("shoulder_flex", "shoulder_abd", "shoulder_rot", "elbow")


def _base(model: BodyModel, xy, heading: float) -> np.ndarray:
    """The zero pose of ``model`` with its pelvis above ``xy`` (metres), facing ``heading``
    (radians about +z, 0 = +x), the arms at rest."""
    xy = np.asarray(xy, dtype=np.float64)
    if xy.shape != (2,) or not np.all(np.isfinite(xy)) or not math.isfinite(heading):
        raise ValueError(f"xy must be two finite numbers (metres) and heading finite radians, got {xy!r}, {heading!r}")
    pose = np.zeros(model.num_dofs)
    pose[model.dof("x")], pose[model.dof("y")] = xy
    pose[model.dof("heading")] = wrap_angle(heading)
    for side in ("left", "right"):
        for name, value in zip(_ARM, ARM_REST):
            pose[model.dof(f"{side}_{name}")] = value
    return pose


def _has_legs(model: BodyModel) -> bool:
    return "left_knee" in model.dof_names


def standing_pose(model: BodyModel, xy=(0.0, 0.0), heading: float = 0.0) -> np.ndarray:
    """A relaxed upright pose (D,) of ``model``: pelvis above ``xy`` (metres), facing
    ``heading`` (radians about +z, 0 = +x), arms hanging (:data:`ARM_REST`), knees bent by
    :data:`STAND_KNEE` with the ankles under the hips at the model's ankle height (a model
    without legs: its pelvis at the same height)."""
    dims = model.dims
    pose = _base(model, xy, heading)
    thigh, shin, knee = dims.thigh, dims.shin, STAND_KNEE
    # the thigh leans forward so that the shin, bent back by the knee, ends under the hip
    flex = math.atan2(shin * math.sin(knee), thigh + shin * math.cos(knee))
    pose[model.dof("z")] = dims.ankle_height + math.sqrt(thigh**2 + shin**2 + 2.0 * thigh * shin * math.cos(knee))
    if _has_legs(model):
        for side in ("left", "right"):
            pose[model.dof(f"{side}_hip_flex")] = flex
            pose[model.dof(f"{side}_knee")] = knee
    return pose


def seated_pose(model: BodyModel, seat_height: float, xy=(0.0, 0.0), heading: float = 0.0) -> np.ndarray:
    """A pose (D,) of ``model`` seated upright on a seat ``seat_height`` metres high: the
    pelvis ``dims.seat_clearance`` above the seat and above ``xy``, the shins vertical with
    the ankles at the model's ankle height, the thighs reaching from the knees to the hips,
    the arms hanging (:data:`ARM_REST`), facing ``heading``. ValueError for a seat the
    thighs cannot reach from the knees (higher or lower than a thigh's length)."""
    dims = model.dims
    if not (isinstance(seat_height, (int, float, np.floating)) and math.isfinite(seat_height)):
        raise ValueError(f"seat_height must be a number of metres, got {seat_height!r}")
    pose = _base(model, xy, heading)
    hips = seat_height + dims.seat_clearance
    rise = (hips - (dims.ankle_height + dims.shin)) / dims.thigh  # sine of the thigh's rise to the hip
    if not -1.0 < rise < 1.0:
        raise ValueError(f"seat_height {seat_height:.2f} m is out of a {dims.thigh:.2f} m thigh's reach from the knee")
    pose[model.dof("z")] = hips
    if _has_legs(model):
        flex = 0.5 * math.pi - math.asin(rise)  # pi / 2: the thigh horizontal
        for side in ("left", "right"):
            pose[model.dof(f"{side}_hip_flex")] = flex
            pose[model.dof(f"{side}_knee")] = flex  # the shin hangs vertical from the knee
    return pose
