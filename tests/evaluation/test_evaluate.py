"""occupose.evaluation.evaluate: its checks, and one tiny evaluation end to end (no_occlusion, 20
procedural frames, `ours`) through the command line."""

import csv
from dataclasses import replace

import numpy as np
import pytest
from click.testing import CliRunner

from occupose.cli import main
from occupose.evaluation.evaluate import arm_points, evaluate, render_recording
from occupose.evaluation.pixels import arm_epsilons
from occupose.io.joint_table import read_tracks_csv
from occupose.io.recording import Recording

FRAMES = 20


def test_the_package_exports_its_public_names_and_keeps_evaluate_a_module():
    import types

    import occupose.evaluation as evaluation
    from occupose.evaluation.matching import score

    assert set(evaluation.__all__) <= set(dir(evaluation)) and evaluation.score is score
    assert isinstance(evaluation.evaluate, types.ModuleType) and evaluation.evaluate.evaluate is evaluate


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
                      progress=lambda n, total: seen.append((n, total)), force=True)
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
