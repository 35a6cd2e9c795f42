"""Stage 2: tracking the blobs over frames, ids through gaps, merges and splits (constructed masks)."""

import numpy as np
import pytest

from occupose.grid.blobs import Blob
from occupose.grid.spec import GridSpec
from occupose.testing import column_blobs
from occupose.grid.tracking import BlobTracker

SPEC = GridSpec((-2.0, -2.0, 0.0), 0.05, (80, 80, 50))  # 4 x 4 x 2.5 m
FPS = 30.0


def people(*positions, **box):
    return column_blobs(SPEC, positions, **box)


def run(tracker, frames):
    """Feed lists of (x, y) positions; returns per frame {track id: rounded blob centroid x}."""
    out = []
    for positions in frames:
        tracks = tracker.update(people(*positions))
        out.append({tid: round(float(b.centroid[0]), 2) for tid, b in tracks.items()})
    return out


def test_ids_persist_for_people_walking_side_by_side():
    tracker = BlobTracker(FPS)
    steps = [[(-1.0 + 0.05 * t, -0.5), (-1.0 + 0.05 * t, 0.5)] for t in range(30)]
    history = run(tracker, steps)
    assert all(list(frame) == [1, 2] for frame in history)
    state = tracker.states[1]
    assert state.age == 29 and state.last_seen == 29 and state.first_seen == 0 and state.merged_with == ()
    np.testing.assert_allclose(state.velocity, [1.5, 0.0], atol=0.05)  # 0.05 m per frame at 30 fps
    assert state.predicted[0] == pytest.approx(state.centroid[0] + 0.05, abs=0.01)
    np.testing.assert_array_equal(state.cells, np.sort(state.blob.cells))


def test_gate_starts_a_new_track_for_a_jump():
    tracker = BlobTracker(FPS, gate_m=0.5)
    history = run(tracker, [[(0.0, 0.0)]] * 3 + [[(1.2, 0.0)]])
    assert list(history[-1]) == [2]
    assert set(tracker.states) == {1, 2} and tracker.states[1].blob is None  # 1 waits out its gap


def test_track_survives_a_short_gap_and_ends_after_the_limit():
    tracker = BlobTracker(FPS, max_gap_s=1.0)
    walk = [[(-1.0 + 0.05 * t, 0.0)] for t in range(10)]
    hidden = [[]] * 20  # 0.67 s unseen, walking on at 1.5 m/s
    back = [[(-1.0 + 0.05 * t, 0.0)] for t in range(30, 35)]
    history = run(tracker, walk + hidden + back)
    assert all(list(frame) == [1] for frame in history[30:])
    assert tracker.max_gap_frames == 30
    run(tracker, [[]] * 30)
    assert list(tracker.states) == [1]
    run(tracker, [[]])  # 31 frames unseen
    assert tracker.states == {}
    assert list(run(tracker, [[(0.0, 0.0)]])[0]) == [2]  # ids are never reused


def test_merge_then_split_keeps_both_ids():
    # two people pass each other shoulder to shoulder: one blob for ~10 frames, then two
    tracker = BlobTracker(FPS)
    steps = [[(-1.0 + 0.04 * t, -0.06), (1.0 - 0.04 * t, 0.06)] for t in range(50)]
    history = run(tracker, steps)
    merged = [t for t, frame in enumerate(history) if len(set(frame.values())) == 1 and len(frame) == 2]
    assert len(merged) >= 5  # they really were one blob for a while
    assert all(list(frame) == [1, 2] for frame in history)
    assert merged[-1] < 45  # and two again at the end
    assert history[-1][1] > 0.5 and history[-1][2] < -0.5  # 1 walked on to +x, 2 to -x


def test_merged_tracks_report_each_other_and_their_own_share():
    tracker = BlobTracker(FPS)
    steps = [[(-1.0 + 0.04 * t, -0.06), (1.0 - 0.04 * t, 0.06)] for t in range(25)]
    history = run(tracker, steps)
    assert history[-1][1] == history[-1][2]  # one blob now
    one, two = tracker.states[1], tracker.states[2]
    assert one.merged_with == (2,) and two.merged_with == (1,)
    assert one.blob is two.blob
    assert one.centroid[0] < two.centroid[0]  # not yet past each other
    assert np.intersect1d(one.cells, two.cells).size == 0
    assert one.cells.size + two.cells.size == one.blob.cell_count
    assert one.velocity[0] > 0.6 and two.velocity[0] < -0.6


def test_split_the_piece_on_the_predicted_path_keeps_the_id():
    # two people walk in as one blob (one track); then one stops and the other walks on
    tracker = BlobTracker(FPS)
    together = [[(-1.5 + 0.05 * t, 0.0), (-1.2 + 0.05 * t, 0.0)] for t in range(15)]
    stop = -1.5 + 0.05 * 14
    apart = [[(stop, 0.0), (-1.2 + 0.05 * t, 0.0)] for t in range(15, 40)]
    history = run(tracker, together + apart)
    assert all(list(frame) == [1] for frame in history[:15])
    last = history[-1]
    assert list(last) == [1, 2]
    assert last[1] == pytest.approx(-1.2 + 0.05 * 39, abs=0.01)  # 1 went on with the walker
    assert last[2] == pytest.approx(stop, abs=0.01)


def test_optimal_assignment_where_greedy_would_swap():
    # A at 0.0 and B at 1.0; then blobs at 0.6 and 1.45: the nearest pair (B, 0.6) first
    # would leave A nothing within its gate; the optimal assignment gives A 0.6 and B 1.45
    tracker = BlobTracker(FPS, gate_m=0.7)
    history = run(tracker, [[(0.0, 0.0), (1.0, 0.0)]] * 3 + [[(0.6, 0.0), (1.45, 0.0)]])
    assert history[-1] == {1: 0.6, 2: 1.45}


def test_bad_input_to_tracker():
    with pytest.raises(ValueError, match="fps"):
        BlobTracker(0)
    with pytest.raises(ValueError, match="min_share"):
        BlobTracker(FPS, min_share=2)
    with pytest.raises(ValueError, match="Blob objects"):
        BlobTracker(FPS).update([np.zeros(3)])
    assert BlobTracker(FPS).update([]) == {}
    assert isinstance(people((0.0, 0.0))[0], Blob)
