"""Cells to hold as moving: the grid cells near the bodies the tracker predicts.

With the paper's ``psi`` a cell that stays occupied in state M turns static (O) after
:func:`occupose.grid.occupancy.frames_until_static` frames (77 by default): a person who
stands or sits still fades into the background. The tracker knows better for the people
it follows: it passes a hold mask to :meth:`occupose.grid.occupancy.OccupancyGrid.update`,
which disables the M -> O transition in those cells for that frame. This module makes that
mask from the round cones of the predicted bodies (``occupose.body.capsules_from_poses``;
tests and benchmarks that hold the true bodies take the capsules covering a rendered body
from ``occupose.testing.capsules_from_primitives``). For a body model's predicted pose::

    a, b = capsules_from_poses(model, pose[None])            # (1, C, 3) each
    hold = cells_near_capsules(grid.spec, a[0], b[0], model.capsule_radii)
    grid.update(depths, hold=hold)                           # several people: OR their masks

Measured on the synthetic scenes with the true bodies held (benchmarks/bench_blobs.py,
benchmarks/results/latest.md): pixel assignment over all 300 frames of
``top_view_two_people`` 99.66 % (without the hold, where the still bodies fade, 75.41 % on
the 205 frames that still have pixels assigned); holding the previous frame's blob cells
dilated by 0.1 m instead gave 90.64 % with 24 identity swaps.
"""

from __future__ import annotations

import math

import numpy as np

from occupose.config import GridConfig
from occupose.grid import _kernels
from occupose.grid.spec import GridSpec

#: Default margin (metres) around each capsule: the half diagonal of a 5 cm cell (a cell
#: whose centre is that far from the surface can still hold surface points) plus about
#: 6 cm of prediction error.
MARGIN = GridConfig.hold_margin


def cells_near_capsules(spec: GridSpec, a, b, radii, margin: float = MARGIN) -> np.ndarray:
    """The cells whose centre lies within ``margin`` of one of the capsules.

    spec : GridSpec of the occupancy grid
    a, b : (C, 3) float, world metres, the capsules' ends (C may be 0)
    radii : (C, 2) float metres, the radius at a and at b
    margin : float >= 0, metres, added to the radius
    Returns (nx, ny, nz) bool. A round cone is taken as a capsule whose radius varies
    linearly along its axis, measured at the axis point nearest the cell centre (within a
    few millimetres of the true round cone for a body's tapers, far less than the margin).
    One small numba kernel visits only the box of cells around each capsule (about 0.1 ms
    for 16 body capsules on 80 x 80 x 50 cells, see benchmarks/bench_grid.py).
    """
    if not isinstance(spec, GridSpec):
        raise ValueError(f"spec must be a GridSpec, got {type(spec).__name__}")
    a = np.ascontiguousarray(a, np.float64)
    b = np.ascontiguousarray(b, np.float64)
    radii = np.ascontiguousarray(radii, np.float64)
    if a.ndim != 2 or a.shape[1] != 3 or b.shape != a.shape or radii.shape != (a.shape[0], 2):
        raise ValueError(f"capsules must be a (C, 3), b (C, 3) and radii (C, 2), "
                         f"got {a.shape}, {b.shape} and {radii.shape}")
    if not (np.all(np.isfinite(a)) and np.all(np.isfinite(b)) and np.all(np.isfinite(radii))
            and np.all(radii >= 0)):
        raise ValueError("capsule ends must be finite and radii finite and >= 0")
    if not (isinstance(margin, (int, float, np.floating)) and math.isfinite(margin) and margin >= 0):
        raise ValueError(f"margin must be a number of metres >= 0, got {margin!r}")
    out = np.zeros(spec.shape, np.bool_)
    _kernels.mark_capsules(np.asarray(spec.origin), spec.cell, *spec.shape, a, b, radii, float(margin), out)
    return out
