"""Procedural human motion: canonical joint trajectories from a few chained actions.

Used when the real mocap clips are absent and for motions they lack (sitting). Three
modules, their public names re-exported here (``from occupose.synth import motion as pm``):

- :mod:`~occupose.synth.motion.pose`: the generator's pose vector (layout
  :data:`POSE_NAMES`, conventions in the module's docstring), its forward kinematics
  :func:`joints_from_procedural` to the 15 canonical joints, the upright :func:`stance`,
  :func:`pose_with`;
- :mod:`~occupose.synth.motion.actions`: :func:`walk`, :func:`turn`, :func:`stand`,
  :func:`sit_down`, :func:`sitting`, :func:`stand_up`, :func:`gesture`, :func:`wave`,
  :func:`keyframes`, each mapping a start pose (D,) to the poses (n, D) of the frames that
  follow it, so they chain without jumps;
- :mod:`~occupose.synth.motion.builder`: :class:`MotionBuilder` chains actions and keeps
  the frame range (:class:`Segment`) of each.

>>> joints = pm.MotionBuilder((0.0, 0.0)).walk([(2.0, 0.0)]).sit_down(0.45).joints()  # (T, 15, 3)
"""

from occupose.synth.motion.actions import (
    ARM_SWING, CORNER_SMOOTHING, FOOT_AHEAD, FOOT_MOVING, GESTURES, HEEL_ROCKER, HEEL_STRIKE, INTERPOLATIONS,
    MAX_CORNER, MIN_STEP_TIME, PELVIS_BOB, PELVIS_DROP, PELVIS_SWAY, SIT_ARMS, SIT_LEAN, STEP_LENGTH, SWING_LIFT,
    TURN_BEFORE_WALK, WALK_FOOT_OFFSET, WAVE_ARM, gesture, keyframes, pelvis_offset_from_seat, sit_down, sitting,
    stand, stand_up, turn, walk, wave,
)
from occupose.synth.motion.builder import MotionBuilder, Segment
from occupose.synth.motion.pose import (
    ELBOW, HEADING, HIP_ABD, HIP_FLEX, KNEE, LEFT, NECK_FLEX, POSE_INDEX, POSE_NAMES, POSE_SIZE, RIGHT, SHOULDER_ABD,
    SHOULDER_FLEX, SHOULDER_ROT, STAND_KNEE, TRUNK_LEAN, TRUNK_SIDE, TRUNK_TWIST, X, Y, Z, joints_from_procedural,
    pose_with, stance,
)

__all__ = [
    # pose
    "X", "Y", "Z", "HEADING", "TRUNK_LEAN", "TRUNK_SIDE", "TRUNK_TWIST", "NECK_FLEX", "LEFT", "RIGHT",
    "HIP_FLEX", "HIP_ABD", "KNEE", "SHOULDER_FLEX", "SHOULDER_ABD", "SHOULDER_ROT", "ELBOW",
    "POSE_NAMES", "POSE_INDEX", "POSE_SIZE", "STAND_KNEE", "joints_from_procedural", "pose_with", "stance",
    # actions
    "walk", "turn", "stand", "sit_down", "sitting", "stand_up", "gesture", "wave", "keyframes",
    "pelvis_offset_from_seat", "GESTURES", "INTERPOLATIONS", "WAVE_ARM", "SIT_ARMS", "SIT_LEAN",
    "STEP_LENGTH", "MIN_STEP_TIME", "FOOT_MOVING", "FOOT_AHEAD", "SWING_LIFT", "WALK_FOOT_OFFSET",
    "PELVIS_DROP", "PELVIS_BOB", "PELVIS_SWAY", "ARM_SWING", "CORNER_SMOOTHING", "MAX_CORNER",
    "TURN_BEFORE_WALK", "HEEL_STRIKE", "HEEL_ROCKER",
    # builder
    "MotionBuilder", "Segment",
]
