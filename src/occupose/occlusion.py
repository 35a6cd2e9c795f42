"""Which body parts are hidden by the scene, and what the filter may estimate (paper III-D).

Each body part is approximated by ``n`` spheres along the axes of its capsules. At every
frame the previous estimate, moved to its blob's new centre of mass, is tested against the
occupancy grid's visibility: a part with more than half of its spheres in HIDDEN cells is
hidden. Every part runs the two-state machine of the paper's Fig. 7:

- VISIBLE: its configuration (its DOFs, relative to its parent) is saved in a memory M;
  it becomes HIDDEN when its current configuration tests hidden;
- HIDDEN: the memory configuration is tested instead; it becomes VISIBLE again when that
  configuration tests visible.

A hidden part hides its whole subtree (a hidden thigh hides the shin); a hidden root part
(the torso) suspends the track: it is kept but not estimated. The filter runs only on the
DOFs of visible parts; hidden parts keep their memory configuration relative to their
parent. A part that becomes visible again gets a wider search for a few frames (its DOFs'
diffusion multiplied by ``resume_scale`` for ``resume_frames`` frames).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

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
                 resume_frames: int = 10, resume_scale: float = 3.0):
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
