"""Shared test fixtures. Tests that need ../shared/data are marked ``shared`` and skip without it."""

from occupose._numba import configure

configure()  # before numba is imported: compiled kernels cached across test runs

import numpy as np  # noqa: E402
import pytest  # noqa: E402

from occupose.paths import mocap_dir  # noqa: E402


@pytest.fixture
def rng():
    return np.random.default_rng(12345)


@pytest.fixture
def mocap():
    """Path of the shared mocap folder; skips the test when the shared data is absent."""
    path = mocap_dir()
    if path is None:
        pytest.skip("shared mocap data (../shared/data/mocap or OCCUPOSE_DATA) not present")
    return path


@pytest.fixture
def small_camera():
    """A 160 x 120 camera 3 m in front of the origin (at y = -3), 1.2 m high, looking at it."""
    from occupose.camera import Camera, look_at

    return Camera("cam", 160, 120, 120.0, 120.0, 79.5, 59.5, 0.001,
                  look_at(eye=(0.0, -3.0, 1.2), target=(0.0, 0.0, 1.0)))


@pytest.fixture(scope="session")
def walk():
    """The first 60 frames of no_occlusion (procedural motion): the scenario and its frames."""
    from occupose.synth.generate import frames
    from occupose.synth.scenarios import build_scenario

    scenario = build_scenario("no_occlusion", use_mocap=False)
    return scenario, list(frames(scenario, seed=0, num_frames=60))


@pytest.fixture
def tracking(walk):
    """(a tracker that has tracked the walk's first 12 frames (person 1), the 12th frame's depths)."""
    from occupose.tracker import Tracker

    scenario, rendered = walk
    tracker = Tracker(scenario.cameras, scenario.fps, "ours", seed=0)
    for f in rendered[:12]:
        out = tracker.update(f.depth)
    assert list(out.estimates) == [1]
    return tracker, rendered[11].depth


@pytest.fixture
def standing_skeleton():
    """(15, 3) a standing canonical skeleton facing +y (its left side at smaller x), metres, z up."""
    from occupose.joints import JOINTS

    p = {
        "head": (0, 0, 1.60), "neck": (0, 0, 1.45), "pelvis": (0, 0, 0.95),
        "left_shoulder": (-0.18, 0, 1.42), "left_elbow": (-0.20, 0, 1.12), "left_wrist": (-0.21, 0, 0.86),
        "right_shoulder": (0.18, 0, 1.42), "right_elbow": (0.20, 0, 1.12), "right_wrist": (0.21, 0, 0.86),
        "left_hip": (-0.09, 0, 0.95), "left_knee": (-0.10, 0, 0.52), "left_ankle": (-0.10, 0, 0.08),
        "right_hip": (0.09, 0, 0.95), "right_knee": (0.10, 0, 0.52), "right_ankle": (0.10, 0, 0.08),
    }
    return np.array([p[name] for name in JOINTS], dtype=np.float64)
