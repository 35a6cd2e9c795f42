"""The warm-up before a run: every kernel the run calls compiled before its first frame,
once per machine and settings (occupose.warmup)."""

import json
import os
import subprocess
import sys
import textwrap

import numpy as np

from occupose.camera import camera_preset, look_at
from occupose.config import method_config
from occupose.warmup import marker_key, model_of, warm_up

FRONT = camera_preset("kinect_v1", world_from_camera=look_at((0.0, 0.0, 1.0), (0.0, 3.0, 1.0)))
CEILING = camera_preset("kinect_v1", world_from_camera=look_at((0.0, 0.0, 2.9), (0.0, 0.01, 0.0), up=(0, 1, 0)))


def test_the_body_model_is_the_trackers_choice():
    ours = method_config("ours")
    assert model_of(ours, [FRONT]) == "full"
    assert model_of(ours, [CEILING]) == "upper"
    assert model_of(ours, [FRONT, CEILING]) == "full"  # upper only when every camera looks down
    assert model_of(ours.with_values({"pose.model": "upper"}), [FRONT]) == "upper"


def test_the_marker_changes_with_the_code_it_chooses_not_with_sizes():
    ours = method_config("ours")
    key = marker_key(ours, "full")
    assert marker_key(ours.with_values({"pose.particles": 123}), "full") == key  # a size: same kernels
    assert marker_key(ours.with_values({"pose.likelihood": "points"}), "full") != key  # other kernels
    assert marker_key(ours, "upper") != key
    assert marker_key(method_config("apf"), "full") != key


def test_a_warm_up_runs_once_per_settings(tmp_path):
    told = []
    ours = method_config("ours")
    assert warm_up(ours, [FRONT], report=told.append, folder=tmp_path) is True
    assert len(told) == 1 and "compiling" in told[0]
    assert [p.name for p in tmp_path.iterdir()] == [marker_key(ours, "full")]
    assert warm_up(ours.with_values({"pose.particles": 123}), [FRONT], report=told.append, folder=tmp_path) is False
    assert len(told) == 1  # nothing said when nothing is done


def test_a_warm_up_with_measured_noise_measures_its_scenes_noise(tmp_path):
    """A warm-up with measured noise runs: its tracker measures the scene's noise on its
    first grid.noise_frames frames itself (every `occupose track` with
    ``--set grid.noise_model=measured`` failed in its warm-up before 94973bb)."""
    measured = method_config("ours").with_values({"grid.noise_model": "measured", "grid.noise_frames": 5})
    assert warm_up(measured, [FRONT], folder=tmp_path, load=True) is True


# In a process of its own, so that only its warm-up has called the kernels: after it, tracking
# recordings of other scenes (two people; legs hidden by a couch, which the occlusion test
# looks for with many candidate poses; a ceiling camera) adds no compiled
# specialisation to any kernel of the package.
_NOTHING_COMPILED_AFTER = textwrap.dedent("""
    import json, sys
    from occupose._numba import configure
    configure()
    import numba
    from occupose.synth.generate import frames
    from occupose.synth.scenarios import build_scenario
    from occupose.run import track_frames
    from occupose.tracker import Tracker
    from occupose.warmup import warm_up

    def signatures():
        found = {}
        for name, module in list(sys.modules.items()):
            if name.startswith("occupose"):
                for attr, value in vars(module).items():
                    if isinstance(value, numba.core.registry.CPUDispatcher):
                        found[f"{value.py_func.__module__}.{value.__name__}"] = len(value.signatures)
        return found

    out = {}
    for scene, count in (("two_people_crossing", 30), ("walk_behind_couch", 20), ("top_view_two_people", 20)):
        scenario = build_scenario(scene, use_mocap=False)
        rendered = list(frames(scenario, num_frames=count))  # the renderer's kernels before the count
        warm_up("ours", scenario.cameras, folder=sys.argv[1] + "/" + scene)
        before = signatures()
        tracker = Tracker(scenario.cameras, scenario.fps, "ours", seed=0)
        result = track_frames(tracker, rendered, count)
        after = signatures()
        out[scene] = {"tracks": len(result.tracks), "kernels": len(after),
                      "new": {k: v - before.get(k, 0) for k, v in after.items() if v > before.get(k, 0)}}
    print(json.dumps(out))
""")


def test_after_a_warm_up_tracking_compiles_nothing(tmp_path):
    done = subprocess.run([sys.executable, "-c", _NOTHING_COMPILED_AFTER, str(tmp_path)], capture_output=True,
                          text=True, env=os.environ | {"PYTHONHASHSEED": "0"}, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    out = json.loads(done.stdout.strip().splitlines()[-1])
    for scene, seen in out.items():
        assert seen["tracks"] >= 1, scene  # people were started and tracked, the pose stage ran
        assert seen["kernels"] > 20, scene  # the kernels were found
        assert seen["new"] == {}, f"{scene}: compiled during tracking {seen['new']}"


def test_a_warm_up_leaves_the_run_as_it_was(tmp_path):
    from occupose.run import track_recording
    from occupose.synth.generate import write_scenario
    from occupose.synth.scenarios import build_scenario

    rec = write_scenario(build_scenario("no_occlusion", use_mocap=False), tmp_path / "rec", num_frames=16)
    told = []
    cold = track_recording(rec, "ours", warm_up=told.append)
    plain = track_recording(rec, "ours")
    assert "warm_up" in cold.seconds and "warm_up" not in plain.seconds
    assert cold.tracks.keys() == plain.tracks.keys() == {1}
    for tid, (joints, visible) in plain.tracks.items():
        np.testing.assert_array_equal(cold.tracks[tid][0], joints)
        np.testing.assert_array_equal(cold.tracks[tid][1], visible)
