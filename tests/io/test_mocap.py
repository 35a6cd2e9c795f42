"""Tests of occupose.io.mocap: tiny hand-written files (always) and the shared real clips (when present)."""

import math

import numpy as np
import pytest

from occupose.io import mocap as mc
from occupose.joints import BONES, JOINT_INDEX as J, JOINTS
from occupose.synth.retarget import facing_from_joints

# ---------------------------------------------------------------------------------------
# Tiny hand-written BVH files: hand-computed positions

_BVH = """HIERARCHY
ROOT Hips
{{
  OFFSET 0 0 0
  CHANNELS 6 Xposition Yposition Zposition {root_rotations}
  JOINT Chest
  {{
    OFFSET 0 1 0
    CHANNELS 3 Xrotation Yrotation Zrotation
    End Site
    {{
      OFFSET 0 0 1
    }}
  }}
}}
MOTION
Frames: 2
Frame Time: 0.5
0 0 0 0 0 0 0 0 0
1 2 3 {root_angles} 0 90 0
"""


def _write(tmp_path, text, name="clip.bvh"):
    path = tmp_path / name
    path.write_text(text)
    return path


def _zup(p):
    """y-up file coordinates -> z-up world: (x, y, z) -> (x, -z, y)."""
    x, y, z = p
    return (x, -z, y)


def test_bvh_zxy_rotation_order_matches_hand_computation(tmp_path):
    # Root R = Rz(90) Rx(90) Ry(0) (intrinsic, as written); Chest R = Rx(0) Ry(90) Rz(0).
    # Chest = (1,2,3) + R_root (0,1,0) = (1,2,3) + Rz90 (0,0,1) = (1,2,4)
    # End   = Chest + R_root Ry90 (0,0,1) = Chest + R_root (1,0,0) = Chest + (0,1,0) = (1,3,4)
    text = _BVH.format(root_rotations="Zrotation Xrotation Yrotation", root_angles="90 90 0")
    clip = mc.load_bvh(_write(tmp_path, text), units=1.0)
    assert clip.names == ("Hips", "Chest", "Chest_end")
    np.testing.assert_array_equal(clip.parents, [-1, 0, 1])
    assert clip.fps == 2.0 and clip.source == "bvh"
    expected0 = [_zup((0, 0, 0)), _zup((0, 1, 0)), _zup((0, 1, 1))]
    expected1 = [_zup((1, 2, 3)), _zup((1, 2, 4)), _zup((1, 3, 4))]
    np.testing.assert_allclose(clip.positions, [expected0, expected1], atol=1e-12)


def test_bvh_xyz_rotation_order_matches_hand_computation(tmp_path):
    # Root R = Rx(90) Ry(0) Rz(90): Chest = (1,2,3) + Rx90 Rz90 (0,1,0) = (1,2,3) + Rx90 (-1,0,0) = (0,2,3)
    # End = Chest + R_root Ry90 (0,0,1) = Chest + Rx90 Rz90 (1,0,0) = Chest + Rx90 (0,1,0) = (0,2,4)
    text = _BVH.format(root_rotations="Xrotation Yrotation Zrotation", root_angles="90 0 90")
    clip = mc.load_bvh(_write(tmp_path, text), units=1.0)
    expected1 = [_zup((1, 2, 3)), _zup((0, 2, 3)), _zup((0, 2, 4))]
    np.testing.assert_allclose(clip.positions[1], expected1, atol=1e-12)
    # The same numbers read in the other order give a different pose: order matters.
    other = _BVH.format(root_rotations="Zrotation Yrotation Xrotation", root_angles="90 0 90")
    assert not np.allclose(mc.load_bvh(_write(tmp_path, other, "b.bvh"), units=1.0).positions[1], expected1)


def test_bvh_position_channels_replace_offset_and_units_scale(tmp_path):
    text = """HIERARCHY
ROOT Root
{
  OFFSET 7 7 7
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT Child
  {
    OFFSET 5 0 0
    CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
    End Site
    {
      OFFSET 0 0 0
    }
  }
}
MOTION
Frames: 1
Frame Time: 0.0333333
10 20 30 0 0 0 0 2 0 0 0 0
"""
    clip = mc.load_bvh(_write(tmp_path, text), units=0.01)
    # Root at its position channels (10, 20, 30) cm, child at root + (0, 2, 0) cm, not + OFFSET.
    np.testing.assert_allclose(clip.positions[0, 0], np.array(_zup((10, 20, 30))) * 0.01, atol=1e-12)
    np.testing.assert_allclose(clip.positions[0, 1], np.array(_zup((10, 22, 30))) * 0.01, atol=1e-12)
    assert clip.fps == 30.0  # 1 / 0.0333333 snapped


def test_bvh_auto_units_for_unknown_skeleton_asks_for_units(tmp_path):
    path = _write(tmp_path, _BVH.format(root_rotations="Zrotation Xrotation Yrotation", root_angles="0 0 0"))
    with pytest.raises(ValueError, match="units="):
        mc.load_bvh(path)
    with pytest.raises(ValueError, match="units"):
        mc.load_bvh(path, units=-1.0)


@pytest.mark.parametrize(
    "change, line, message",
    [
        (("1 2 3 90 90 0 0 90 0", "1 2 3 90 90 0 0 90"), 20, "expected 9 values"),
        (("1 2 3 90 90 0 0 90 0", "1 2 3 90 90 0 0 x 0"), 20, "non-numeric"),
        (("CHANNELS 3 Xrotation", "CHANNELS 3 Wrotation"), 9, "unknown channel 'Wrotation'"),
        (("Frames: 2", "Frames: 3"), 17, "header says 3 frames"),
        (("OFFSET 0 1 0", "OFFSET 0 one 0"), 8, "OFFSET number"),
        (("    }\n  }\n}", "    }\n  }"), 15, "end of the HIERARCHY"),
    ],
)
def test_malformed_bvh_error_names_file_and_line(tmp_path, change, line, message):
    text = _BVH.format(root_rotations="Zrotation Xrotation Yrotation", root_angles="90 90 0")
    assert change[0] in text
    path = _write(tmp_path, text.replace(change[0], change[1]), "broken.bvh")
    with pytest.raises(ValueError, match=message) as err:
        mc.load_bvh(path, units=1.0)
    assert f"{path}:{line}:" in str(err.value)


def test_missing_bvh_is_file_not_found(tmp_path):
    with pytest.raises(FileNotFoundError, match="nope.bvh"):
        mc.load_bvh(tmp_path / "nope.bvh")


# ---------------------------------------------------------------------------------------
# Tiny hand-written ASF/AMC

_ASF = """:units
  mass 1.0
  length 0.5
  angle deg
:root
   order TX TY TZ RX RY RZ
   axis XYZ
   position 0 0 0
   orientation 0 0 0
:bonedata
  begin
     id 1
     name bone
     direction 1 0 0
     length 2
     axis 0 0 90 XYZ
    dof rx
    limits (-180.0 180.0)
  end
:hierarchy
  begin
    root bone
  end
"""

_AMC = """:FULLY-SPECIFIED
:DEGREES
1
root 1 2 3 0 0 0
bone 0
2
root 1 2 3 0 0 0
bone 90
3
root 0 0 0 0 0 90
bone 0
"""


def test_asf_amc_axis_and_dof_match_hand_computation(tmp_path):
    asf, amc = tmp_path / "s.asf", tmp_path / "s_01.amc"
    asf.write_text(_ASF)
    amc.write_text(_AMC)
    clip = mc.load_asf_amc(asf, amc, units=1.0)
    assert clip.names == ("root", "bone") and clip.source == "asf" and clip.fps == 120.0
    # Frame 1: end = (1,2,3) + 2 (1,0,0).
    # Frame 2: C = Rz90, M = Rx90, C M C^-1 = rotation of 90 deg about C x = y: (2,0,0) -> (0,0,-2).
    # Frame 3: root Rz90 turns (2,0,0) into (0,2,0).
    expected = [_zup((3, 2, 3)), _zup((1, 2, 1)), _zup((0, 2, 0))]
    np.testing.assert_allclose(clip.positions[:, 1], expected, atol=1e-12)
    # units="auto" reads ':units length 0.5': 1 unit = 0.0254 / 0.5 m.
    auto = mc.load_asf_amc(asf, amc)
    np.testing.assert_allclose(auto.positions, clip.positions * 0.0254 / 0.5, atol=1e-12)
    # load_clip finds the ASF from the AMC's subject prefix.
    np.testing.assert_allclose(mc.load_clip(amc, units=1.0).positions, clip.positions)


def test_malformed_amc_names_file_and_line(tmp_path):
    asf, amc = tmp_path / "s.asf", tmp_path / "s_01.amc"
    asf.write_text(_ASF)
    amc.write_text(_AMC.replace("bone 90", "bone 90 5"))
    with pytest.raises(ValueError, match=f"{amc}:8: malformed AMC: bone 'bone' has 1 dof"):
        mc.load_asf_amc(asf, amc)


# ---------------------------------------------------------------------------------------
# Canonical joints and measurements on synthetic arrays


def _standing(facing_y=True):
    """A standing canonical skeleton facing +y (left side at smaller x), metres, z up."""
    p = {
        "head": (0, 0, 1.60), "neck": (0, 0, 1.45), "pelvis": (0, 0, 0.95),
        "left_shoulder": (-0.18, 0, 1.42), "left_elbow": (-0.20, 0, 1.12), "left_wrist": (-0.21, 0, 0.86),
        "right_shoulder": (0.18, 0, 1.42), "right_elbow": (0.20, 0, 1.12), "right_wrist": (0.21, 0, 0.86),
        "left_hip": (-0.09, 0, 0.95), "left_knee": (-0.10, 0, 0.52), "left_ankle": (-0.10, 0, 0.08),
        "right_hip": (0.09, 0, 0.95), "right_knee": (0.10, 0, 0.52), "right_ankle": (0.10, 0, 0.08),
    }
    return np.array([p[name] for name in JOINTS], dtype=np.float64)


def test_bone_lengths_and_standing_height():
    body = _standing()
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

_ARM, _FOREARM = (J["left_shoulder"], J["left_elbow"]), (J["left_elbow"], J["left_wrist"])
_THIGH, _SHIN = (J["left_hip"], J["left_knee"]), (J["left_knee"], J["left_ankle"])


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
        clip = mc.load_asf_amc(mocap / "cmu" / asf, mocap / "cmu" / amc)
        assert clip.source == "asf" and clip.num_frames == frames and clip.fps == 120.0
        _check_body(mc.canonical_from_clip(clip))


@pytest.mark.shared
def test_cmu_bvh_clip(mocap):
    clip = mc.load_bvh(mocap / "cmu" / "01_01.bvh")
    assert clip.source == "cmu" and clip.num_frames == 2752 and clip.fps == 120.0
    # Frame 0 of this BVH is a rest pose; the take starts at frame 1. Its forearm is the
    # ASF lradius only (0.19-0.20 m): the file has no joint at the end of lwrist.
    _check_body(mc.canonical_from_clip(clip)[1:], forearm=(0.18, 0.22))


@pytest.mark.shared
def test_cmu_bvh_and_asf_amc_of_the_same_take_agree(mocap):
    bvh = mc.load_bvh(mocap / "cmu" / "01_01.bvh")
    asf = mc.load_asf_amc(mocap / "cmu" / "01.asf", mocap / "cmu" / "01_01.amc")
    b, a = mc.canonical_from_clip(bvh)[1:], mc.canonical_from_clip(asf)  # BVH frame k+1 = AMC frame k
    lower = [J[n] for n in ("pelvis", "left_hip", "left_knee", "left_ankle",
                            "right_hip", "right_knee", "right_ankle")]
    assert np.abs(b[:, lower] - a[:, lower]).max() < 1e-4
    # The BVH drops the ASF thorax segment (2.06488 units = 0.1166 m): its neck, shoulders,
    # arms and head are carried down by that vector, and are otherwise identical.
    gap = np.linalg.norm(b[:, J["neck"]] - a[:, J["neck"]], axis=-1)
    np.testing.assert_allclose(gap, 2.06488 * mc.CMU_UNIT, atol=1e-4)
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
    clip = mc.load_bvh(mocap / folder / f"{name}.bvh")
    assert clip.source == "bandai" and clip.fps == 30.0
    joints = mc.canonical_from_clip(clip)
    # The Bandai actor's skeleton is small (about 1.55 m; upper arm 0.243 m).
    _check_body(joints, upper_arm=(0.23, 0.35))


@pytest.mark.shared
def test_bandai_left_right_and_turn_direction(mocap):
    def load(folder, name):
        return mc.canonical_from_clip(mc.load_bvh(mocap / folder / f"{name}.bvh"))

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
