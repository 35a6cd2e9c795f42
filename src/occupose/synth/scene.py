"""Rooms and furniture as boxes.

Every builder takes its footprint centre ``(x, y)`` on the floor in world metres and a
``heading`` in radians (about z; 0 means the furniture's front faces +x) and returns a
:class:`~occupose.geometry.primitives.Primitives` batch with ``person = 0``.
"""

from __future__ import annotations

import numpy as np

from occupose.geometry.primitives import Primitives, box, concat

WOOD = (150, 105, 60)
FABRIC = (95, 110, 140)
METAL = (170, 170, 175)
WALL = (215, 210, 200)
FLOOR = (165, 150, 130)


def _rot(heading: float) -> np.ndarray:
    c, s = np.cos(heading), np.sin(heading)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _part(center_xy, heading, local_center, half, color) -> Primitives:
    """A box given in the furniture's local frame (x forward, y left, z up)."""
    rot = _rot(heading)
    centre = np.array([center_xy[0], center_xy[1], 0.0]) + rot @ np.asarray(local_center, float)
    return box(centre, half, color, rot)


def room(width: float = 6.0, depth: float = 6.0, height: float = 2.8,
         center_xy=(0.0, 0.0), walls: tuple[str, ...] = ("+x", "-x", "+y", "-y"),
         ceiling: bool = False) -> Primitives:
    """Floor (top face at z = 0), the named walls and optionally the ceiling of a
    ``width`` (x) by ``depth`` (y) room."""
    cx, cy = center_xy
    t = 0.05
    prims = [box((cx, cy, -t), (width / 2 + t, depth / 2 + t, t), FLOOR)]
    if ceiling:
        prims.append(box((cx, cy, height + t), (width / 2 + t, depth / 2 + t, t), WALL))
    spec = {
        "+x": ((cx + width / 2 + t, cy, height / 2), (t, depth / 2 + t, height / 2)),
        "-x": ((cx - width / 2 - t, cy, height / 2), (t, depth / 2 + t, height / 2)),
        "+y": ((cx, cy + depth / 2 + t, height / 2), (width / 2 + t, t, height / 2)),
        "-y": ((cx, cy - depth / 2 - t, height / 2), (width / 2 + t, t, height / 2)),
    }
    for name in walls:
        if name not in spec:
            raise ValueError(f"unknown wall {name!r}; valid: {', '.join(spec)}")
        prims.append(box(*spec[name], WALL))
    return concat(prims)


def table(center_xy, heading: float = 0.0, size=(1.2, 0.7), height: float = 0.75,
          panel: bool = False, color=WOOD) -> Primitives:
    """A table: a 4 cm top of ``size`` (length along y, depth along x) on four legs.

    panel : add a front panel from 5 cm above the floor to the top on the local +x side
        (a desk), so the table hides the legs of someone sitting behind it.
    """
    d, w = size[1] / 2, size[0] / 2
    parts = [_part(center_xy, heading, (0, 0, height - 0.02), (d, w, 0.02), color)]
    if panel:
        parts.append(_part(center_xy, heading, (d - 0.03, 0, (height + 0.05) / 2), (0.015, w - 0.03, (height - 0.05) / 2),
                           color))
    for sx in (-1, 1):
        for sy in (-1, 1):
            parts.append(_part(center_xy, heading, (sx * (d - 0.05), sy * (w - 0.05), (height - 0.04) / 2),
                               (0.025, 0.025, (height - 0.04) / 2), color))
    return concat(parts)


def couch(center_xy, heading: float = 0.0, width: float = 1.9, depth: float = 0.85,
          seat_height: float = 0.45, back_height: float = 0.85, color=FABRIC) -> Primitives:
    """A couch facing +x (local): seat block, back rest and two arm rests."""
    d, w = depth / 2, width / 2
    back_t = 0.18
    return concat([
        _part(center_xy, heading, (0.0, 0.0, seat_height / 2), (d, w, seat_height / 2), color),
        _part(center_xy, heading, (-d + back_t / 2, 0.0, back_height / 2), (back_t / 2, w, back_height / 2), color),
        _part(center_xy, heading, (0.0, w - 0.09, (seat_height + 0.18) / 2), (d, 0.09, (seat_height + 0.18) / 2), color),
        _part(center_xy, heading, (0.0, -w + 0.09, (seat_height + 0.18) / 2), (d, 0.09, (seat_height + 0.18) / 2), color),
    ])


def chair(center_xy, heading: float = 0.0, seat_height: float = 0.46, size: float = 0.46,
          back_height: float = 0.92, color=WOOD) -> Primitives:
    """A chair facing +x (local): four legs, a seat and a back rest."""
    h = size / 2
    parts = [_part(center_xy, heading, (0, 0, seat_height - 0.02), (h, h, 0.02), color),
             _part(center_xy, heading, (-h + 0.02, 0, (seat_height + back_height) / 2),
                   (0.02, h, (back_height - seat_height) / 2), color)]
    for sx in (-1, 1):
        for sy in (-1, 1):
            parts.append(_part(center_xy, heading, (sx * (h - 0.025), sy * (h - 0.025), (seat_height - 0.04) / 2),
                               (0.02, 0.02, (seat_height - 0.04) / 2), color))
    return concat(parts)


def cabinet(center_xy, heading: float = 0.0, width: float = 1.0, depth: float = 0.5,
            height: float = 1.9, color=WOOD) -> Primitives:
    """A tall closed cabinet (one box); ``width`` along the local y axis."""
    return _part(center_xy, heading, (0, 0, height / 2), (depth / 2, width / 2, height / 2), color)


def counter(center_xy, heading: float = 0.0, width: float = 1.8, depth: float = 0.6, height: float = 0.9,
            overhang: float = 0.03, color=(220, 215, 205), top_color=(90, 85, 80)) -> Primitives:
    """A kitchen counter: a closed base unit up to 4 cm below ``height`` and a 4 cm worktop
    that overhangs it by ``overhang`` metres on every side; ``width`` along the local y axis."""
    top = 0.04
    return concat([
        _part(center_xy, heading, (0, 0, (height - top) / 2), (depth / 2, width / 2, (height - top) / 2), color),
        _part(center_xy, heading, (0, 0, height - top / 2), (depth / 2 + overhang, width / 2 + overhang, top / 2),
              top_color),
    ])


def shelf(center_xy, heading: float = 0.0, width: float = 1.0, depth: float = 0.35, height: float = 1.8,
          boards: int = 4, back: bool = False, color=WOOD) -> Primitives:
    """An open bookshelf facing +x (local): two 2 cm side panels, a bottom and top board and
    ``boards`` shelf boards between them (evenly spaced), optionally a back panel; the
    openings between the boards let the camera see through when there is no back."""
    if boards < 0:
        raise ValueError(f"boards must be >= 0, got {boards!r}")
    t = 0.01  # half thickness of a panel, metres
    d, w = depth / 2, width / 2
    parts = [_part(center_xy, heading, (0, side * (w - t), height / 2), (d, t, height / 2), color)
             for side in (-1, 1)]
    for k in range(boards + 2):
        z = t + k * (height - 2 * t) / (boards + 1)
        parts.append(_part(center_xy, heading, (0, 0, z), (d, w - 2 * t, t), color))
    if back:
        parts.append(_part(center_xy, heading, (-d + t / 2, 0, height / 2), (t / 2, w - 2 * t, height / 2), color))
    return concat(parts)


def pillar(center_xy, size: float = 0.4, height: float = 2.8, color=WALL) -> Primitives:
    """A square pillar from floor to ceiling."""
    return _part(center_xy, 0.0, (0, 0, height / 2), (size / 2, size / 2, height / 2), color)


#: Furniture builders by name, for scenario definitions and the command line.
FURNITURE = {"table": table, "couch": couch, "chair": chair, "cabinet": cabinet, "counter": counter,
             "shelf": shelf, "pillar": pillar}
