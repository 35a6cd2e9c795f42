"""Input checks shared by the likelihoods' ``evaluate`` (private)."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from occupose.likelihood import _distance_kernels


def check_capsules(a, b, radii, capsule_part, num_parts):
    """Check and convert the particles' capsules.

    a, b : (P, C, 3) float, metres, world; radii : (C, 2) float > 0, metres;
    capsule_part : (C,) int in [0, num_parts); num_parts : int >= 1.
    Returns C-contiguous a, b, radii (float64), capsule_part (int64) and num_parts (int).
    """
    if isinstance(num_parts, bool) or not isinstance(num_parts, (int, np.integer)) or num_parts < 1:
        raise ValueError(f"num_parts must be a positive integer, got {num_parts!r}")
    a = np.ascontiguousarray(a, dtype=np.float64)
    b = np.ascontiguousarray(b, dtype=np.float64)
    if a.ndim != 3 or a.shape[2] != 3 or a.shape[1] < 1 or b.shape != a.shape:
        raise ValueError(f"a and b must both have shape (P, C, 3) with C >= 1, got {a.shape} and {b.shape}")
    if not (np.isfinite(a).all() and np.isfinite(b).all()):
        raise ValueError("capsule ends a and b must be finite")
    num_capsules = a.shape[1]
    radii = np.ascontiguousarray(radii, dtype=np.float64)
    if radii.shape != (num_capsules, 2) or not np.all(np.isfinite(radii)) or np.any(radii <= 0):
        raise ValueError(f"radii must be a ({num_capsules}, 2) array of positive finite metres, "
                         f"got shape {radii.shape}")
    part = np.asarray(capsule_part)
    if part.shape != (num_capsules,) or part.dtype.kind not in "iu":
        raise ValueError(f"capsule_part must be a ({num_capsules},) integer array, got {part.dtype} {part.shape}")
    if part.size and (part.min() < 0 or part.max() >= num_parts):
        raise ValueError(f"capsule_part values must be in [0, {num_parts}), got {part.min()}..{part.max()}")
    return a, b, radii, np.ascontiguousarray(part, dtype=np.int64), int(num_parts)


def check_positive(value, what: str) -> float:
    """``value`` as a positive finite float, else ValueError naming ``what``."""
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{what} must be a positive number, got {value!r}") from None
    if not (np.isfinite(number) and number > 0):
        raise ValueError(f"{what} must be a positive finite number, got {value!r}")
    return number


#: Metres added to the blocks' radii to cover float32 rounding of the point distances.
BOUND_SLACK = 1e-5
#: Points per block of the points kernels (see occupose.likelihood._distance_kernels._nearest_in_block).
BLOCK_SIZE = 64
#: Blocks are padded to a multiple of this many points (copies of their last point, weight
#: 0), so that the vectorised point loop has no scalar remainder (4 x 8 float32 lanes).
BLOCK_PAD = 32


class PointBlocks(NamedTuple):
    """Observed points prepared for the points kernels.

    origin : (3,) float64, metres, the points' centroid (0 for no points)
    px, py, pz : (M,) float32, the points minus origin, reordered into blocks and padded
    block_start : (B + 1,) int64; block b holds entries block_start[b] to block_start[b + 1] - 1
    block_centre : (3, B) float64 (minus origin) and block_radius : (B,) float64 metres,
        a ball holding each block (its radius plus a slack of ``BOUND_SLACK`` for float32
        rounding of the point distances)
    weight : (M,) float32, 1 for a point, 0 for padding
    position : (N,) int64, where each input point went
    """

    origin: np.ndarray
    px: np.ndarray
    py: np.ndarray
    pz: np.ndarray
    block_start: np.ndarray
    block_centre: np.ndarray
    block_radius: np.ndarray
    weight: np.ndarray
    position: np.ndarray

    @property
    def kernel_args(self) -> tuple:
        """The arguments of the kernels, origin to block_radius."""
        return tuple(self)[:7]


def blocked_points(points: np.ndarray, block_size: int = BLOCK_SIZE, pad: int = BLOCK_PAD, *,
                   sort: bool = True) -> PointBlocks:
    """Split (N, 3) float64 points into spatially compact blocks of at most ``block_size``
    points (halving each set at the median of its longest side), each padded to a multiple
    of ``pad`` entries, for the points kernels.

    sort : False cuts the points as given into runs of ``block_size``: for points already
        in a spatially coherent order (an image's pixels row by row), about 15x quicker to
        prepare for 15000 points, at the price of looser block bounds (the kernels' results
        are the same).
    """
    points = np.ascontiguousarray(points, dtype=np.float64)
    if not len(points):
        empty = np.zeros(0, np.float32)
        return PointBlocks(np.zeros(3), empty, empty, empty, np.zeros(1, np.int64), np.zeros((3, 0)), np.zeros(0),
                           empty, np.zeros(0, np.int64))
    if sort:
        order = np.empty(len(points), np.int64)
        leaf_start = _distance_kernels.block_order(points, int(block_size), order)
    else:
        order = np.arange(len(points))
        leaf_start = np.append(np.arange(0, len(points), int(block_size)), len(points))
    return PointBlocks(*_distance_kernels.pack_blocks(points, order, leaf_start, int(pad), BOUND_SLACK))
