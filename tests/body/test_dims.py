"""occupose.body.dims: the default body, scaling, and the dimensions measured on joints
(procedural and real mocap), which drive the generator's skeleton to the same bone lengths."""

import numpy as np
import pytest

from occupose.body.dims import BodyDims, bone_lengths_from_dims, dims_from_joints
from occupose.io.mocap import bone_lengths
from occupose.joints import BONES, JOINT_INDEX as J
from occupose.synth import motion as m


def test_default_body_is_an_average_adult():
    dims = BodyDims()
    assert dims.height == pytest.approx(1.72)
    j = m.joints_from_procedural(m.stance())
    assert dims.hip_height == pytest.approx(0.92)
    assert j[J["left_hip"], 2] == pytest.approx(dims.hip_height, abs=1e-3)  # the knees barely bent
    assert j.shape == (15, 3) and j.dtype == np.float64
    assert j[J["left_ankle"], 2] == pytest.approx(0.08, abs=1e-9)
    assert j[J["pelvis"], 2] == pytest.approx(0.92, abs=0.005)
    assert j[J["head"], 2] - j[J["neck"], 2] == pytest.approx(0.11)
    assert j[J["head"], 2] + dims.neck_head == pytest.approx(1.72, abs=0.005)  # top of the head
    # pelvis is the midpoint of the hips
    np.testing.assert_allclose(j[J["pelvis"]], 0.5 * (j[J["left_hip"]] + j[J["right_hip"]]), atol=1e-12)


def test_scaled_body_keeps_proportions():
    small = BodyDims().scaled(1.55)
    assert small.height == pytest.approx(1.55)
    assert small.thigh / small.shin == pytest.approx(BodyDims().thigh / BodyDims().shin)
    with pytest.raises(ValueError, match="height"):
        BodyDims().scaled(17.2)
    with pytest.raises(ValueError, match="thigh"):
        BodyDims(thigh=-0.4)


def test_dims_from_joints_recovers_the_body():
    dims = BodyDims().scaled(1.85)
    joints = m.MotionBuilder(dims=dims).walk([(3.0, 0.0)]).joints()
    found = dims_from_joints(joints)
    for name in ("pelvis_width", "spine", "neck_head", "shoulder_width", "shoulder_drop",
                 "upper_arm", "forearm", "thigh", "shin", "ankle_height", "seat_clearance"):
        assert getattr(found, name) == pytest.approx(getattr(dims, name), abs=1e-6), name
    with pytest.raises(ValueError, match=r"\(T, 15, 3\)"):
        dims_from_joints(joints[0])


@pytest.mark.shared
def test_dims_from_a_real_clip_drive_the_procedural_skeleton(mocap):
    from occupose.io import mocap as mocap_io

    path = mocap / "bandai1" / "dataset-1_walk_normal_001.bvh"
    if not path.exists():
        pytest.skip(f"{path.name} not in the shared data")
    clip = mocap_io.canonical_from_clip(mocap_io.load_clip(path))
    dims = dims_from_joints(clip)
    assert 1.4 < dims.height < 2.0
    assert 0.2 < dims.upper_arm < 0.35 and 0.35 < dims.thigh < 0.5
    np.testing.assert_allclose(np.median(bone_lengths(clip)[:, [3, 9, 10]], axis=0),
                               [dims.upper_arm, dims.thigh, dims.shin], atol=0.01)
    joints = m.MotionBuilder(dims=dims).walk([(2.0, 0.0)]).sit_down(0.45).joints()
    np.testing.assert_allclose(bone_lengths(joints), np.broadcast_to(bone_lengths_from_dims(dims),
                                                                     (len(joints), len(BONES))), atol=1e-6)
