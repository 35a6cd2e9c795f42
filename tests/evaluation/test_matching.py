"""occupose.evaluation.matching on hand-made tracks: matching tracks to people, identity switches, score."""

import math

import numpy as np
import pytest

from occupose.evaluation.matching import identity_switches, match_tracks, score
from occupose.joints import JOINTS, UPPER_JOINTS


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


def test_joints_left_out_count_as_missed_and_never_improve_a_score():
    gt = _full_people()[:, :1]
    visible = np.ones(gt.shape[:3], dtype=bool)
    full = gt[:, 0] + [0.05, 0.0, 0.0]  # 5 cm on every joint ...
    full[:, JOINTS.index("pelvis")] = gt[:, 0, JOINTS.index("pelvis")]  # ... but the pelvis exact
    pelvis_only = np.full_like(full, np.nan)
    pelvis_only[:, JOINTS.index("pelvis")] = full[:, JOINTS.index("pelvis")]
    whole, pelvis = (score(gt, visible, {1: est}, fps=10.0).persons[0] for est in (full, pelvis_only))
    assert whole.all_joints.mean_cm == pytest.approx(14 * 5.0 / 15) and not whole.all_joints.fail
    # the pelvis alone is an upper-body track (no hip, knee or ankle): 8 of its 9 joints missed
    assert list(pelvis.per_joint_cm) == list(UPPER_JOINTS)
    assert pelvis.all_joints.mean_cm == pytest.approx(8 * 100.0 / 9) and pelvis.all_joints.fail
    assert pelvis.per_joint_cm["head"] == pytest.approx(100.0) and pelvis.per_joint_cm["pelvis"] == 0.0
    assert pelvis.visible_joints.mean_cm == pytest.approx(8 * 100.0 / 9)
    # a full-body track that drops its left leg in frames 10-19: 3 of 15 joints at 1 m there
    dropped = full.copy()
    dropped[10:20, [JOINTS.index(j) for j in ("left_hip", "left_knee", "left_ankle")]] = np.nan
    row = score(gt, visible, {1: dropped}, fps=10.0).persons[0].all_joints
    assert row.coverage == 100.0 and row.over20 == pytest.approx(100 / 3)
    assert row.mean_cm == pytest.approx((20 * 14 * 5.0 / 15 + 10 * (11 * 5.0 + 3 * 100.0) / 15) / 30)
    # a joint hidden in the ground truth and left out is no miss in the visible-only row
    visible[:, 0, JOINTS.index("left_ankle")] = False
    no_ankle = full.copy()
    no_ankle[:, JOINTS.index("left_ankle")] = np.nan
    person = score(gt, visible, {1: no_ankle}, fps=10.0).persons[0]
    assert person.visible_joints.mean_cm == pytest.approx(13 * 5.0 / 14)
    assert person.all_joints.mean_cm == pytest.approx((13 * 5.0 + 100.0) / 15)
