"""Stage 2: labelling moving cells into blobs (constructed masks)."""

import numpy as np
import pytest
from scipy import ndimage

from occupose.grid._label_kernels import label_cells
from occupose.grid.blobs import blobs_from_mask, union_of_blobs
from occupose.grid.spec import GridSpec
from occupose.testing import column_blobs, mark_column

SPEC = GridSpec((-2.0, -2.0, 0.0), 0.05, (80, 80, 50))  # 4 x 4 x 2.5 m


def people(*positions, **box):
    return column_blobs(SPEC, positions, **box)


# ---------------------------------------------------------------------------- labelling


def test_label_kernel_matches_scipy_on_random_masks(rng):
    for density in (0.001, 0.05, 0.3):
        mask = rng.random((23, 17, 11)) < density
        labels = np.zeros(mask.size, np.int32)
        num, stats = label_cells(np.flatnonzero(mask), *mask.shape, labels)
        expected, count = ndimage.label(mask, np.ones((3, 3, 3), bool))
        assert num == count
        np.testing.assert_array_equal(labels.reshape(mask.shape), expected)  # same numbering too
        for n in range(1, num + 1):
            idx = np.argwhere(expected == n)
            np.testing.assert_array_equal(stats[n - 1], [len(idx), *idx.sum(0), *idx.min(0), *idx.max(0)])


def test_26_connectivity_joins_corner_neighbours():
    mask = np.zeros(SPEC.shape, bool)
    mask[10, 10, 10] = mask[11, 11, 11] = True  # touch at a corner only
    mask[20, 10, 10] = mask[22, 10, 10] = True  # one empty cell between: apart
    labels, blobs = blobs_from_mask(mask, SPEC, min_cells=1, min_height=0, min_top=0, join_m=None)
    assert [b.cell_count for b in blobs] == [2, 1, 1]
    assert labels[10, 10, 10] == labels[11, 11, 11] == 1
    assert labels[20, 10, 10] != labels[22, 10, 10]


def test_blob_geometry():
    mask = np.zeros(SPEC.shape, bool)
    mask[40:46, 40:42, 0:34] = True  # x 0 .. 0.3, y 0 .. 0.1, z 0 .. 1.7
    labels, (blob,) = blobs_from_mask(mask, SPEC)
    assert blob.label == 1 and blob.labels == (1,) and blob.cell_count == 6 * 2 * 34
    np.testing.assert_allclose(blob.low, [0.0, 0.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(blob.high, [0.3, 0.1, 1.7], atol=1e-12)
    np.testing.assert_allclose(blob.centroid, [0.15, 0.05, 0.85], atol=1e-12)
    assert blob.top == pytest.approx(1.7) and blob.height == pytest.approx(1.7)
    np.testing.assert_array_equal(blob.cells, np.flatnonzero(mask))
    np.testing.assert_allclose(blob.centers, SPEC.centers().reshape(-1, 3)[blob.cells])
    assert np.count_nonzero(labels) == blob.cell_count


def test_filter_drops_what_cannot_be_a_person_and_keeps_a_seated_upper_body():
    mask = np.zeros(SPEC.shape, bool)
    mark_column(mask, SPEC, -1.5, -1.5)                                               # standing person
    mark_column(mask, SPEC, 0.0, -1.5, width=0.4, depth=0.2, z_low=0.75, z_high=1.3)  # seated, behind a table
    mark_column(mask, SPEC, 1.5, -1.5, width=1.0, depth=1.0, z_low=0.0, z_high=0.1)   # a rug: flat
    mark_column(mask, SPEC, -1.5, 1.5, width=0.1, depth=0.1, z_low=1.0, z_high=1.2)   # a small thing: too few cells
    mark_column(mask, SPEC, 1.5, 1.5, width=0.4, depth=0.2, z_low=0.0, z_high=0.5)    # a low box: top too low
    _, blobs = blobs_from_mask(mask, SPEC)
    assert sorted(np.round(b.centroid[:2], 1).tolist() for b in blobs) == [[-1.5, -1.5], [0.0, -1.5]]
    _, everything = blobs_from_mask(mask, SPEC, min_cells=1, min_height=0, min_top=0)
    assert len(everything) == 5


def test_pieces_in_one_column_make_one_blob():
    # a ceiling camera sees the head top, the shoulders and the feet, nothing in between
    mask = np.zeros(SPEC.shape, bool)
    mark_column(mask, SPEC, 0.0, 0.0, width=0.2, depth=0.2, z_low=1.6, z_high=1.75)
    mark_column(mask, SPEC, 0.0, 0.0, width=0.45, depth=0.25, z_low=1.3, z_high=1.45)
    mark_column(mask, SPEC, 0.0, 0.0, width=0.3, depth=0.2, z_low=0.0, z_high=0.1)
    mark_column(mask, SPEC, 1.0, 0.0, width=0.45, depth=0.25, z_low=1.3, z_high=1.75)  # someone else, 0.55 m away
    labels, blobs = blobs_from_mask(mask, SPEC)
    assert len(blobs) == 2
    assert blobs[0].low[2] == pytest.approx(0.0) and blobs[0].top == pytest.approx(1.75)
    assert len(np.unique(labels[mask])) == 2
    _, apart = blobs_from_mask(mask, SPEC, join_m=None, min_cells=1, min_height=0, min_top=0)
    assert len(apart) == 4


@pytest.mark.parametrize("gap, joined", [(1, True), (2, True), (3, False)])
def test_footprints_join_across_a_gap_of_join_m(gap, joined):
    mask = np.zeros(SPEC.shape, bool)
    mask[10:16, 10:12, 20:34] = True  # upper body
    mask[16 + gap:20 + gap, 10 + gap:12 + gap, 0:10] = True  # diagonal from it, gap empty cells apart
    _, blobs = blobs_from_mask(mask, SPEC, join_m=0.1, min_cells=1, min_height=0, min_top=0)
    assert len(blobs) == (1 if joined else 2)


def test_union_of_blobs_pools_cells():
    a, b = people((-1.0, 0.0), (1.0, 0.0))
    both = union_of_blobs([b, a])
    assert both.labels == (1, 2) and both.label == 1 and both.cell_count == a.cell_count + b.cell_count
    np.testing.assert_allclose(both.centroid, both.centers.mean(axis=0))
    assert np.all(np.diff(both.cells) > 0)
    np.testing.assert_allclose(both.low, np.minimum(a.low, b.low))
    assert union_of_blobs([a]) is a


def test_bad_input_to_labelling():
    with pytest.raises(ValueError, match="bool array of the grid's shape"):
        blobs_from_mask(np.zeros((80, 80, 49), bool), SPEC)
    with pytest.raises(ValueError, match="bool array"):
        blobs_from_mask(np.zeros(SPEC.shape, np.uint8), SPEC)
    with pytest.raises(ValueError, match="GridSpec"):
        blobs_from_mask(np.zeros(SPEC.shape, bool), (80, 80, 50))
    with pytest.raises(ValueError, match="min_height"):
        blobs_from_mask(np.zeros(SPEC.shape, bool), SPEC, min_height=-1)
    with pytest.raises(ValueError, match="at least one blob"):
        union_of_blobs([])
