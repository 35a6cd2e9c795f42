"""Canonical joints, the bones between them, and the body-part labels of synthetic scenes.

Every source of skeletons (mocap clips, procedural motion, trackers) reports the 15
canonical joints of DESIGN.md in this order, as arrays of shape (..., 15, 3) in world
metres (z up).
"""

from __future__ import annotations

JOINTS: tuple[str, ...] = (
    "head", "neck", "pelvis",
    "left_shoulder", "left_elbow", "left_wrist",
    "right_shoulder", "right_elbow", "right_wrist",
    "left_hip", "left_knee", "left_ankle",
    "right_hip", "right_knee", "right_ankle",
)
JOINT_INDEX: dict[str, int] = {name: i for i, name in enumerate(JOINTS)}
NUM_JOINTS = len(JOINTS)

#: JOINTS[MIRRORED] relabels a skeleton's joints left for right (the same points, the
#: person taken as facing the other way).
MIRRORED: tuple[int, ...] = tuple(
    JOINT_INDEX[name.replace("left", "@").replace("right", "left").replace("@", "right")] for name in JOINTS
)

#: Joints reported by the upper-body model.
UPPER_JOINTS: tuple[str, ...] = JOINTS[:9]

#: Skeleton edges (pairs of joint indices), for drawing and bone lengths.
BONES: tuple[tuple[int, int], ...] = tuple(
    (JOINT_INDEX[a], JOINT_INDEX[b])
    for a, b in (
        ("head", "neck"), ("neck", "pelvis"),
        ("neck", "left_shoulder"), ("left_shoulder", "left_elbow"), ("left_elbow", "left_wrist"),
        ("neck", "right_shoulder"), ("right_shoulder", "right_elbow"), ("right_elbow", "right_wrist"),
        ("pelvis", "left_hip"), ("left_hip", "left_knee"), ("left_knee", "left_ankle"),
        ("pelvis", "right_hip"), ("right_hip", "right_knee"), ("right_knee", "right_ankle"),
    )
)

#: Body-part labels of the synthetic renderer's part image (0 = not a body).
PARTS: tuple[str, ...] = (
    "none", "head", "chest", "pelvis",
    "left_upper_arm", "left_forearm", "left_hand",
    "right_upper_arm", "right_forearm", "right_hand",
    "left_thigh", "left_shin", "left_foot",
    "right_thigh", "right_shin", "right_foot",
)
PART_INDEX: dict[str, int] = {name: i for i, name in enumerate(PARTS)}

#: The body part whose visibility decides a joint's ground-truth ``visible`` flag:
#: the part that starts at the joint (the wrist belongs to the hand, and so on).
JOINT_PART: tuple[int, ...] = tuple(
    PART_INDEX[p]
    for p in (
        "head", "chest", "pelvis",
        "left_upper_arm", "left_forearm", "left_hand",
        "right_upper_arm", "right_forearm", "right_hand",
        "left_thigh", "left_shin", "left_foot",
        "right_thigh", "right_shin", "right_foot",
    )
)
