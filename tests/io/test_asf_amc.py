"""Tests of occupose.io.asf_amc: a tiny hand-written ASF/AMC pair, hand-computed positions,
errors that name the file and line."""

import numpy as np
import pytest

from occupose.io.asf_amc import load_asf_amc
from occupose.io.mocap import load_clip


def _zup(p):
    """y-up file coordinates -> z-up world: (x, y, z) -> (x, -z, y)."""
    x, y, z = p
    return (x, -z, y)


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
    clip = load_asf_amc(asf, amc, units=1.0)
    assert clip.names == ("root", "bone") and clip.source == "asf" and clip.fps == 120.0
    # Frame 1: end = (1,2,3) + 2 (1,0,0).
    # Frame 2: C = Rz90, M = Rx90, C M C^-1 = rotation of 90 deg about C x = y: (2,0,0) -> (0,0,-2).
    # Frame 3: root Rz90 turns (2,0,0) into (0,2,0).
    expected = [_zup((3, 2, 3)), _zup((1, 2, 1)), _zup((0, 2, 0))]
    np.testing.assert_allclose(clip.positions[:, 1], expected, atol=1e-12)
    # units="auto" reads ':units length 0.5': 1 unit = 0.0254 / 0.5 m.
    auto = load_asf_amc(asf, amc)
    np.testing.assert_allclose(auto.positions, clip.positions * 0.0254 / 0.5, atol=1e-12)
    # load_clip finds the ASF from the AMC's subject prefix.
    np.testing.assert_allclose(load_clip(amc, units=1.0).positions, clip.positions)


def test_malformed_amc_names_file_and_line(tmp_path):
    asf, amc = tmp_path / "s.asf", tmp_path / "s_01.amc"
    asf.write_text(_ASF)
    amc.write_text(_AMC.replace("bone 90", "bone 90 5"))
    with pytest.raises(ValueError, match=f"{amc}:8: malformed AMC: bone 'bone' has 1 dof"):
        load_asf_amc(asf, amc)
