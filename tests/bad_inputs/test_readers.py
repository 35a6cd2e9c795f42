"""Bad recordings, ground truth and tracks files through the command line (issue 26).

Every reading and scoring row of the review ``bad-inputs-931038f.md`` (rows 1-12, 16-19,
21-29 and 34-71) is a case here, the rows that always worked included: a copy of a tiny
synthetic recording and a good ``tracks.csv`` are changed as the row says, a command runs
in-process, and the case checks the exit status, a distinctive part of the message, that
no exception escaped (a traceback) and that every file there before is unchanged.
"""

from __future__ import annotations

import binascii
import ctypes
import json
import os
import pickle
import re
import shutil
import struct
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np
import pytest
from click.testing import CliRunner
from PIL import Image

from occupose.cli import main
from occupose.io.joint_table import write_tracks_csv
from occupose.io.recording import Recording
from occupose.testing import folder_snapshot

DEPTH = Path("front/depth")
COLOR = Path("front/color")
TRACK = 7  # the id of the good tracks.csv's track


@pytest.fixture(scope="module")
def base(tmp_path_factory):
    """(a 3-frame no_occlusion recording, a tracks.csv 5 cm off its ground truth along x)."""
    root = tmp_path_factory.mktemp("bad_inputs")
    rec = root / "rec"
    result = CliRunner().invoke(main, ["synth", "no_occlusion", str(rec), "--frames", "3", "--procedural"])
    assert result.exit_code == 0, result.output
    gt = Recording(rec).groundtruth()
    assert np.isfinite(gt.joints[:, 0]).all()  # the person is seen in every frame
    joints = gt.joints[:, 0] + [0.05, 0.0, 0.0]
    write_tracks_csv(root / "tracks.csv", {TRACK: (joints, np.ones(joints.shape[:2], bool))})
    return rec, root / "tracks.csv"


# --------------------------------------------------------------------------- changing files


def header(change: Callable[[dict], object]) -> Callable[[Path, Path], None]:
    """A mutation of recording.json: ``change`` edits the parsed header in place."""
    def mutate(rec: Path, tracks: Path) -> None:
        data = json.loads((rec / "recording.json").read_text())
        change(data)
        (rec / "recording.json").write_text(json.dumps(data))
    return mutate


def header_text(make: Callable[[str], str | bytes]) -> Callable[[Path, Path], None]:
    """recording.json replaced by ``make(its text)``."""
    def mutate(rec: Path, tracks: Path) -> None:
        made = make((rec / "recording.json").read_text())
        (rec / "recording.json").write_bytes(made if isinstance(made, bytes) else made.encode())
    return mutate


def camera(**values) -> Callable[[Path, Path], None]:
    return header(lambda h: h["cameras"][0].update(values))


def pose(change: Callable[[np.ndarray], np.ndarray]) -> Callable[[Path, Path], None]:
    """world_from_camera replaced by ``change(it as an array)``."""
    def edit(h: dict) -> None:
        h["cameras"][0]["world_from_camera"] = change(np.array(h["cameras"][0]["world_from_camera"])).tolist()
    return header(edit)


def second_camera(copy_folder: bool) -> Callable[[Path, Path], None]:
    def mutate(rec: Path, tracks: Path) -> None:
        header(lambda h: h["cameras"].append(dict(h["cameras"][0], name="side")))(rec, tracks)
        if copy_folder:
            shutil.copytree(rec / "front", rec / "side")
    return mutate


def frame_file(name: Path, write: Callable[[Path], None]) -> Callable[[Path, Path], None]:
    """The file ``name`` (relative to the recording) removed and made again by ``write``."""
    def mutate(rec: Path, tracks: Path) -> None:
        (rec / name).unlink()
        write(rec / name)
    return mutate


def image(array: np.ndarray, format: str = "PNG") -> Callable[[Path], None]:
    return lambda path: Image.fromarray(array).save(path, format=format)


def raw(data: bytes) -> Callable[[Path], None]:
    return lambda path: path.write_bytes(data)


def symlink(target: str) -> Callable[[Path], None]:
    return lambda path: path.symlink_to(target)


def bytes_changed(name: Path, change: Callable[[bytes], bytes]) -> Callable[[Path, Path], None]:
    def mutate(rec: Path, tracks: Path) -> None:
        (rec / name).write_bytes(change((rec / name).read_bytes()))
    return mutate


def flip_idat(data: bytes) -> bytes:
    """64 bytes in the middle of the first IDAT chunk inverted."""
    start = data.index(b"IDAT") + 4 + 1000
    return data[:start] + bytes(b ^ 0xFF for b in data[start:start + 64]) + data[start + 64:]


def break_ihdr_crc(data: bytes) -> bytes:
    at = 8 + 4 + 4 + 13  # signature, length, "IHDR", its 13 bytes: the CRC follows
    return data[:at] + bytes(b ^ 0xFF for b in data[at:at + 4]) + data[at + 4:]


def png_header_only(width: int, height: int) -> bytes:
    """A PNG whose header says 16-bit grayscale ``width`` x ``height``, as a bomb's does,
    and whose image data is not zlib data: decoding it fails at once, so an error about
    its size shows that it was refused from the header, nothing decoded."""
    def chunk(kind: bytes, body: bytes) -> bytes:
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", binascii.crc32(kind + body))
    ihdr = struct.pack(">IIBBBBB", width, height, 16, 0, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", b"not zlib data") + chunk(b"IEND", b"")


def all_frames(value: Callable[[np.random.Generator], np.ndarray]) -> Callable[[Path, Path], None]:
    def mutate(rec: Path, tracks: Path) -> None:
        rng = np.random.default_rng(0)
        for file in sorted((rec / DEPTH).iterdir()):
            Image.fromarray(value(rng)).save(file)
    return mutate


def chmod(name: str | Path, mode: int) -> Callable[[Path, Path], None]:
    return lambda rec, tracks: os.chmod(rec / name, mode)


def emptied(name: Path) -> Callable[[Path, Path], None]:
    def mutate(rec: Path, tracks: Path) -> None:
        for file in (rec / name).iterdir():
            file.unlink()
    return mutate


def both(*mutations: Callable[[Path, Path], None]) -> Callable[[Path, Path], None]:
    def mutate(rec: Path, tracks: Path) -> None:
        for change in mutations:
            change(rec, tracks)
    return mutate


def lines_of(name: str, change: Callable[[list[str]], list[str]], which: str = "rec") -> Callable[[Path, Path], None]:
    """A CSV file (``name`` in the recording, or the tracks file) rewritten from ``change(its lines)``."""
    def mutate(rec: Path, tracks: Path) -> None:
        path = rec / name if which == "rec" else tracks
        path.write_text("".join(change(path.read_text().splitlines(keepends=True))))
    return mutate


def groundtruth(change: Callable[[list[str]], list[str]]) -> Callable[[Path, Path], None]:
    return lines_of("groundtruth.csv", change)


def tracks_csv(change: Callable[[list[str]], list[str]]) -> Callable[[Path, Path], None]:
    return lines_of("", change, which="tracks")


def cells(line: str, **values: str) -> str:
    """A CSV row with some of its cells (by column name of either table) replaced."""
    names = ["frame", "id", "joint", "x", "y", "z", "visible"]
    parts = line.rstrip("\r\n").split(",")
    for key, value in values.items():
        parts[names.index(key)] = value
    return ",".join(parts) + "\n"


def without_column(index: int) -> Callable[[list[str]], list[str]]:
    return lambda lines: [",".join(line.rstrip("\n").split(",")[:index]) + "\n" if not line.startswith("#") else line
                          for line in lines]


def millimetres(line: str) -> str:
    """A tracks.csv row with its coordinates in millimetres."""
    xyz = [float(value) * 1000.0 for value in line.split(",")[3:6]]
    return cells(line, **{axis: f"{value:.3f}" for axis, value in zip("xyz", xyz)})


def rows_kept(keep: Callable[[list[str]], list[str]]) -> Callable[[list[str]], list[str]]:
    """The end line kept (with its count made right) around the data rows ``keep`` leaves."""
    def change(lines: list[str]) -> list[str]:
        rows = keep(lines[1:-1])
        return [lines[0], *rows, f"# end: {len(rows)} rows\n"]
    return change


# --------------------------------------------------------------------------- the cases


@dataclass(frozen=True)
class Case:
    """row : the review's row; mutate(rec, tracks) : the change; command : "track",
    "score", "score --unmarked" or "show"; code : the exit status; message : a part of
    the output; check : more to assert on the output, or None; no_dac : run with the
    permission checks root otherwise bypasses."""

    row: int
    name: str
    mutate: Callable[[Path, Path], None]
    command: str
    code: int
    message: str
    check: Callable[[str], None] | None = None
    no_dac: bool = False


def avg_err(output: str, label: str) -> float:
    """The Avg Err cell (cm) of the table row starting with ``label``."""
    row = next(line for line in output.splitlines() if line.startswith(f"| {label}"))
    return float(row.split("|")[6])


def same_rows_as_good_tracks(output: str) -> None:
    """The numbers of the good tracks.csv: 5 cm on every joint, every frame within 10 cm."""
    assert avg_err(output, f"person 1 (track {TRACK}) all joints") == pytest.approx(5.0, abs=0.01)
    assert "| person 1 (track 7) all joints | 100.00 | 100.00 | 100.00 | 0.00 |" in output


def visible_row_is_all_joints_row(output: str) -> None:
    rows = [line.split("|")[2:] for line in output.splitlines() if line.startswith("| person 1 (track 7)")]
    assert len(rows) == 2 and rows[0] == rows[1]


def pelvis_scores_worse(output: str) -> None:
    """Far worse than the full skeleton's 5 cm: 8 of the 9 upper-body joints missed, 1 m
    each, and the pelvis 5 cm off. (Nothing FAILs in 3 frames: the FAIL rule starts a
    second after the first frame.)"""
    assert avg_err(output, f"person 1 (track {TRACK}) all joints") == pytest.approx((8 * 100 + 5) / 9, abs=0.01)


def kilometres_off(output: str) -> None:
    """Millimetres read as metres: the mean error is over a kilometre (no unit guessed)."""
    assert avg_err(output, f"person 1 (track {TRACK}) all joints") > 1e5


def scored_with_the_warning(output: str) -> None:
    """The first 30 rows (frames 0 and 1) scored, after the warning that the file may be cut."""
    assert "no end line ('# end: 30 rows') after its 30 rows" in output
    assert avg_err(output, f"person 1 (track {TRACK}) all joints") == pytest.approx(5.0, abs=0.01)


def nobody_tracked(output: str) -> None:
    assert "0 track(s) in 3 frames" in output


BIG = "9" * 5001  # an integer of 5001 digits
CASES = [
    # recording.json
    Case(1, "missing", lambda rec, tracks: (rec / "recording.json").unlink(), "track", 1,
         "recording.json: no such file; a recording folder needs a recording.json"),
    Case(2, "empty", header_text(lambda text: ""), "track", 1,
         "recording.json: not valid JSON (Expecting value at line 1 column 1)"),
    Case(3, "truncated", header_text(lambda text: text[:len(text) // 2]), "track", 1,
         "recording.json: not valid JSON ("),
    Case(4, "random-bytes", header_text(lambda text: np.random.default_rng(4).bytes(300)), "track", 1,
         "recording.json: not a UTF-8 text file"),
    Case(5, "a-list", header_text(lambda text: "[1, 2]"), "track", 1, "expected a JSON object, got list"),
    Case(6, "format", header(lambda h: h.update(format="occupose-rec")), "track", 1,
         "\"format\" must be 'occupose-recording', got 'occupose-rec'"),
    Case(7, "version-2", header(lambda h: h.update(version=2)), "track", 1,
         "unsupported version 2; this occupose reads versions [1]"),
    Case(7, "version-text", header(lambda h: h.update(version="1")), "track", 1, "unsupported version '1'"),
    Case(8, "version-1.0", header(lambda h: h.update(version=1.0)), "score", 0, "person 1 (track 7) all joints",
         same_rows_as_good_tracks),
    Case(9, "no-num-frames", header(lambda h: h.pop("num_frames")), "track", 1, "missing key(s) ['num_frames']"),
    Case(10, "unknown-key", header(lambda h: h.update(comment="hi")), "track", 1, "unknown key(s) ['comment']"),
    Case(11, "fps-twice", header_text(lambda text: text.replace('"fps": 30.0', '"fps": 12.0, "fps": 30.0')),
         "score", 0, "person 1 (track 7) all joints", same_rows_as_good_tracks),
    *[Case(12, f"fps-{name}", header_text(lambda text, v=value: text.replace('"fps": 30.0', f'"fps": {v}')),
           "track", 1, f"\"fps\" must be a positive number, got {shown}")
      for name, value, shown in [("0", "0", "0"), ("negative", "-30", "-30"), ("nan", "NaN", "nan"),
                                 ("inf", "Infinity", "inf"), ("text", '"30"', "'30'")]],
    Case(16, "deep-array", header_text(lambda text: "[" * 200_000 + "]" * 200_000), "track", 1,
         "recording.json: JSON nested too deeply to be a recording header"),
    Case(16, "deep-object", header_text(lambda text: '{"a": ' * 200_000 + "1" + "}" * 200_000), "track", 1,
         "recording.json: JSON nested too deeply to be a recording header"),
    Case(17, "huge-integer", header_text(lambda text: re.sub(r'"num_frames": \d+', f'"num_frames": {BIG}', text)),
         "track", 1, "recording.json: not a readable recording header (Exceeds the limit (4300 digits)"),
    Case(18, "one-frame-more", header(lambda h: h.update(num_frames=4)), "track", 1,
         "front/depth/000003.png: missing frame file (recording has 4 frames)"),
    Case(18, "a-hundred-million", header(lambda h: h.update(num_frames=100_000_000)), "track", 1,
         "front/depth/000003.png: missing frame file (recording has 100000000 frames)"),
    Case(19, "zero-frames", both(header(lambda h: h.update(num_frames=0)), emptied(DEPTH), emptied(COLOR),
                                 lambda rec, tracks: (rec / "groundtruth.csv").unlink()), "track", 1,
         "the recording has no frames, nothing to track"),
    Case(19, "negative", header(lambda h: h.update(num_frames=-1)), "track", 1,
         "\"num_frames\" must be a non-negative integer, got -1"),
    Case(19, "float", header(lambda h: h.update(num_frames=3.0)), "track", 1,
         "\"num_frames\" must be a non-negative integer, got 3.0"),
    Case(19, "zero-with-frames", header(lambda h: h.update(num_frames=0)), "track", 1,
         "front/depth: 3 frame file(s) past the recording's \"num_frames\" 0 (000000.png .. 000002.png)"),
    Case(21, "fewer-than-on-disk", both(header(lambda h: h.update(num_frames=2)),
                                        lambda rec, tracks: (rec / "groundtruth.csv").unlink()), "track", 1,
         "front/depth: 1 frame file(s) past the recording's \"num_frames\" 2 (000002.png); set num_frames"),
    Case(21, "fewer-with-groundtruth", header(lambda h: h.update(num_frames=2)), "score", 1,
         "1 frame file(s) past the recording's \"num_frames\" 2"),
    # cameras
    Case(22, "width-0", camera(width=0), "track", 1, "cameras[0]: camera 'front': width must be a positive integer, "
         "got 0"),
    Case(23, "fx-0", camera(fx=0), "track", 1, "fx must be a positive finite number, got 0"),
    Case(23, "fx-negative", camera(fx=-594.21), "track", 1, "fx must be a positive finite number, got -594.21"),
    Case(24, "singular-pose", pose(lambda m: np.diag([0.0, 0.0, 0.0, 1.0])), "track", 1,
         "world_from_camera is not rigid: its rotation block is not orthonormal"),
    Case(25, "pose-3x3", pose(lambda m: m[:3, :3]), "track", 1, "world_from_camera must be a 4x4 list of numbers"),
    Case(26, "pose-nan", pose(lambda m: np.where(np.eye(4, k=3) > 0, np.nan, m)), "track", 1,
         "world_from_camera must be finite"),
    Case(27, "pose-scaled", pose(lambda m: np.diag([2.0, 2.0, 2.0, 1.0]) @ m), "track", 1,
         "world_from_camera is not rigid"),
    Case(27, "pose-mirrored", pose(lambda m: np.diag([-1.0, 1.0, 1.0, 1.0]) @ m), "track", 1,
         "is not a proper rotation: det(R) = -1"),
    Case(28, "names-twice", header(lambda h: h["cameras"].append(dict(h["cameras"][0]))), "track", 1,
         "camera names must be unique, got ['front', 'front']"),
    Case(29, "unknown-camera-key", camera(k1=0.1), "track", 1, "unknown key(s) ['k1']"),
    Case(29, "no-cameras", header(lambda h: h.update(cameras=[])), "track", 1,
         "\"cameras\" must be a non-empty list, got []"),
    Case(29, "width-text", camera(width="640"), "track", 1, "width must be a positive integer, got '640'"),
    Case(29, "name-a-path", camera(name="../front"), "track", 1,
         "camera name '../front' must be usable as a folder name"),
    Case(29, "depth-scale-0", camera(depth_scale=0), "track", 1, "depth_scale must be a positive finite number, got 0"),
    # frame files
    Case(34, "camera-without-folder", second_camera(copy_folder=False), "track", 1,
         "side/depth: no such folder; it should hold the camera's 3 frames"),
    Case(35, "copied-camera", second_camera(copy_folder=True), "score", 0, "person 1 (track 7) all joints",
         same_rows_as_good_tracks),
    Case(36, "frame-deleted", lambda rec, tracks: (rec / DEPTH / "000001.png").unlink(), "track", 1,
         "front/depth/000001.png: missing frame file (recording has 3 frames)"),
    Case(37, "frame-cut", bytes_changed(DEPTH / "000000.png", lambda data: data[:3000]), "track", 1,
         "front/depth/000000.png: not a readable PNG image (image file is truncated"),
    Case(38, "8-bit", frame_file(DEPTH / "000001.png", image(np.zeros((480, 640), np.uint8))), "track", 1,
         "000001.png: expected a 16-bit grayscale depth PNG (mode 'I;16'), got a PNG image of mode 'L'"),
    Case(39, "rgb", frame_file(DEPTH / "000001.png", image(np.zeros((480, 640, 3), np.uint8))), "track", 1,
         "got a PNG image of mode 'RGB'"),
    Case(40, "320x240", frame_file(DEPTH / "000001.png", image(np.zeros((240, 320), np.uint16))), "track", 1,
         "000001.png: image is 320x240, the camera is 640x480"),
    Case(41, "text", frame_file(DEPTH / "000001.png", raw(b"hello")), "track", 1,
         "000001.png: not a readable PNG image (cannot identify image file)"),
    Case(42, "jpeg", frame_file(DEPTH / "000001.png", image(np.zeros((480, 640), np.uint8), "JPEG")), "track", 1,
         "got a JPEG image of mode 'L'"),
    Case(42, "tiff", frame_file(DEPTH / "000001.png", image(np.zeros((480, 640), np.uint16), "TIFF")), "track", 1,
         "got a TIFF image of mode 'I;16'"),
    Case(43, "zero-bytes", frame_file(DEPTH / "000000.png", raw(b"")), "track", 1,
         "000000.png: not a readable PNG image (cannot identify image file)"),
    Case(44, "idat-flipped", bytes_changed(DEPTH / "000000.png", flip_idat), "track", 1,
         "front/depth/000000.png: not a readable PNG image ("),
    Case(44, "ihdr-crc", bytes_changed(DEPTH / "000000.png", break_ihdr_crc), "track", 1,
         "front/depth/000000.png: not a readable PNG image ("),
    Case(45, "all-zero", all_frames(lambda rng: np.zeros((480, 640), np.uint16)), "track", 0,
         "nobody was tracked", nobody_tracked),
    Case(45, "all-65535", all_frames(lambda rng: np.full((480, 640), 65535, np.uint16)), "track", 1,
         "sees nothing within its far range of 4.5 m: of its 307,200 measured pixels the nearest is at 65.5 m"),
    Case(45, "noise", all_frames(lambda rng: rng.integers(0, 65536, (480, 640)).astype(np.uint16)), "track", 0,
         "nobody was tracked", nobody_tracked),
    Case(46, "link-to-itself", frame_file(DEPTH / "000001.png", symlink("000001.png")), "track", 1,
         "000001.png: cannot read it (Too many levels of symbolic links)"),
    Case(46, "link-loop", both(frame_file(DEPTH / "000001.png", symlink("a")),
                               lambda rec, tracks: (rec / DEPTH / "a").symlink_to("b"),
                               lambda rec, tracks: (rec / DEPTH / "b").symlink_to("000001.png")), "track", 1,
         "000001.png: cannot read it (Too many levels of symbolic links)"),
    Case(47, "dangling-link", frame_file(DEPTH / "000001.png", symlink("nowhere.png")), "track", 1,
         "front/depth/000001.png: missing frame file"),
    Case(48, "a-folder", frame_file(DEPTH / "000001.png", lambda path: path.mkdir()), "track", 1,
         "000001.png: is a folder; expected a 16-bit grayscale depth PNG"),
    Case(49, "dev-zero", frame_file(DEPTH / "000001.png", symlink("/dev/zero")), "track", 1,
         "000001.png: is a device, pipe or socket; expected a 16-bit grayscale depth PNG"),
    Case(50, "frame-unreadable", chmod(DEPTH / "000001.png", 0), "track", 1,
         "000001.png: cannot read it (Permission denied)", no_dac=True),
    Case(51, "folder-unreadable", chmod(DEPTH, 0), "track", 1,
         "front/depth: cannot list it (Permission denied)", no_dac=True),
    Case(52, "header-unreadable", chmod("recording.json", 0), "track", 1,
         "recording.json: cannot read it (Permission denied)", no_dac=True),
    Case(53, "bomb", frame_file(DEPTH / "000001.png", raw(png_header_only(20000, 20000))), "track", 1,
         "000001.png: far too large an image for a frame; expected a 16-bit grayscale depth PNG (mode 'I;16') "
         "of 640x480"),
    Case(54, "10000x10000", frame_file(DEPTH / "000001.png", raw(png_header_only(10000, 10000))), "track", 1,
         "000001.png: image is 10000x10000, the camera is 640x480"),
    Case(55, "grey-colour", frame_file(COLOR / "000001.png", image(np.zeros((480, 640), np.uint8))), "track", 1,
         "color/000001.png: expected an 8-bit RGB colour PNG (mode 'RGB'), got a PNG image of mode 'L'"),
    Case(55, "colour-deleted", lambda rec, tracks: (rec / COLOR / "000002.png").unlink(), "track", 1,
         "color/000002.png: missing frame file (recording has 3 frames)"),
    Case(55, "colour-emptied", emptied(COLOR), "track", 1, "color/000000.png: missing frame file"),
    Case(56, "label-corrupt", frame_file(Path("front/person/000001.png"), raw(b"garbage")), "show", 0, "wrote"),
    # groundtruth.csv
    Case(57, "no-z-visible", groundtruth(without_column(5)), "score", 1,
         "bad header ['frame', 'person', 'joint', 'x', 'y']; expected columns frame,person,joint,x,y,z,visible "
         "(visible optional)"),
    Case(58, "no-visible", groundtruth(without_column(6)), "score", 0, "person 1 (track 7) visible joints",
         visible_row_is_all_joints_row),
    Case(59, "nan", groundtruth(lambda lines: [lines[0], cells(lines[1], x="nan"), *lines[2:]]), "score", 1,
         "groundtruth.csv, line 2: x must be finite, got 'nan'"),
    Case(59, "duplicate-row", groundtruth(lambda lines: [*lines, lines[1]]), "score", 1,
         "duplicate row for frame 0, person 1, joint head"),
    Case(59, "empty", groundtruth(lambda lines: []), "score", 1, "groundtruth.csv: bad header [] (an empty file)"),
    Case(59, "binary-tail", lambda rec, tracks: (rec / "groundtruth.csv").write_bytes(
        (rec / "groundtruth.csv").read_bytes() + np.random.default_rng(59).bytes(200)), "score", 1,
         "groundtruth.csv: not a readable UTF-8 CSV file"),
    Case(59, "open-quote", groundtruth(lambda lines: [lines[0], '0,1,"head,0,0,0,1\n', *lines[1:]]), "score", 1,
         "groundtruth.csv, lines 2-47: expected 7 columns, got 3: ['0', '1', 'head,0,0,0,1\\n0,1...."),
    Case(59, "person-1.0", groundtruth(lambda lines: [lines[0], cells(lines[1], id="1.0"), *lines[2:]]), "score", 1,
         "groundtruth.csv, line 2: person must be an integer, got '1.0'"),
    Case(59, "joint-name", groundtruth(lambda lines: [lines[0], cells(lines[1], joint="LeftShoulder"), *lines[2:]]),
         "score", 1, "line 2: unknown joint 'LeftShoulder'"),
    Case(59, "visible-yes", groundtruth(lambda lines: [lines[0], cells(lines[1], visible="yes"), *lines[2:]]),
         "score", 1, "line 2: visible must be 0 or 1, got 'yes'"),
    Case(60, "header-only", groundtruth(lambda lines: lines[:1]), "score", 0, "unmatched tracks: [7]"),
    Case(61, "a-folder", both(lambda rec, tracks: (rec / "groundtruth.csv").unlink(),
                              lambda rec, tracks: (rec / "groundtruth.csv").mkdir()), "score", 1,
         "groundtruth.csv: is a folder; expected a groundtruth CSV file"),
    Case(62, "unreadable", chmod("groundtruth.csv", 0), "score", 1,
         "groundtruth.csv: cannot read it (Permission denied)", no_dac=True),
    Case(63, "person-2", groundtruth(lambda lines: [lines[0], *(cells(line, id="2") for line in lines[1:])]), "score",
         0, "person 2 (track 7) all joints"),
    # tracks.csv
    Case(64, "empty", tracks_csv(lambda lines: []), "score", 1, "tracks.csv: bad header [] (an empty file)"),
    Case(64, "6-columns", tracks_csv(without_column(6)), "score", 1,
         "bad header ['frame', 'track', 'joint', 'x', 'y', 'z']; expected columns frame,track,joint,x,y,z,visible"),
    Case(64, "joint-Head", tracks_csv(lambda lines: [lines[0], cells(lines[1], joint="Head"), *lines[2:]]), "score", 1,
         "tracks.csv, line 2: unknown joint 'Head'"),
    Case(64, "nan", tracks_csv(lambda lines: [lines[0], cells(lines[1], z="nan"), *lines[2:]]), "score", 1,
         "tracks.csv, line 2: z must be finite, got 'nan'"),
    Case(64, "inf", tracks_csv(lambda lines: [lines[0], cells(lines[1], z="inf"), *lines[2:]]), "score", 1,
         "tracks.csv, line 2: z must be finite, got 'inf'"),
    Case(64, "duplicate-row", tracks_csv(rows_kept(lambda rows: [*rows, rows[0]])), "score", 1,
         "tracks.csv, line 47: duplicate row for frame 0, track 7, joint head"),
    Case(64, "frame-3", tracks_csv(rows_kept(lambda rows: [*rows, cells(rows[-1], frame="3")])), "score", 1,
         "tracks.csv, line 47: frame 3 out of range; the recording has frames 0..2"),
    Case(64, "frame-negative", tracks_csv(lambda lines: [lines[0], cells(lines[1], frame="-1"), *lines[2:]]),
         "score", 1, "tracks.csv, line 2: frame -1 out of range"),
    Case(64, "track-1.5", tracks_csv(lambda lines: [lines[0], cells(lines[1], id="1.5"), *lines[2:]]), "score", 1,
         "tracks.csv, line 2: track must be an integer, got '1.5'"),
    Case(64, "track-abc", tracks_csv(lambda lines: [lines[0], cells(lines[1], id="abc"), *lines[2:]]), "score", 1,
         "tracks.csv, line 2: track must be an integer, got 'abc'"),
    Case(65, "no-rows", tracks_csv(rows_kept(lambda rows: [])), "score", 0,
         "| person 1 (none) all joints | 0.00 | 0.00 | 0.00 | 100.00 | n/a | n/a | ok | 0.00 |"),
    Case(66, "pelvis-only", tracks_csv(rows_kept(lambda rows: [r for r in rows if ",pelvis," in r])), "score", 0,
         "person 1 (track 7): scored on the 9 upper-body joints (the track has no hip, knee or ankle)",
         pelvis_scores_worse),
    Case(67, "byte-order-mark", tracks_csv(lambda lines: ["\ufeff" + lines[0], *lines[1:]]), "score", 0,
         "person 1 (track 7) all joints", same_rows_as_good_tracks),
    Case(68, "crlf", tracks_csv(lambda lines: [line.replace("\n", "\r\n") for line in lines]), "score", 0,
         "person 1 (track 7) all joints", same_rows_as_good_tracks),
    Case(68, "track-negative", tracks_csv(lambda lines: [lines[0], *(cells(line, id="-7") for line in lines[1:-1]),
                                                         lines[-1]]), "score", 0, "person 1 (track -7) all joints"),
    Case(68, "track-23-digits", tracks_csv(lambda lines: [lines[0], *(cells(line, id="1" * 23) for line in lines[1:-1]),
                                                          lines[-1]]), "score", 0, f"person 1 (track {'1' * 23})"),
    Case(69, "millimetres", tracks_csv(lambda lines: [lines[0], *map(millimetres, lines[1:-1]), lines[-1]]), "score", 0,
         "person 1 (track 7) all joints | 0.00 | 0.00 | 0.00 | 100.00 |", kilometres_off),
    Case(70, "cut-at-a-line", tracks_csv(lambda lines: lines[:31]), "score", 1,
         "tracks.csv: no end line ('# end: 30 rows') after its 30 rows"),
    Case(70, "cut-unmarked-allowed", tracks_csv(lambda lines: lines[:31]), "score --unmarked", 0,
         "warning: ", scored_with_the_warning),
    Case(70, "cut-mid-line", tracks_csv(lambda lines: [*lines[:31], lines[31][:14]]), "score", 1,
         "tracks.csv, line 32: expected 7 columns, got 4: ['2', '7', 'head', '"),
    Case(70, "row-lost", tracks_csv(lambda lines: [*lines[:10], *lines[11:]]), "score", 1,
         "tracks.csv: its end line says 45 rows, the file has 44"),
    Case(71, "dev-zero", lambda rec, tracks: (tracks.unlink(), tracks.symlink_to("/dev/zero")), "score", 1,
         "tracks.csv: is a device, pipe or socket; expected a tracks CSV file"),
]


# --------------------------------------------------------------------------- running them


def _drop_dac() -> None:
    """Give up root's permission override in this process (capabilities DAC_OVERRIDE and
    DAC_READ_SEARCH), so that a file's mode is obeyed as for any user."""
    class Header(ctypes.Structure):
        _fields_ = [("version", ctypes.c_uint32), ("pid", ctypes.c_int)]

    class Data(ctypes.Structure):
        _fields_ = [("effective", ctypes.c_uint32), ("permitted", ctypes.c_uint32), ("inheritable", ctypes.c_uint32)]

    libc = ctypes.CDLL(None, use_errno=True)
    head, data = Header(0x20080522, 0), (Data * 2)()  # _LINUX_CAPABILITY_VERSION_3
    if libc.capget(ctypes.byref(head), data) != 0:
        raise OSError(ctypes.get_errno(), "capget failed")
    data[0].effective &= ~((1 << 1) | (1 << 2))
    if libc.capset(ctypes.byref(head), data) != 0:
        raise OSError(ctypes.get_errno(), "capset failed")


def _invoke(args: list[str], no_dac: bool) -> tuple[int, str, BaseException | None]:
    """(exit status, output, the exception that ended the command) of ``occupose ARGS``;
    with ``no_dac`` as root, in a forked child without root's permission override."""
    if not (no_dac and os.geteuid() == 0):
        result = CliRunner().invoke(main, args)
        return result.exit_code, result.output, result.exception
    read, write = os.pipe()
    pid = os.fork()
    if pid == 0:  # the child: never returns into pytest
        try:
            _drop_dac()
            result = CliRunner().invoke(main, args)
            outcome = (result.exit_code, result.output, type(result.exception).__name__ if result.exception else None)
        except BaseException as error:  # noqa: BLE001 - reported to the parent, which fails the test
            outcome = (-1, repr(error), type(error).__name__)
        with os.fdopen(write, "wb") as pipe:
            pickle.dump(outcome, pipe)
        os._exit(0)
    os.close(write)
    with os.fdopen(read, "rb") as pipe:
        code, output, exception = pickle.load(pipe)
    os.waitpid(pid, 0)
    return code, output, SystemExit() if exception == "SystemExit" else (exception and RuntimeError(exception))


@pytest.mark.parametrize("case", CASES, ids=[f"row{c.row}-{c.name}" for c in CASES])
def test_bad_input(case, base, tmp_path):
    rec, tracks = tmp_path / "rec", tmp_path / "tracks.csv"
    shutil.copytree(base[0], rec, symlinks=True)
    shutil.copy(base[1], tracks)
    case.mutate(rec, tracks)
    before = folder_snapshot(tmp_path)
    command, *flags = case.command.split()
    args = {"track": ["track", str(rec), "--out", str(tmp_path / "out")],
            "score": ["score", str(rec), str(tracks), *flags],
            "show": ["show", str(rec), "--frame", "1", "--out", str(tmp_path / "frame.png")]}[command]
    try:
        code, output, exception = _invoke(args, case.no_dac)
    finally:
        for path in (rec / "recording.json", rec / DEPTH, rec / DEPTH / "000001.png", rec / "groundtruth.csv"):
            if path.exists() and not path.is_symlink():
                os.chmod(path, 0o755 if path.is_dir() else 0o644)
    assert exception is None or isinstance(exception, SystemExit), f"{exception!r} escaped:\n{output}"
    assert "Traceback" not in output
    assert code == case.code, output
    assert case.message in output, output
    if case.check is not None:
        case.check(output)
    after = folder_snapshot(tmp_path)
    assert {key: after.get(key) for key in before} == before
