"""Tests of occupose.io.bvh: tiny hand-written BVH files, hand-computed positions, errors that
name the file and line."""

import numpy as np
import pytest

from occupose.io.bvh import load_bvh


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
    clip = load_bvh(_write(tmp_path, text), units=1.0)
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
    clip = load_bvh(_write(tmp_path, text), units=1.0)
    expected1 = [_zup((1, 2, 3)), _zup((0, 2, 3)), _zup((0, 2, 4))]
    np.testing.assert_allclose(clip.positions[1], expected1, atol=1e-12)
    # The same numbers read in the other order give a different pose: order matters.
    other = _BVH.format(root_rotations="Zrotation Yrotation Xrotation", root_angles="90 0 90")
    assert not np.allclose(load_bvh(_write(tmp_path, other, "b.bvh"), units=1.0).positions[1], expected1)


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
    clip = load_bvh(_write(tmp_path, text), units=0.01)
    # Root at its position channels (10, 20, 30) cm, child at root + (0, 2, 0) cm, not + OFFSET.
    np.testing.assert_allclose(clip.positions[0, 0], np.array(_zup((10, 20, 30))) * 0.01, atol=1e-12)
    np.testing.assert_allclose(clip.positions[0, 1], np.array(_zup((10, 22, 30))) * 0.01, atol=1e-12)
    assert clip.fps == 30.0  # 1 / 0.0333333 snapped


def test_bvh_auto_units_for_unknown_skeleton_asks_for_units(tmp_path):
    path = _write(tmp_path, _BVH.format(root_rotations="Zrotation Xrotation Yrotation", root_angles="0 0 0"))
    with pytest.raises(ValueError, match="units="):
        load_bvh(path)
    with pytest.raises(ValueError, match="units"):
        load_bvh(path, units=-1.0)


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
        load_bvh(path, units=1.0)
    assert f"{path}:{line}:" in str(err.value)


def test_missing_bvh_is_file_not_found(tmp_path):
    with pytest.raises(FileNotFoundError, match="nope.bvh"):
        load_bvh(tmp_path / "nope.bvh")
