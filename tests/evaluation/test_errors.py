"""Tests of occupose.evaluation.errors on hand-computed cases."""

import math

import numpy as np
import pytest

from occupose.joints import JOINT_INDEX, NUM_JOINTS, UPPER_JOINTS
from occupose.evaluation.errors import (
    MIN_ARM_POINTS,
    MISSED_ERROR_M,
    TableRow,
    arm_epsilons,
    fail_curve,
    foreground_scores,
    format_table,
    frame_errors,
    identity_switches,
    is_fail,
    joint_errors,
    markdown_table,
    match_tracks,
    per_joint_errors,
    pixel_assignment_accuracy,
    rolling_mean,
    score,
    segment_distances,
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


# --------------------------------------------------------------------------- arm error


def test_segment_distances_to_the_nearest_segment_its_ends_included():
    starts = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    ends = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])  # a segment and a point
    points = np.array([[0.5, 0.3, 0.4], [-0.3, 0.0, 0.4], [0.0, 0.0, 0.9], [1.6, 0.8, 0.0]])
    np.testing.assert_allclose(segment_distances(points, starts, ends), [0.5, 0.5, 0.1, 1.0])
    with pytest.raises(ValueError, match="shape"):
        segment_distances(points, starts, ends[:1])


def _arm_skeleton():
    """15 joints with both arms hanging straight down from shoulders at z = 1.4 m."""
    joints = np.zeros((NUM_JOINTS, 3))
    for side, x in (("left", 0.2), ("right", -0.2)):
        for joint, z in (("shoulder", 1.4), ("elbow", 1.1), ("wrist", 0.85)):
            joints[JOINT_INDEX[f"{side}_{joint}"]] = (x, 0.0, z)
    return joints


def test_arm_epsilon_is_the_limb_radius_on_the_truth_and_grows_with_a_wrong_arm():
    rng = np.random.default_rng(0)
    skeleton = _arm_skeleton()
    # points on 4 cm cylinders round the two left bones and the right forearm
    z = rng.uniform(0.86, 1.39, 300)
    angle = rng.uniform(0, 2 * np.pi, 300)
    x = np.where(np.arange(300) < 200, 0.2, -0.2)
    z = np.where(np.arange(300) < 200, z, rng.uniform(0.86, 1.09, 300))
    points = np.stack([x + 0.04 * np.cos(angle), 0.04 * np.sin(angle), z], axis=1)
    raised = skeleton.copy()  # the right forearm pointing forward instead of down
    raised[JOINT_INDEX["right_wrist"]] = (-0.2, 0.25, 1.1)
    missing = skeleton.copy()
    missing[JOINT_INDEX["left_elbow"]] = np.nan
    eps = arm_epsilons([points, points, points, points[: MIN_ARM_POINTS - 1]],
                       np.stack([skeleton, raised, missing, skeleton]))
    assert eps[0] == pytest.approx(0.04, abs=1e-9)
    # the right forearm's points are now nearest the raised forearm (at z = 1.1 m, along +y
    # from the elbow) or, behind it (y < 0), the elbow itself
    fore = points[200:]
    across = np.where(fore[:, 1] >= 0, np.abs(fore[:, 0] + 0.2), 0.04)
    expected = (200 * 0.04 + np.hypot(across, 1.1 - fore[:, 2]).sum()) / 300
    assert eps[1] == pytest.approx(expected, rel=1e-9) and eps[1] > 0.065
    assert np.isnan(eps[2]) and np.isnan(eps[3])
    with pytest.raises(ValueError, match="shape"):
        arm_epsilons([points], np.stack([skeleton, skeleton]))


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


# --------------------------------------------------------------------------- tables


def _row(**changes):
    values = dict(mean_cm=12.0, std_cm=5.0, under10=30.0, under15=60.0, under20=80.0,
                  over20=20.0, fail=False, frames=100, coverage=100.0)
    values.update(changes)
    return TableRow(**values)


def test_format_table_aligned():
    text = format_table({"OUR": _row(), "APF": _row(mean_cm=math.nan, fail=True)})
    lines = text.splitlines()
    assert lines[0].split("  ")[0].strip() == "method"
    for heading in ("<10cm [%]", ">20cm [%]", "Avg Err [cm]", "Std Dev [cm]", "Status"):
        assert heading in lines[0]
    assert len({len(line) for line in lines}) == 1  # right-aligned last column
    assert "12.00" in lines[1] and "ok" in lines[1]
    assert "n/a" in lines[2] and "FAIL" in lines[2]
    assert "avg 12.00 cm" in _row().format() and "ok" in _row().format()


def test_markdown_table_bolds_best_per_group():
    groups = {
        "Seq1": {"OUR": _row(mean_cm=10.0, under10=50.0), "APF": _row(mean_cm=15.0, under10=50.0, std_cm=4.0)},
        "Seq2": {"OUR": _row(over20=math.nan)},
    }
    lines = markdown_table(groups).splitlines()
    assert lines[0].startswith("| sequence | method | <10cm [%]")
    our, apf, seq2 = (line.split(" | ") for line in lines[2:5])
    assert our[0] == "| Seq1" and apf[0] == "| " and seq2[0] == "| Seq2"
    assert our[2] == "**50.00**" and apf[2] == "**50.00**"  # tie: both bold
    assert our[6] == "**10.00**" and apf[6] == "15.00"  # lower mean is better
    assert our[7] == "5.00" and apf[7] == "**4.00**"
    assert our[8] == "ok"  # status not ranked
    assert seq2[5] == "n/a" and seq2[6] == "**12.00**"


# --------------------------------------------------------------------------- tracks vs people


def _two_people(num_frames=10):
    """Person 0 walks along x at y = 0, person 1 at y = 2; 3 joints 0.5 m apart in z."""
    gt = np.zeros((num_frames, 2, 3, 3))
    gt[..., 0] = 0.1 * np.arange(num_frames)[:, None, None]
    gt[:, 1, :, 1] = 2.0
    gt[..., 2] = [0.5, 1.0, 1.5]
    return gt


def test_match_tracks_swapped_ids_and_unmatched():
    gt = _two_people()
    gt[8:] = np.nan  # nobody in the last two frames
    only_late = np.full((10, 3, 3), np.nan)
    only_late[8:] = 0.0
    far = gt[:, 0] + [0.0, 5.0, 0.0]
    tracks = {7: gt[:, 1] + 0.01, 3: gt[:, 0] - 0.02, 9: only_late, 4: far}
    assert match_tracks(gt, tracks) == {7: 1, 3: 0}
    assert match_tracks(gt, {}) == {}
    with pytest.raises(ValueError, match="track 7"):
        match_tracks(gt, {7: np.zeros((9, 3, 3))})


def test_identity_switches_on_constructed_swap():
    gt = _two_people()
    a = np.where(np.arange(10)[:, None, None] < 5, gt[:, 0], gt[:, 1])
    b = np.where(np.arange(10)[:, None, None] < 5, gt[:, 1], gt[:, 0])
    assert identity_switches(gt, {1: a, 2: b}).tolist() == [1, 1]
    # A gap (no track) is skipped; the same track coming back is not a switch.
    gap = gt[:, 0].copy()
    gap[3:6] = np.nan
    assert identity_switches(gt, {1: gap, 2: gt[:, 1]}).tolist() == [0, 0]
    # A new track 0.6 m off: beyond the 0.5 m gate it never covers the person, within 0.7 m it does.
    first = np.where(np.arange(10)[:, None, None] < 5, gt[:, 0], np.nan)
    second = np.where(np.arange(10)[:, None, None] >= 5, gt[:, 0] + [0.0, 0.0, 0.6], np.nan)
    tracks = {1: first, 3: second, 2: gt[:, 1]}
    assert identity_switches(gt, tracks).tolist() == [0, 0]
    assert identity_switches(gt, tracks, gate_m=0.7).tolist() == [1, 0]


def _full_people(num_frames=30):
    gt = np.zeros((num_frames, 2, 15, 3))
    gt[..., 2] = np.linspace(0.1, 1.7, 15)
    gt[:, 1, :, 0] = 3.0
    return gt


def test_score_upper_body_track_visible_only_and_unmatched_person():
    gt = _full_people()
    visible = np.ones(gt.shape[:3], dtype=bool)
    visible[:, 0, 0] = False  # person 0's head hidden all along
    est = gt[:, 0] + [0.06, 0.0, 0.0]  # 6 cm on every joint ...
    est[:, 0] = gt[:, 0, 0] + [0.33, 0.0, 0.0]  # ... but 33 cm on the (hidden) head
    est[:, len(UPPER_JOINTS):] = np.nan  # upper-body model: 9 joints
    est[20:] = np.nan  # track lost at frame 20 (t = 2 s at 10 fps)
    gt[:, 0, 9:] += 1.0  # wild lower-body ground truth must not count
    result = score(gt, visible, {5: est, 8: np.full((30, 15, 3), np.nan)}, fps=10.0)

    first, second = result.persons
    assert first.track == 5 and second.track is None
    assert result.unmatched_tracks == (8,)
    assert list(first.per_joint_cm) == list(UPPER_JOINTS)
    assert first.per_joint_cm["head"] == pytest.approx(33.0)
    assert first.per_joint_cm["left_wrist"] == pytest.approx(6.0)
    # all joints: D = (33 + 8 * 6) / 9 = 9 cm in frames 0-19, frames 20-29 missed
    row = first.all_joints
    assert row.mean_cm == pytest.approx(9.0) and row.std_cm == pytest.approx(0.0, abs=1e-9)
    assert row.frames == 30 and row.coverage == pytest.approx(200 / 3)
    assert row.under10 == pytest.approx(200 / 3) and row.over20 == pytest.approx(100 / 3)
    assert row.fail
    # visible only: the head drops out, D = 6 cm
    assert first.visible_joints.mean_cm == pytest.approx(6.0)
    assert first.visible_joints.frames == 30
    # the person without a track: every frame missed
    assert second.all_joints.frames == 30 and second.all_joints.coverage == 0.0
    assert second.all_joints.over20 == 100.0 and second.all_joints.fail
    assert math.isnan(second.all_joints.mean_cm)
    assert result.identity_switches == 0


def test_score_checks_inputs():
    gt = _full_people()
    visible = np.ones(gt.shape[:3], dtype=bool)
    with pytest.raises(ValueError, match="15 canonical"):
        score(gt[:, :, :9], visible[:, :, :9], {}, fps=10.0)
    with pytest.raises(ValueError, match="gt_visible"):
        score(gt, visible.astype(float), {}, fps=10.0)


# --------------------------------------------------------------------------- pixels


def test_pixel_assignment_accuracy():
    truth = np.array([[0, 1, 1], [2, 2, 0]])
    assigned = np.array([[0, 1, 2], [2, 1, 0]])
    foreground = truth > 0
    assert pixel_assignment_accuracy(assigned, truth, foreground) == pytest.approx(0.5)
    assert math.isnan(pixel_assignment_accuracy(assigned, truth, np.zeros((2, 3), bool)))
    with pytest.raises(ValueError, match="integer"):
        pixel_assignment_accuracy(assigned.astype(float), truth, foreground)


def test_foreground_scores():
    pred = np.array([[1, 1, 0], [1, 0, 0]], dtype=bool)
    true = np.array([[1, 0, 0], [1, 1, 1]], dtype=bool)
    precision, recall, iou = foreground_scores(pred, true)
    assert (precision, recall, iou) == pytest.approx((2 / 3, 2 / 4, 2 / 5))
    empty = np.zeros((2, 3), dtype=bool)
    assert all(math.isnan(v) for v in foreground_scores(empty, empty))


def test_a_track_present_in_one_frame_does_not_steal_the_match():
    gt = np.zeros((300, 1, 15, 3))
    steady = gt[:, 0] + [0.10, 0.0, 0.0]  # 10 cm off, every frame
    stray = np.full((300, 15, 3), np.nan)
    stray[7] = gt[7, 0] + [0.01, 0.0, 0.0]  # 1 cm off, one frame
    assert match_tracks(gt, {"steady": steady, "stray": stray}) == {"steady": 0}


def test_frames_before_anything_of_the_person_is_visible_are_not_scored():
    gt = np.zeros((90, 1, 15, 3))
    visible = np.ones((90, 1, 15), bool)
    visible[:30] = False  # walking in: in the image, but no joint visible yet
    track = gt[:, 0].copy()
    track[:33] = np.nan  # the tracker starts 3 frames after the first visible joint
    person = score(gt, visible, {1: track}, fps=30.0).persons[0]
    assert person.all_joints.frames == 60 and person.all_joints.coverage == pytest.approx(95.0)
    assert not person.all_joints.fail and person.all_joints.mean_cm == 0.0


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
