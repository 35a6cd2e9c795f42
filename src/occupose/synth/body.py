"""Synthetic human bodies posed from canonical joints.

The rendered body is deliberately *not* the tracker's round-cone model: ellipsoids for the
head, chest and pelvis, tapered round cones for the limbs and the neck, boxes for hands
and feet. Each person gets random girth and proportions within human ranges and a set of
clothing and skin colours.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from occupose.joints import JOINT_INDEX as J
from occupose.joints import PART_INDEX as P
from occupose.geometry.primitives import Primitives, box, concat, ellipsoid, round_cone

#: Clothing styles: "normal" (everyday colours), "dark" (near-black, the second paper's
#: S1) and "flashy" (saturated, a different colour per body part: its S2).
CLOTHING_STYLES = ("normal", "dark", "flashy")

_SKIN_TONES = np.array([[241, 194, 167], [224, 172, 105], [198, 134, 66], [141, 85, 36], [92, 56, 36]])
_EVERYDAY = np.array([[40, 60, 120], [120, 120, 125], [200, 200, 195], [90, 40, 40],
                      [50, 90, 60], [160, 130, 90], [30, 30, 35], [70, 100, 160]])
_FLASHY = np.array([[235, 30, 40], [250, 220, 20], [30, 200, 60], [20, 120, 250],
                    [250, 120, 10], [200, 40, 220], [20, 220, 220]])

# Parts in the order of the `colors` array of a BodyShape.
_COLORED_PARTS = ("head", "chest", "pelvis", "left_upper_arm", "left_forearm", "left_hand",
                  "right_upper_arm", "right_forearm", "right_hand", "left_thigh", "left_shin",
                  "left_foot", "right_thigh", "right_shin", "right_foot")


@dataclass(frozen=True)
class BodyShape:
    """Girth and colours of one synthetic person (lengths come from the joints).

    radii : dict of part name -> metres (see :func:`random_body_shape` for the keys)
    colors : (15, 3) uint8, albedo per part in the order of ``_COLORED_PARTS``
    """

    radii: dict
    colors: np.ndarray

    def color(self, part: str) -> np.ndarray:
        return self.colors[_COLORED_PARTS.index(part)]


def random_body_shape(rng: np.random.Generator, clothing: str = "normal") -> BodyShape:
    """Draw a body shape: girth factor ~ N(1, 0.08) (clipped to 0.8-1.25), per-part
    proportion jitter of about 6 %, a skin tone, and clothing colours of ``clothing`` style.
    """
    if clothing not in CLOTHING_STYLES:
        raise ValueError(f"unknown clothing style {clothing!r}; valid: {', '.join(CLOTHING_STYLES)}")
    girth = float(np.clip(rng.normal(1.0, 0.08), 0.8, 1.25))

    def r(base: float) -> float:
        return base * girth * float(np.clip(rng.normal(1.0, 0.06), 0.85, 1.15))

    radii = {
        "head": np.array([r(0.075), r(0.095), r(0.115)]),     # lateral, forward, up
        "neck": r(0.055),
        "chest": np.array([r(0.165), r(0.110), 0.0]),          # lateral, forward (height from joints)
        "pelvis": np.array([r(0.165), r(0.115), r(0.125)]),
        "upper_arm": (r(0.050), r(0.040)),
        "forearm": (r(0.040), r(0.030)),
        "hand": np.array([r(0.085), r(0.045), r(0.016)]),      # half length, width, thickness
        "thigh": (r(0.080), r(0.056)),
        "shin": (r(0.052), r(0.040)),
        "foot": np.array([r(0.125), r(0.045), 0.038]),         # half length, width, height
    }
    return BodyShape(radii=radii, colors=clothing_colors(rng, clothing))


def clothing_colors(rng: np.random.Generator, clothing: str = "normal") -> np.ndarray:
    """Draw a skin tone and clothing colours of ``clothing`` style (:data:`CLOTHING_STYLES`):
    (15, 3) uint8, albedo per part in the order of a BodyShape's ``colors``."""
    if clothing not in CLOTHING_STYLES:
        raise ValueError(f"unknown clothing style {clothing!r}; valid: {', '.join(CLOTHING_STYLES)}")
    skin = _SKIN_TONES[rng.integers(len(_SKIN_TONES))]
    if clothing == "flashy":
        top, sleeve, trousers, shoes = _FLASHY[rng.permutation(len(_FLASHY))[:4]]
    elif clothing == "dark":
        top, sleeve, trousers, shoes = (rng.integers(15, 45, size=(4, 3)))
        sleeve = top
    else:
        top, trousers = _EVERYDAY[rng.permutation(len(_EVERYDAY))[:2]]
        sleeve = top if rng.random() < 0.6 else skin  # long or short sleeves
        shoes = np.array([35, 30, 30])
    per_part = {
        "head": skin, "chest": top, "pelvis": trousers,
        "left_upper_arm": top, "left_forearm": sleeve, "left_hand": skin,
        "right_upper_arm": top, "right_forearm": sleeve, "right_hand": skin,
        "left_thigh": trousers, "left_shin": trousers, "left_foot": shoes,
        "right_thigh": trousers, "right_shin": trousers, "right_foot": shoes,
    }
    return np.array([per_part[name] for name in _COLORED_PARTS], np.uint8)


def _unit(v: np.ndarray, fallback: np.ndarray) -> np.ndarray:
    n = np.linalg.norm(v)
    return v / n if n > 1e-9 else fallback


def _frame(forward_hint: np.ndarray, up: np.ndarray) -> np.ndarray:
    """Rotation whose columns are (lateral-left, forward, up) for a body segment."""
    up = _unit(up, np.array([0.0, 0.0, 1.0]))
    fwd = forward_hint - up * (forward_hint @ up)
    fwd = _unit(fwd, np.cross(up, [1.0, 0.0, 0.0]) if abs(up[0]) < 0.9 else np.cross(up, [0.0, 1.0, 0.0]))
    left = np.cross(up, fwd)
    return np.column_stack([left, fwd, up])


def primitives_from_joints(joints: np.ndarray, shape: BodyShape, person: int) -> Primitives:
    """Pose a body shape on one frame of canonical joints.

    joints : (15, 3) float64, metres, world frame (z up), order of :data:`occupose.joints.JOINTS`
    person : person id (>= 1) written into the renderer's person image
    Returns 16 primitives (head, neck, chest, pelvis, 2 x (upper arm, forearm, hand,
    thigh, shin, foot)).
    """
    joints = np.asarray(joints, np.float64)
    if joints.shape != (15, 3) or not np.all(np.isfinite(joints)):
        raise ValueError(f"joints must be a finite (15, 3) array, got shape {joints.shape}")
    rd = shape.radii
    head, neck, pelvis = joints[J["head"]], joints[J["neck"]], joints[J["pelvis"]]
    z = np.array([0.0, 0.0, 1.0])
    trunk_up = _unit(neck - pelvis, z)
    # forward = (left - right) x up: shoulders for the chest, hips for the pelvis and feet
    chest_fwd = np.cross(joints[J["left_shoulder"]] - joints[J["right_shoulder"]], trunk_up)
    hip_fwd = np.cross(joints[J["left_hip"]] - joints[J["right_hip"]], trunk_up)
    chest_axes = _frame(chest_fwd, trunk_up)
    pelvis_axes = _frame(hip_fwd, trunk_up)
    head_axes = _frame(chest_fwd, head - neck)
    spine = np.linalg.norm(neck - pelvis)

    prims = [
        ellipsoid(head, rd["head"], shape.color("head"), head_axes, person, P["head"]),
        round_cone(neck - 0.03 * trunk_up, neck + 0.55 * (head - neck), rd["neck"], rd["neck"] * 0.9,
                   shape.color("head"), person, P["chest"]),
        ellipsoid(pelvis + 0.64 * spine * trunk_up, (rd["chest"][0], rd["chest"][1], 0.44 * spine),
                  shape.color("chest"), chest_axes, person, P["chest"]),
        ellipsoid(pelvis + 0.06 * trunk_up, rd["pelvis"], shape.color("pelvis"), pelvis_axes,
                  person, P["pelvis"]),
    ]
    for side in ("left", "right"):
        sh, el, wr = (joints[J[f"{side}_{n}"]] for n in ("shoulder", "elbow", "wrist"))
        hip, kn, an = (joints[J[f"{side}_{n}"]] for n in ("hip", "knee", "ankle"))
        prims.append(round_cone(sh, el, *rd["upper_arm"], shape.color(f"{side}_upper_arm"),
                                person, P[f"{side}_upper_arm"]))
        prims.append(round_cone(el, wr, *rd["forearm"], shape.color(f"{side}_forearm"),
                                person, P[f"{side}_forearm"]))
        along = _unit(wr - el, -z)
        hand_axes = _frame(chest_fwd, along)  # columns: palm width, thickness, along
        hand_axes = hand_axes[:, [2, 0, 1]]
        prims.append(box(wr + along * rd["hand"][0] * 0.9, rd["hand"], shape.color(f"{side}_hand"),
                         hand_axes, person, P[f"{side}_hand"]))
        prims.append(round_cone(hip, kn, *rd["thigh"], shape.color(f"{side}_thigh"),
                                person, P[f"{side}_thigh"]))
        prims.append(round_cone(kn, an, *rd["shin"], shape.color(f"{side}_shin"),
                                person, P[f"{side}_shin"]))
        foot_fwd = _unit(hip_fwd - z * (hip_fwd @ z), np.array([1.0, 0.0, 0.0]))
        foot_axes = np.column_stack([foot_fwd, np.cross(z, foot_fwd), z])
        half = rd["foot"]
        centre = an + foot_fwd * (0.55 * half[0]) - z * 0.042  # sole ~0.0 m for an ankle at 0.08 m
        prims.append(box(centre, half, shape.color(f"{side}_foot"), foot_axes, person, P[f"{side}_foot"]))
    return concat(prims)
