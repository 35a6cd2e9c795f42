"""occupose batch: many recordings, one folder each, as `occupose track` writes them;
resumable, failures reported while the others finish; locally and on a Dask cluster."""

from __future__ import annotations

import csv
import sys

import pytest
from click.testing import CliRunner

from occupose.batch import output_names, plan
from occupose.cli import main
from occupose.synth.generate import write_scenario
from occupose.synth.scenarios import build_scenario

FRAMES = 12


@pytest.fixture(scope="module")
def inputs(tmp_path_factory):
    """Two short recordings (one person walking; two people crossing) and a broken one."""
    root = tmp_path_factory.mktemp("batch-inputs")
    walk = write_scenario(build_scenario("no_occlusion", use_mocap=False), root / "walk", num_frames=FRAMES)
    two = write_scenario(build_scenario("two_people_crossing", use_mocap=False), root / "two", num_frames=FRAMES)
    broken = root / "broken"
    broken.mkdir()
    (broken / "recording.json").write_text("{ not json")
    return walk, two, broken


@pytest.fixture(scope="module")
def tracked(inputs, tmp_path_factory):
    """`occupose track` of each good input: {name: tracks.csv bytes}."""
    out = tmp_path_factory.mktemp("batch-tracked")
    runner = CliRunner()
    found = {}
    for rec in inputs[:2]:
        assert runner.invoke(main, ["track", str(rec), "--out", str(out / rec.name)]).exit_code == 0
        found[rec.name] = (out / rec.name / "tracks.csv").read_bytes()
    return found


def _table(path):
    with open(path, newline="") as handle:
        return {row["out"].rsplit("/", 1)[-1]: row for row in csv.DictReader(handle)}


def test_names_are_the_inputs_and_unique(tmp_path):
    (tmp_path / "a").mkdir()
    (tmp_path / "b").mkdir()
    (tmp_path / "b" / "a").mkdir()
    (tmp_path / "a.bag").write_bytes(b"")
    (tmp_path / "my run").mkdir()
    names = output_names([tmp_path / "a", tmp_path / "b" / "a", tmp_path / "a.bag", tmp_path / "my run"])
    assert names == ["a", "a-2", "a-3", "my_run"]
    with pytest.raises(ValueError, match="more than once"):
        plan([tmp_path / "a", tmp_path / "b" / ".." / "a"], tmp_path / "out", {})
    with pytest.raises(ValueError, match="no recordings"):
        plan([], tmp_path / "out", {})


def test_a_batch_tracks_each_as_track_does_reports_failures_and_resumes(inputs, tracked, tmp_path):
    out = tmp_path / "out"
    args = ["batch", *map(str, inputs), "--out", str(out), "--jobs", "2"]
    result = CliRunner().invoke(main, args)
    assert result.exit_code == 1, result.output  # one failed
    table = _table(out / "batch.csv")
    assert {k: v["status"] for k, v in table.items()} == {"walk": "done", "two": "done", "broken": "failed"}
    assert "recording.json" in table["broken"]["error"] and "JSON" in table["broken"]["error"]
    assert (table["walk"]["tracks"], table["two"]["tracks"]) == ("1", "2")
    assert table["walk"]["frames"] == table["two"]["frames"] == str(FRAMES)
    for name, expected in tracked.items():  # one worker process, one numba thread: the same tracks
        assert (out / name / "tracks.csv").read_bytes() == expected, name
    assert not (out / "broken").exists()  # nothing half-written
    assert "2 done, 0 skipped (done earlier), 1 failed" in result.output
    assert "broken" in result.output and "failed" in result.output

    stamps = {name: (out / name / "tracks.csv").stat().st_mtime_ns for name in tracked}
    again = CliRunner().invoke(main, args)
    assert again.exit_code == 1
    table = _table(out / "batch.csv")
    assert [table[n]["status"] for n in ("walk", "two", "broken")] == ["skipped", "skipped", "failed"]
    assert table["two"]["tracks"] == "2"  # from the earlier run's summary
    assert {name: (out / name / "tracks.csv").stat().st_mtime_ns for name in tracked} == stamps  # untouched

    redo = CliRunner().invoke(main, ["batch", str(inputs[0]), "--out", str(out), "--force"])
    assert redo.exit_code == 0, redo.output
    assert _table(out / "batch.csv")["walk"]["status"] == "done"
    assert (out / "walk" / "tracks.csv").stat().st_mtime_ns != stamps["walk"]
    assert (out / "walk" / "tracks.csv").read_bytes() == tracked["walk"]


def test_a_batch_on_a_dask_cluster_gives_the_same_tracks(inputs, tracked, tmp_path):
    distributed = pytest.importorskip("dask.distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                                  env={"NUMBA_NUM_THREADS": "1"}) as cluster:
        result = CliRunner().invoke(main, ["batch", *map(str, inputs[:2]), "--out", str(tmp_path / "out"),
                                           "--scheduler", cluster.scheduler_address])
    assert result.exit_code == 0, result.output
    table = _table(tmp_path / "out" / "batch.csv")
    assert {k: v["status"] for k, v in table.items()} == {"walk": "done", "two": "done"}
    for name, expected in tracked.items():
        assert (tmp_path / "out" / name / "tracks.csv").read_bytes() == expected, name


def test_the_scheduler_names_its_extra_and_excludes_jobs(inputs, tmp_path, monkeypatch):
    args = ["batch", str(inputs[0]), "--out", str(tmp_path / "out")]
    result = CliRunner().invoke(main, [*args, "--scheduler", "tcp://127.0.0.1:1", "--jobs", "2"])
    assert result.exit_code != 0 and "--jobs or --scheduler" in result.output
    monkeypatch.setitem(sys.modules, "dask.distributed", None)  # as if not installed
    result = CliRunner().invoke(main, [*args, "--scheduler", "tcp://127.0.0.1:1"])
    assert result.exit_code != 0 and "pip install 'occupose[dask]'" in result.output
