"""occupose.evaluation.errors on hand-computed cases: joint and frame errors, Table I rows, the FAIL rule."""

import math

import numpy as np
import pytest

from occupose.evaluation.errors import (
    MISSED_ERROR_M,
    fail_curve,
    fail_frame,
    frame_errors,
    is_fail,
    joint_errors,
    per_joint_errors,
    rolling_mean,
    table_row,
)

# 3-4-5 triangles: offsets of length 3, 6 and 9 cm for three joints.
OFFSETS = np.array([[0.018, 0.024, 0.0], [0.0, 0.036, 0.048], [0.054, 0.0, 0.072]])


# --------------------------------------------------------------------------- errors


def test_joint_errors_are_euclidean_and_nan_where_missing():
    gt = np.zeros((2, 3, 3))
    est = gt + OFFSETS
    est[1, 2, 0] = np.nan
    gt[1, 0, 1] = np.nan
    errors = joint_errors(gt, est)
    np.testing.assert_allclose(errors[0], [0.03, 0.06, 0.09])
    assert np.isnan(errors[1, 0]) and np.isnan(errors[1, 2])
    assert errors[1, 1] == pytest.approx(0.06)


def test_joint_errors_rejects_mismatched_shapes():
    with pytest.raises(ValueError, match="same shape"):
        joint_errors(np.zeros((2, 3, 3)), np.zeros((2, 4, 3)))


def test_frame_errors_mean_over_counted_joints():
    errors = np.array([[0.1, 0.2, np.nan], [np.nan, np.nan, np.nan], [0.1, 0.2, 0.6]])
    np.testing.assert_allclose(frame_errors(errors), [0.15, np.nan, 0.3])
    mask = np.array([[False, True, True], [True, True, True], [True, False, False]])
    np.testing.assert_allclose(frame_errors(errors, mask), [0.2, np.nan, 0.1])
    with pytest.raises(ValueError, match="boolean"):
        frame_errors(errors, mask.astype(int))


def test_per_joint_errors_in_cm():
    errors = np.array([[0.1, np.nan], [0.3, np.nan]])
    result = per_joint_errors(errors, ["head", "neck"])
    assert result["head"] == pytest.approx(20.0)
    assert math.isnan(result["neck"])
    with pytest.raises(ValueError, match="names"):
        per_joint_errors(errors, ["head"])


# --------------------------------------------------------------------------- Table I row


def test_table_row_constant_offset_three_joints(rng):
    """Frames 0-5: joint errors 3, 6, 9 cm (D = 6 cm); frames 6-9: doubled (D = 12 cm).

    mean = (6*6 + 4*12)/10 = 8.4 cm; population variance = (6*2.4^2 + 4*3.6^2)/10 = 8.64 cm^2.
    """
    gt = rng.normal(size=(10, 3, 3))
    scale = np.where(np.arange(10) < 6, 1.0, 2.0)[:, None, None]
    errors = joint_errors(gt, gt + scale * OFFSETS)
    row = table_row(frame_errors(errors), fps=10.0)
    assert row.mean_cm == pytest.approx(8.4)
    assert row.std_cm == pytest.approx(math.sqrt(8.64))
    assert (row.under10, row.under15, row.under20, row.over20) == pytest.approx((60, 100, 100, 0))
    assert row.fail is False and row.frames == 10 and row.coverage == 100.0
    assert per_joint_errors(errors, ["a", "b", "c"]) == pytest.approx({"a": 4.2, "b": 8.4, "c": 12.6})


def test_table_row_bounds_are_inclusive_under_and_strict_over():
    """D = 10 cm counts as <10; D = 20 cm counts as <20 and not as >20 (paper: "does not exceed")."""
    row = table_row(np.array([0.10, 0.15, 0.20, 0.25]), fps=10.0)
    assert (row.under10, row.under15, row.under20, row.over20) == (25.0, 50.0, 75.0, 25.0)
    above = np.nextafter(np.array([0.10, 0.15, 0.20]), 1.0)
    row = table_row(above, fps=10.0)
    assert (row.under10, row.under15, row.under20, row.over20) == pytest.approx(
        (0.0, 100 / 3, 200 / 3, 100 / 3)
    )


def test_table_row_missed_and_excluded_frames():
    """Frame 1 missed, frame 3 has no ground-truth person (excluded)."""
    errors = np.array([0.05, np.nan, 0.30, np.nan])
    missed = np.array([False, True, False, False])
    row = table_row(errors, fps=10.0, missed=missed)
    assert row.frames == 3
    assert row.coverage == pytest.approx(200 / 3)
    assert row.mean_cm == pytest.approx(17.5) and row.std_cm == pytest.approx(12.5)
    assert (row.under10, row.under15, row.under20, row.over20) == pytest.approx(
        (100 / 3, 100 / 3, 100 / 3, 200 / 3)
    )


def test_table_row_without_counted_frames():
    row = table_row(np.full(5, np.nan), fps=10.0)
    assert row.frames == 0 and row.fail is False
    assert all(math.isnan(v) for v in (row.mean_cm, row.std_cm, row.under10, row.over20, row.coverage))


def test_table_row_rejects_bad_frame_errors():
    with pytest.raises(ValueError, match="missed"):
        table_row(np.array([0.1, 0.2]), fps=10.0, missed=np.array([False, True]))
    with pytest.raises(ValueError, match="inf"):
        table_row(np.array([0.1, np.inf]), fps=10.0)
    with pytest.raises(ValueError, match="shape"):
        table_row(np.array([0.1, 0.2]), fps=10.0, missed=np.array([False]))
    with pytest.raises(ValueError, match="fps"):
        table_row(np.array([0.1]), fps=0.0)


# --------------------------------------------------------------------------- FAIL rule
# fps = 10: the 2 s window holds 20 frames, the grace period is frames 0-9.


def test_rolling_mean_trailing_with_partial_windows_and_skipped_nan():
    np.testing.assert_allclose(rolling_mean([1.0, 2.0, 3.0, 4.0], fps=1.0), [1.0, 1.5, 2.5, 3.5])
    np.testing.assert_allclose(
        rolling_mean([1.0, np.nan, 3.0, np.nan, np.nan], fps=1.0), [1.0, 1.0, 3.0, 3.0, np.nan]
    )
    np.testing.assert_allclose(rolling_mean([1.0, 2.0, 6.0], fps=1.5, window_s=2.0), [1, 1.5, 3])
    assert rolling_mean([1.0, np.inf, 1.0], fps=1.0)[1:].tolist() == [np.inf, np.inf]
    assert rolling_mean([], fps=1.0).shape == (0,)


def test_short_spike_does_not_fail_but_a_longer_one_does():
    """Base 10 cm, spike 1 m: 3 frames give (17*0.1 + 3)/20 = 23.5 cm, 4 frames 28 cm."""
    errors = np.full(60, 0.10)
    errors[40:43] = 1.0
    assert np.nanmax(fail_curve(errors, 10.0)) == pytest.approx(0.235)
    assert not is_fail(errors, 10.0)
    errors[43] = 1.0
    assert np.nanmax(fail_curve(errors, 10.0)) == pytest.approx(0.28)
    assert is_fail(errors, 10.0)


def test_sustained_error_fails():
    errors = np.full(60, 0.10)
    errors[30:] = 0.30
    assert is_fail(errors, 10.0)
    assert not is_fail(errors, 10.0, threshold_m=0.30)
    # the rule trips where the 20-frame window's mean first exceeds 25 cm:
    # (20 - n) * 0.10 + n * 0.30 > 0.25 * 20 for n > 15 frames at 30 cm, i.e. at frame 45
    assert fail_frame(errors, 10.0) == 45
    assert fail_frame(errors, 10.0, threshold_m=0.30) is None
    assert fail_frame(np.full(60, 0.05), 10.0) is None


def test_grace_period_then_windows_include_the_first_second():
    errors = np.full(60, 0.05)
    errors[:5] = 0.40  # a slow start: 0.5 s at 40 cm
    curve = fail_curve(errors, 10.0)
    assert np.all(np.isnan(curve[:10]))  # nothing judged before t = 1 s
    assert curve[10] == pytest.approx((5 * 0.40 + 6 * 0.05) / 11)  # but the window reaches back
    assert not is_fail(errors, 10.0)
    errors[:10] = 2.0  # wrong for the whole first second: the first judged window FAILs
    assert is_fail(errors, 10.0)
    errors = np.full(60, 0.05)
    errors[10] = 0.30  # one bad frame at t = 1.0 s is averaged, not judged alone
    assert not is_fail(errors, 10.0)


def test_grace_period_starts_at_the_first_counted_frame():
    errors = np.full(60, np.nan)
    errors[30:] = 0.05
    errors[30:35] = 2.0  # a person who walks in at 3 s, tracked badly at first
    curve = fail_curve(errors, 10.0)
    assert np.all(np.isnan(curve[:40])) and np.isfinite(curve[40])
    assert is_fail(errors, 10.0) == (curve[40] > 0.25)


def test_fail_threshold_is_strict():
    assert not is_fail(np.full(60, 0.25), 10.0)
    assert is_fail(np.full(60, np.nextafter(0.25, 1.0)), 10.0)


def test_missed_frames_count_as_one_metre_in_the_window():
    errors = np.full(60, 0.05)
    missed = np.zeros(60, dtype=bool)
    errors[45], missed[45] = np.nan, True  # one dropped frame does not FAIL
    assert not is_fail(errors, 10.0, missed=missed)
    assert fail_curve(errors, 10.0, missed=missed)[45] == pytest.approx((19 * 0.05 + MISSED_ERROR_M) / 20)
    errors[40:], missed[40:] = np.nan, True  # a person lost for good does
    assert is_fail(errors, 10.0, missed=missed)
    assert table_row(errors, 10.0, missed=missed).fail


def test_excluded_frames_are_skipped_in_windows():
    errors = np.full(60, 0.20)
    errors[20:40] = np.nan  # person absent for 2 s
    assert not is_fail(errors, 10.0)
    np.testing.assert_allclose(fail_curve(errors, 10.0)[40], 0.20)


def test_frames_missed_while_the_tracker_finds_a_person_do_not_fail():
    fps = 30.0
    errors = np.full(300, 0.08)
    missed = np.zeros(300, bool)
    errors[:12], missed[:12] = np.nan, True  # found 0.4 s after the first counted frame
    assert not is_fail(errors, fps, missed=missed)
    late = errors.copy(), missed.copy()
    late[0][150:], late[1][150:] = np.nan, True  # lost for good later: FAIL
    assert is_fail(late[0], fps, missed=late[1])
    never = np.full(300, np.nan)  # never found: FAIL
    assert is_fail(never, fps, missed=np.ones(300, bool))
    slow = errors.copy(), missed.copy()
    slow[0][:45], slow[1][:45] = np.nan, True  # found only 1.5 s in: the misses after 1 s count
    assert is_fail(slow[0], fps, missed=slow[1])
