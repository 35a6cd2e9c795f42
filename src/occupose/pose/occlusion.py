"""Which body parts are hidden by the scene, and what the filter may estimate (paper III-D).

Each body part is approximated by ``n`` spheres along the axes of its capsules. At every
frame the previous estimate, moved to its blob's new centre of mass, is tested for what
hides it (the paper tests the occupancy grid's visibility; the tracker tests the depth
images, :func:`hidden_parts_in_views`, below): a part with more than half of its spheres
hidden is hidden. Every part runs the two-state machine of the paper's Fig. 7:

- VISIBLE: its configuration (its DOFs, relative to its parent) is saved in a memory M;
  it becomes HIDDEN when its current configuration tests hidden;
- HIDDEN: the memory configuration is tested instead; it becomes VISIBLE again when that
  configuration tests visible.

A hidden part hides its whole subtree (a hidden thigh hides the shin); a hidden root part
(the torso) suspends the track: it is kept but not estimated. The filter runs only on the
DOFs of visible parts; hidden parts keep their memory configuration relative to their
parent. A part that becomes visible again gets a wider search for a few frames (its DOFs'
diffusion multiplied by ``resume_scale`` for ``resume_frames`` frames).

Two tests of which parts are hidden: :func:`hidden_parts` against the grid's cell
visibility, as in the paper, and :func:`hidden_parts_in_views` against the depth images
and each pixel's owner, which the tracker uses (the paper's grid test hides parts behind
the person's own surface). :func:`part_tree` gives a body model's part tree for the state
machine, :func:`joint_parts` which parts a joint's visibility depends on, and
:func:`planted_legs` where hidden legs most likely are (feet on the floor).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence

import numpy as np

from occupose.body import BodyModel, joints_from_poses, limb_angles
from occupose.camera import Camera, pixels_from_points
from occupose.config import OcclusionConfig
from occupose.joints import JOINT_INDEX
from occupose.pose.proposals import forward, reach_towards

#: Grid visibility code of a hidden cell (see occupose.grid.occupancy).
HIDDEN_CELL = 2


def sphere_centres(a: np.ndarray, b: np.ndarray, n: int = 5) -> np.ndarray:
    """Centres of ``n`` spheres spread evenly along each capsule's axis.

    a, b : (C, 3) float64, metres, world capsule ends
    Returns (C, n, 3): the i-th centre at fraction (i + 0.5) / n from a to b.
    """
    t = (np.arange(n) + 0.5) / n
    return a[:, None, :] + t[None, :, None] * (b - a)[:, None, :]


def hidden_parts(a: np.ndarray, b: np.ndarray, capsule_part: np.ndarray, num_parts: int,
                 visibility_at: Callable[[np.ndarray], np.ndarray], n: int = 5) -> np.ndarray:
    """Which parts have more than half of their spheres in hidden cells.

    a, b : (C, 3) capsule ends of one pose, metres, world; capsule_part : (C,) part index
    visibility_at : callable mapping points (N, 3) to grid visibility codes (N,)
    Returns (num_parts,) bool.
    """
    centres = sphere_centres(np.asarray(a, float), np.asarray(b, float), n)
    codes = np.asarray(visibility_at(centres.reshape(-1, 3))).reshape(len(a), n)
    hidden = np.bincount(capsule_part, weights=(codes == HIDDEN_CELL).sum(axis=1), minlength=num_parts)
    total = np.bincount(capsule_part, weights=np.full(len(a), n, float), minlength=num_parts)
    return hidden > 0.5 * np.maximum(total, 1)


class OcclusionState:
    """The visible/hidden state machine of one tracked person (Fig. 7 of the paper).

    part_parents : (K,) int, the parent part of each part (-1 for the root, the torso)
    part_dofs : K arrays of DOF indices, the DOFs that place each part relative to its parent
        (the root's DOFs place the whole body)
    resume_frames, resume_scale : the wider search of a part that is visible again
    """

    def __init__(self, part_parents: Sequence[int], part_dofs: Sequence[np.ndarray], num_dofs: int,
                 resume_frames: int = OcclusionConfig.resume_frames,
                 resume_scale: float = OcclusionConfig.resume_scale):
        self.parents = np.asarray(part_parents, int)
        k = len(self.parents)
        if len(part_dofs) != k:
            raise ValueError(f"part_dofs must have one entry per part ({k}), got {len(part_dofs)}")
        if np.sum(self.parents < 0) != 1 or np.any(self.parents >= np.arange(k)):
            raise ValueError(f"part_parents must be parent-first with one root (-1), got {self.parents.tolist()}")
        if resume_frames < 0 or not resume_scale >= 1.0:
            raise ValueError(f"resume_frames must be >= 0 and resume_scale >= 1, got {resume_frames}, {resume_scale}")
        self.root = int(np.flatnonzero(self.parents < 0)[0])
        self.part_dofs = [np.asarray(d, int) for d in part_dofs]
        self.num_dofs = int(num_dofs)
        self.resume_frames = int(resume_frames)
        self.resume_scale = float(resume_scale)
        self.visible = np.ones(k, bool)
        self.memory = np.zeros(self.num_dofs)
        self.resuming = np.zeros(k, int)  # frames of wider search left, per part
        self._has_memory = False

    @property
    def suspended(self) -> bool:
        """The root part is hidden: the track is kept but not estimated."""
        return not self.visible[self.root]

    def update(self, pose: np.ndarray, hidden_fn: Callable[[np.ndarray], np.ndarray]) -> np.ndarray:
        """Advance one frame.

        pose : (D,) the previous estimate moved to the blob's new centre of mass
        hidden_fn : pose (D,) -> (K,) bool, which parts of a pose lie in hidden cells
        Returns (K,) bool, the parts visible in this frame.
        """
        pose = np.asarray(pose, float)
        if not self._has_memory:
            self.memory = pose.copy()
            self._has_memory = True
        tested = self.memory.copy()
        for k, dofs in enumerate(self.part_dofs):  # visible parts test their current configuration
            if self.visible[k] or k == self.root:  # the root is tested where its blob now is
                tested[dofs] = pose[dofs]
        hidden = np.asarray(hidden_fn(tested), bool)
        visible = ~hidden
        for k in range(len(self.parents)):  # parents come first: inherit hidden down the tree
            if self.parents[k] >= 0 and not visible[self.parents[k]]:
                visible[k] = False
        came_back = visible & ~self.visible
        self.resuming = np.where(came_back, self.resume_frames, np.maximum(self.resuming - 1, 0))
        self.visible = visible
        for k, dofs in enumerate(self.part_dofs):  # M keeps the last visible configuration
            if visible[k]:
                self.memory[dofs] = pose[dofs]
        return visible.copy()

    def remember(self, estimate: np.ndarray) -> None:
        """Save the filter's estimate of the visible parts as their memory configuration."""
        estimate = np.asarray(estimate, float)
        for k, dofs in enumerate(self.part_dofs):
            if self.visible[k]:
                self.memory[dofs] = estimate[dofs]

    def active_dofs(self) -> np.ndarray:
        """(D,) bool: the DOFs the filter may estimate (those of visible parts)."""
        active = np.zeros(self.num_dofs, bool)
        for k, dofs in enumerate(self.part_dofs):
            active[dofs] |= self.visible[k]
        return active

    def diffusion_scale(self) -> np.ndarray:
        """(D,) multiplier of the filter's diffusion: ``resume_scale`` on parts that just came back."""
        scale = np.ones(self.num_dofs)
        for k, dofs in enumerate(self.part_dofs):
            if self.resuming[k] > 0:
                scale[dofs] = self.resume_scale
        return scale

    def with_memory(self, pose: np.ndarray) -> np.ndarray:
        """``pose`` with every hidden part's DOFs replaced by its memory configuration."""
        out = np.array(pose, float, copy=True)
        for k, dofs in enumerate(self.part_dofs):
            if not self.visible[k]:
                out[dofs] = self.memory[dofs]
        return out


def _dof_parts(model: BodyModel) -> np.ndarray:
    """(D,) int, the part (weight group) each DOF of ``model`` belongs to."""
    owner = np.full(model.num_dofs, -1)
    for k, group in enumerate(model.weight_groups):
        owner[group.dofs] = k
    return owner


def part_tree(model: BodyModel) -> tuple[list[int], list[np.ndarray]]:
    """Parent part of each part (-1 for the root) and the DOFs that place each part relative
    to its parent (the model's weight groups), for the occlusion state machine.

    A part's parent is the part owning the DOFs of the nearest ancestor node with DOFs.
    Raises ValueError for a model whose parts are not in parent-first order.
    """
    owner = _dof_parts(model)
    node_part = np.full(len(model.node_names), -1)
    for d in range(model.num_dofs):
        node_part[model.dof_node[d]] = owner[d]
    parents = []
    for group in model.weight_groups:
        node = int(model.dof_node[group.dofs].min())
        parent, up = -1, int(model.parents[node])
        while up >= 0 and parent < 0:
            parent, up = int(node_part[up]), int(model.parents[up])
        parents.append(parent)
    if any(p >= k for k, p in enumerate(parents)) or parents.count(-1) != 1:
        raise ValueError(f"body model {model.name!r} has no parent-first part tree (parents {parents})")
    return parents, [np.asarray(g.dofs) for g in model.weight_groups]


def joint_parts(model: BodyModel) -> list[np.ndarray]:
    """For each canonical joint, the parts whose DOFs place it (empty where the model does
    not report the joint): a joint is visible when all of them are."""
    owner = _dof_parts(model)
    out = []
    for node in model.joint_nodes:
        if node < 0:
            out.append(np.zeros(0, int))
            continue
        up = int(model.parents[node])
        chain = [int(node)] if up < 0 else []  # the root is placed by its own DOFs
        while up >= 0:
            chain.append(up)
            up = int(model.parents[up])
        out.append(np.unique(owner[np.isin(model.dof_node, chain)]))
    return out


def hidden_parts_in_views(a: np.ndarray, b: np.ndarray, radii: np.ndarray, capsule_part: np.ndarray,
                          num_parts: int, depths: Mapping[str, np.ndarray], owners: Mapping[str, np.ndarray],
                          cameras: Sequence[Camera], track_id: int, n: int = OcclusionConfig.spheres,
                          margin: float = OcclusionConfig.margin) -> np.ndarray:
    """Which parts have more than half of their spheres hidden from every camera.

    A sphere (``n`` per capsule, along its axis) is hidden from a camera when it projects
    outside the image, or onto a pixel whose measured surface is nearer than the sphere's
    front (its centre minus the capsule's radius there) by more than ``margin`` and that
    pixel does not belong to this person (``owners`` is not ``track_id``): the person's
    own body in front of a part (an arm across the chest) does not hide it, furniture
    and other people do. A pixel without a measurement hides nothing.

    This is the test of the paper's III-D with the depth images in place of the grid's
    cell visibility (:func:`occupose.pose.occlusion.hidden_parts`): a sphere on a limb's axis
    lies a few centimetres behind the person's own measured surface, in a cell the grid
    calls hidden, so the grid test hides visible parts (the paper notes this for seated
    legs); the pixel's owner tells the person's own surface from the scene's.

    a, b : (C, 3) capsule ends of one pose, metres, world; radii : (C, 2) metres
    capsule_part : (C,) part index; depths : camera name -> (H, W) float32 metres
    owners : camera name -> (H, W) int track id of each pixel (0 = nobody)
    Returns (num_parts,) bool.
    """
    centres, radius = _spheres(a, b, radii, n)
    hidden = np.ones(len(centres), bool)
    for camera in cameras:
        inside, ui, vi, z, measured = _measured_at(centres, camera, depths[camera.name])
        blocked = (measured > 0) & (measured < z - radius - margin) & (owners[camera.name][vi, ui] != track_id)
        hidden &= ~inside | blocked
    return _most_of_part(hidden, capsule_part, num_parts, n)


def parts_seen_through(a: np.ndarray, b: np.ndarray, radii: np.ndarray, capsule_part: np.ndarray, num_parts: int,
                       depths: Mapping[str, np.ndarray], cameras: Sequence[Camera],
                       n: int = OcclusionConfig.spheres, margin: float = OcclusionConfig.margin) -> np.ndarray:
    """Which parts have more than half of their spheres seen through by some camera: the
    sphere projects into its image onto a pixel whose measured surface lies beyond the
    sphere's back (its centre plus the capsule's radius there) by more than ``margin``. No
    body is there, whoever's pixel it is. A pixel without a measurement sees through nothing.

    The arguments are those of :func:`hidden_parts_in_views`. Returns (num_parts,) bool.
    """
    centres, radius = _spheres(a, b, radii, n)
    through = np.zeros(len(centres), bool)
    for camera in cameras:
        inside, _, _, z, measured = _measured_at(centres, camera, depths[camera.name])
        through |= inside & (measured > z + radius + margin)
    return _most_of_part(through, capsule_part, num_parts, n)


def _spheres(a: np.ndarray, b: np.ndarray, radii: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray]:
    """(C * n, 3) centres of ``n`` spheres along each capsule's axis (metres) and (C * n,) their radii."""
    t = (np.arange(n) + 0.5) / n
    centres = (a[:, None, :] + t[None, :, None] * (b - a)[:, None, :]).reshape(-1, 3)
    return centres, (radii[:, :1] + t[None, :] * (radii[:, 1:] - radii[:, :1])).reshape(-1)


def parts_out_of_view(a: np.ndarray, b: np.ndarray, radii: np.ndarray, capsule_part: np.ndarray, num_parts: int,
                      cameras: Sequence[Camera], n: int = OcclusionConfig.spheres) -> np.ndarray:
    """Which parts have more than half of their spheres outside every camera's image (beside
    it, or behind the camera): no camera could see them there, whatever the depths say.

    The arguments are those of :func:`hidden_parts_in_views`. Returns (num_parts,) bool.
    """
    centres, _ = _spheres(a, b, radii, n)
    inside = np.zeros(len(centres), bool)
    for camera in cameras:
        inside |= _in_image(centres, camera)[0]
    return _most_of_part(~inside, capsule_part, num_parts, n)


def _in_image(points: np.ndarray, camera: Camera):
    """Where points (N, 3) fall in ``camera``'s image: (inside (N,) bool, their pixel's
    column and row (N,) int (0 outside), their depth along the optical axis (N,) metres)."""
    uv, z = pixels_from_points(points, camera)
    uv = np.round(np.nan_to_num(uv, nan=-1.0, posinf=-1.0, neginf=-1.0))
    u, v = uv[:, 0].astype(np.int64), uv[:, 1].astype(np.int64)
    inside = (z > 0) & (u >= 0) & (u < camera.width) & (v >= 0) & (v < camera.height)
    return inside, np.where(inside, u, 0), np.where(inside, v, 0), z


def _measured_at(points: np.ndarray, camera: Camera, depth: np.ndarray):
    """Where points (N, 3) fall in ``camera``'s (H, W) ``depth`` (metres): :func:`_in_image`'s
    (inside, column, row, depth along the optical axis) and the depth measured at their
    pixel (N,) metres."""
    inside, ui, vi, z = _in_image(points, camera)
    return inside, ui, vi, z, depth[vi, ui]


def _most_of_part(flags: np.ndarray, capsule_part: np.ndarray, num_parts: int, n: int) -> np.ndarray:
    """(num_parts,) bool: the parts with more than half of their spheres (``n`` per capsule) flagged."""
    per_part = np.bincount(np.repeat(capsule_part, n), weights=flags, minlength=num_parts)
    total = np.bincount(np.repeat(capsule_part, n), minlength=num_parts)
    return per_part > 0.5 * np.maximum(total, 1)


def planted_legs(model: BodyModel, pose: np.ndarray, sides: Sequence[str], shins: Sequence[str] = (),
                 feet: Mapping[str, np.ndarray] | None = None, config: OcclusionConfig | None = None) -> np.ndarray:
    """``pose`` (D,) with the legs of ``sides`` ("left", "right") placed with their feet on
    the floor: hip flexion and knee bend (abduction and rotation 0) that put the ankle at
    the model's ankle height, the least bent such leg, the shin near vertical; for the
    ``shins`` (legs whose thigh is seen, its shin hidden) only the knee bend, the thigh
    left as it is. Where ``feet`` (side -> (3,) ankle, world metres, as
    :func:`occupose.pose.proposals.feet` finds them) shows a leg's foot, the leg reaches it
    instead: the knee bent forwards (the ankle as near it as the knee bend gets it, for a
    shin).

    For legs hidden behind furniture: the paper keeps a hidden part's last seen
    configuration relative to its parent, so straight legs sink through the floor when
    the person sits down behind a table (and a shin last seen folded stays folded under a
    thigh that moves on); feet stay on the floor while standing, sitting down and getting
    up, so this is where hidden legs are most likely. A chair's back can hide a leg whose
    foot shows below it. The hip flexions and knee bends tried are ``config``'s
    ``plant_hip_*`` and ``plant_knee_*`` (:class:`occupose.config.OcclusionConfig`).
    """
    config = OcclusionConfig() if config is None else config
    pose = np.array(pose, float)
    feet = feet or {}
    hips = np.linspace(0.0, config.plant_hip_max, config.plant_hip_steps)
    knees = np.linspace(0.0, config.plant_knee_max, config.plant_knee_steps)
    grid = np.meshgrid(hips, knees, indexing="ij")
    for side, whole in [(side, True) for side in sides] + [(side, False) for side in shins]:
        dofs = [model.dof_names.index(f"{side}_hip_{n}") for n in ("flex", "abd", "rot")]
        bend = model.dof_names.index(f"{side}_knee")
        if whole and side in feet:
            hip, knee, ankle = joints_from_poses(model, pose[None])[0, [JOINT_INDEX[f"{side}_{j}"]
                                                                         for j in ("hip", "knee", "ankle")]]
            knee, ankle = reach_towards(hip, feet[side], np.linalg.norm(knee - hip), np.linalg.norm(ankle - knee),
                                        None, bend=forward(model, pose))
            pose[dofs + [bend]] = limb_angles(model, pose, side, "leg", hip, knee, ankle)
            continue
        hip, knee = (grid[0].reshape(-1), grid[1].reshape(-1)) if whole else (pose[dofs[0]], knees)
        candidates = np.repeat(pose[None], len(knee), axis=0)
        if whole:
            candidates[:, dofs] = np.stack([hip, np.zeros_like(hip), np.zeros_like(hip)], axis=1)
        candidates[:, bend] = knee
        ankle = joints_from_poses(model, candidates)[:, JOINT_INDEX[f"{side}_ankle"]]
        if side in feet:
            cost = np.linalg.norm(ankle - feet[side], axis=1)
        else:
            cost = np.abs(ankle[:, 2] - model.dims.ankle_height) + 0.05 * np.abs(knee - hip) + 0.01 * knee
        pose = candidates[int(np.argmin(cost))]
    return pose
