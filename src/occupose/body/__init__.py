"""Articulated body models of round cones, their forward kinematics, pose fitting, size
estimation and motion model (see :mod:`occupose.body.model` for the conventions)."""

from occupose.body.fit import LIMB_DOFS, limb_angles, pose_from_joints, twin_pose
from occupose.body.dims import DEFAULT_DIMS, BodyDims
from occupose.body.kinematics import capsules_from_poses, joints_from_pose, joints_from_poses
from occupose.body.model import BODY_MODELS, BodyModel, Partition, body_model, full_model, upper_model
from occupose.body.postures import ARM_REST, seated_pose, standing_pose
from occupose.body.dynamics import BOUNDARY_MODES, DIFFUSION_30FPS, diffuse, diffusion_scales, root_drift
from occupose.body.size import BodySize, dims_from_observation

__all__ = [
    "ARM_REST", "BODY_MODELS", "BOUNDARY_MODES", "BodyDims", "BodyModel", "BodySize", "DEFAULT_DIMS", "DIFFUSION_30FPS", "LIMB_DOFS", "Partition",
    "body_model", "capsules_from_poses", "diffuse", "diffusion_scales", "dims_from_observation",
    "full_model", "joints_from_pose", "joints_from_poses", "limb_angles", "pose_from_joints", "root_drift", "seated_pose", "standing_pose", "twin_pose", "upper_model",
]
