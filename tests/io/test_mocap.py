"""Tests of occupose.io.mocap: canonical joints and measurements on synthetic arrays, finding
clips in a data folder (always), and the shared real clips read by both readers (when present)."""

import math

import numpy as np
import pytest

from occupose.io import mocap as mc
from occupose.io.asf_amc import load_asf_amc
from occupose.io.bvh import CMU_UNIT, load_bvh
from occupose.joints import BONES, JOINT_INDEX as J, JOINTS
from occupose.synth.retarget import facing_from_joints

# ---------------------------------------------------------------------------------------
# Canonical joints and measurements on synthetic arrays


def test_bone_lengths_and_standing_height(standing_skeleton):
    body = standing_skeleton
    lengths = mc.bone_lengths(body)
    assert lengths.shape == (len(BONES),)
    assert lengths[BONES.index((J["left_knee"], J["left_ankle"]))] == pytest.approx(0.44)
    # head 1.60 + 0.10 top - (ankle 0.08 - 0.08 ankle height)
    assert mc.standing_height(body) == pytest.approx(1.70)
    assert mc.standing_height(np.stack([body, body + [0, 0, 1.0]])).shape == (2,)
    with pytest.raises(ValueError, match=r"\(\.\.\., 15, 3\)"):
        mc.bone_lengths(np.zeros((14, 3)))


def _bandai_like_clip(head_end_up):
    names = ("Hips", "UpperLeg_L", "UpperLeg_R", "LowerLeg_L", "LowerLeg_R", "Foot_L", "Foot_R", "Neck",
             "Head", "Head_end", "UpperArm_L", "UpperArm_R", "LowerArm_L", "LowerArm_R", "Hand_L", "Hand_R")
    rng = np.random.default_rng(3)
    positions = rng.normal(size=(2, len(names), 3))
    head = names.index("Head")
    positions[:, names.index("Head_end")] = positions[:, head] + head_end_up
    return mc.Clip(names, np.array([-1] + [0] * (len(names) - 1)), 30.0, positions, "bandai")


def test_canonical_from_clip_pelvis_and_head_centre():
    clip = _bandai_like_clip(head_end_up=0.0)  # zero-length end site, as in Bandai files
    joints = mc.canonical_from_clip(clip)
    assert joints.shape == (2, 15, 3)
    pos = {n: clip.positions[:, clip.index(n)] for n in clip.names}
    np.testing.assert_allclose(joints[:, J["pelvis"]], (pos["UpperLeg_L"] + pos["UpperLeg_R"]) / 2)
    np.testing.assert_allclose(joints[:, J["right_elbow"]], pos["LowerArm_R"])
    up = pos["Head"] - pos["Neck"]
    up /= np.linalg.norm(up, axis=-1, keepdims=True)
    np.testing.assert_allclose(joints[:, J["head"]], pos["Head"] + 0.10 * up)
    # An end site away from the head joint gives the head's direction instead.
    tipped = mc.canonical_from_clip(_bandai_like_clip(head_end_up=np.array([0.0, 0.3, 0.4])))
    np.testing.assert_allclose(tipped[:, J["head"]], pos["Head"] + [0.0, 0.06, 0.08])
    with pytest.raises(ValueError, match="no canonical joint mapping"):
        mc.canonical_from_clip(mc.Clip(("a",), np.array([-1]), 30.0, np.zeros((1, 1, 3)), "bvh"))


def test_list_and_find_clips_in_a_data_folder(tmp_path, monkeypatch):
    for rel in ("cmu/01_01.bvh", "cmu/01_01.amc", "cmu/01.asf", "bandai1/dataset-1_walk_normal_001.bvh",
                "bandai1/dataset-1_walk_normal_002.bvh", "bandai2/dataset-2_wave-left-hand_active_001.bvh"):
        (tmp_path / "mocap" / rel).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / "mocap" / rel).write_text("")
    monkeypatch.setenv("OCCUPOSE_DATA", str(tmp_path))
    assert [p.name for p in mc.list_clips("cmu")] == ["01_01.amc", "01_01.bvh"]
    assert len(mc.list_clips()) == 5 and len(mc.list_clips("bandai")) == 3
    assert mc.find_clip("wave-left").name == "dataset-2_wave-left-hand_active_001.bvh"
    assert mc.find_clip("01_01.bvh").suffix == ".bvh"
    with pytest.raises(ValueError, match="2 clips match 'walk_normal'"):
        mc.find_clip("walk_normal")
    with pytest.raises(FileNotFoundError, match="no shared mocap clip"):
        mc.find_clip("dance")
    with pytest.raises(ValueError, match="valid: None, cmu"):
        mc.list_clips("kinect")
    monkeypatch.setattr(mc, "mocap_dir", lambda: None)
    assert mc.list_clips() == [] and mc.find_clip("wave") is None


# ---------------------------------------------------------------------------------------
# The shared real clips



def _check_body(joints, forearm=(0.20, 0.32), upper_arm=(0.25, 0.35), height=(1.4, 2.0)):
    """Median bone lengths of both sides and the upright height of a canonical clip."""
    lengths = np.median(mc.bone_lengths(joints), axis=0)
    for (a, b), (lo, hi) in (((J["left_shoulder"], J["left_elbow"]), upper_arm),
                             ((J["right_shoulder"], J["right_elbow"]), upper_arm),
                             ((J["left_elbow"], J["left_wrist"]), forearm),
                             ((J["right_elbow"], J["right_wrist"]), forearm),
                             ((J["left_hip"], J["left_knee"]), (0.35, 0.50)),
                             ((J["right_hip"], J["right_knee"]), (0.35, 0.50)),
                             ((J["left_knee"], J["left_ankle"]), (0.33, 0.50)),
                             ((J["right_knee"], J["right_ankle"]), (0.33, 0.50))):
        assert lo <= lengths[BONES.index((a, b))] <= hi, (JOINTS[a], JOINTS[b], lengths[BONES.index((a, b))])
    assert height[0] <= np.percentile(mc.standing_height(joints), 95) <= height[1]
    first = joints[0]
    assert first[J["head"], 2] > first[J["neck"], 2] > first[J["pelvis"], 2] > first[J["left_knee"], 2]
    assert first[J["pelvis"], 2] > max(first[J["left_ankle"], 2], first[J["right_ankle"], 2])


@pytest.mark.shared
def test_cmu_asf_amc_clips(mocap):
    for asf, amc, frames in (("01.asf", "01_01.amc", 2751), ("11.asf", "11_01.amc", 597)):
        clip = load_asf_amc(mocap / "cmu" / asf, mocap / "cmu" / amc)
        assert clip.source == "asf" and clip.num_frames == frames and clip.fps == 120.0
        _check_body(mc.canonical_from_clip(clip))


@pytest.mark.shared
def test_cmu_bvh_clip(mocap):
    clip = load_bvh(mocap / "cmu" / "01_01.bvh")
    assert clip.source == "cmu" and clip.num_frames == 2752 and clip.fps == 120.0
    # Frame 0 of this BVH is a rest pose; the take starts at frame 1. Its forearm is the
    # ASF lradius only (0.19-0.20 m): the file has no joint at the end of lwrist.
    _check_body(mc.canonical_from_clip(clip)[1:], forearm=(0.18, 0.22))


@pytest.mark.shared
def test_cmu_bvh_and_asf_amc_of_the_same_take_agree(mocap):
    bvh = load_bvh(mocap / "cmu" / "01_01.bvh")
    asf = load_asf_amc(mocap / "cmu" / "01.asf", mocap / "cmu" / "01_01.amc")
    b, a = mc.canonical_from_clip(bvh)[1:], mc.canonical_from_clip(asf)  # BVH frame k+1 = AMC frame k
    lower = [J[n] for n in ("pelvis", "left_hip", "left_knee", "left_ankle",
                            "right_hip", "right_knee", "right_ankle")]
    assert np.abs(b[:, lower] - a[:, lower]).max() < 1e-4
    # The BVH drops the ASF thorax segment (2.06488 units = 0.1166 m): its neck, shoulders,
    # arms and head are carried down by that vector, and are otherwise identical.
    gap = np.linalg.norm(b[:, J["neck"]] - a[:, J["neck"]], axis=-1)
    np.testing.assert_allclose(gap, 2.06488 * CMU_UNIT, atol=1e-4)
    upper = [J[n] for n in ("head", "left_shoulder", "left_elbow", "right_shoulder", "right_elbow")]
    rel_b = b[:, upper] - b[:, J["neck"], None]
    rel_a = a[:, upper] - a[:, J["neck"], None]
    assert np.abs(rel_b - rel_a).max() < 1e-4
    # And its hand sits at the end of the ASF lradius, short of the ASF wrist (lwrist end).
    hand_b = bvh.positions[1:, bvh.index("LeftHand")] - bvh.positions[1:, bvh.index("Neck1")]
    hand_a = asf.positions[:, asf.index("lradius")] - asf.positions[:, asf.index("lowerneck")]
    assert np.abs(hand_b - hand_a).max() < 1e-4


@pytest.mark.shared
@pytest.mark.parametrize("name", [
    "dataset-1_walk_normal_001", "dataset-1_walk_happy_001", "dataset-1_walk-back_normal_001",
    "dataset-2_walk-turn-left_active_001", "dataset-2_wave-left-hand_active_001",
    "dataset-2_wave-right-hand_feminine_028", "dataset-2_wave-both-hands_elderly_006",
])
def test_bandai_clips(mocap, name):
    folder = "bandai1" if name.startswith("dataset-1") else "bandai2"
    clip = load_bvh(mocap / folder / f"{name}.bvh")
    assert clip.source == "bandai" and clip.fps == 30.0
    joints = mc.canonical_from_clip(clip)
    # The Bandai actor's skeleton is small (about 1.55 m; upper arm 0.243 m).
    _check_body(joints, upper_arm=(0.23, 0.35))


@pytest.mark.shared
def test_bandai_left_right_and_turn_direction(mocap):
    def load(folder, name):
        return mc.canonical_from_clip(load_bvh(mocap / folder / f"{name}.bvh"))

    wave_left = load("bandai2", "dataset-2_wave-left-hand_active_001")
    assert wave_left[:, J["left_wrist"], 2].max() > wave_left[:, J["head"], 2].max()
    assert wave_left[:, J["right_wrist"], 2].max() < wave_left[:, J["pelvis"], 2].max()
    turn = load("bandai2", "dataset-2_walk-turn-left_active_001")
    facing = np.unwrap(facing_from_joints(turn))
    assert math.radians(60) < facing[-1] - facing[0] < math.radians(120)  # a left turn is counterclockwise
    walk = load("bandai1", "dataset-1_walk_normal_001")
    step = walk[30, J["pelvis"], :2] - walk[0, J["pelvis"], :2]
    heading = facing_from_joints(walk[0])
    assert np.dot(step, [math.cos(heading), math.sin(heading)]) > 0.9 * np.linalg.norm(step)  # walks forward
