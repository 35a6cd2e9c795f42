"""The README is the users' entry point: its Python example runs as written, its quick start is the two commands."""

import json
import os
import re
from pathlib import Path

import numpy as np

from occupose.io.joint_table import read_tracks_csv
from occupose.synth.catalogue import render_scenario

README = Path(__file__).resolve().parents[1] / "README.md"


def test_the_readme_python_example_runs_on_the_demo_recording(tmp_path, monkeypatch, capsys):
    """The example, run on the first 75 frames of the recording `make demo` writes (a person
    walks in from the image's edge at frame 38): it prints the track and writes the run."""
    code = re.search(r"```python\n(.*?)```", README.read_text(), re.S).group(1)
    assert len(code.strip().splitlines()) <= 12
    render_scenario("sit_behind_table", tmp_path / "demo-output" / "sit_behind_table", frames=75, procedural=True)
    monkeypatch.chdir(tmp_path)
    exec(compile(code, str(README), "exec"), {})
    printed = capsys.readouterr().out
    assert re.fullmatch(r"track 1: \d+ frames, pelvis first at \[[-\d. ]+\]\n", printed), printed
    summary = json.loads((tmp_path / "my-run" / "summary.json").read_text())
    assert summary["method"] == "ours" and summary["config"]["start"]["look_back_s"] == 0.5
    assert summary["people"] == 1 and summary["frames"] == 75
    tracks = read_tracks_csv(tmp_path / "my-run" / "tracks.csv", 75)
    assert list(tracks) == [1]
    assert np.flatnonzero(np.isfinite(tracks[1][0][:, 0, 0]))[0] < 63  # tracked back before its start at frame 63


def test_the_quick_start_is_the_two_commands_and_the_readme_stays_short():
    text = README.read_text()
    quick = re.search(r"## Quick start\n\n```\n(.*?)```", text, re.S).group(1)
    assert quick.split("\n")[:2] == ["make demo", "make test"]
    assert len(text.splitlines()) <= 150
    for link in re.findall(r"\]\((docs/[^)#]+)", text):
        assert (README.parent / link).exists(), link
    assert os.path.exists(README.parent / "Makefile")
