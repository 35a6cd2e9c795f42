"""Property-based fuzzing of the readers (issue 26): the recording folder (its header and its
frame images), the config file and the two CSV tables (tracks.csv, groundtruth.csv).

Whatever the bytes, a reader gives a valid result or a clean error: a ValueError (the
package's RecordingError, JointTableError and ConfigError are ValueErrors) or a
FileNotFoundError, whose message names the file; any other exception fails the test.
Hypothesis runs derandomized (its seed fixed by the test) and without an example database,
so every run, in CI too, tries the same inputs.
"""

from __future__ import annotations

import binascii
import dataclasses
import json
import math
import struct
import tempfile
import zlib
from pathlib import Path

import numpy as np
import pytest
import tomli_w
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from occupose.camera import Camera, look_at
from occupose.config import TrackerConfig, read_settings
from occupose.io.joint_table import read_joint_table, write_joint_table
from occupose.io.recording import Recording, RecordingWriter
from occupose.joints import NUM_JOINTS

FUZZ = settings(derandomize=True, database=None, deadline=None, max_examples=300,
                suppress_health_check=[HealthCheck.too_slow])
FRAMES = 2


def clean(call, names: str):
    """``call()``'s result, or None after a clean error whose message contains ``names``."""
    try:
        return call()
    except (ValueError, FileNotFoundError) as error:
        assert names in str(error), f"{type(error).__name__} does not name {names}: {error}"
        return None


@pytest.fixture(scope="module")
def recording(tmp_path_factory):
    """A 2-frame recording of one 8 x 6 camera with colour and ground truth: its files' bytes."""
    path = tmp_path_factory.mktemp("fuzz") / "rec"
    rng = np.random.default_rng(26)
    camera = Camera("cam", 8, 6, 5.0, 5.0, 3.5, 2.5, world_from_camera=look_at((0, -3, 2), (0, 0, 1)))
    with RecordingWriter(path, [camera], fps=30.0) as writer:
        for _ in range(FRAMES):
            writer.write_frame({"cam": rng.integers(0, 5000, (6, 8)).astype(np.uint16)},
                               {"cam": rng.integers(0, 256, (6, 8, 3)).astype(np.uint8)})
        writer.write_groundtruth(rng.uniform(-2, 2, (FRAMES, 1, NUM_JOINTS, 3)), rng.random((FRAMES, 1, NUM_JOINTS)) < 0.5,
                                 [1])
    return {str(p.relative_to(path)): p.read_bytes() for p in path.rglob("*") if p.is_file()}


def _written(files: dict[str, bytes], root: Path) -> Path:
    for name, data in files.items():
        (root / name).parent.mkdir(parents=True, exist_ok=True)
        (root / name).write_bytes(data)
    return root


def _check_recording(path: Path) -> None:
    """Open the recording and read every frame: valid arrays or a clean error naming the folder."""
    recording = clean(lambda: Recording(path), str(path))
    if recording is None:
        return
    assert recording.fps > 0 and math.isfinite(recording.fps) and recording.num_frames >= 0
    for index in range(recording.num_frames):
        frame = clean(lambda: recording.frame(index), str(path))
        if frame is None:
            return
        for camera in recording.cameras:
            depth = frame.depth[camera.name]
            assert depth.shape == (camera.height, camera.width) and depth.dtype == np.float32
            assert np.isfinite(depth).all() and (depth >= 0).all()
        for name, color in frame.color.items():
            assert color.shape == frame.depth[name].shape + (3,) and color.dtype == np.uint8


# --------------------------------------------------------------------------- the recording

# Values that break careless checks: integers beyond any float, the float extremes.
EXTREMES = st.sampled_from([10 ** 400, -(10 ** 400), 2 ** 63, -1, 0, 1e308, -1e308, 5e-324, math.nan, math.inf, -math.inf])
# Values of the wrong type for every key.
SIMPLE = st.sampled_from(["", "30", True, None, [], {}, [[1, 0], [0, 1]], 1.5, 640])
JSON = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats() | st.text(max_size=8) | EXTREMES,
    lambda children: st.lists(children, max_size=4) | st.dictionaries(st.text(max_size=6), children, max_size=4),
    max_leaves=12,
)


# JSON arrays or objects nested up to 100 000 deep.
NESTED = st.tuples(st.integers(1, 100_000), st.sampled_from(['[', '{"a": '])).map(
    lambda n_open: (n_open[1] * n_open[0] + "0" + ("]" if n_open[1] == "[" else "}") * n_open[0]).encode())


@st.composite
def headers(draw, text: str) -> bytes:
    """recording.json's text changed: a value anywhere replaced, a key removed or added."""
    header = json.loads(text)
    places = [(header, key) for key in header] + [(header["cameras"][0], key) for key in header["cameras"][0]]
    places += [(header["cameras"][0]["world_from_camera"][i], j) for i in range(4) for j in range(4)]
    for _ in range(draw(st.integers(1, 3))):
        holder, key = draw(st.sampled_from(places))
        action = draw(st.sampled_from(["replace", "remove", "add"]))
        value = draw(EXTREMES | SIMPLE | JSON)
        if action == "replace" or isinstance(holder, list):
            holder[key] = value
        elif action == "remove":
            holder.pop(key, None)
        else:
            holder[draw(st.text(max_size=6))] = value
    return json.dumps(header).encode()


@FUZZ
@given(data=st.data())
def test_recording_header(recording, data):
    files = dict(recording)
    files["recording.json"] = data.draw(
        headers(recording["recording.json"].decode()) | st.binary(max_size=300)
        | st.text(max_size=300).map(str.encode) | NESTED)
    with tempfile.TemporaryDirectory() as root:
        _check_recording(_written(files, Path(root)))


@st.composite
def damaged(draw, data: bytes) -> bytes:
    """``data`` with a few bytes changed, cut, removed or put in."""
    data = bytearray(data)
    for _ in range(draw(st.integers(1, 4))):
        at = draw(st.integers(0, len(data)))
        action = draw(st.sampled_from(["change", "cut", "remove", "insert"]))
        if action == "change" and at < len(data):
            data[at] = draw(st.integers(0, 255))
        elif action == "cut":
            del data[at:]
        elif action == "remove":
            del data[at:at + draw(st.integers(1, 64))]
        else:
            data[at:at] = draw(st.binary(min_size=1, max_size=32))
    return bytes(data)


def _chunk(kind: bytes, body: bytes) -> bytes:
    return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", binascii.crc32(kind + body))


@st.composite
def pngs(draw) -> bytes:
    """A PNG made of well-formed chunks (right lengths and checksums) with any header
    values (size, bit depth, colour type, interlace) and image data, compressed or not."""
    ihdr = struct.pack(">IIBBBBB", draw(st.integers(0, 2 ** 31)), draw(st.integers(0, 2 ** 31)),
                       draw(st.sampled_from([0, 1, 2, 4, 8, 16, 3])), draw(st.sampled_from([0, 2, 3, 4, 6, 1, 7])),
                       draw(st.integers(0, 1)), draw(st.integers(0, 1)), draw(st.integers(0, 2)))
    pixels = draw(st.binary(max_size=400))
    idat = zlib.compress(pixels) if draw(st.booleans()) else pixels
    extra = draw(st.lists(st.sampled_from([b"PLTE", b"tRNS", b"gAMA", b"iCCP", b"tEXt", b"zTXt", b"pHYs"]), max_size=2))
    chunks = [_chunk(b"IHDR", ihdr), *(_chunk(kind, draw(st.binary(max_size=30))) for kind in extra),
              _chunk(b"IDAT", idat), _chunk(b"IEND", b"")]
    return b"\x89PNG\r\n\x1a\n" + b"".join(chunks)


@FUZZ
@given(data=st.data())
def test_frame_images(recording, data):
    files = dict(recording)
    name = data.draw(st.sampled_from(sorted(n for n in files if n.endswith(".png"))))
    files[name] = data.draw(damaged(files[name]) | st.binary(max_size=200) | pngs())
    with tempfile.TemporaryDirectory() as root:
        _check_recording(_written(files, Path(root)))


# --------------------------------------------------------------------------- the CSV tables


@st.composite
def tables(draw, text: str) -> str:
    """A CSV file's lines changed: one removed, repeated or put in, a cell replaced."""
    lines = text.splitlines(keepends=True)
    for _ in range(draw(st.integers(1, 3))):
        at = draw(st.integers(0, len(lines)))
        action = draw(st.sampled_from(["remove", "repeat", "insert", "cell"]))
        if action == "remove" and at < len(lines):
            del lines[at]
        elif action == "repeat" and at < len(lines):
            lines.insert(at, lines[at])
        elif action == "insert":
            lines.insert(at, draw(st.text(max_size=40)) + "\n")
        elif at < len(lines):
            cells = lines[at].rstrip("\n").split(",")
            cells[draw(st.integers(0, len(cells) - 1))] = draw(st.text(max_size=8) | st.floats().map(str))
            lines[at] = ",".join(cells) + "\n"
    return "".join(lines)


@pytest.mark.filterwarnings("ignore::occupose.io.joint_table.UnmarkedTableWarning")
@pytest.mark.parametrize("kind", ["tracks", "groundtruth"])
@FUZZ
@given(data=st.data())
def test_joint_tables(kind, data):
    rng = np.random.default_rng(70)
    joints = rng.uniform(-2, 2, (3, NUM_JOINTS, 3))
    joints[1, 4:] = np.nan
    with tempfile.TemporaryDirectory() as root:
        path = Path(root) / f"{kind}.csv"
        write_joint_table(path, {2: (joints, rng.random((3, NUM_JOINTS)) < 0.5)}, kind)
        text = data.draw(tables(path.read_text()) | st.text(max_size=200))
        path.write_bytes(data.draw(st.sampled_from([text.encode(), text.encode("utf-16"), b"\xef\xbb\xbf" + text.encode()])))
        allow = data.draw(st.booleans())
        table = clean(lambda: read_joint_table(path, 3, kind, allow_unmarked=allow), str(path))
    for ident, (points, visible) in (table or {}).items():
        assert isinstance(ident, int) and points.shape == (3, NUM_JOINTS, 3) and visible.shape == (3, NUM_JOINTS)
        known = np.isfinite(points).all(axis=2)
        assert (known | np.isnan(points).all(axis=2)).all() and not (visible & ~known).any()


# --------------------------------------------------------------------------- the config file

SECTIONS = {section: [f.name for f in dataclasses.fields(value)] for section, value in
            ((f.name, getattr(TrackerConfig(), f.name)) for f in dataclasses.fields(TrackerConfig))}


def _toml(table: dict) -> str:
    """``table`` as TOML, or as JSON where TOML cannot hold it (a None): then not valid TOML."""
    try:
        return tomli_w.dumps(table)
    except TypeError:
        return json.dumps(table)


@st.composite
def settings_tables(draw) -> dict:
    """A table of settings: real sections and fields (and a few unknown ones) with any values."""
    table = {}
    for _ in range(draw(st.integers(1, 4))):
        section = draw(st.sampled_from(sorted(SECTIONS)) | st.text(max_size=5))
        field = draw(st.sampled_from(SECTIONS.get(section) or ["x"]) | st.text(max_size=5))
        table.setdefault(section, {})[field] = draw(JSON)
    if draw(st.booleans()):
        table["method"] = draw(st.sampled_from(["ours", "apf", "ps", "part-based"]) | JSON)
    return table


@FUZZ
@given(data=st.data())
def test_config_files(data):
    suffix = data.draw(st.sampled_from([".toml", ".json"]))
    with tempfile.TemporaryDirectory() as root:
        path = Path(root) / f"settings{suffix}"
        table = data.draw(settings_tables())
        text = json.dumps(table) if suffix == ".json" else _toml(table)
        path.write_bytes(data.draw(st.just(text.encode()) | st.binary(max_size=200)
                                   | st.text(max_size=200).map(str.encode)))
        settings_read = clean(lambda: read_settings(path), str(path))
        if settings_read is None:
            return
        config = clean(lambda: TrackerConfig.from_dict(settings_read, source=str(path)), str(path))
    if config is not None:
        assert TrackerConfig.from_dict(config.to_dict()) == config
