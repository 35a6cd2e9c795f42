"""Outputs under bad, careless and hostile conditions (issue 26, the rows of
reviews/bad-inputs-931038f.md about outputs): every command refuses what is in the way
with a clear message and a non-zero exit, reports OS errors with the path, is stopped by
Ctrl-C or SIGTERM with status 130 or 143, and leaves every file there before unchanged;
``--force`` replaces only what occupose wrote.

Each case builds its situation in a folder of its own from a tiny recording (3 frames)
and an earlier run made once for the module, and compares that folder's files (SHA-256)
before and after. Interruptions are real signals sent to this process from the progress
callback; the full disk is a real OS limit on the file size (RLIMIT_FSIZE), as root can
neither mount a small file system nor make a folder read-only.
"""

import os
import resource
import shutil
import signal
from pathlib import Path

import pytest
from click.testing import CliRunner
from PIL import Image

from occupose import cli
from occupose.cli import main
from occupose.io.joint_table import read_tracks_csv
from occupose.io.output import MANIFEST, OutputError, is_occupose_picture, read_manifest
from occupose.io.recording import Recording
from occupose.run import TrackingResult, write_run
from occupose.viz import show_frame
from occupose.testing import folder_snapshot

FRAMES = 3


def _invoke(args):
    return CliRunner().invoke(main, [str(a) for a in args])


@pytest.fixture(scope="module")
def made(tmp_path_factory):
    """(a 3-frame recording written by ``occupose synth``, an earlier run of it by ``occupose track``)."""
    root = tmp_path_factory.mktemp("made")
    result = _invoke(["synth", "no_occlusion", root / "rec", "--frames", FRAMES, "--procedural"])
    assert result.exit_code == 0, result.output
    result = _invoke(["track", root / "rec", "--out", root / "run"])
    assert result.exit_code == 0, result.output
    return root / "rec", root / "run"


@pytest.fixture
def place(tmp_path, made):
    """A folder of the case's own, with copies of the recording (``rec``) and the run (``run``)."""
    rec, run = made
    shutil.copytree(rec, tmp_path / "rec", symlinks=True)
    shutil.copytree(run, tmp_path / "run", symlinks=True)
    return tmp_path


def _user_png(path: Path) -> Path:
    Image.new("RGB", (8, 8), (200, 10, 10)).save(path)
    return path


def _long_name(place: Path) -> Path:
    return place / ("n" * 300)


def _file(place: Path, name: str = "afile") -> Path:
    (place / name).write_text("the user's\n")
    return place / name


def _with_notes(folder: Path, name: str = "notes.txt") -> Path:
    (folder / name).write_text("the user's notes\n")
    return folder


def _user_folder(place: Path) -> Path:
    folder = place / "mine"
    (folder / "summary.json").mkdir(parents=True)  # a folder where a run writes a file (row 105)
    return folder


def _notes_folder(place: Path) -> Path:
    (place / "notes").mkdir()
    return _with_notes(place / "notes")


def _cut_frame(place: Path) -> Path:
    """The recording with its last depth frame cut short (a run that fails at the end)."""
    frame = place / "rec" / "front" / "depth" / f"{FRAMES - 1:06d}.png"
    frame.write_bytes(frame.read_bytes()[:200])
    return place / "rec"


# Each refused case: (row, arguments built in the case's folder, expected exit status, words of the message).
REFUSED = [
    ("97 --out = the input recording", lambda p: ["track", p / "rec", "--out", p / "rec"], 1,
     "is inside the input recording"),
    ("97 --out inside the input recording", lambda p: ["track", p / "rec", "--out", p / "rec" / "front" / "o"], 1,
     "is inside the input recording"),
    ("97 --out holding the input recording", lambda p: ["track", p / "rec", "--out", p, "--force"], 1,
     "holds the input recording"),
    ("98 --out an existing file", lambda p: ["track", p / "rec", "--out", _file(p)], 1, "exists and is not a folder"),
    ("99 --out under /proc", lambda p: ["track", p / "rec", "--out", "/proc/occupose_out"], 1,
     "/proc/occupose_out: cannot write it (No such file or directory)"),
    ("100 --out under /sys", lambda p: ["track", p / "rec", "--out", "/sys/kernel/occupose_out"], 1,
     "/sys/kernel/occupose_out: cannot write it ("),
    ("101 --out a 300-character name", lambda p: ["track", p / "rec", "--out", _long_name(p)], 1,
     "is 300 bytes long; the file system takes at most 255"),
    ("102 --out an earlier run, no --force", lambda p: ["track", p / "rec", "--out", _with_notes(p / "run")], 1,
     "exists and is not empty (use --force to replace an earlier output of occupose)"),
    ("103 a failed run into an earlier run", lambda p: ["track", _cut_frame(p), "--out", p / "run", "--force"], 1,
     "not a readable PNG image"),
    ("105 summary.json a folder, no --force", lambda p: ["track", p / "rec", "--out", _user_folder(p)], 1,
     "exists and is not empty"),
    ("105 summary.json a folder, --force", lambda p: ["track", p / "rec", "--out", _user_folder(p), "--force"], 1,
     f"was not written by occupose (no {MANIFEST}): not replacing it, even with --force"),
    ("-- a file where a folder should be", lambda p: ["track", p / "rec", "--out", _file(p) / "sub"], 1,
     "afile is a file, not a folder"),
    ("-- --force over a recording of occupose", lambda p: ["track", p / "rec", "--out", _rec_copy(p), "--force"], 1,
     "holds an occupose recording, not a run: not replacing it, even with --force"),
    ("113 synth over a recording, no --force", lambda p: ["synth", "no_occlusion", p / "rec", "--frames", 2], 1,
     "exists and is not empty (use --force"),
    ("114 synth OUT an existing file", lambda p: ["synth", "no_occlusion", _file(p), "--frames", 2], 1,
     "exists and is not a folder"),
    ("115 synth --force on a folder of the user", lambda p: ["synth", "no_occlusion", _notes_folder(p), "--frames", 2,
                                                             "--force"], 1, "was not written by occupose"),
    ("118 synth OUT under /proc", lambda p: ["synth", "no_occlusion", "/proc/occupose_rec", "--frames", 2], 1,
     "/proc/occupose_rec: cannot write it"),
    ("119 show over a user's picture", lambda p: ["show", p / "rec", "--out", _user_png(p / "keep.png")], 1,
     "keep.png exists (use --force to replace a picture occupose made)"),
    ("119 show --force over a user's picture",
     lambda p: ["show", p / "rec", "--out", _user_png(p / "keep.png"), "--force"], 1,
     "keep.png was not written by occupose: not replacing it, even with --force"),
    ("120 show into the recording's depth frame",
     lambda p: ["show", p / "rec", "--frame", 1, "--out", p / "rec" / "front" / "depth" / "000001.png", "--force"], 1,
     "is inside the input recording"),
    ("121 show --out an existing folder", lambda p: ["show", p / "rec", "--out", p / "run"], 1,
     "is a folder; give the picture's file name"),
    ("122 show --out the recording.json", lambda p: ["show", p / "rec", "--out", p / "rec" / "recording.json"], 1,
     "pictures are written as PNG"),
    ("123 demo over an earlier recording", lambda p: ["demo", "--out", _demo_place(p), "--frames", 2], 1,
     "sit_behind_table exists and is not empty (use --force"),
    ("124 demo --out an existing file", lambda p: ["demo", "--out", _file(p), "--frames", 2], 1,
     "afile is a file, not a folder"),
    ("127 evaluate over a folder of the user", lambda p: ["evaluate", "--scenarios", "no_occlusion", "--methods",
                                                          "ours", "--runs", 1, "--frames", 2, "--out", p / "run"], 1,
     "exists and is not empty"),
    ("127 evaluate --force over a run", lambda p: ["evaluate", "--scenarios", "no_occlusion", "--methods", "ours",
                                                   "--runs", 1, "--frames", 2, "--out", p / "run", "--force"], 1,
     "holds an occupose run, not a evaluation"),
]


def _rec_copy(place: Path) -> Path:
    shutil.copytree(place / "rec", place / "rec2")
    return place / "rec2"


def _demo_place(place: Path) -> Path:
    demo = place / "demo"
    demo.mkdir()
    shutil.copytree(place / "rec", demo / "sit_behind_table")
    _with_notes(demo / "sit_behind_table")
    return demo


@pytest.mark.parametrize("row, arguments, status, message", REFUSED, ids=[case[0] for case in REFUSED])
def test_refused_or_failed_outputs_change_nothing(place, row, arguments, status, message):
    args = arguments(place)
    if any(str(a).startswith(("/proc", "/sys")) for a in args) and not Path("/proc/self").is_dir():
        pytest.skip("needs Linux's /proc and /sys")
    before = folder_snapshot(place)
    result = _invoke(args)
    assert result.exit_code == status, result.output
    assert message in result.output and "Error: " in result.output
    assert "Traceback" not in result.output and isinstance(result.exception, SystemExit)
    assert folder_snapshot(place) == before  # nothing there before changed, nothing half-written left


def test_writability_is_checked_before_the_tracking(place, monkeypatch):
    """Row 104: an output that cannot be written fails before the first frame is tracked."""
    frames = []
    monkeypatch.setattr(cli, "_progress_bar", lambda total, desc, unit="frame": _Bar(frames.append))
    result = _invoke(["track", place / "rec", "--out", "/proc/occupose_out"])
    assert result.exit_code == 1 and "cannot write it" in result.output
    assert frames == []


class _Bar:
    """A progress bar that calls ``act(n)`` on every update (the CLI's tqdm stand-in)."""

    def __init__(self, act):
        self.act = act

    def update(self, n):
        self.act(n)

    def close(self):
        pass


def _signal_at(count: int, signum: int):
    """A progress bar that sends ``signum`` to this process at its ``count``-th update."""
    seen = []

    def act(n):
        seen.append(n)
        if len(seen) == count:
            os.kill(os.getpid(), signum)

    return lambda total, desc, unit="frame": _Bar(act)


INTERRUPTED = [
    ("107 Ctrl-C in track, fresh OUT", signal.SIGINT, 130, lambda p: ["track", p / "rec", "--out", p / "new"]),
    ("108 SIGTERM in track, fresh OUT", signal.SIGTERM, 143, lambda p: ["track", p / "rec", "--out", p / "new"]),
    ("109 SIGTERM in track over an earlier run", signal.SIGTERM, 143,
     lambda p: ["track", p / "rec", "--out", _with_notes(p / "run"), "--force"]),
    ("110 Ctrl-C in synth, fresh OUT", signal.SIGINT, 130,
     lambda p: ["synth", "no_occlusion", p / "new", "--frames", FRAMES, "--procedural"]),
    ("110 SIGTERM in synth, fresh OUT", signal.SIGTERM, 143,
     lambda p: ["synth", "no_occlusion", p / "new", "--frames", FRAMES, "--procedural"]),
    ("138 Ctrl-C in synth --force over a recording", signal.SIGINT, 130,
     lambda p: ["synth", "no_occlusion", p / "rec", "--frames", FRAMES, "--procedural", "--seed", 4, "--force"]),
    ("-- Ctrl-C in demo, fresh OUT", signal.SIGINT, 130, lambda p: ["demo", "--out", p / "new", "--frames", FRAMES]),
    ("-- SIGTERM in evaluate, fresh OUT", signal.SIGTERM, 143,
     lambda p: ["evaluate", "--scenarios", "no_occlusion", "--methods", "ours", "--runs", 1, "--frames", FRAMES,
                "--procedural", "--jobs", 1, "--out", p / "new"]),
]


@pytest.mark.parametrize("row, signum, status, arguments", INTERRUPTED, ids=[case[0] for case in INTERRUPTED])
def test_an_interrupted_command_leaves_everything_as_it_was(place, monkeypatch, row, signum, status, arguments):
    args = arguments(place)
    before = folder_snapshot(place)
    handler = signal.getsignal(signal.SIGTERM)
    monkeypatch.setattr(cli, "_progress_bar", _signal_at(2, signum))
    # a process started in the background by a shell ignores SIGINT; Ctrl-C is what is tested
    interrupt = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        result = _invoke(args)
    finally:
        signal.signal(signal.SIGINT, interrupt)
    assert result.exit_code == status, result.output
    what = "interrupted" if signum == signal.SIGINT else "terminated"
    assert result.output.strip().splitlines()[-1] == (f"Error: {what}; no output was left half-written, earlier "
                                                      "outputs are as they were")
    assert folder_snapshot(place) == before
    assert signal.getsignal(signal.SIGTERM) == handler  # the command's handler is gone again
    if row.startswith("110"):  # nothing to clean by hand: the same command runs again, without --force
        monkeypatch.setattr(cli, "_progress_bar", lambda total, desc, unit="frame": _Bar(lambda n: None))
        assert _invoke(args).exit_code == 0 and Recording(place / "new").num_frames == FRAMES


def test_force_replaces_a_run_and_keeps_the_users_files(place):
    """Rows 102 and 116: --force replaces the run's own files only; the user's notes stay."""
    _with_notes(place / "run")
    (place / "run" / "mine").mkdir()
    _with_notes(place / "run" / "mine", "more.txt")
    theirs = {k: v for k, v in folder_snapshot(place / "run").items() if k.startswith(("notes", "mine"))}
    old = read_manifest(place / "run")
    result = _invoke(["track", place / "rec", "--out", place / "run", "--force", "--seed", 3])
    assert result.exit_code == 0, result.output
    after = folder_snapshot(place / "run")
    assert {k: v for k, v in after.items() if k.startswith(("notes", "mine"))} == theirs
    assert sorted(after) == sorted([*old["files"], MANIFEST, *theirs])
    assert read_manifest(place / "run")["files"] == ["summary.json", "tracks.csv"]  # not the user's
    assert '"seed": 3' in (place / "run" / "summary.json").read_text()
    assert [p.name for p in place.iterdir() if p.name.startswith(".")] == []  # nothing left beside


def test_synth_force_keeps_annotations_and_follows_a_symlink(place):
    """Rows 116 and 117: a recording with the user's annotations in it, reached through a
    symbolic link, is replaced by --force; the annotations and the link stay."""
    _with_notes(place / "rec", "my_annotations.txt")
    _with_notes(place / "rec" / "front", "camera_notes.txt")
    (place / "link").symlink_to(place / "rec")
    result = _invoke(["synth", "no_occlusion", place / "link", "--frames", 2, "--procedural", "--force"])
    assert result.exit_code == 0, result.output
    assert (place / "link").is_symlink() and Recording(place / "rec").num_frames == 2
    assert (place / "rec" / "my_annotations.txt").read_text() == "the user's notes\n"
    assert (place / "rec" / "front" / "camera_notes.txt").read_text() == "the user's notes\n"
    assert "my_annotations.txt" not in read_manifest(place / "rec")["files"]


def test_demo_force_replaces_its_recording_and_keeps_the_users_notes(place):
    """Row 123 with --force: the earlier demo recording is replaced, the notes in it kept."""
    demo = _demo_place(place)
    result = _invoke(["demo", "--out", demo, "--frames", 2, "--force"])
    assert result.exit_code == 0, result.output
    assert "nobody is in view in the first 2 frames" in result.output
    assert Recording(demo / "sit_behind_table").num_frames == 2
    assert (demo / "sit_behind_table" / "notes.txt").read_text() == "the user's notes\n"


def test_show_reports_the_path_it_writes(place):
    """Rows 121 and 137: a name without a suffix is written as NAME.png, and said so; the
    picture says occupose made it, so --force may replace it and nothing else."""
    result = _invoke(["show", place / "rec", "--frame", 1, "--out", place / "frame5"])
    assert result.exit_code == 0 and result.output.strip() == f"wrote {place / 'frame5.png'}"
    assert is_occupose_picture(place / "frame5.png") and not (place / "frame5").exists()
    result = _invoke(["show", place / "rec", "--frame", 2, "--out", place / "frame5.png", "--force"])
    assert result.exit_code == 0, result.output
    assert show_frame(Recording(place / "rec"), 0, place / "o") == place / "o.png"
    assert (place / "o.png").is_file() and not is_occupose_picture(_user_png(place / "user.png"))


def test_a_scoring_error_after_tracking_is_a_clean_error(place):
    """Row 20: ground truth that breaks the recording's frame count, found when scoring."""
    header = (place / "rec" / "recording.json").read_text()
    (place / "rec" / "recording.json").write_text(header.replace(f'"num_frames": {FRAMES}', '"num_frames": 2'))
    for image in (place / "rec" / "front").glob(f"*/{FRAMES - 1:06d}.png"):  # the last frame gone, its truth kept
        image.unlink()
    result = _invoke(["track", place / "rec", "--out", place / "new"])
    assert result.exit_code == 1 and "groundtruth.csv" in result.output and "Error: " in result.output
    assert "Traceback" not in result.output and isinstance(result.exception, SystemExit)


def test_a_full_disk_leaves_the_earlier_run_whole(place):
    """Row 106: writing fails half-way (files may not grow past 2 KiB, a real OS limit);
    the earlier run stays as it was and nothing half-written is left."""
    tracks = read_tracks_csv(place / "run" / "tracks.csv", FRAMES)
    result = TrackingResult(tracks, num_frames=FRAMES)
    before = folder_snapshot(place)
    soft, hard = resource.getrlimit(resource.RLIMIT_FSIZE)
    previous = signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write past the limit fails instead of killing
    resource.setrlimit(resource.RLIMIT_FSIZE, (2048, hard))
    try:
        with pytest.raises(OutputError, match=r"run/summary\.json: cannot write it \(File too large\)"):
            write_run(place / "run", result, place / "rec", "ours", force=True)
    finally:
        resource.setrlimit(resource.RLIMIT_FSIZE, (soft, hard))
        signal.signal(signal.SIGXFSZ, previous)
    assert folder_snapshot(place) == before
