"""Pixel-level and arm metrics: the share of foreground pixels given to the right person,
foreground precision / recall / IoU, and the second paper's arm error.

arm error ``epsilon`` (the second paper's)
    Mean distance from a person's observed arm points (pixels of its upper arms,
    forearms and hands: the renderer's part image) to the nearest arm bone
    (shoulder-elbow, elbow-wrist) of a skeleton. The paper measures them "to the
    estimated model state"; a skeleton is what every method reports, and the arms' bones
    alone do not credit an arm point that the trunk would explain. The points lie on the
    surface, a limb's radius from its bone and a hand's length beyond the wrist, so the
    ground-truth skeleton has an epsilon too: the floor any estimate is read against.
"""

from __future__ import annotations

import math
from typing import Any, Sequence

import numpy as np

from occupose._validate import bool_array, float_array
from occupose.joints import JOINT_INDEX, NUM_JOINTS, PART_INDEX


# --------------------------------------------------------------------------- arm error


#: Body parts (occupose.joints.PARTS labels) whose points the arm error measures.
ARM_PARTS: tuple[int, ...] = tuple(PART_INDEX[f"{side}_{part}"] for side in ("left", "right")
                                   for part in ("upper_arm", "forearm", "hand"))
#: Bones (joint index pairs) the arm points are measured to.
ARM_BONES: tuple[tuple[int, int], ...] = tuple(
    (JOINT_INDEX[f"{side}_{a}"], JOINT_INDEX[f"{side}_{b}"])
    for side in ("left", "right") for a, b in (("shoulder", "elbow"), ("elbow", "wrist")))
#: A frame with fewer arm points than this has no arm error (an arm seen by a few pixels
#: at the edge of a hand says little).
MIN_ARM_POINTS = 20


def segment_distances(points: Any, starts: Any, ends: Any) -> np.ndarray:
    """Distance from each point to the nearest of S segments.

    points : (N, 3) float, metres; starts, ends : (S, 3) float, metres, S >= 1
    Returns (N,) float64, metres.
    """
    points = float_array(points, "points", (None, 3))
    starts = float_array(starts, "starts", (None, 3))
    ends = float_array(ends, "ends", (starts.shape[0], 3))
    if starts.shape[0] == 0:
        raise ValueError("segment_distances needs at least one segment")
    axis = ends - starts                                          # (S, 3)
    length2 = np.maximum(np.einsum("sk,sk->s", axis, axis), 1e-18)
    offset = points[:, None, :] - starts[None]                    # (N, S, 3)
    along = np.clip(np.einsum("nsk,sk->ns", offset, axis) / length2, 0.0, 1.0)
    gap = offset - along[..., None] * axis[None]
    return np.sqrt(np.einsum("nsk,nsk->ns", gap, gap).min(axis=1))


def arm_epsilons(arm_points: Sequence[Any], joints: Any) -> np.ndarray:
    """The second paper's arm error of every frame (module docstring).

    arm_points : T arrays (N_t, 3), metres, world: the person's observed arm points
    joints : (T, 15, 3) float, metres: the skeleton measured (NaN where not reported)
    Returns (T,) float64, metres; NaN where a frame has fewer than MIN_ARM_POINTS points
    or the skeleton misses an arm joint.
    """
    joints = float_array(joints, "joints", (len(arm_points), NUM_JOINTS, 3))
    starts = np.array([a for a, _ in ARM_BONES])
    ends = np.array([b for _, b in ARM_BONES])
    out = np.full(len(arm_points), np.nan)
    for t, points in enumerate(arm_points):
        skeleton = joints[t]
        if len(points) >= MIN_ARM_POINTS and np.all(np.isfinite(skeleton[np.r_[starts, ends]])):
            out[t] = float(segment_distances(points, skeleton[starts], skeleton[ends]).mean())
    return out


# --------------------------------------------------------------------------- pixels


def pixel_assignment_accuracy(assigned: Any, truth: Any, foreground: Any) -> float:
    """Share of foreground pixels assigned to the right person.

    Parameters
    ----------
    assigned : (H, W) int, person label given to each pixel by the tracker (labels
        already mapped to ground-truth person ids).
    truth : (H, W) int, true person label of each pixel.
    foreground : (H, W) bool, pixels that are scored (e.g. the true foreground).

    Returns
    -------
    Fraction in [0, 1]; NaN when ``foreground`` is empty.
    """
    assigned = np.asarray(assigned)
    truth = np.asarray(truth)
    if assigned.ndim != 2 or assigned.shape != truth.shape:
        raise ValueError(
            f"assigned and truth must be (H, W) label images of the same shape, got "
            f"{assigned.shape} and {truth.shape}"
        )
    for name, image in (("assigned", assigned), ("truth", truth)):
        if not np.issubdtype(image.dtype, np.integer):
            raise ValueError(f"{name} must hold integer labels, got dtype {image.dtype}")
    foreground = bool_array(foreground, "foreground", truth.shape)
    total = int(np.count_nonzero(foreground))
    if total == 0:
        return math.nan
    return float(np.count_nonzero(assigned[foreground] == truth[foreground]) / total)


def foreground_scores(pred_mask: Any, true_mask: Any) -> tuple[float, float, float]:
    """Precision, recall and intersection over union of a foreground mask.

    Parameters
    ----------
    pred_mask, true_mask : (H, W) bool (any matching shape), predicted and true foreground.

    Returns
    -------
    ``(precision, recall, iou)`` as fractions in [0, 1]; each is NaN when its
    denominator (predicted, true, union pixels) is empty.
    """
    pred_mask = np.asarray(pred_mask)
    if pred_mask.dtype != np.bool_:
        raise ValueError(f"pred_mask must be a boolean array, got dtype {pred_mask.dtype}")
    true_mask = bool_array(true_mask, "true_mask", pred_mask.shape)
    hits = int(np.count_nonzero(pred_mask & true_mask))

    def ratio(denominator: int) -> float:
        return hits / denominator if denominator else math.nan

    return (
        ratio(int(np.count_nonzero(pred_mask))),
        ratio(int(np.count_nonzero(true_mask))),
        ratio(int(np.count_nonzero(pred_mask | true_mask))),
    )
