"""Helpers for the tests and benchmarks only: ground truth the tracker never sees.

Nothing in ``src/`` imports this module, and it may import anything, the scene generator
included. It holds what tests and benchmarks use to feed a stage the truth (the true
bodies' capsules, one person's observations straight from the renderer) or to score a
stage against it (foreground from the grid, track -> person by pixel overlap).

- :func:`capsules_from_primitives`: capsules covering a rendered body, to hold the true
  bodies in the occupancy grid (:func:`occupose.grid.hold.cells_near_capsules`);
- :func:`foreground_from_grid`: the pixels whose 3D point lies in a moving grid cell;
- :func:`persons_from_tracks`: the ground-truth person of each track id, by pixel overlap;
- :func:`person_observations` and :data:`UPPER_BODY_PARTS`: one person's likelihood
  observations taken from the renderer's labels (stage 3 without stages 1-2);
- :func:`folder_snapshot`: every entry under a folder, to tell that a command changed
  nothing there.
"""

from __future__ import annotations

import hashlib
import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from occupose.camera import Camera
from occupose.geometry.primitives import BOX, ROUND_CONE, Primitives
from occupose.grid.occupancy import M, cells_from_depth
from occupose.grid.spec import GridSpec
from occupose.joints import PARTS
from occupose.likelihood import View, observation_from_views
from occupose.synth.generate import frames
from occupose.synth.scenarios import Scenario

# ------------------------------------------------------------------------- the grid (stages 1-2)


def capsules_from_primitives(prims: Primitives) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Capsules covering a batch of renderer primitives (e.g. a true body,
    :func:`occupose.synth.body.primitives_from_joints`).

    Round cones are taken as they are; a box or an ellipsoid becomes the capsule along its
    longest axis, from ``center - s axis`` to ``center + s axis`` (``s`` the longest half
    extent), with the radius of its cross-section (the other two half extents' norm for a
    box, their maximum for an ellipsoid), which contains it.
    Returns a, b : (K, 3) float64 world metres and radii : (K, 2) float64 metres.
    """
    if not isinstance(prims, Primitives):
        raise ValueError(f"prims must be occupose.geometry.primitives.Primitives, got {type(prims).__name__}")
    cone = prims.kind == ROUND_CONE
    longest = np.argmax(prims.size, axis=1)
    rows = np.arange(len(prims))
    axis = prims.axes[rows, :, longest]  # (K, 3): the column of the longest local axis
    half = prims.size[rows, longest]
    others = np.sort(prims.size, axis=1)[:, :2]  # the two shorter half extents
    radius = np.where(prims.kind == BOX, np.hypot(others[:, 0], others[:, 1]), others[:, 1])
    a = np.where(cone[:, None], prims.center, prims.center - half[:, None] * axis)
    b = np.where(cone[:, None], prims.end, prims.center + half[:, None] * axis)
    radii = np.where(cone[:, None], prims.size[:, :2], radius[:, None])
    return np.ascontiguousarray(a), np.ascontiguousarray(b), np.ascontiguousarray(radii)


def foreground_from_grid(states: np.ndarray, spec: GridSpec, depth: np.ndarray, camera: Camera) -> np.ndarray:
    """Pixels whose back-projected 3D point lies in a moving cell (the paper's Fig. 2(d)).

    states : (nx, ny, nz) uint8 cell states (points in E cells go to their nearest occupied
        neighbour, see :func:`occupose.grid.occupancy.cells_from_depth`), or a bool cell mask (used as is)
    spec : GridSpec of ``states``; depth : (H, W) float metres or uint16 raw; camera : Camera
    Returns (H, W) bool foreground.
    """
    states = np.asarray(states)
    if states.dtype == np.bool_:
        if states.shape != spec.shape:
            raise ValueError(f"cell mask must have the grid's shape {spec.shape}, got {states.shape}")
        mask, index = states, cells_from_depth(depth, camera, spec)
    else:
        index = cells_from_depth(depth, camera, spec, states)  # checks the states: uint8, the grid's shape
        mask = states == M
    return np.where(index >= 0, mask.reshape(-1)[np.maximum(index, 0)], False)


def persons_from_tracks(assigned: Sequence[np.ndarray], truth: Sequence[np.ndarray]) -> dict[int, int]:
    """Ground-truth person of each track id by majority overlap (for scoring).

    assigned : sequence of (H, W) int track-id images (0 = nobody), e.g. over frames and cameras
    truth : sequence of (H, W) int person-id images of the same shapes (0 = nobody)
    Returns ``{track_id: person_id}`` for every track id that overlaps some person; the
    person is the one sharing the most pixels with the track over all the images.
    """
    assigned, truth = list(assigned), list(truth)
    if len(assigned) != len(truth) or any(np.shape(a) != np.shape(t) for a, t in zip(assigned, truth)):
        raise ValueError("assigned and truth must be sequences of label images of matching shapes")
    if not assigned:
        return {}
    tracks = np.concatenate([np.asarray(a).reshape(-1) for a in assigned]).astype(np.int64)
    people = np.concatenate([np.asarray(t).reshape(-1) for t in truth]).astype(np.int64)
    both = (tracks > 0) & (people > 0)
    tracks, people = tracks[both], people[both]
    if tracks.size == 0:
        return {}
    pairs, counts = np.unique(tracks * (people.max() + 1) + people, return_counts=True)
    track_of, person_of = np.divmod(pairs, people.max() + 1)
    order = np.lexsort((-counts, track_of))  # by track, most shared pixels first
    first = np.unique(track_of[order], return_index=True)[1]
    return {int(track_of[order][i]): int(person_of[order][i]) for i in first}



def mark_column(mask: np.ndarray, spec: GridSpec, x: float, y: float, *, width: float = 0.3, depth: float = 0.1,
                z_low: float = 0.0, z_high: float = 1.7) -> np.ndarray:
    """Mark the cells of a box centred at (``x``, ``y``) metres, ``width`` x ``depth`` across and
    from ``z_low`` to ``z_high`` high, in the cell mask ``mask`` (``spec.shape`` bool) as moving:
    a crude standing person. Returns ``mask``."""
    low = np.floor((np.array([x - width / 2, y - depth / 2, z_low]) - spec.origin) / spec.cell + 1e-9).astype(int)
    high = np.floor((np.array([x + width / 2, y + depth / 2, z_high]) - spec.origin) / spec.cell - 1e-9).astype(int) + 1
    mask[low[0]:high[0], low[1]:high[1], low[2]:high[2]] = True
    return mask


def column_blobs(spec: GridSpec, positions: Sequence[tuple[float, float]], **box) -> list:
    """The blobs (:func:`occupose.grid.blobs.blobs_from_mask`) of one :func:`mark_column` at
    each (x, y) of ``positions``; ``box`` : its size keywords."""
    from occupose.grid.blobs import blobs_from_mask

    mask = np.zeros(spec.shape, bool)
    for x, y in positions:
        mark_column(mask, spec, x, y, **box)
    return blobs_from_mask(mask, spec)[1]

# ------------------------------------------------------------------------- stage 3 alone


#: Renderer part labels of the upper body (head, chest, pelvis, arms and hands): the second
#: paper thresholds its top-view images to these pixels for its upper-body model.
UPPER_BODY_PARTS = tuple(PARTS.index(name) for name in (
    "head", "chest", "pelvis", "left_upper_arm", "left_forearm", "left_hand",
    "right_upper_arm", "right_forearm", "right_hand"))


def person_observations(scenario: Scenario, num_frames: int, *, person: int = 1, parts: Sequence[int] | None = None,
                        max_points: int = 1000, seed: int = 0) -> list:
    """One person's likelihood observations straight from the renderer (no stages 1-2).

    For testing and benchmarking stage 3 alone: each of the first ``num_frames`` frames
    gives an :class:`occupose.likelihood.Observation` of the first camera, the person's
    pixels taken from the renderer's person-id image (person ids from 1), with ``parts``
    only those of these part labels (e.g. :data:`UPPER_BODY_PARTS`); ``max_points`` points.
    """
    camera = scenario.cameras[0]
    out = []
    for frame in frames(scenario, seed=seed, num_frames=num_frames):
        rendered = frame.rendered[camera.name]
        mask = rendered.person == person
        if parts is not None:
            mask &= np.isin(rendered.part, parts)
        out.append(observation_from_views([View(camera, frame.depth[camera.name], mask)], max_points=max_points))
    return out


def folder_snapshot(folder: str | os.PathLike) -> dict[str, str]:
    """Every entry under ``folder``, hidden ones included, by its path relative to it (with
    ``/``): a file's SHA-256, ``"folder"``, or a symbolic link's ``"-> target"`` (not
    followed). Two snapshots are equal when nothing under the folder changed."""
    folder = Path(folder)
    entries = {}
    for root, dirs, files in os.walk(folder):
        for name in dirs + files:
            path = Path(root) / name
            key = path.relative_to(folder).as_posix()
            if path.is_symlink():
                entries[key] = "-> " + os.readlink(path)
            elif path.is_dir():
                entries[key] = "folder"
            else:
                entries[key] = hashlib.sha256(path.read_bytes()).hexdigest()
    return entries
