"""Articulated body models made of round cones: the kinematic tree, DOFs, limits and parts.

A :class:`BodyModel` is a kinematic tree of ``J`` nodes in parent-first order. Node ``j``
sits at ``offsets[j]`` in its parent's frame (metres); its frame is the parent's frame
turned by the node's rotational DOFs, applied in DOF order about the node's own (already
turned) coordinate axes. The root's parent is the world; its translational DOFs move it in
the world frame. At the zero pose every frame is aligned with the world: x forward, y to
the person's left, z up (the person stands upright facing +x, arms and legs hanging).

Every model part is a set of round cones (capsules, :data:`occupose.geometry.primitives.ROUND_CONE`):
end ``a`` (radius ra) to end ``b`` (radius rb), each end a fixed offset in a node's frame.

Two built-in models (:data:`BODY_MODELS`, :func:`body_model`):

``full`` -- the first paper's 10-part, 25-DOF body (Fig. 6 of the occupancy-HMM paper).
    DOFs in order (the index of the first of each group in brackets):

    - [0] ``x, y, z``: the pelvis (midpoint of the hips), world metres;
    - [3] ``heading, trunk_lean, trunk_side``: the torso turned about +z (0 = facing +x,
      periodic), leaned forward, leaned to its left (Z-Y-X Euler angles);
    - [6] ``neck_flex, neck_side, neck_twist``: the head nodded forward, tilted left, turned left;
    - [9] ``left_shoulder_flex, _abd, _rot, left_elbow``: the upper arm forward (pi/2
      horizontal, pi straight up), then out to the side, then turned outwards about its
      axis; elbow flexion (0 = straight); [13] the same for the right arm (mirrored);
    - [17] ``left_hip_flex, _abd, _rot, left_knee``: the thigh forward, out to the side,
      turned outwards; knee flexion (0 = straight, the shin swings back); [21] right leg.

    Parts (one round cone each, the torso two side by side): torso, head, left_upper_arm,
    left_forearm (the hand included as a short extension past the wrist), right_upper_arm,
    right_forearm, left_thigh, left_shin, right_thigh, right_shin. Partitions: the root
    with the torso's orientation (weighted by the torso and the upper arms and thighs,
    whose attachment shows the heading too), the head, the left arm, the right arm, the
    left leg, the right leg.

``upper`` -- the second paper's 6-part, 17-DOF upper body (top view):
    x, y, z (pelvis), heading, trunk_lean (the bend at the pelvis), neck_flex, neck_side,
    per arm shoulder flex/abd/rot, elbow and forearm_twist (the turn of the forearm and
    the hand plane about the forearm's axis). Shapes: a head cone, a shoulder bar, an
    elliptic-cylinder torso as 3 parallel cones (left, centre, right), per arm an upper
    arm cone, a forearm cone and a flat hand of 2 thin parallel cones. Weighting parts and
    their DOFs are Table 1 of the paper: head (neck), shoulders (x, y, z), torso (heading,
    trunk_lean), right_arm and left_arm (5 each). Partitions: the root with heading and
    lean (weighted by the shoulders and the torso), the head, the left arm, the right arm.
    (The paper's state vector lists the right arm first; both models here put left first.)

Angle conventions equal :mod:`occupose.synth.motion` (same names), so a procedural pose's
arm and leg angles carry over; the model's hips turn with the torso where the generator's
stay level, so hip flexion here = the generator's hip flexion + trunk lean.

Deviations from the papers, and why: the full model's torso is not one cylinder but two
cones side by side, a flat section like the upper model's (and a person's): a round torso
looks the same turned any way, so a standing person's heading rested on the shoulders and
hips alone and drifted by 30-60 degrees while they gestured with their legs hidden behind
a chair. The upper model's second neck DOF is the sideways tilt, not the turn about the
head's axis, because a round-cone head does not change when turned about its axis (the
full model keeps the first paper's 3 head DOFs; its neck_twist is unobservable for the
same reason and gets a small diffusion). Each limb is one partition (shoulder + elbow,
hip + knee) because the upper segment's roll about its own axis is seen only through the
bent lower segment.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

from occupose.joints import JOINTS
from occupose.body.dims import DEFAULT_DIMS, BodyDims

TRANSLATION, ROTATION = 0, 1


class Partition(NamedTuple):
    """A group of DOFs sampled together and the parts whose likelihood weights them.

    dofs : (n,) int64, indices into the pose vector
    parts : (k,) int64, indices into the model's ``part_names``
    """

    dofs: np.ndarray
    parts: np.ndarray


@dataclass(frozen=True, eq=False)
class BodyModel:
    """An articulated body of round cones (see the module docstring for the conventions).

    name : the registry name ("full" or "upper"); dims, girth : the body size it was built for
    dof_names : (D,) str; limits : (D, 2) float64, radians or metres
    angular : (D,) bool, True for angles; periodic : (D,) bool, angles that wrap in
        [-pi, pi) instead of stopping at their limits (the heading)
    kinds : (D,) str, the DOF's kind for default diffusion scales (see occupose.body.dynamics)
    node_names : (J,) str; parents : (J,) int64, -1 for the root; offsets : (J, 3) metres
    dof_node : (D,) int64, the node each DOF turns or moves; dof_type : (D,) int64,
        TRANSLATION or ROTATION; dof_axis : (D,) int64, 0/1/2 = local x/y/z;
        dof_sign : (D,) float64, +1 or -1 (the DOF turns about sign * axis)
    part_names : (K,) str, the weighting / visibility parts
    capsule_part : (C,) int64; capsule_radii : (C, 2) float64 (ra, rb) metres
    capsule_nodes : (2, C) int64 and capsule_offsets : (2, C, 3) metres: ends a ([0]) and
        b ([1]) of each round cone as offsets in a node's frame
    joint_nodes : (15,) int64, the node at each canonical joint, -1 where the model does
        not report the joint; joint_offsets : (15, 3) offsets in those nodes' frames
    partitions : list of Partition in partitioned-sampling order (torso first, then down
        the tree); weight_groups : list of Partition, one per part, for part-based filters
    """

    name: str
    dims: BodyDims
    girth: float
    dof_names: tuple[str, ...]
    limits: np.ndarray
    angular: np.ndarray
    periodic: np.ndarray
    kinds: tuple[str, ...]
    node_names: tuple[str, ...]
    parents: np.ndarray
    offsets: np.ndarray
    dof_node: np.ndarray
    dof_type: np.ndarray
    dof_axis: np.ndarray
    dof_sign: np.ndarray
    part_names: tuple[str, ...]
    capsule_part: np.ndarray
    capsule_radii: np.ndarray
    capsule_nodes: np.ndarray
    capsule_offsets: np.ndarray
    joint_nodes: np.ndarray
    joint_offsets: np.ndarray
    partitions: tuple[Partition, ...]
    weight_groups: tuple[Partition, ...]

    @property
    def num_dofs(self) -> int:
        return len(self.dof_names)

    @property
    def num_parts(self) -> int:
        return len(self.part_names)

    @property
    def num_capsules(self) -> int:
        return int(self.capsule_part.shape[0])

    @property
    def reported_joints(self) -> np.ndarray:
        """(15,) bool, the canonical joints this model reports."""
        return self.joint_nodes >= 0

    def dof(self, name: str) -> int:
        """Index of the DOF called ``name``."""
        if name not in self.dof_names:
            raise ValueError(f"model {self.name!r} has no DOF {name!r}; valid names: {', '.join(self.dof_names)}")
        return self.dof_names.index(name)


# ---------------------------------------------------------------------------------------
# Building models from a node table


class _Builder:
    """Collects nodes, DOFs, capsules and joints, then freezes them into a BodyModel."""

    def __init__(self):
        self.nodes: list[tuple[str, int, tuple]] = []   # name, parent, offset
        self.dofs: list[tuple] = []                     # name, node, type, axis, sign, lo, hi, kind
        self.capsules: list[tuple] = []                 # part, node_a, off_a, node_b, off_b, ra, rb
        self.joints: dict[str, tuple[int, tuple]] = {}

    def node(self, name: str, parent: str | None, offset, dofs=(), joint: str | None = None) -> int:
        """Add a node; ``dofs`` are (name, type, axis, sign, lo, hi, kind) in application order."""
        index = len(self.nodes)
        parent_index = -1 if parent is None else [n[0] for n in self.nodes].index(parent)
        self.nodes.append((name, parent_index, tuple(float(v) for v in offset)))
        for dof_name, kind_of_dof, axis, sign, lo, hi, kind in dofs:
            self.dofs.append((dof_name, index, kind_of_dof, axis, sign, lo, hi, kind))
        if joint is not None:
            self.joints[joint] = (index, (0.0, 0.0, 0.0))
        return index

    def index(self, node: str) -> int:
        return [n[0] for n in self.nodes].index(node)

    def capsule(self, part: str, node_a: str, off_a, node_b: str, off_b, ra: float, rb: float) -> None:
        self.capsules.append((part, self.index(node_a), off_a, self.index(node_b), off_b, ra, rb))

    def build(self, name: str, dims: BodyDims, girth: float, part_names: tuple[str, ...],
              partitions: list[tuple[list[str], list[str]]],
              weight_groups: list[tuple[list[str], list[str]]]) -> BodyModel:
        dof_names = tuple(d[0] for d in self.dofs)

        def frozen(values, dtype):
            array = np.ascontiguousarray(np.array(values, dtype=dtype))
            array.flags.writeable = False
            return array

        def groups(spec) -> tuple[Partition, ...]:
            return tuple(Partition(frozen([dof_names.index(d) for d in dofs], np.int64),
                                   frozen([part_names.index(p) for p in parts], np.int64))
                         for dofs, parts in spec)

        joint_nodes = [self.joints[j][0] if j in self.joints else -1 for j in JOINTS]
        joint_offsets = [self.joints[j][1] if j in self.joints else (0.0, 0.0, 0.0) for j in JOINTS]
        periodic = [d[7] == "heading" for d in self.dofs]
        model = BodyModel(
            name=name, dims=dims, girth=girth, dof_names=dof_names,
            limits=frozen([(d[5], d[6]) for d in self.dofs], np.float64),
            angular=frozen([d[2] == ROTATION for d in self.dofs], bool),
            periodic=frozen(periodic, bool),
            kinds=tuple(d[7] for d in self.dofs),
            node_names=tuple(n[0] for n in self.nodes),
            parents=frozen([n[1] for n in self.nodes], np.int64),
            offsets=frozen([n[2] for n in self.nodes], np.float64),
            dof_node=frozen([d[1] for d in self.dofs], np.int64),
            dof_type=frozen([d[2] for d in self.dofs], np.int64),
            dof_axis=frozen([d[3] for d in self.dofs], np.int64),
            dof_sign=frozen([d[4] for d in self.dofs], np.float64),
            part_names=part_names,
            capsule_part=frozen([part_names.index(c[0]) for c in self.capsules], np.int64),
            capsule_radii=frozen([(c[5], c[6]) for c in self.capsules], np.float64),
            capsule_nodes=frozen([[c[1] for c in self.capsules], [c[3] for c in self.capsules]], np.int64),
            capsule_offsets=frozen([[c[2] for c in self.capsules], [c[4] for c in self.capsules]], np.float64),
            joint_nodes=frozen(joint_nodes, np.int64),
            joint_offsets=frozen(joint_offsets, np.float64),
            partitions=groups(partitions), weight_groups=groups(weight_groups),
        )
        _check_model(model)
        return model


def _check_model(m: BodyModel) -> None:
    """Internal consistency of a built model (a bug here is ours, not the caller's)."""
    if np.any(m.parents >= np.arange(len(m.parents))):
        raise RuntimeError(f"model {m.name!r}: nodes are not in parent-first order")
    if np.any(np.diff(m.dof_node) < 0):
        raise RuntimeError(f"model {m.name!r}: DOFs must be grouped by node in node order")
    for groups, what in ((m.partitions, "partitions"), (m.weight_groups, "weight_groups")):
        covered = np.sort(np.concatenate([g.dofs for g in groups]))
        if not np.array_equal(covered, np.arange(m.num_dofs)):
            raise RuntimeError(f"model {m.name!r}: {what} must hold every DOF exactly once")


# ---------------------------------------------------------------------------------------
# DOF tables (anatomical ranges of motion, radians; Kapandji / AAOS normal values, slightly
# widened so procedural and mocap poses stay inside)

_PI = math.pi
_ROOT_XY = 50.0   # metres: the root may be anywhere in a (large) room
#: Pelvis height range, metres (lying on the floor to standing on tiptoe of a tall person).
ROOT_Z_RANGE = (0.0, 1.6)


def _t(name, axis, lo, hi, kind):
    return (name, TRANSLATION, axis, 1.0, lo, hi, kind)


def _r(name, axis, sign, lo, hi, kind):
    return (name, ROTATION, axis, sign, lo, hi, kind)


def _root_dofs(with_side: bool):
    dofs = [_t("x", 0, -_ROOT_XY, _ROOT_XY, "root_xy"), _t("y", 1, -_ROOT_XY, _ROOT_XY, "root_xy"),
            _t("z", 2, *ROOT_Z_RANGE, "root_z"),
            _r("heading", 2, 1.0, -_PI, _PI, "heading"),
            _r("trunk_lean", 1, 1.0, -0.6, 1.7, "trunk")]     # extension 35 deg .. flexion 95 deg
    if with_side:
        dofs.append(_r("trunk_side", 0, -1.0, -0.7, 0.7, "trunk"))
    return dofs


def _shoulder_dofs(side: str, s: float):
    return [_r(f"{side}_shoulder_flex", 1, -1.0, -1.1, _PI, "shoulder"),   # extension 60 .. 180 deg
            _r(f"{side}_shoulder_abd", 0, s, -0.7, 2.9, "shoulder"),       # adduction 40 .. 165 deg
            _r(f"{side}_shoulder_rot", 2, s, -1.7, 1.7, "shoulder")]       # internal / external 95 deg


def _hip_dofs(side: str, s: float):
    return [_r(f"{side}_hip_flex", 1, -1.0, -0.6, 2.45, "hip"),            # extension 35 .. 140 deg
            _r(f"{side}_hip_abd", 0, s, -0.6, 1.0, "hip"),                 # adduction 35 .. 57 deg
            _r(f"{side}_hip_rot", 2, s, -0.9, 0.9, "hip")]                 # internal / external 50 deg


_ELBOW = (0.0, 2.7)        # flexion 0 .. 155 deg
_KNEE = (0.0, 2.7)         # flexion 0 .. 155 deg
_FOREARM_TWIST = (-1.6, 1.6)


# ---------------------------------------------------------------------------------------
# Shapes: radii of an average adult at girth 1 (metres), from mean circumferences of the
# ANSUR II survey rounded to the nearest 5 mm and adjusted to cover the renderer's bodies:
# upper arm 0.05 -> 0.04, forearm 0.04 -> 0.035, thigh 0.08 -> 0.055, calf 0.05 -> 0.04;
# the torso's two cones (FULL_TORSO_SPREAD), 0.12 at the hips -> 0.118 at the chest, were
# chosen among three flat sections by tracking the catalogue's scenes. The head is sized
# from the neck -> head-centre length (0.11 m at the default), not the girth.

FULL_RADII = {"torso": (0.12, 0.118), "head": (0.055, 0.085), "upper_arm": (0.05, 0.04),
              "forearm": (0.04, 0.035), "thigh": (0.08, 0.055), "shin": (0.05, 0.04)}
UPPER_RADII = {"head": (0.055, 0.085), "shoulders": (0.06, 0.06), "torso": (0.10, 0.10),
               "upper_arm": (0.05, 0.04), "forearm": (0.04, 0.03), "hand": (0.02, 0.018)}
#: Lateral offset of the upper model's side torso cones at girth 1, metres: with radius
#: 0.10 the 3 cones span an elliptic section of half-width 0.165 and half-depth 0.10.
UPPER_TORSO_SPREAD = 0.065
#: Lateral offsets of the full model's two torso cones at girth 1, metres, at the hips and
#: at the chest: with their radii they span a section of half-width 0.15 and half-depth 0.12
#: at the hips and 0.173 x 0.118 at the chest (the renderer's chest: 0.165 x 0.110). Hips
#: as wide as the chest (a flat section all the way) tracked a walk seen side on worse:
#: the legs swapped more often.
FULL_TORSO_SPREAD = (0.03, 0.055)
#: Hand of the upper model: half the palm width (the offset of its two thin cones across
#: the palm) and the start and end of the cones past the wrist, metres at default size.
HAND_HALF_WIDTH, HAND_START, HAND_END = 0.022, 0.015, 0.15
#: Full model: the forearm cone continues this far past the wrist (the hand), metres at
#: default size.
FULL_HAND_EXTENSION = 0.08


def _head(b: _Builder, dims: BodyDims, radii) -> None:
    k = dims.neck_head / DEFAULT_DIMS.neck_head
    nh = dims.neck_head
    # the top of the head, b + rb, lands about 2 * neck_head above the neck (BodyDims.height)
    b.capsule("head", "neck", (0.0, 0.0, 0.3 * nh), "neck", (0.0, 0.0, 1.25 * nh),
              radii["head"][0] * k, radii["head"][1] * k)


def _check_size(dims: BodyDims, girth: float) -> None:
    if not isinstance(dims, BodyDims):
        raise ValueError(f"dims must be a BodyDims, got {type(dims).__name__}")
    if not (isinstance(girth, (int, float, np.floating, np.integer)) and math.isfinite(girth) and 0.5 <= girth <= 2.0):
        raise ValueError(f"girth must be a radius scale in [0.5, 2.0] (1 = average adult), got {girth!r}")


def full_model(dims: BodyDims = DEFAULT_DIMS, girth: float = 1.0) -> BodyModel:
    """The 10-part, 25-DOF body of the first paper for a body of size ``dims`` (segment
    lengths, metres) and ``girth`` (scale of the radii of torso and limbs and of the torso
    cones' spacing, 1 = average adult)."""
    _check_size(dims, girth)
    g, d = float(girth), dims
    b = _Builder()
    sh_z = d.spine - d.shoulder_drop
    b.node("pelvis", None, (0, 0, 0), _root_dofs(with_side=True), joint="pelvis")
    b.node("neck", "pelvis", (0, 0, d.spine),
           [_r("neck_flex", 1, 1.0, -0.9, 1.2, "neck"), _r("neck_side", 0, -1.0, -0.8, 0.8, "neck"),
            _r("neck_twist", 2, 1.0, -1.4, 1.4, "neck_twist")], joint="neck")
    b.node("head", "neck", (0, 0, d.neck_head), joint="head")
    for side, s in (("left", 1.0), ("right", -1.0)):
        b.node(f"{side}_shoulder", "pelvis", (0, s * d.shoulder_width, sh_z), _shoulder_dofs(side, s),
               joint=f"{side}_shoulder")
        b.node(f"{side}_elbow", f"{side}_shoulder", (0, 0, -d.upper_arm),
               [_r(f"{side}_elbow", 1, -1.0, *_ELBOW, "elbow")], joint=f"{side}_elbow")
        b.node(f"{side}_wrist", f"{side}_elbow", (0, 0, -d.forearm), joint=f"{side}_wrist")
    for side, s in (("left", 1.0), ("right", -1.0)):
        b.node(f"{side}_hip", "pelvis", (0, s * 0.5 * d.pelvis_width, 0), _hip_dofs(side, s), joint=f"{side}_hip")
        b.node(f"{side}_knee", f"{side}_hip", (0, 0, -d.thigh),
               [_r(f"{side}_knee", 1, 1.0, *_KNEE, "knee")], joint=f"{side}_knee")
        b.node(f"{side}_ankle", f"{side}_knee", (0, 0, -d.shin), joint=f"{side}_ankle")

    r = {k: (v[0] * g, v[1] * g) for k, v in FULL_RADII.items()}
    # torso: two cones side by side (a flat section, which shows the heading), closer at the
    # hips; bottom caps ~5 cm below the hip joints, top caps at about the neck joint
    hips, chest = FULL_TORSO_SPREAD
    for side in (g, -g):  # left, right (the spacing scales with the girth)
        b.capsule("torso", "pelvis", (0, side * hips, 0.12 * d.spine), "pelvis", (0, side * chest, 0.79 * d.spine),
                  *r["torso"])
    _head(b, d, FULL_RADII)
    hand = FULL_HAND_EXTENSION * d.forearm / DEFAULT_DIMS.forearm
    for side in ("left", "right"):
        b.capsule(f"{side}_upper_arm", f"{side}_shoulder", (0, 0, 0), f"{side}_elbow", (0, 0, 0), *r["upper_arm"])
        b.capsule(f"{side}_forearm", f"{side}_elbow", (0, 0, 0), f"{side}_elbow", (0, 0, -d.forearm - hand),
                  *r["forearm"])
    for side in ("left", "right"):
        b.capsule(f"{side}_thigh", f"{side}_hip", (0, 0, 0), f"{side}_knee", (0, 0, 0), *r["thigh"])
        b.capsule(f"{side}_shin", f"{side}_knee", (0, 0, 0), f"{side}_ankle", (0, 0, 0), *r["shin"])

    parts = ("torso", "head", "left_upper_arm", "left_forearm", "right_upper_arm", "right_forearm",
             "left_thigh", "left_shin", "right_thigh", "right_shin")
    names = [n for n, *_ in b.dofs]

    def block(prefix):
        return [n for n in names if n.startswith(prefix)]

    root = ["x", "y", "z", "heading", "trunk_lean", "trunk_side"]
    limbs = [("left_shoulder", "left_elbow", ["left_upper_arm", "left_forearm"]),
             ("right_shoulder", "right_elbow", ["right_upper_arm", "right_forearm"]),
             ("left_hip", "left_knee", ["left_thigh", "left_shin"]),
             ("right_hip", "right_knee", ["right_thigh", "right_shin"])]
    # The shoulders and hips the torso carries show its heading too (and the torso alone
    # little of it when seen side on), so the upper arms and thighs weight its partition.
    partitions = [(root, ["torso", "left_upper_arm", "right_upper_arm", "left_thigh", "right_thigh"]),
                  (block("neck_"), ["head"])]
    partitions += [(block(upper) + block(lower), list(limb_parts)) for upper, lower, limb_parts in limbs]
    weight_groups = [(root, ["torso"]), (block("neck_"), ["head"])]
    for upper, lower, (p_upper, p_lower) in limbs:
        weight_groups += [(block(upper), [p_upper]), (block(lower), [p_lower])]
    weight_groups.sort(key=lambda group: parts.index(group[1][0]))
    return b.build("full", dims, float(girth), parts, partitions, weight_groups)


def upper_model(dims: BodyDims = DEFAULT_DIMS, girth: float = 1.0) -> BodyModel:
    """The 6-part, 17-DOF upper body of the second paper for a body of size ``dims`` and
    ``girth`` (see :func:`full_model`)."""
    _check_size(dims, girth)
    g, d = float(girth), dims
    b = _Builder()
    sh_z = d.spine - d.shoulder_drop
    b.node("pelvis", None, (0, 0, 0), _root_dofs(with_side=False), joint="pelvis")
    b.node("neck", "pelvis", (0, 0, d.spine),
           [_r("neck_flex", 1, 1.0, -0.9, 1.2, "neck"), _r("neck_side", 0, -1.0, -0.8, 0.8, "neck")], joint="neck")
    b.node("head", "neck", (0, 0, d.neck_head), joint="head")
    for side, s in (("left", 1.0), ("right", -1.0)):
        b.node(f"{side}_shoulder", "pelvis", (0, s * d.shoulder_width, sh_z), _shoulder_dofs(side, s),
               joint=f"{side}_shoulder")
        b.node(f"{side}_elbow", f"{side}_shoulder", (0, 0, -d.upper_arm),
               [_r(f"{side}_elbow", 1, -1.0, *_ELBOW, "elbow"),
                _r(f"{side}_forearm_twist", 2, s, *_FOREARM_TWIST, "forearm_twist")], joint=f"{side}_elbow")
        b.node(f"{side}_wrist", f"{side}_elbow", (0, 0, -d.forearm), joint=f"{side}_wrist")

    r = {k: (v[0] * g, v[1] * g) for k, v in UPPER_RADII.items()}
    _head(b, d, UPPER_RADII)
    inset = d.shoulder_width - 0.05 * g
    b.capsule("shoulders", "pelvis", (0, inset, sh_z + 0.01), "pelvis", (0, -inset, sh_z + 0.01), *r["shoulders"])
    for y in (UPPER_TORSO_SPREAD * g, 0.0, -UPPER_TORSO_SPREAD * g):
        b.capsule("torso", "pelvis", (0, y, 0.1 * d.spine), "pelvis", (0, y, sh_z - 0.07), *r["torso"])
    k = d.forearm / DEFAULT_DIMS.forearm
    for side in ("left", "right"):
        arm = f"{side}_arm"
        b.capsule(arm, f"{side}_shoulder", (0, 0, 0), f"{side}_elbow", (0, 0, 0), *r["upper_arm"])
        b.capsule(arm, f"{side}_elbow", (0, 0, 0), f"{side}_elbow", (0, 0, -d.forearm), *r["forearm"])
        # the palm spans the forearm's local x (forward when the arm hangs: palm facing the thigh)
        for x in (HAND_HALF_WIDTH * g, -HAND_HALF_WIDTH * g):
            b.capsule(arm, f"{side}_elbow", (x, 0, -d.forearm - HAND_START * k),
                      f"{side}_elbow", (0.9 * x, 0, -d.forearm - HAND_END * k), *r["hand"])

    parts = ("head", "shoulders", "torso", "right_arm", "left_arm")
    names = [n for n, *_ in b.dofs]
    arm = {side: [n for n in names if n.startswith(f"{side}_")] for side in ("left", "right")}
    neck = ["neck_flex", "neck_side"]
    partitions = [(["x", "y", "z", "heading", "trunk_lean"], ["shoulders", "torso"]), (neck, ["head"]),
                  (arm["left"], ["left_arm"]), (arm["right"], ["right_arm"])]
    weight_groups = [(neck, ["head"]), (["x", "y", "z"], ["shoulders"]), (["heading", "trunk_lean"], ["torso"]),
                     (arm["right"], ["right_arm"]), (arm["left"], ["left_arm"])]
    return b.build("upper", dims, float(girth), parts, partitions, weight_groups)


_BUILDERS = {"full": full_model, "upper": upper_model}

#: The built-in models at the default body size (an average adult, girth 1).
BODY_MODELS: dict[str, BodyModel] = {name: build() for name, build in _BUILDERS.items()}


def body_model(name: str, dims: BodyDims = DEFAULT_DIMS, girth: float = 1.0) -> BodyModel:
    """The built-in model ``name`` ("full" or "upper") sized for ``dims`` and ``girth``."""
    if name not in _BUILDERS:
        raise ValueError(f"unknown body model {name!r}; valid names: {', '.join(_BUILDERS)}")
    return _BUILDERS[name](dims, girth)

