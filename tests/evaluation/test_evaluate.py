"""occupose.evaluation.evaluate: the report and table formatting on hand-made scores, and one tiny
evaluation end to end (no_occlusion, 20 procedural frames, `ours`) through the command line."""

import csv
import math
from dataclasses import replace

import numpy as np
import pytest
from click.testing import CliRunner

from occupose.cli import main
from occupose.evaluation.evaluate import (
    RunResult, arm_points, evaluate, hidden_share, intervals_from_mask, mean_row, per_joint_table, render_recording,
    report_markdown, results_table, table_rows, write_results_csv,
)
from occupose.joints import JOINTS
from occupose.evaluation.errors import TableRow
from occupose.evaluation.matching import PersonScore, Score
from occupose.evaluation.pixels import arm_epsilons
from occupose.io.joint_table import read_tracks_csv
from occupose.io.recording import Recording

FRAMES = 20


def _row(mean_cm, fail=False, under10=50.0, coverage=100.0):
    return TableRow(mean_cm=mean_cm, std_cm=mean_cm / 4, under10=under10, under15=60.0, under20=70.0,
                    over20=30.0, fail=fail, frames=100, coverage=coverage)


def _run(scenario, method, seed, means, fails=None, fps=20.0, switches=0, joints=JOINTS):
    """A RunResult with one person per entry of ``means`` (cm)."""
    fails = fails or [False] * len(means)
    persons = tuple(PersonScore(track=k + 1, all_joints=_row(m, f), visible_joints=_row(m - 1.0, f),
                                per_joint_cm={j: m for j in joints}, identity_switches=switches)
                    for k, (m, f) in enumerate(zip(means, fails)))
    return RunResult(scenario, method, seed, Score(persons, (), switches * len(means)),
                     tuple(range(1, len(means) + 1)), np.full((100, len(means)), np.mean(means) / 100.0), fps,
                     {"grid": 1.0, "pose": 2.0, "total": 4.95, "startup": 0.5})


@pytest.fixture
def runs():
    return [
        _run("sit", "ours", 0, [8.0]), _run("sit", "ours", 1, [10.0]),
        _run("sit", "apf", 0, [20.0], fails=[True]), _run("sit", "apf", 1, [12.0]),
        _run("cross", "ours", 0, [7.0, 30.0], fps=10.0, switches=1), _run("cross", "apf", 0, [9.0, 6.0], fps=10.0),
    ]


# --------------------------------------------------------------------------- tables on hand-made scores


def test_mean_row_averages_each_number_and_fails_when_any_run_fails():
    row = mean_row([_row(8.0), _row(10.0, fail=True, under10=70.0), _row(math.nan, coverage=0.0)])
    assert row.mean_cm == pytest.approx(9.0)  # the run without estimates is left out
    assert row.std_cm == pytest.approx(2.25)
    assert row.under10 == pytest.approx(170.0 / 3)
    assert row.coverage == pytest.approx(200.0 / 3)
    assert row.fail is True and row.frames == 100
    assert mean_row([_row(8.0), _row(9.0)]).fail is False
    with pytest.raises(ValueError, match="at least one row"):
        mean_row([])


def test_table_rows_group_by_sequence_and_person(runs):
    rows = table_rows(runs)
    assert list(rows) == ["sit", "cross, person 1", "cross, person 2"]
    assert rows["sit"]["ours"].mean_cm == pytest.approx(9.0)
    assert rows["sit"]["apf"].mean_cm == pytest.approx(16.0) and rows["sit"]["apf"].fail
    assert rows["cross, person 2"]["ours"].mean_cm == pytest.approx(30.0)
    assert table_rows(runs, visible=True)["sit"]["ours"].mean_cm == pytest.approx(8.0)


def test_report_bolds_the_best_mean_per_sequence_and_names_failed_runs(runs, tmp_path):
    report = report_markdown(runs, [tmp_path / "error_sit.png"], tmp_path, jobs=2)
    lines = report.splitlines()
    table = lines[lines.index("## Table I: all joints") + 2:]
    assert table[0].startswith("| sequence | method | <10cm [%]")
    sit_ours, sit_apf = table[2], table[3]
    assert sit_ours.startswith("| sit | ours |") and "**9.00**" in sit_ours and "| ok |" in sit_ours
    assert sit_apf.startswith("|  | apf |") and "| 16.00 |" in sit_apf and "| FAIL |" in sit_apf
    assert "**6.00**" in table[7]  # cross, person 2: apf beats ours
    assert "- sit, apf: 1 of 2 runs (seeds 0)" in report
    assert "FAIL when any run FAILs" in report
    assert "![error_sit](error_sit.png)" in report
    # per-joint table: mean over scenarios, runs and people; speed: all runs pooled
    joints = per_joint_table(runs)
    assert joints["head"]["ours"] == pytest.approx(np.mean([8, 10, 7, 30]))
    assert "| head | 13.75 | **11.75** |" in report
    assert "| ours | 20.0 | 50.0 | 10.0 | 20.0 |" in report  # each run: 4.95 s over 99 frames after the first


def test_report_has_the_arm_error_of_runs_with_part_labels_only(runs):
    assert "## Arm error" not in report_markdown(runs)
    truth = np.full((100, 1), 0.05)

    def with_arms(run, centimetres):
        tracked = np.full((100, 1), centimetres / 100.0)
        tracked[:10] = np.nan  # frames without an estimate or arm points are left out
        return replace(run, arm_epsilon=tracked, truth_arm_epsilon=truth)

    sit = [with_arms(r, cm) for r, cm in zip(runs[:4], (6.0, 8.0, 9.0, 12.0))]
    report = report_markdown(sit + runs[4:])
    assert "| sit | **7.00** | 10.50 | 5.00 |" in report
    assert "| cross" not in report.split("## Arm error")[1].split("##")[0]
    rows = results_table(sit)
    assert [r["arm_eps_cm"] for r in rows] == pytest.approx([6.0, 8.0, 9.0, 12.0])
    assert [r["truth_arm_eps_cm"] for r in rows] == pytest.approx([5.0] * 4)


def test_per_joint_table_leaves_unreported_joints_out():
    upper = JOINTS[:9]
    joints = per_joint_table([_run("top", "part-based", 0, [5.0], joints=upper), _run("top", "ours", 0, [6.0])])
    assert joints["head"] == {"part-based": 5.0, "ours": 6.0}
    assert math.isnan(joints["left_knee"]["part-based"]) and joints["left_knee"]["ours"] == 6.0


def test_results_csv_has_one_row_per_scenario_method_run_and_person(runs, tmp_path):
    rows = results_table(runs)
    assert len(rows) == 4 + 2 * 2
    assert [(r["scenario"], r["method"], r["seed"], r["person"]) for r in rows[-4:]] == [
        ("cross", "ours", 0, 1), ("cross", "ours", 0, 2), ("cross", "apf", 0, 1), ("cross", "apf", 0, 2)]
    path = write_results_csv(tmp_path / "results.csv", runs)
    with path.open() as handle:
        read = list(csv.DictReader(handle))
    assert len(read) == 8
    first = read[0]
    for column in ("mean_cm", "std_cm", "under10", "under15", "under20", "over20", "fail", "visible_mean_cm",
                   "identity_switches", "fps", "seconds_grid", "seconds_pose", "seconds_total", "seconds_startup"):
        assert column in first
    assert float(first["mean_cm"]) == 8.0 and float(first["visible_mean_cm"]) == 7.0
    assert read[2]["fail"] == "1" and read[4]["identity_switches"] == "1"


def test_intervals_and_hidden_share():
    assert intervals_from_mask([0, 1, 1, 0, 1]) == [(1, 3), (4, 5)]
    assert intervals_from_mask(np.zeros(3, bool)) == []
    with pytest.raises(ValueError, match="shape"):
        intervals_from_mask(np.zeros((2, 2), bool))
    joints = np.zeros((2, 1, 15, 3))
    joints[1] = np.nan
    visible = np.zeros((2, 1, 15), bool)
    visible[0, 0, :5] = True
    share = hidden_share(joints, visible)
    assert share[0, 0] == pytest.approx(10 / 15) and np.isnan(share[1, 0])


def test_bad_names_and_counts_are_refused_before_any_work(tmp_path):
    with pytest.raises(ValueError, match="unknown scenario.*'dance'; valid names: no_occlusion, sit_behind_table"):
        evaluate("dance", out=tmp_path / "a")
    with pytest.raises(ValueError, match="unknown method.*'kalman'; valid names: ours, apf, ps, part-based"):
        evaluate(["no_occlusion"], ["ours", "kalman"], out=tmp_path / "a")
    with pytest.raises(ValueError, match="runs must be an integer >= 1, got 0"):
        evaluate("no_occlusion", "ours", 0, out=tmp_path / "a")
    with pytest.raises(ValueError, match="named twice"):
        evaluate("no_occlusion,no_occlusion", "ours", out=tmp_path / "a")
    assert not (tmp_path / "a").exists()
    result = CliRunner().invoke(main, ["evaluate", "--scenarios", "dance", "--out", str(tmp_path / "b")])
    assert result.exit_code != 0 and "valid names: no_occlusion" in result.output


# --------------------------------------------------------------------------- end to end


@pytest.fixture(scope="module")
def evaluated(tmp_path_factory):
    out = tmp_path_factory.mktemp("evaluate")
    result = CliRunner().invoke(main, ["evaluate", "--scenarios", "no_occlusion", "--methods", "ours", "--runs", "1",
                                       "--frames", str(FRAMES), "--procedural", "--jobs", "1", "--out", str(out)])
    assert result.exit_code == 0, result.output
    return out, result.output


def test_evaluate_writes_runs_results_report_and_plots(evaluated):
    out, output = evaluated
    assert "| no_occlusion | ours |" in output and str(out / "report.md") in output
    assert (out / "recordings" / "no_occlusion" / "recording.json").is_file()
    assert (out / "runs" / "no_occlusion" / "ours" / "0" / "tracks.csv").is_file()
    with (out / "results.csv").open() as handle:
        rows = list(csv.DictReader(handle))
    assert [(r["scenario"], r["method"], r["seed"], r["person"]) for r in rows] == [("no_occlusion", "ours", "0", "1")]
    assert 0 < float(rows[0]["mean_cm"]) < 20 and rows[0]["fail"] == "0" and float(rows[0]["fps"]) > 0
    # the arm error of the ground truth is about an arm's radius (4-5 cm) plus the hands beyond
    # the wrists; the track's is its own, from its tracks.csv and the recording's arm pixels
    truth_eps, eps = float(rows[0]["truth_arm_eps_cm"]), float(rows[0]["arm_eps_cm"])
    assert 3.0 < truth_eps < 7.0 and truth_eps < eps < truth_eps + 5.0
    rec = Recording(out / "recordings" / "no_occlusion")
    arms = arm_points(rec, rec.groundtruth().person_ids)
    (track,) = read_tracks_csv(out / "runs" / "no_occlusion" / "ours" / "0" / "tracks.csv", FRAMES).values()
    assert 100 * np.nanmean(arm_epsilons(arms[0], track[0])) == pytest.approx(eps, abs=1e-4)
    report = (out / "report.md").read_text()
    assert "| no_occlusion | ours |" in report and "**" in report
    assert f"| no_occlusion | {eps:.2f} | {truth_eps:.2f} |" in report
    for name in ("error_no_occlusion.png", "error_vs_time.png"):
        assert (out / name).stat().st_size > 10_000 and f"]({name})" in report


def test_evaluate_reuses_the_recording_and_runs_in_workers_as_in_process(evaluated):
    out, _ = evaluated
    recording = out / "recordings" / "no_occlusion" / "recording.json"
    stamp = recording.stat().st_mtime_ns
    in_process = (out / "runs" / "no_occlusion" / "ours" / "0" / "tracks.csv").read_text()
    seen = []
    result = evaluate("no_occlusion", "ours", 2, out=out, frames=FRAMES, procedural=True, jobs=2,
                      progress=lambda n, total: seen.append((n, total)))
    assert recording.stat().st_mtime_ns == stamp  # same settings: not rendered again
    assert sum(n for n, _ in seen) == 3 * FRAMES and {t for _, t in seen} == {3 * FRAMES}
    assert [(r.scenario, r.method, r.seed) for r in result.runs] == [("no_occlusion", "ours", 0), ("no_occlusion", "ours", 1)]
    assert (out / "runs" / "no_occlusion" / "ours" / "0" / "tracks.csv").read_text() == in_process


def test_a_recording_of_motion_the_scenario_no_longer_makes_is_rendered_again(tmp_path, monkeypatch):
    from occupose.synth import scenarios

    out = tmp_path / "no_occlusion"
    render_recording("no_occlusion", out, 3, procedural=True)
    stamp = (out / "recording.json").stat().st_mtime_ns
    render_recording("no_occlusion", out, 3, procedural=True)
    assert (out / "recording.json").stat().st_mtime_ns == stamp  # the same: kept
    build = scenarios.build_scenario

    def moved(*args, **kwargs):  # the same settings, the person 1 cm further along x
        built = build(*args, **kwargs)
        return replace(built, people=tuple(replace(p, joints=p.joints + [0.01, 0.0, 0.0]) for p in built.people))

    monkeypatch.setattr(scenarios, "build_scenario", moved)
    render_recording("no_occlusion", out, 3, procedural=True)
    assert (out / "recording.json").stat().st_mtime_ns != stamp
