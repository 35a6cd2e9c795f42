"""Per-person body proportions drawn from anthropometric ranges, independent of the tracker.

The tracker builds its bodies from :mod:`occupose.body.dims` (one set of proportions scaled
to a height). The randomized scenes must not share that assumption, so every person here
gets their own proportions: a stature, and each segment length as a fraction of stature
drawn around the segment ratios of Drillis & Contini (1966) as tabulated by Winter
(*Biomechanics and Motor Control of Human Movement*, 4th ed., 2009, Fig. 4.1), with a
per-person spread of a few percent, plus shoulder and hip widths and limb girths that vary
by person. Nothing here reads :data:`occupose.body.dims.DEFAULT_DIMS`.

Winter's ratios (fractions of stature H) used: ankle (lateral malleolus) height 0.039 H,
knee 0.285 H, hip (greater trochanter) 0.530 H, chin 0.870 H (taken as the level of the
canonical neck joint), upper arm 0.186 H, forearm 0.146 H, hand length 0.108 H, foot
length 0.152 H, foot breadth 0.055 H, shoulder (biacromial) breadth 0.259 H, hip breadth
0.191 H. Canonical joints are joint centres, not bony landmarks: the shoulder joint
centres sit :data:`SHOULDER_JOINT_SHARE` of the half biacromial breadth out from the
neck, the hip joint centres :data:`HIP_JOINT_SHARE` of the hip breadth apart (estimates
of this module, not of the sources). The spreads (one standard deviation, relative) are
this module's choice, in line with the 3-6 % coefficients of variation of segment
lengths relative to stature in adult surveys; girth spreads follow the about 10 %
coefficient of variation of limb circumferences (e.g. ANSUR II, Gordon et al. 2014).
Every draw is clipped to +-:data:`CLIP_SDS` standard deviations.

A person (:class:`Anthropometry`) gives what the generator needs: the bone lengths of
the 15 canonical joints for retargeting mocap (:meth:`Anthropometry.bone_lengths`,
:func:`occupose.synth.retarget.retarget_lengths`), the lengths as the procedural motion
generator's input (:meth:`Anthropometry.motion_dims`), and the renderer's girths
(:meth:`Anthropometry.body_shape`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from occupose.body.dims import BodyDims
from occupose.joints import BONES, JOINT_INDEX
from occupose.synth.body import BodyShape, clothing_colors

#: Stature range, metres (uniform).
STATURE_RANGE = (1.50, 1.95)
#: Draws are clipped to this many standard deviations about their mean.
CLIP_SDS = 2.0

# Vertical segments as fractions of stature: (mean, relative sd). Their sum is
# normalised to 1 per person, so the drawn stature is exact.
#: Floor to ankle joint (Winter: malleolus 0.039 H).
ANKLE_RATIO = (0.039, 0.08)
#: Ankle to knee (Winter: 0.285 - 0.039 H).
SHIN_RATIO = (0.246, 0.03)
#: Knee to hip (Winter: 0.530 - 0.285 H).
THIGH_RATIO = (0.245, 0.03)
#: Hip level to the neck joint (Winter: chin 0.870 - hip 0.530 H).
SPINE_RATIO = (0.340, 0.03)
#: Neck joint to the top of the head (1 - 0.870 H); the head centre is half way.
HEAD_NECK_RATIO = (0.130, 0.04)

# Other lengths as fractions of stature: (mean, relative sd).
#: Shoulder to elbow (Winter 0.186 H).
UPPER_ARM_RATIO = (0.186, 0.04)
#: Elbow to wrist (Winter 0.146 H).
FOREARM_RATIO = (0.146, 0.04)
#: Hand length (Winter 0.108 H).
HAND_RATIO = (0.108, 0.04)
#: Foot length (Winter 0.152 H).
FOOT_RATIO = (0.152, 0.04)
#: Foot breadth (Winter 0.055 H).
FOOT_WIDTH_RATIO = (0.055, 0.06)
#: Biacromial (shoulder) breadth (Winter 0.259 H).
SHOULDER_BREADTH_RATIO = (0.259, 0.05)
#: Hip breadth (Winter 0.191 H).
HIP_BREADTH_RATIO = (0.191, 0.06)
#: Shoulder joints below the neck joint along the trunk, fraction of stature (this module's estimate).
SHOULDER_DROP_RATIO = (0.035, 0.20)
#: Lateral offset of a shoulder joint centre from the neck, as a share of half the biacromial breadth.
SHOULDER_JOINT_SHARE = 0.80
#: Distance between the hip joint centres as a share of the hip breadth.
HIP_JOINT_SHARE = 0.58
#: Hip joints above a seat when sitting (buttocks and thigh), fraction of stature.
SEAT_CLEARANCE_RATIO = 0.052

#: Build (overall girth) factor: (mean, relative sd); multiplies every limb and trunk radius.
BUILD = (1.0, 0.10)
#: Per-part girth jitter on top of the build, relative sd.
PART_GIRTH_SD = 0.06
#: Base radii at a stature of 1 m with build 1, metres per metre of stature (the
#: generator's own body: limb radii at the proximal and distal ends, head semi-axes
#: lateral / forward / up, neck radius, trunk forward depths).
BASE_RADII = {
    "head": (0.0436, 0.0552, 0.0669), "neck": 0.0320, "chest_forward": 0.0640,
    "pelvis_forward": 0.0669, "pelvis_up": 0.0727, "upper_arm": (0.0291, 0.0233),
    "forearm": (0.0233, 0.0174), "hand_half_width": 0.0262, "hand_thickness": 0.0093, "thigh": (0.0465, 0.0326),
    "shin": (0.0302, 0.0233), "foot_height": 0.0221,
}
#: Chest lateral semi-axis as a share of half the biacromial breadth.
CHEST_WIDTH_SHARE = 0.74


def _draw(rng: np.random.Generator, mean: float, relative_sd: float) -> float:
    """mean * (1 + relative_sd * z), z ~ N(0, 1) clipped to +-CLIP_SDS."""
    return mean * (1.0 + relative_sd * float(np.clip(rng.standard_normal(), -CLIP_SDS, CLIP_SDS)))


@dataclass(frozen=True)
class Anthropometry:
    """One person's proportions, metres. Vertical segments add up to ``stature``:
    ``ankle_height + shin + thigh + spine + 2 * neck_head``.

    shoulder_offset : lateral offset of each shoulder joint from the neck joint
    shoulder_drop : shoulder joints below the neck joint along the trunk
    hip_width : hip joint centre to hip joint centre
    shoulder_breadth, hip_breadth : the outer breadths (biacromial, hips)
    build : overall girth factor (1 = average); radii : the renderer's radii (BodyShape keys)
    """

    stature: float
    ankle_height: float
    shin: float
    thigh: float
    spine: float
    neck_head: float
    upper_arm: float
    forearm: float
    hand: float
    foot: float
    foot_width: float
    shoulder_breadth: float
    shoulder_offset: float
    shoulder_drop: float
    hip_breadth: float
    hip_width: float
    build: float
    radii: dict

    def bone_lengths(self) -> np.ndarray:
        """Lengths of :data:`occupose.joints.BONES`, (14,) float64 metres."""
        shoulder = float(np.hypot(self.shoulder_offset, self.shoulder_drop))
        # each bone by the joint farther from the pelvis
        by_outer = {"head": self.neck_head, "neck": self.spine, "shoulder": shoulder, "elbow": self.upper_arm,
                    "wrist": self.forearm, "hip": self.hip_width / 2.0, "knee": self.thigh, "ankle": self.shin}
        order = ("pelvis", "neck", "hip", "shoulder", "head", "knee", "elbow", "ankle", "wrist")
        names = {i: name.split("_")[-1] for name, i in JOINT_INDEX.items()}
        return np.array([by_outer[max(names[a], names[b], key=order.index)] for a, b in BONES])

    def motion_dims(self) -> BodyDims:
        """These lengths in the procedural motion generator's input format (the values
        are this person's, nothing is taken from :data:`occupose.body.dims.DEFAULT_DIMS`)."""
        return BodyDims(pelvis_width=self.hip_width, spine=self.spine, neck_head=self.neck_head,
                        shoulder_width=self.shoulder_offset, shoulder_drop=self.shoulder_drop,
                        upper_arm=self.upper_arm, forearm=self.forearm, thigh=self.thigh, shin=self.shin,
                        ankle_height=self.ankle_height, seat_clearance=SEAT_CLEARANCE_RATIO * self.stature)

    def body_shape(self, rng: np.random.Generator, clothing: str = "normal") -> BodyShape:
        """The renderer's body for this person, with colours of ``clothing`` style."""
        return BodyShape(radii=self.radii, colors=clothing_colors(rng, clothing))


def draw_anthropometry(rng: np.random.Generator) -> Anthropometry:
    """Draw one person (module docstring for the ranges and their sources)."""
    stature = float(rng.uniform(*STATURE_RANGE))
    vertical = np.array([_draw(rng, *r) for r in (ANKLE_RATIO, SHIN_RATIO, THIGH_RATIO, SPINE_RATIO,
                                                  HEAD_NECK_RATIO)])
    ankle, shin, thigh, spine, head_neck = stature * vertical / vertical.sum()
    upper_arm, forearm, hand, foot, foot_width, shoulder_breadth, hip_breadth, drop = (
        stature * _draw(rng, *r) for r in (UPPER_ARM_RATIO, FOREARM_RATIO, HAND_RATIO, FOOT_RATIO,
                                           FOOT_WIDTH_RATIO, SHOULDER_BREADTH_RATIO, HIP_BREADTH_RATIO,
                                           SHOULDER_DROP_RATIO))
    build = _draw(rng, *BUILD)

    def girth(base: float) -> float:
        return stature * build * _draw(rng, base, PART_GIRTH_SD)

    b = BASE_RADII
    head = np.array([stature * _draw(rng, r, PART_GIRTH_SD) for r in b["head"]])  # heads do not follow the build
    radii = {
        "head": head,
        "neck": girth(b["neck"]),
        "chest": np.array([CHEST_WIDTH_SHARE * shoulder_breadth / 2 * build, girth(b["chest_forward"]), 0.0]),
        "pelvis": np.array([hip_breadth / 2 * float(np.sqrt(build)), girth(b["pelvis_forward"]),
                            girth(b["pelvis_up"])]),
        "upper_arm": tuple(girth(r) for r in b["upper_arm"]),
        "forearm": tuple(girth(r) for r in b["forearm"]),
        "hand": np.array([hand / 2, girth(b["hand_half_width"]), girth(b["hand_thickness"])]),
        "thigh": tuple(girth(r) for r in b["thigh"]),
        "shin": tuple(girth(r) for r in b["shin"]),
        "foot": np.array([foot / 2, foot_width / 2, stature * b["foot_height"]]),
    }
    return Anthropometry(
        stature=stature, ankle_height=float(ankle), shin=float(shin), thigh=float(thigh), spine=float(spine),
        neck_head=float(head_neck / 2), upper_arm=upper_arm, forearm=forearm, hand=hand, foot=foot,
        foot_width=foot_width, shoulder_breadth=shoulder_breadth,
        shoulder_offset=SHOULDER_JOINT_SHARE * shoulder_breadth / 2, shoulder_drop=drop,
        hip_breadth=hip_breadth, hip_width=HIP_JOINT_SHARE * hip_breadth, build=build, radii=radii,
    )
