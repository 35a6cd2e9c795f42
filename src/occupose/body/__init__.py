"""Articulated body models of round cones, their forward kinematics, pose fitting, size
estimation and motion model (see :mod:`occupose.body.model` for the conventions)."""

from occupose.body.kinematics import capsules_from_poses, joints_from_poses
from occupose.body.model import BODY_MODELS, BodyModel, Partition, body_model, full_model, upper_model

__all__ = [
    "BODY_MODELS", "BodyModel", "Partition", "body_model", "full_model", "upper_model",
    "capsules_from_poses", "joints_from_poses",
]
