"""Tests of occupose.synth.catalogue: a named scenario rendered into a folder, the three
policies for a folder already there, the reusable render's record."""

import json
from pathlib import Path

import pytest

from occupose.io.recording import Recording
from occupose.synth import catalogue
from occupose.io.output import MANIFEST, OutputError
from occupose.synth.catalogue import RENDER_INFO, FramesOutOfRange, render_scenario

FRAMES = 3


def _files(folder):
    return {p.relative_to(folder): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def test_a_short_render_is_a_recording_and_is_reused(tmp_path):
    out = tmp_path / "rec"
    calls = []
    made = render_scenario("no_occlusion", out, frames=FRAMES, procedural=True, exists="reuse",
                           progress=lambda done, total: calls.append((done, total)))
    assert made.path == out and made.num_frames == FRAMES and not made.reused
    assert made.scenario.name == "no_occlusion" and made.scenario.motion_source == "procedural"
    assert calls == [(0, FRAMES)] + [(1, FRAMES)] * FRAMES  # the total first, then every frame
    rec = Recording(out)
    assert rec.num_frames == FRAMES and rec.groundtruth().joints.shape[:2] == (FRAMES, 1)
    info = json.loads((out / RENDER_INFO).read_text())
    assert info["scenario"] == "no_occlusion" and info["seed"] == 0 and info["frames"] == FRAMES
    assert set(info) == {"scenario", "seed", "frames", "motion_source", "events", "truth"}
    stamp = (out / "recording.json").stat().st_mtime_ns
    calls.clear()
    again = render_scenario("no_occlusion", out, frames=FRAMES, procedural=True, exists="reuse",
                            progress=lambda done, total: calls.append((done, total)))
    assert again.reused and again.num_frames == FRAMES
    assert (out / "recording.json").stat().st_mtime_ns == stamp  # the same arguments: kept
    assert calls == [(0, FRAMES), (FRAMES, FRAMES)]
    other = render_scenario("no_occlusion", out, frames=FRAMES - 1, procedural=True, exists="reuse")
    assert not other.reused and Recording(out).num_frames == FRAMES - 1  # other settings: rendered again


def test_every_policy_writes_the_same_recording(tmp_path):
    refused = render_scenario("no_occlusion", tmp_path / "a", frames=2, procedural=True, seed=1).path
    reused = render_scenario("no_occlusion", tmp_path / "b", frames=2, procedural=True, seed=1, exists="reuse").path
    a, b = _files(refused), _files(reused)
    assert RENDER_INFO not in {p.name for p in a}  # only "reuse" records itself
    del b[next(p for p in b if p.name == RENDER_INFO)]
    manifest_a, manifest_b = json.loads(a.pop(Path(MANIFEST))), json.loads(b.pop(Path(MANIFEST)))
    assert manifest_b["files"] == sorted([*manifest_a["files"], RENDER_INFO])  # every file it wrote
    assert a == b


def test_what_is_in_the_way_is_refused_and_kept(tmp_path):
    keep = tmp_path / "keep"
    keep.mkdir()
    (keep / "notes.txt").write_text("precious")
    with pytest.raises(OutputError, match=f"was not written by occupose \\(no {MANIFEST}\\)"):
        render_scenario("no_occlusion", keep, frames=2, procedural=True, exists="replace")
    with pytest.raises(OutputError, match="exists and is not empty"):
        render_scenario("no_occlusion", keep, frames=2, procedural=True)
    assert (keep / "notes.txt").read_text() == "precious" and len(list(keep.iterdir())) == 1
    afile = tmp_path / "a.txt"
    afile.write_text("x")
    with pytest.raises(OutputError, match="exists and is not a folder"):
        render_scenario("no_occlusion", afile, frames=2, procedural=True, exists="replace")
    # an earlier recording is replaced with "replace" only
    old = tmp_path / "old"
    render_scenario("no_occlusion", old, frames=2, procedural=True)
    with pytest.raises(OutputError, match="exists and is not empty"):
        render_scenario("no_occlusion", old, frames=3, procedural=True)
    assert render_scenario("no_occlusion", old, frames=3, procedural=True, exists="replace").num_frames == 3
    assert Recording(old).num_frames == 3


def test_input_is_checked_before_the_folder_is_touched(tmp_path, monkeypatch):
    keep = tmp_path / "keep"
    keep.mkdir()
    (keep / "notes.txt").write_text("precious")
    with pytest.raises(ValueError, match="unknown scenario 'dance'"):
        render_scenario("dance", keep, exists="reuse")
    with pytest.raises(ValueError, match="unknown camera preset 'webcam'"):
        render_scenario("no_occlusion", keep, sensor="webcam", exists="reuse")
    with pytest.raises(FramesOutOfRange, match=r"frames must be in 1\.\.390 for no_occlusion, got 9999") as error:
        render_scenario("no_occlusion", keep, frames=9999, procedural=True, exists="reuse")
    assert error.value.available == 390
    with pytest.raises(ValueError, match="exists must be one of refuse, replace, reuse"):
        render_scenario("no_occlusion", keep, exists="overwrite")
    assert (keep / "notes.txt").read_text() == "precious"
    # clip_frames renders at most the scenario's frames (the renderer replaced: 300 frames are slow)
    written = []
    monkeypatch.setattr(catalogue, "write_scenario", lambda scenario, out, seed, num_frames, progress: written.append(
        (scenario.name, out, seed, num_frames)))
    clipped = render_scenario("top_view_two_people", tmp_path / "clip", frames=9999, procedural=True, clip_frames=True)
    assert clipped.num_frames == clipped.scenario.num_frames == 300
    assert [(name, seed, frames) for name, _, seed, frames in written] == [("top_view_two_people", 0, 300)]
    assert (tmp_path / "clip").is_dir()  # where the folder it wrote in was moved
