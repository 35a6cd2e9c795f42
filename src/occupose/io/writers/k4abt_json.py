"""The JSON layout of the Azure Kinect Body Tracking SDK's offline processor (docs/outputs.md).

Top level: ``k4abt_sdk_version`` (null: no SDK was involved), ``source_file``,
``joint_names`` (the SDK's 32, in its order), ``bone_list`` (its 31 pairs of names),
``frames``; and occupose's own keys ``writer`` ("occupose"), ``coordinate_frame``
("world", z up, or "camera:<name>", OpenCV axes) and ``units`` ("mm").

A frame: ``frame_id`` (the recording's frame index), ``timestamp_usec`` (index / fps in
microseconds), ``num_bodies``, ``bodies``. A body (a track with at least one known joint in
the frame): ``body_id`` (the track id), ``joint_positions`` (32 x [x, y, z] millimetres, or
null for a joint occupose does not estimate or did not know in that frame),
``joint_orientations`` (32 x null: occupose estimates no joint orientations), and
``joint_visible`` (32 x 1 estimated from data in the frame, 0 carried from memory, null
where the position is null). Of the 32 joints, the 15 of occupose map onto
:data:`K4ABT_FROM_OURS`; the other 17 are always null.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from occupose.io.writers import Tracks
from occupose.joints import JOINT_INDEX

#: The SDK's joints, in its order (k4abt_joint_id_t).
K4ABT_JOINTS: tuple[str, ...] = (
    "PELVIS", "SPINE_NAVEL", "SPINE_CHEST", "NECK",
    "CLAVICLE_LEFT", "SHOULDER_LEFT", "ELBOW_LEFT", "WRIST_LEFT", "HAND_LEFT", "HANDTIP_LEFT", "THUMB_LEFT",
    "CLAVICLE_RIGHT", "SHOULDER_RIGHT", "ELBOW_RIGHT", "WRIST_RIGHT", "HAND_RIGHT", "HANDTIP_RIGHT", "THUMB_RIGHT",
    "HIP_LEFT", "KNEE_LEFT", "ANKLE_LEFT", "FOOT_LEFT",
    "HIP_RIGHT", "KNEE_RIGHT", "ANKLE_RIGHT", "FOOT_RIGHT",
    "HEAD", "NOSE", "EYE_LEFT", "EAR_LEFT", "EYE_RIGHT", "EAR_RIGHT",
)

#: The SDK's bones (parent, child), in the offline processor's order.
K4ABT_BONES: tuple[tuple[str, str], ...] = (
    ("SPINE_CHEST", "SPINE_NAVEL"), ("SPINE_NAVEL", "PELVIS"), ("SPINE_CHEST", "NECK"), ("NECK", "HEAD"),
    ("HEAD", "NOSE"),
    ("SPINE_CHEST", "CLAVICLE_LEFT"), ("CLAVICLE_LEFT", "SHOULDER_LEFT"), ("SHOULDER_LEFT", "ELBOW_LEFT"),
    ("ELBOW_LEFT", "WRIST_LEFT"), ("WRIST_LEFT", "HAND_LEFT"), ("HAND_LEFT", "HANDTIP_LEFT"),
    ("WRIST_LEFT", "THUMB_LEFT"), ("PELVIS", "HIP_LEFT"), ("HIP_LEFT", "KNEE_LEFT"), ("KNEE_LEFT", "ANKLE_LEFT"),
    ("ANKLE_LEFT", "FOOT_LEFT"), ("NOSE", "EYE_LEFT"), ("EYE_LEFT", "EAR_LEFT"),
    ("SPINE_CHEST", "CLAVICLE_RIGHT"), ("CLAVICLE_RIGHT", "SHOULDER_RIGHT"), ("SHOULDER_RIGHT", "ELBOW_RIGHT"),
    ("ELBOW_RIGHT", "WRIST_RIGHT"), ("WRIST_RIGHT", "HAND_RIGHT"), ("HAND_RIGHT", "HANDTIP_RIGHT"),
    ("WRIST_RIGHT", "THUMB_RIGHT"), ("PELVIS", "HIP_RIGHT"), ("HIP_RIGHT", "KNEE_RIGHT"),
    ("KNEE_RIGHT", "ANKLE_RIGHT"), ("ANKLE_RIGHT", "FOOT_RIGHT"), ("NOSE", "EYE_RIGHT"), ("EYE_RIGHT", "EAR_RIGHT"),
)

#: The SDK joint each of occupose's joints is written as (HEAD: the SDK's head joint
#: sits near the head's centre, as occupose's does).
K4ABT_FROM_OURS: dict[str, str] = {
    "head": "HEAD", "neck": "NECK", "pelvis": "PELVIS",
    "left_shoulder": "SHOULDER_LEFT", "left_elbow": "ELBOW_LEFT", "left_wrist": "WRIST_LEFT",
    "right_shoulder": "SHOULDER_RIGHT", "right_elbow": "ELBOW_RIGHT", "right_wrist": "WRIST_RIGHT",
    "left_hip": "HIP_LEFT", "left_knee": "KNEE_LEFT", "left_ankle": "ANKLE_LEFT",
    "right_hip": "HIP_RIGHT", "right_knee": "KNEE_RIGHT", "right_ankle": "ANKLE_RIGHT",
}

_WRITER = "occupose"
# (ours, theirs) index pairs
_PAIRS = tuple((JOINT_INDEX[ours], K4ABT_JOINTS.index(theirs)) for ours, theirs in K4ABT_FROM_OURS.items())


def document_from_tracks(tracks: Tracks) -> dict:
    """The JSON document (module docstring) of ``tracks`` as a dict."""
    millimetres = np.round(tracks.joints * 1000.0, 3)
    known = tracks.known
    frames = []
    for t in range(tracks.joints.shape[0]):
        bodies = []
        for p in np.flatnonzero(known[t].any(axis=1)):
            positions: list = [None] * len(K4ABT_JOINTS)
            visible: list = [None] * len(K4ABT_JOINTS)
            for ours, theirs in _PAIRS:
                if known[t, p, ours]:
                    positions[theirs] = millimetres[t, p, ours].tolist()
                    visible[theirs] = int(tracks.visible[t, p, ours])
            bodies.append({"body_id": int(tracks.ids[p]), "joint_positions": positions,
                           "joint_orientations": [None] * len(K4ABT_JOINTS), "joint_visible": visible})
        frames.append({"frame_id": t, "timestamp_usec": int(round(t * 1e6 / tracks.fps)),
                       "num_bodies": len(bodies), "bodies": bodies})
    return {"k4abt_sdk_version": None, "writer": _WRITER, "source_file": tracks.source,
            "coordinate_frame": tracks.frame, "units": "mm", "joint_names": list(K4ABT_JOINTS),
            "bone_list": [list(bone) for bone in K4ABT_BONES], "frames": frames}


def write_k4abt_json(path: Path, tracks: Tracks) -> None:
    """Write ``tracks`` to ``path`` in the offline processor's layout (module docstring)."""
    with open(path, "w", encoding="utf-8") as handle:
        json.dump(document_from_tracks(tracks), handle, indent=1)
        handle.write("\n")


def is_occupose_json(path: Path) -> bool:
    """Whether ``path`` is a JSON file of this writer (its ``writer`` key)."""
    try:
        with open(path, encoding="utf-8") as handle:
            data = json.load(handle)
    except (OSError, ValueError):
        return False
    return isinstance(data, dict) and data.get("writer") == _WRITER and "joint_names" in data
