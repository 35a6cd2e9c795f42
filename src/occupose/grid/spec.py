"""The geometry of a voxel grid: where its cells are in the world."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class GridSpec:
    """An axis-aligned voxel grid in the world frame.

    origin : (3,) float64, metres, world position of the low corner of cell (0, 0, 0)
    cell : float, metres, edge length of a cubic cell
    shape : (nx, ny, nz) number of cells along world x, y, z
    Cell (i, j, k) spans ``origin + cell * [i, i+1) x [j, j+1) x [k, k+1)``.
    """

    origin: tuple[float, float, float]
    cell: float
    shape: tuple[int, int, int]

    def __post_init__(self) -> None:
        origin = tuple(float(v) for v in self.origin)
        shape = tuple(int(v) for v in self.shape)
        if len(origin) != 3 or not np.all(np.isfinite(origin)):
            raise ValueError(f"grid origin must be 3 finite numbers, got {self.origin!r}")
        if not (np.isfinite(self.cell) and self.cell > 0):
            raise ValueError(f"grid cell size must be a positive number of metres, got {self.cell!r}")
        if len(shape) != 3 or min(shape) < 1:
            raise ValueError(f"grid shape must be 3 positive cell counts (an empty grid box has none), got {self.shape!r}")
        object.__setattr__(self, "origin", origin)
        object.__setattr__(self, "shape", shape)
        object.__setattr__(self, "cell", float(self.cell))

    @classmethod
    def from_bounds(cls, low, high, cell: float = 0.05) -> GridSpec:
        """The grid of ``cell``-sized cells covering the box from ``low`` to ``high`` (metres)."""
        low, high = np.asarray(low, float), np.asarray(high, float)
        if low.shape != (3,) or high.shape != (3,) or not np.all(high > low):
            raise ValueError(f"grid box must have high > low on every axis, got low={low.tolist()} high={high.tolist()}")
        shape = np.ceil((high - low) / cell - 1e-9).astype(int)
        return cls(tuple(low), cell, tuple(shape))

    @property
    def num_cells(self) -> int:
        return int(np.prod(self.shape))

    @property
    def high(self) -> np.ndarray:
        """(3,) world position of the high corner of the grid box, metres."""
        return np.asarray(self.origin) + self.cell * np.asarray(self.shape)

    def centers(self) -> np.ndarray:
        """(nx, ny, nz, 3) float64 world positions of the cell centres, metres."""
        axes = [self.origin[a] + self.cell * (np.arange(self.shape[a]) + 0.5) for a in range(3)]
        return np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1)

    def cells_from_points(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Cell indices of world points.

        points : (N, 3) float, metres, world frame
        Returns (indices (N, 3) int64, inside (N,) bool); indices are clipped into the grid,
        so use them only where ``inside``.
        """
        points = np.asarray(points, np.float64).reshape(-1, 3)
        idx = np.floor((points - np.asarray(self.origin)) / self.cell).astype(np.int64)
        inside = np.all((idx >= 0) & (idx < np.asarray(self.shape)), axis=1)
        return np.clip(idx, 0, np.asarray(self.shape) - 1), inside
