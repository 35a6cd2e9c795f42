"""The capsule checks every likelihood's evaluate runs, and the blocks of nearby points the
distance kernels work on (median splits by quickselect) against NumPy."""

import numpy as np
import pytest

from occupose.body import BODY_MODELS
from occupose.likelihood import FreeSpaceLikelihood, Observation, PointsLikelihood

FULL = BODY_MODELS["full"]


def _blocks_reference(points, block_size):
    """Index sets of the median splits (lower half first), by NumPy partitioning."""
    leaves, stack = [], [np.arange(len(points))]
    while stack:
        index = stack.pop()
        if len(index) <= block_size:
            if len(index):
                leaves.append(index)
            continue
        chosen = points[index]
        axis = int(np.argmax(np.ptp(chosen, axis=0)))
        split = np.argsort(chosen[:, axis], kind="stable")
        half = len(index) // 2
        stack += [index[split[half:]], index[split[:half]]]
    return leaves


def test_blocked_points_match_reference(rng):
    from occupose.likelihood._capsules import blocked_points

    points = rng.normal(size=(500, 3)) * [0.3, 0.2, 0.6] + [1.0, 2.0, 1.0]
    blocks = blocked_points(points, block_size=40, pad=16)
    leaves = _blocks_reference(points, 40)
    assert len(blocks.block_start) == len(leaves) + 1
    entries = np.stack([blocks.px, blocks.py, blocks.pz], axis=1).astype(np.float64) + blocks.origin
    np.testing.assert_allclose(entries[blocks.position], points, atol=1e-6)
    np.testing.assert_allclose(blocks.origin, points.mean(axis=0))
    for b, leaf in enumerate(leaves):
        lo, hi = blocks.block_start[b], blocks.block_start[b + 1]
        assert (hi - lo) % 16 == 0 and hi - lo - len(leaf) < 16
        assert sorted(blocks.position[leaf]) == list(range(lo, lo + len(leaf)))  # the same points, first
        np.testing.assert_array_equal(blocks.weight[lo:hi], np.arange(hi - lo) < len(leaf))
        assert np.all(entries[lo + len(leaf):hi] == entries[lo + len(leaf) - 1])  # padding: the last point
        box = points[leaf] - blocks.origin
        np.testing.assert_allclose(blocks.block_centre[:, b], (box.min(axis=0) + box.max(axis=0)) / 2, atol=1e-12)
        ball = np.linalg.norm(points[leaf] - blocks.origin - blocks.block_centre[:, b], axis=1)
        np.testing.assert_allclose(blocks.block_radius[b], ball.max() + 1e-5, atol=1e-9)
    empty = blocked_points(np.zeros((0, 3)))
    assert len(empty.px) == 0 and list(empty.block_start) == [0]


def test_select_partitions_around_the_kth_with_ties(rng):
    """The quickselect of the median splits against the order statistics, on keys with
    many ties (only 4 distinct values) and on distinct ones, for several k."""
    from occupose.likelihood._distance_kernels import _select

    for points in (rng.integers(0, 4, size=(301, 3)).astype(np.float64), rng.normal(size=(301, 3))):
        for lo, hi, kth in ((0, 301, 150), (17, 280, 20), (17, 280, 279), (100, 102, 101)):
            order = np.arange(301)
            _select(points, 1, order, lo, hi, kth)
            keys = points[order, 1]
            assert sorted(order[lo:hi]) == list(range(lo, hi))  # a permutation of the range
            assert keys[lo:kth].max(initial=-np.inf) <= keys[kth] <= keys[kth:hi].min()
            assert keys[kth] == np.sort(points[lo:hi, 1])[kth - lo]


def test_blocked_points_with_tied_coordinates(rng):
    """Median splits by quickselect on points with many equal coordinates (a coarse grid,
    duplicates): every point in exactly one block, halves of equal size, no block too big."""
    from occupose.likelihood._capsules import blocked_points

    points = rng.integers(0, 3, size=(700, 3)).astype(np.float64) * 0.1
    points[:100] = points[0]  # 100 copies of one point
    blocks = blocked_points(points, block_size=50, pad=8)
    counts = np.add.reduceat(blocks.weight, blocks.block_start[:-1])
    assert len(np.unique(blocks.position)) == 700 and np.all(blocks.weight[blocks.position] == 1)
    assert counts.sum() == 700 and np.all(counts <= 50) and np.all(counts >= 43)  # 700 / 16
    entries = np.stack([blocks.px, blocks.py, blocks.pz], axis=1).astype(np.float64) + blocks.origin
    np.testing.assert_allclose(entries[blocks.position], points, atol=1e-6)


def test_evaluate_checks_its_input(front, model_capsules):
    obs, pose = front
    like = PointsLikelihood(obs)
    a, b, radii, part, k = model_capsules(FULL, pose)
    with pytest.raises(ValueError, match=r"\(P, C, 3\)"):
        like.evaluate(a[0], b[0], radii, part, k)
    with pytest.raises(ValueError, match="radii"):
        like.evaluate(a, b, radii[:-1], part, k)
    with pytest.raises(ValueError, match="capsule_part values"):
        like.evaluate(a, b, radii, part, 3)
    with pytest.raises(ValueError, match="num_parts"):
        like.evaluate(a, b, radii, part, 0)
    with pytest.raises(ValueError, match="finite"):
        like.evaluate(a * np.nan, b, radii, part, k)
    with pytest.raises(ValueError, match="scale"):
        PointsLikelihood(obs, scale=0.0)
    with pytest.raises(ValueError, match="at least one point"):
        PointsLikelihood(Observation(np.zeros((0, 3)), obs.views))
    with pytest.raises(ValueError, match="noise model"):
        FreeSpaceLikelihood(obs, noise="sonar")
