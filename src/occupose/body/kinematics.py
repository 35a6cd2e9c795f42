"""Forward kinematics of body models, vectorised over particles (numba, parallel over poses)."""

from __future__ import annotations

import numpy as np

from occupose.body import _kernels
from occupose.body.model import BodyModel
from occupose.joints import NUM_JOINTS

#: The second, empty set of points of :func:`joints_from_poses`: read-only like a model's
#: arrays, so that both functions call one compiled specialisation of each kernel (numba
#: compiles another for writable arrays).
_EMPTY_NODES = np.zeros(0, np.int64)
_EMPTY_OFFSETS = np.zeros((0, 3))
_EMPTY_NODES.setflags(write=False)
_EMPTY_OFFSETS.setflags(write=False)


def _check_poses(model: BodyModel, poses) -> np.ndarray:
    if not isinstance(model, BodyModel):
        raise ValueError(f"model must be a BodyModel, got {type(model).__name__}")
    poses = np.ascontiguousarray(poses, dtype=np.float64)
    if poses.ndim != 2 or poses.shape[1] != model.num_dofs:
        raise ValueError(f"poses must have shape (P, {model.num_dofs}) for the {model.name!r} model, "
                         f"got {poses.shape}")
    return poses


def _tree(model: BodyModel):
    return (model.parents, model.offsets, model.dof_node, model.dof_type, model.dof_axis, model.dof_sign)


def _kernel(num_poses: int):
    """The forward-kinematics kernel for this many poses (serial for a few hundred)."""
    return _kernels.points_from_poses_serial if num_poses <= _kernels.SERIAL_POSES else _kernels.points_from_poses


def capsules_from_poses(model: BodyModel, poses) -> tuple[np.ndarray, np.ndarray]:
    """World ends of every round cone of the model for each pose.

    poses : (P, D) float, pose vectors of ``model`` (radians and metres)
    Returns a, b : (P, C, 3) float64, C-contiguous, world metres; the radii are
    ``model.capsule_radii`` and the parts ``model.capsule_part``.
    """
    poses = _check_poses(model, poses)
    num = poses.shape[0]
    a = np.empty((num, model.num_capsules, 3))
    b = np.empty((num, model.num_capsules, 3))
    _kernel(num)(poses, *_tree(model), model.capsule_nodes[0], model.capsule_offsets[0], a,
                 model.capsule_nodes[1], model.capsule_offsets[1], b)
    return a, b


def joints_from_poses(model: BodyModel, poses) -> np.ndarray:
    """The 15 canonical joints (order :data:`occupose.joints.JOINTS`) of each pose.

    poses : (P, D) float, pose vectors of ``model``
    Returns (P, 15, 3) float64, world metres; NaN for the joints the model does not report
    (the upper model has no hips, knees or ankles).
    """
    poses = _check_poses(model, poses)
    out = np.empty((poses.shape[0], NUM_JOINTS, 3))
    _kernel(poses.shape[0])(poses, *_tree(model), model.joint_nodes, model.joint_offsets, out,
                            _EMPTY_NODES, _EMPTY_OFFSETS, np.empty((poses.shape[0], 0, 3)))
    return out


def joints_from_pose(model: BodyModel, pose) -> np.ndarray:
    """The 15 canonical joints of one pose (D,) of ``model``: (15, 3) float64 world metres,
    NaN where the model does not report a joint (:func:`joints_from_poses` of one)."""
    return joints_from_poses(model, np.asarray(pose, float)[None])[0]
