"""Numba kernel of stage 2: 26-connected labelling of the moving cells, with per-label statistics.

The grid is sparse (a few thousand moving cells in 320 000), so the kernel visits only the
moving cells: union-find over each cell's 13 already-visited neighbours (raster order),
then labels numbered in raster order of their first cell, as ``scipy.ndimage.label`` does.
"""

from __future__ import annotations

import numba
import numpy as np


@numba.njit(cache=True)
def _root(parent, node):
    while parent[node] != node:
        parent[node] = parent[parent[node]]
        node = parent[node]
    return node


@numba.njit(cache=True)
def label_cells(flat, nx, ny, nz, labels):
    """Label the 26-connected components of the cells ``flat``.

    flat : (K,) int64, increasing flat indices ``(i * ny + j) * nz + k`` of the moving cells
    labels : (nx * ny * nz,) int32, all zero on entry; on return the component label
        (1..n) of every cell of ``flat``, 0 elsewhere
    Returns (n, stats): n components; stats (n, 10) int64 rows
        [count, sum i, sum j, sum k, min i, min j, min k, max i, max j, max k].
    """
    count = flat.size
    parent = np.arange(count)
    for n in range(count):
        cell = flat[n]
        i = cell // (ny * nz)
        j = (cell // nz) % ny
        k = cell % nz
        a = n  # root of this cell's set so far
        seen = 0  # the last neighbour value merged, to skip repeats
        # the 13 neighbours that come earlier in raster order
        for di in range(-1, 1):
            if i + di < 0:
                continue
            for dj in range(-1, 2):
                if j + dj < 0 or j + dj >= ny or (di == 0 and dj > 0):
                    continue
                for dk in range(-1, 2):
                    if k + dk < 0 or k + dk >= nz or (di == 0 and dj == 0 and dk >= 0):
                        continue
                    other = labels[cell + (di * ny + dj) * nz + dk]
                    if other > 0 and other != seen:
                        seen = other
                        b = _root(parent, other - 1)
                        if a != b:
                            if a < b:
                                parent[b] = a
                            else:
                                parent[a] = b
                                a = b
        labels[cell] = a + 1  # a node of the cell's set, + 1, until the final pass
    compact = np.full(count, -1, np.int64)
    num = 0
    for n in range(count):
        r = _root(parent, n)
        if compact[r] < 0:
            compact[r] = num
            num += 1
    stats = np.zeros((num, 10), np.int64)
    stats[:, 4:7] = np.iinfo(np.int64).max
    stats[:, 7:10] = -1
    for n in range(count):
        cell = flat[n]
        label = compact[_root(parent, n)]
        labels[cell] = label + 1
        idx = (cell // (ny * nz), (cell // nz) % ny, cell % nz)
        stats[label, 0] += 1
        for a in range(3):
            stats[label, 1 + a] += idx[a]
            stats[label, 4 + a] = min(stats[label, 4 + a], idx[a])
            stats[label, 7 + a] = max(stats[label, 7 + a], idx[a])
    return num, stats
