"""occupose.evaluation.report: the tables, results.csv and the report on hand-made rows and runs."""

import csv
import math
from dataclasses import replace

import numpy as np
import pytest

from occupose.evaluation.errors import TableRow
from occupose.evaluation.report import RunResult
from occupose.evaluation.matching import PersonScore, Score
from occupose.evaluation.report import (
    hidden_share,
    intervals_from_mask,
    markdown_table,
    mean_row,
    number_cell,
    per_joint_table,
    report_markdown,
    results_table,
    table_i_cells,
    table_i_markdown,
    table_rows,
    write_results_csv,
)
from occupose.joints import JOINTS


# --------------------------------------------------------------------------- tables


def _row(**changes):
    values = dict(mean_cm=12.0, std_cm=5.0, under10=30.0, under15=60.0, under20=80.0,
                  over20=20.0, fail=False, frames=100, coverage=100.0)
    values.update(changes)
    return TableRow(**values)


def test_markdown_table_rule_follows_the_alignment():
    assert markdown_table(["a", "b", "c"], [["x", "1", "2"]], text_columns=1) == (
        "| a | b | c |\n|---|---:|---:|\n| x | 1 | 2 |")
    assert markdown_table(["a", "b"], [], text_columns=2) == "| a | b |\n|---|---|"
    assert markdown_table(["a", "b"], [["x", "y"]]).splitlines()[1] == "|---|---|"  # no alignment
    with pytest.raises(ValueError, match=r"a row of 2 columns \['a', 'b'\] has 1 cells"):
        markdown_table(["a", "b"], [["x"]])


def test_table_i_cells_and_the_one_line_summary():
    assert table_i_cells(_row()) == ["30.00", "60.00", "80.00", "20.00", "12.00", "5.00", "ok", "100.00"]
    assert table_i_cells(_row(mean_cm=math.nan, fail=True))[4:7] == ["n/a", "5.00", "FAIL"]
    assert number_cell(math.nan) == "n/a" and number_cell(2.345, 1) == "2.3"
    assert "avg 12.00 cm" in _row().format() and "ok" in _row().format()


def test_table_i_markdown_bolds_best_per_group():
    groups = {
        "Seq1": {"OUR": _row(mean_cm=10.0, under10=50.0), "APF": _row(mean_cm=15.0, under10=50.0, std_cm=4.0)},
        "Seq2": {"OUR": _row(over20=math.nan)},
    }
    lines = table_i_markdown(groups).splitlines()
    assert lines[0].startswith("| sequence | method | <10cm [%]")
    our, apf, seq2 = (line.split(" | ") for line in lines[2:5])
    assert our[0] == "| Seq1" and apf[0] == "| " and seq2[0] == "| Seq2"
    assert our[2] == "**50.00**" and apf[2] == "**50.00**"  # tie: both bold
    assert our[6] == "**10.00**" and apf[6] == "15.00"  # lower mean is better
    assert our[7] == "5.00" and apf[7] == "**4.00**"
    assert our[8] == "ok"  # status not ranked
    assert seq2[5] == "n/a" and seq2[6] == "**12.00**"


# --------------------------------------------------------------------------- runs


def _mean_row(mean_cm, fail=False, under10=50.0, coverage=100.0):
    """A TableRow of mean ``mean_cm`` (cm) and std a quarter of it."""
    return TableRow(mean_cm=mean_cm, std_cm=mean_cm / 4, under10=under10, under15=60.0, under20=70.0,
                    over20=30.0, fail=fail, frames=100, coverage=coverage)


def _run(scenario, method, seed, means, fails=None, fps=20.0, switches=0, joints=JOINTS):
    """A RunResult with one person per entry of ``means`` (cm)."""
    fails = fails or [False] * len(means)
    persons = tuple(PersonScore(track=k + 1, all_joints=_mean_row(m, f), visible_joints=_mean_row(m - 1.0, f),
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




def test_mean_row_averages_each_number_and_fails_when_any_run_fails():
    row = mean_row([_mean_row(8.0), _mean_row(10.0, fail=True, under10=70.0), _mean_row(math.nan, coverage=0.0)])
    assert row.mean_cm == pytest.approx(9.0)  # the run without estimates is left out
    assert row.std_cm == pytest.approx(2.25)
    assert row.under10 == pytest.approx(170.0 / 3)
    assert row.coverage == pytest.approx(200.0 / 3)
    assert row.fail is True and row.frames == 100
    assert mean_row([_mean_row(8.0), _mean_row(9.0)]).fail is False
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


def test_plots_use_the_figure_api_only(tmp_path, monkeypatch):
    import sys

    import matplotlib

    from occupose.camera import Camera
    from occupose.evaluation.report import write_plots
    from occupose.io.recording import RecordingWriter

    joints = np.zeros((100, 1, 15, 3))
    joints[..., 2] = np.linspace(0.1, 1.7, 15)
    visible = np.ones((100, 1, 15), bool)
    visible[30:60, 0, :12] = False  # mostly hidden for a second
    with RecordingWriter(tmp_path / "tiny", [Camera("cam0", 8, 6, 5.0, 5.0, 3.5, 2.5)], fps=30.0) as writer:
        for _ in range(100):
            writer.write_frame({"cam0": np.zeros((6, 8), np.uint16)})
        writer.write_groundtruth(joints, visible, [1])
    monkeypatch.setitem(sys.modules, "matplotlib.pyplot", None)  # importing pyplot now fails
    monkeypatch.setattr(matplotlib, "use", lambda *args, **kwargs: pytest.fail("matplotlib.use called"))
    runs = [_run("tiny", "ours", seed, [8.0 + seed]) for seed in range(2)] + [_run("tiny", "apf", 0, [12.0])]
    paths = write_plots(runs, tmp_path, {"tiny": tmp_path / "tiny"}, {"tiny": {"sit": (10, 40)}})
    assert paths == [tmp_path / "error_tiny.png", tmp_path / "error_vs_time.png"]
    assert all(path.stat().st_size > 10_000 for path in paths)
