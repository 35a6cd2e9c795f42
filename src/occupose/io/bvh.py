"""BVH files: a ``.bvh`` file's hierarchy and motion as a :class:`occupose.io.mocap.Clip`.

Units (``units="auto"``): BVH files are recognised by their joint names:

- ``"cmu"`` skeletons (``LeftUpLeg``, ``LeftArm``, ...; the CMU database as BVH) are in
  the CMU ASF length unit, 1 unit = 0.0254 / 0.45 m (the ASF declares ``length 0.45``);
- ``"bandai"`` skeletons (``UpperLeg_L``, ``UpperArm_L``, ...; Bandai-Namco motion
  datasets 1 and 2) are in centimetres, 0.01 m per unit.

Any other skeleton needs an explicit ``units`` (metres per file unit).

Rotations: a BVH ``CHANNELS`` line lists its rotations in intrinsic order (``Zrotation
Xrotation Yrotation`` means R = Rz Rx Ry), and a joint's position channels, where present,
replace the matching components of its ``OFFSET``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from occupose.io._skeleton import matrices_from_euler, metres_per_unit, positions_from_kinematics, zup_from_yup
from occupose.io.mocap import Clip

#: The CMU ASF length unit in metres (the CMU ASF files declare ``length 0.45``).
CMU_UNIT = 0.0254 / 0.45

_SKELETON_STYLES = {
    # source: (joint names that identify it, metres per file unit)
    "cmu": (("LeftUpLeg", "RightUpLeg", "LeftArm", "RightArm", "Neck1", "Head"), CMU_UNIT),
    "bandai": (("UpperLeg_L", "UpperLeg_R", "UpperArm_L", "UpperArm_R", "Neck", "Head"), 0.01),
}

_CHANNELS = ("Xposition", "Yposition", "Zposition", "Xrotation", "Yrotation", "Zrotation")


class _Tokens:
    """Whitespace tokens of a text with their line numbers, for error messages."""

    def __init__(self, text: str, path: Path):
        self.path = path
        self.items = [(tok, n) for n, line in enumerate(text.splitlines(), 1) for tok in line.split()]
        self.pos = 0
        self.last_line = text.count("\n") + 1

    def error(self, message: str, line: int | None = None) -> ValueError:
        if line is None:
            line = self.items[self.pos][1] if self.pos < len(self.items) else self.last_line
        return ValueError(f"{self.path}:{line}: malformed BVH: {message}")

    def next(self, what: str) -> tuple[str, int]:
        if self.pos >= len(self.items):
            raise self.error(f"expected {what}, got the end of the HIERARCHY section")
        item = self.items[self.pos]
        self.pos += 1
        return item

    def expect(self, word: str) -> int:
        tok, line = self.next(repr(word))
        if tok != word:
            raise self.error(f"expected {word!r}, got {tok!r}", line)
        return line

    def number(self, what: str, kind=float):
        tok, line = self.next(what)
        try:
            return kind(tok)
        except ValueError:
            raise self.error(f"expected {what}, got {tok!r}", line) from None


def load_bvh(path, units="auto") -> Clip:
    """Load a BVH file into a :class:`Clip` (world metres, z up).

    path : str or Path of a ``.bvh`` file (y up, as BVH files are).
        fps is 1 / ``Frame Time``, snapped to a whole number within 0.001.
    units : ``"auto"`` (by skeleton style, see the module docstring) or metres per file unit.

    Raises FileNotFoundError for a missing file, ValueError naming the file and line for
    malformed input, and ValueError asking for ``units`` when ``"auto"`` does not know the
    skeleton.
    """
    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"BVH file {path} does not exist")
    text = path.read_text(errors="replace")
    head, sep, motion = text.partition("MOTION")
    if not sep:
        raise ValueError(f"{path}: malformed BVH: no MOTION section")
    tokens = _Tokens(head, path)
    tokens.expect("HIERARCHY")
    names, parents, offsets, channels = [], [], [], []
    _parse_bvh_joint(tokens, "ROOT", -1, names, parents, offsets, channels)
    if tokens.pos != len(tokens.items):
        raise tokens.error(f"expected MOTION after the root joint, got {tokens.items[tokens.pos][0]!r}")

    num_channels = sum(len(c) for c in channels)
    motion_line0 = head.count("\n") + 1
    data, frame_time = _parse_bvh_motion(motion, num_channels, path, motion_line0)

    source = next((s for s, (need, _) in _SKELETON_STYLES.items() if set(need) <= set(names)), "bvh")
    scale = _units_for(units, source, path)

    num_frames = data.shape[0]
    offsets_t = np.broadcast_to(np.asarray(offsets, dtype=np.float64), (num_frames, len(names), 3)).copy()
    locals_ = []
    column = 0
    for j, chans in enumerate(channels):
        letters, rot_cols = "", []
        for k, chan in enumerate(chans):
            axis = "xyz".index(chan[0].lower())
            if chan.endswith("position"):
                offsets_t[:, j, axis] = data[:, column + k]
            else:
                letters += chan[0].lower()
                rot_cols.append(column + k)
        locals_.append(matrices_from_euler(letters, data[:, rot_cols], degrees=True, intrinsic=True))
        column += len(chans)
    parents_arr = np.asarray(parents, dtype=np.int64)
    positions = positions_from_kinematics(parents_arr, offsets_t, locals_)
    return Clip(
        names=tuple(names),
        parents=parents_arr,
        fps=_fps_from_frame_time(frame_time),
        positions=zup_from_yup(positions) * scale,
        source=source,
    )


def _parse_bvh_joint(tokens: _Tokens, keyword: str, parent: int, names, parents, offsets, channels):
    tokens.expect(keyword)
    name, line = tokens.next("a joint name")
    if name == "{":
        raise tokens.error(f"{keyword} without a name", line)
    if name in names:
        raise tokens.error(f"joint name {name!r} used twice", line)
    index = len(names)
    names.append(name)
    parents.append(parent)
    tokens.expect("{")
    tokens.expect("OFFSET")
    offsets.append([tokens.number("an OFFSET number") for _ in range(3)])
    chans = []
    if tokens.pos < len(tokens.items) and tokens.items[tokens.pos][0] == "CHANNELS":
        tokens.next("CHANNELS")
        count = tokens.number("a channel count", int)
        for _ in range(count):
            chan, line = tokens.next("a channel name")
            if chan not in _CHANNELS:
                raise tokens.error(f"unknown channel {chan!r}; valid: {', '.join(_CHANNELS)}", line)
            if chan in chans:
                raise tokens.error(f"channel {chan!r} repeated for joint {name!r}", line)
            chans.append(chan)
    channels.append(tuple(chans))
    while True:
        tok, line = tokens.next("JOINT, End Site or '}'")
        if tok == "}":
            return
        if tok == "JOINT":
            tokens.pos -= 1
            _parse_bvh_joint(tokens, "JOINT", index, names, parents, offsets, channels)
        elif tok == "End":
            tokens.expect("Site")
            tokens.expect("{")
            tokens.expect("OFFSET")
            end_offset = [tokens.number("an OFFSET number") for _ in range(3)]
            tokens.expect("}")
            end_name = f"{name}_end"
            suffix = 1
            while end_name in names:
                suffix += 1
                end_name = f"{name}_end{suffix}"
            names.append(end_name)
            parents.append(index)
            offsets.append(end_offset)
            channels.append(())
        else:
            raise tokens.error(f"expected JOINT, End Site or '}}', got {tok!r}", line)


def _parse_bvh_motion(motion: str, num_channels: int, path: Path, line0: int):
    """(frames (T, C) float64, frame time s) from the text after ``MOTION``."""
    lines = motion.splitlines()

    def header(i: int, label: str) -> str:
        if i >= len(lines) or not lines[i].strip().startswith(label):
            got = lines[i].strip() if i < len(lines) else "end of file"
            raise ValueError(f"{path}:{line0 + i}: malformed BVH: expected {label!r}, got {got!r}")
        return lines[i].split(":", 1)[1].strip()

    # lines[0] is the rest of the MOTION line.
    try:
        num_frames = int(header(1, "Frames:"))
        frame_time = float(header(2, "Frame Time:"))
    except ValueError as err:
        if "malformed" in str(err):
            raise
        raise ValueError(f"{path}:{line0 + 1}: malformed BVH: bad Frames/Frame Time value ({err})") from None
    if num_frames < 1 or not frame_time > 0:
        raise ValueError(f"{path}:{line0 + 1}: malformed BVH: need Frames >= 1 and Frame Time > 0, "
                         f"got {num_frames} and {frame_time}")
    rows = []
    for i in range(3, len(lines)):
        values = lines[i].split()
        if not values:
            continue
        if len(values) != num_channels:
            raise ValueError(f"{path}:{line0 + i}: malformed BVH: expected {num_channels} values "
                             f"(the channels of the hierarchy), got {len(values)}")
        try:
            rows.append([float(v) for v in values])
        except ValueError:
            raise ValueError(f"{path}:{line0 + i}: malformed BVH: non-numeric value in frame") from None
    if len(rows) != num_frames:
        raise ValueError(f"{path}:{line0 + 1}: malformed BVH: header says {num_frames} frames, "
                         f"file has {len(rows)}")
    return np.asarray(rows, dtype=np.float64).reshape(num_frames, num_channels), frame_time


def _fps_from_frame_time(frame_time: float) -> float:
    """1 / frame_time, snapped to a whole number when the file rounded it (0.0083333 -> 120)."""
    fps = 1.0 / frame_time
    return float(round(fps)) if abs(fps - round(fps)) < 1e-3 else fps


def _units_for(units, source: str, path: Path) -> float:
    if isinstance(units, str) and units == "auto":
        if source not in _SKELETON_STYLES:
            raise ValueError(
                f"{path}: cannot pick units automatically for an unknown skeleton (neither CMU- "
                f"nor Bandai-style joint names); pass units= metres per file unit, e.g. 0.01 for cm"
            )
        return _SKELETON_STYLES[source][1]
    return metres_per_unit(units)
