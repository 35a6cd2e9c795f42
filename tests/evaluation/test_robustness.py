"""occupose.evaluation.robustness on hand-made tracks, and one tiny run of the robustness benchmark."""

import json
import math

import numpy as np
import pytest

from occupose.camera import Camera, look_at
from occupose.evaluation.robustness import (
    condition_keys,
    recording_conditions,
    run_from_dict,
    score_run,
    summarise,
    within_share,
)

FPS = 10.0
T = 40


def _walker(y: float) -> np.ndarray:
    """(T, 15, 3): a person walking along x at ``y``, joints spread in z, metres."""
    joints = np.zeros((T, 15, 3))
    joints[..., 0] = 0.05 * np.arange(T)[:, None]
    joints[..., 1] = y
    joints[..., 2] = np.linspace(0.1, 1.7, 15)
    return joints


def test_within_share_counts_visible_joints_within_ten_centimetres():
    gt = _walker(0.0)[:4]
    est = gt.copy()
    est[:, :5, 0] += 0.05   # 20 joints off by 5 cm: within
    est[:, 5:8, 0] += 0.15  # 12 off by 15 cm: not within
    est[3] = np.nan         # frame 3 not estimated: its 15 joints are not within
    visible = np.ones((4, 15), bool)
    visible[:, 14] = False  # 4 hidden joints do not count
    # counted: 56 joints; within: frames 0-2, joints 0-4 and 8-13 = 3 * 11 = 33
    assert within_share(gt, visible, est) == pytest.approx(100.0 * 33 / 56)
    assert math.isnan(within_share(gt, np.zeros((4, 15), bool), est))


def test_score_run_counts_switches_lasting_tracks_and_a_missed_person():
    gt = np.stack([_walker(0.0), _walker(2.0)], axis=1)  # (T, 2, 15, 3)
    visible = np.ones(gt.shape[:3], bool)
    first = np.arange(T)[:, None, None] < T // 2
    swapped_a = np.where(first, gt[:, 0], gt[:, 1]) + 0.02  # follows person 0, then person 1
    swapped_b = np.where(first, gt[:, 1], gt[:, 0]) + 0.02
    ghost = np.full((T, 15, 3), np.nan)
    ghost[:5] = 9.0  # 5 frames: shorter than MIN_PRESENCE_S at 10 frames/s
    run = score_run("scene", 3, {"view": "front"}, gt, visible, {1: swapped_a, 2: swapped_b, 3: ghost}, FPS)
    assert (run.people, run.tracks, run.right_tracks) == (2, 2, True)
    assert [p.switches for p in run.persons] == [1, 1] and run.switches == 2
    for person in run.persons:  # each track is right half the time, 2 m off the other half
        assert person.coverage == 100.0 and person.fail
        assert person.within10 == pytest.approx(50.0) and person.under20 == pytest.approx(50.0)
    alone = score_run("scene", 0, {}, gt, visible, {1: gt[:, 0] + 0.03}, FPS)
    assert alone.tracks == 1 and not alone.right_tracks
    found, missed = alone.persons
    assert found.mean_cm == pytest.approx(100 * 0.03 * math.sqrt(3)) and found.within10 == 100.0
    assert missed.fail and missed.coverage == 0.0 and missed.within10 == 0.0 and math.isnan(missed.mean_cm)
    # where the FAILs trip: the missed person at the end of the 1 s grace period, wholly
    # without an estimate; a found person has no FAIL to place
    assert (missed.fail_frame, missed.visible_at_fail, missed.missed_before_fail) == (10, 15, 1.0)
    assert found.fail_frame is found.visible_at_fail is found.missed_before_fail is None
    late = gt[:, 0] + 0.03
    late[25:, :, 0] += 0.5  # 50 cm off along x from frame 25, while only 4 joints show
    partly = visible.copy()
    partly[25:, 0, 4:] = False
    drifted = score_run("scene", 0, {}, gt, partly, {1: late}, FPS).persons[0]
    # frames of 5.2 cm and of 53.2 cm (0.53 along x, 0.03 across): the 20-frame window's mean
    # passes 25 cm with n of the latter once 1.04 + 0.480 n > 5 m, n = 9: at frame 33
    assert (drifted.fail_frame, drifted.visible_at_fail, drifted.missed_before_fail) == (33, 4, 0.0)
    text = json.dumps(alone.as_dict())
    assert json.dumps(run_from_dict(json.loads(text)).as_dict()) == text  # NaN != NaN: compared as JSON
    unseen = visible.copy()
    unseen[:, 1] = False  # the second person is never in the sensor's sight: no person of the run
    hidden = score_run("scene", 0, {}, gt, unseen, {1: gt[:, 0] + 0.03}, FPS)
    assert hidden.people == 1 and hidden.right_tracks and [p.person for p in hidden.persons] == [0]


def test_summarise_buckets_runs_by_condition():
    gt = _walker(0.0)[:, None]
    visible = np.ones(gt.shape[:3], bool)
    runs = [score_run(f"s{k}", 0, {"view": view}, gt, visible, {1: gt[:, 0] + offset}, FPS)
            for k, (view, offset) in enumerate([("front", 0.01), ("front", 0.05), ("top", 0.5)])]
    buckets = summarise(runs, "view")
    assert list(buckets) == ["front", "top"]
    front, top = buckets["front"], buckets["top"]
    assert front["runs"] == 2 and front["mean_cm"] == pytest.approx(100 * 0.03 * math.sqrt(3))
    assert front["fail_rate"] == 0.0 and front["within10"] == 100.0 and math.isnan(front["switch_free"])
    assert top["fail_rate"] == 100.0 and top["under20"] == 0.0 and top["within10"] == 0.0
    overall = summarise(runs)["all"]
    assert overall["person_runs"] == 3 and overall["median_cm"] == pytest.approx(100 * 0.05 * math.sqrt(3))
    assert overall["fail_rate"] == pytest.approx(100 / 3) and overall["right_tracks"] == 100.0
    assert list(summarise(runs, "furniture")) == ["n/a"]


def test_numeric_conditions_are_binned_and_lists_are_no_condition():
    gt = _walker(0.0)[:, None]
    visible = np.ones(gt.shape[:3], bool)
    heights = [0.9, 2.5, 1.2, 1.9, 1.5, 2.2]
    runs = [score_run(f"s{k}", 0, {"camera_height_m": h, "focal_scale": [1.0, 1.01], "people": 1}, gt, visible,
                      {1: gt[:, 0] + 0.01 * k}, FPS) for k, h in enumerate(heights)]
    buckets = summarise(runs, "camera_height_m")
    assert list(buckets) == ["0.9..1.4", "1.4..2", "2..2.5"]  # terciles, in increasing order
    assert [b["runs"] for b in buckets.values()] == [2, 2, 2]
    assert buckets["0.9..1.4"]["mean_cm"] == pytest.approx(100 * 0.01 * (0 + 2) / 2 * math.sqrt(3))
    assert list(summarise(runs, "people")) == ["1"]  # few values: one bucket each
    assert condition_keys(runs) == ["camera_height_m", "people"]


def test_recording_conditions_from_the_file_or_from_the_cameras(tmp_path):
    front = Camera("f", 64, 48, 50.0, 50.0, 31.5, 23.5, 0.001, look_at(eye=(0, -3, 1.2), target=(0, 0, 1.0)))
    ceiling = Camera("c", 64, 48, 50.0, 50.0, 31.5, 23.5, 0.001, look_at(eye=(0, 0, 3.0), target=(0, 0.01, 0.0)))
    assert recording_conditions(tmp_path, [front], 1) == {"view": "front", "people": 1}
    assert recording_conditions(tmp_path, [front, ceiling], 2) == {"view": "top", "people": 2}
    (tmp_path / "render.json").write_text(json.dumps({"conditions": {"view": "top", "furniture": "shelf"}}))
    assert recording_conditions(tmp_path, [front], 1) == {"view": "top", "furniture": "shelf"}


def test_a_tiny_benchmark_run_scores_a_rendered_scene(tmp_path):
    from benchmarks.bench_robustness import CURRENT, benchmark, scene_names, tables, write

    assert scene_names("a,random:2") == ["a", "random-0", "random-1"]
    with pytest.raises(ValueError, match="positive count"):
        scene_names("random:0")
    results = benchmark(["no_occlusion"], seeds=1, frames=20, out=tmp_path, procedural=True, jobs=1,
                        variants=["pose.particles=50"])
    assert list(results) == [CURRENT, "pose.particles=50"]
    summary = json.loads((tmp_path / "runs" / "set-pose.particles=50" / "no_occlusion" / "0" / "summary.json").read_text())
    assert summary["config"]["pose"]["particles"] == 50
    (run,) = results[CURRENT]
    assert run.conditions == {"view": "front", "people": 1} and run.people == 1
    (person,) = run.persons
    assert (tmp_path / "runs" / CURRENT / "no_occlusion" / "0" / "tracks.csv").is_file()
    assert 0.0 <= person.coverage <= 100.0 and 0.0 <= person.within10 <= 100.0
    markdown = write(results, tmp_path, "note").read_text()
    assert "#### by view" in markdown and "| front | current | 1 | 1 |" in markdown
    assert json.loads((tmp_path / "robustness.json").read_text())[CURRENT][0]["scene"] == "no_occlusion"


def test_the_fails_table_places_each_fail_and_counts_the_hidden_and_the_missed():
    from benchmarks.bench_robustness import fails_table
    from occupose.evaluation.robustness import PersonRun, Run

    def person(index, fail, frame=None, shown=None, missed=None):
        return PersonRun("s", 0, index, 20.0, 50.0, 40.0, 90.0, fail, 0, frame, shown, missed)

    runs = [Run("s", 0, {}, 3, 3, (person(0, True, 30, 3, 1.0), person(1, True, 97, 12, 0.2), person(2, False)))]
    text = fails_table({"current": runs})
    assert "current: 2 FAILs, 1 with at most 9 of 15 joints visible where they trip, 1 without an estimate" in text
    assert "| current | s | 0 | 0 | 20.0 | 30 | 3 | 100 |" in text
    assert "| current | s | 0 | 1 | 20.0 | 97 | 12 | 20 |" in text
    assert sum(line.startswith("| current |") for line in text.splitlines()) == 2  # not the person who passed
