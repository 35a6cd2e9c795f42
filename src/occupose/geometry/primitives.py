"""Solid shape primitives that the synthetic renderer ray-casts.

A scene is a :class:`Primitives` batch (struct of arrays, K primitives). Three kinds:

- ``BOX``: oriented box; ``center`` (3,), ``axes`` (3, 3) world_from_local rotation whose
  columns are the box's local axes, ``size`` (3,) half extents in metres.
- ``ELLIPSOID``: ``center``, ``axes`` as for the box, ``size`` (3,) semi-axis radii.
- ``ROUND_CONE``: a truncated cone capped by two spheres (a capsule with two radii);
  ``center`` is end a, ``end`` is end b, ``size[0]`` the radius at a, ``size[1]`` the
  radius at b; ``axes`` unused (identity).

``person`` is 0 for the scene and 1, 2, ... for people; ``part`` is the body-part label of
:data:`occupose.joints.PARTS` (0 for the scene); ``color`` is the RGB albedo.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

BOX, ELLIPSOID, ROUND_CONE = 0, 1, 2


@dataclass(frozen=True)
class Primitives:
    """K solid primitives, as contiguous arrays (see module docstring)."""

    kind: np.ndarray    # (K,) int8
    center: np.ndarray  # (K, 3) float64, metres, world
    axes: np.ndarray    # (K, 3, 3) float64, world_from_local rotations
    size: np.ndarray    # (K, 3) float64, metres
    end: np.ndarray     # (K, 3) float64, metres, world (round cones only)
    person: np.ndarray  # (K,) int16
    part: np.ndarray    # (K,) int16
    color: np.ndarray   # (K, 3) uint8

    def __len__(self) -> int:
        return int(self.kind.shape[0])


def _one(kind, center, axes, size, end, person, part, color) -> Primitives:
    return Primitives(
        kind=np.array([kind], np.int8),
        center=np.asarray(center, np.float64).reshape(1, 3),
        axes=np.asarray(axes, np.float64).reshape(1, 3, 3),
        size=np.asarray(size, np.float64).reshape(1, 3),
        end=np.asarray(end, np.float64).reshape(1, 3),
        person=np.array([person], np.int16),
        part=np.array([part], np.int16),
        color=np.asarray(color, np.uint8).reshape(1, 3),
    )


def box(center, half_extents, color, axes=None, person=0, part=0) -> Primitives:
    """One oriented box. ``axes`` defaults to the world axes."""
    axes = np.eye(3) if axes is None else axes
    return _one(BOX, center, axes, half_extents, center, person, part, color)


def ellipsoid(center, radii, color, axes=None, person=0, part=0) -> Primitives:
    """One oriented ellipsoid with semi-axes ``radii`` along the columns of ``axes``."""
    axes = np.eye(3) if axes is None else axes
    return _one(ELLIPSOID, center, axes, radii, center, person, part, color)


def round_cone(a, b, radius_a, radius_b, color, person=0, part=0) -> Primitives:
    """One round cone from point ``a`` (radius ``radius_a``) to ``b`` (``radius_b``)."""
    return _one(ROUND_CONE, a, np.eye(3), (radius_a, radius_b, 0.0), b, person, part, color)


def concat(batches: list[Primitives]) -> Primitives:
    """Join batches into one (an empty list gives an empty batch)."""
    if not batches:
        return Primitives(
            np.zeros(0, np.int8), np.zeros((0, 3)), np.zeros((0, 3, 3)), np.zeros((0, 3)),
            np.zeros((0, 3)), np.zeros(0, np.int16), np.zeros(0, np.int16), np.zeros((0, 3), np.uint8),
        )
    return Primitives(*(np.ascontiguousarray(np.concatenate([getattr(b, f) for b in batches]))
                        for f in ("kind", "center", "axes", "size", "end", "person", "part", "color")))


def select(prims: Primitives, mask) -> Primitives:
    """The primitives where ``mask`` (K,) bool (or an index array) selects them."""
    return Primitives(*(np.ascontiguousarray(getattr(prims, f)[mask])
                        for f in ("kind", "center", "axes", "size", "end", "person", "part", "color")))
