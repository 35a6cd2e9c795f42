"""The long joint table: one CSV row per frame, person (or track) and joint (DESIGN.md "Data contracts").

Two files share the format, each a *kind* of table (`KINDS`):

``groundtruth.csv`` (kind ``"groundtruth"``), a recording's ground truth
    ``frame,person,joint,x,y,z[,visible]``; without the ``visible`` column every row is
    visible. Written with 5 decimals (10 micrometres).
``tracks.csv`` (kind ``"tracks"``), a tracker's output
    ``frame,track,joint,x,y,z,visible``; ``visible`` is 1 where the joint's part was
    estimated from data in that frame, 0 where it was carried from memory. Written with
    6 decimals (micrometres), and ended by a comment line with the number of rows,
    ``# end: 585 rows`` (`END_LINE`; ``pandas.read_csv(path, comment="#")`` skips it), so
    that a file cut short at a line boundary is refused rather than read as short tracks.

Coordinates are world metres; joints are named as in `occupose.joints.JOINTS`. A joint
without a row is unknown. In memory a table is a *joint table*::

    {id (int): (joints (T, 15, 3) float64 metres, NaN where unknown,
                visible (T, 15) bool, False where unknown)}

over the T frames of the recording. `write_joint_table` writes one row per frame, id and
known joint, ordered by frame, then id, then canonical joint order; `read_joint_table`
gives the ids in the order of their first row. Every fault of a file is a
`JointTableError` (a ValueError) naming the file and, for a row, its line. The reader
takes a UTF-8 byte-order mark (a file saved by a spreadsheet), and checks an end line in
either kind where there is one; only in ``tracks.csv`` is it required.
"""

from __future__ import annotations

import csv
import io
import math
import os
import re
import reprlib
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping

import numpy as np

from occupose._validate import bool_array, float_array
from occupose.io._files import read_file_bytes
from occupose.io.output import atomic_path
from occupose.joints import JOINT_INDEX, JOINTS, NUM_JOINTS

#: A joint table in memory: {id: (joints (T, 15, 3) float64 metres, visible (T, 15) bool)}.
JointTable = dict[int, tuple[np.ndarray, np.ndarray]]


class JointTableError(ValueError):
    """A joint table file is malformed; the message names the file and, for a row, its line."""


@dataclass(frozen=True)
class TableKind:
    """The variant of the format that one file uses.

    name : "groundtruth" or "tracks"
    id_column : heading of the second column ("person" or "track")
    visible_optional : whether a file may leave out the ``visible`` column (then all rows are visible)
    decimals : digits after the point of the coordinates written
    end_line : whether the writer ends the file with the end line (`END_LINE`) and the
        reader requires it (for a kind without, an end line is checked when present)
    """

    name: str
    id_column: str
    visible_optional: bool
    decimals: int
    end_line: bool

    @property
    def columns(self) -> tuple[str, ...]:
        """The full header, ``visible`` included."""
        return ("frame", self.id_column, "joint", "x", "y", "z", "visible")


#: The two kinds of joint table, by name.
KINDS: dict[str, TableKind] = {
    "groundtruth": TableKind("groundtruth", "person", visible_optional=True, decimals=5, end_line=False),
    "tracks": TableKind("tracks", "track", visible_optional=False, decimals=6, end_line=True),
}
#: Header of ``groundtruth.csv`` (its last column, ``visible``, may be left out).
GROUNDTRUTH_COLUMNS: tuple[str, ...] = KINDS["groundtruth"].columns
#: Header of ``tracks.csv``.
TRACKS_COLUMNS: tuple[str, ...] = KINDS["tracks"].columns
#: The last line of a ``tracks.csv``, a comment with its number of rows (the header not
#: counted): a file cut short, even at a line boundary, lacks it or has too few rows.
END_LINE = "# end: {rows} rows"
_END_PATTERN = re.compile(r"# end: ([0-9]{1,18}) rows")

# How a row's cells are shown in a message: long ones shortened (a quote left open takes
# in the rest of the file).
_SHOWN = reprlib.Repr()
_SHOWN.maxstring, _SHOWN.maxlist = 40, 10


class UnmarkedTableWarning(UserWarning):
    """A joint table read without the end line its kind is written with (`END_LINE`)."""


def _kind(kind: str) -> TableKind:
    try:
        return KINDS[kind]
    except (KeyError, TypeError):
        raise ValueError(f"unknown joint table kind {kind!r}; valid: {', '.join(KINDS)}") from None


# --------------------------------------------------------------------------- writing


def write_joint_table(path: str | os.PathLike, table: Mapping[int, tuple[Any, Any]], kind: str) -> Path:
    """Write a joint table as CSV (module docstring), replacing the file if present.

    Parameters
    ----------
    path : the csv file; written under a temporary name first, then renamed, so that it
        is never left half-written.
    table : ``{id (int): (joints (T, 15, 3) float metres, visible (T, 15) bool)}``, all
        with the same T; each joint fully finite (written) or fully NaN (unknown, no row).
    kind : "groundtruth" or "tracks" (`KINDS`): the id column's name and the decimals.

    Returns
    -------
    The path written. Raises ValueError for a table that breaks the rules above.
    """
    spec = _kind(kind)
    if not isinstance(table, Mapping):
        raise ValueError(f"the {spec.name} table must be a mapping id -> (joints, visible), got {type(table).__name__}")
    checked = []
    num_frames = None
    for ident, value in table.items():
        what = f"{spec.id_column} {ident}"
        if isinstance(ident, bool) or not isinstance(ident, (int, np.integer)):
            raise ValueError(f"{spec.id_column} ids must be integers, got {ident!r}")
        if not isinstance(value, tuple) or len(value) != 2:
            raise ValueError(f"{what}: expected a (joints, visible) pair, got {type(value).__name__}")
        joints = float_array(value[0], f"{what} joints", (None, NUM_JOINTS, 3))
        visible = bool_array(value[1], f"{what} visible", joints.shape[:2])
        finite = np.isfinite(joints)
        known = finite.all(axis=2)
        if np.any(np.isinf(joints)) or np.any(finite.any(axis=2) & ~known):
            raise ValueError(
                f"{what} joints must be fully finite or fully NaN per joint; some have inf or a partial NaN"
            )
        if num_frames is not None and joints.shape[0] != num_frames:
            raise ValueError(
                f"every {spec.id_column} must have the same number of frames, got {num_frames} and {joints.shape[0]}"
            )
        num_frames = joints.shape[0]
        checked.append((int(ident), joints.tolist(), visible.tolist(), known.tolist()))
    checked.sort(key=lambda item: item[0])
    digits = spec.decimals
    lines = [",".join(spec.columns) + "\n"]
    for frame in range(num_frames or 0):
        for ident, joints, visible, known in checked:
            for joint, ((x, y, z), flag, ok) in enumerate(zip(joints[frame], visible[frame], known[frame])):
                if ok:
                    lines.append(f"{frame},{ident},{JOINTS[joint]},{x:.{digits}f},{y:.{digits}f},{z:.{digits}f},"
                                 f"{int(flag)}\n")
    if spec.end_line:
        lines.append(END_LINE.format(rows=len(lines) - 1) + "\n")
    path = Path(path)
    with atomic_path(path) as temporary, temporary.open("w", newline="", encoding="utf-8") as handle:
        handle.writelines(lines)
    return path


def write_tracks_csv(path: str | os.PathLike, tracks: Mapping[int, tuple[Any, Any]]) -> Path:
    """Write a tracker's output as ``tracks.csv``: `write_joint_table` of kind "tracks"."""
    return write_joint_table(path, tracks, "tracks")


# --------------------------------------------------------------------------- reading


def read_joint_table(path: str | os.PathLike, num_frames: int, kind: str, *,
                     allow_unmarked: bool = False) -> JointTable:
    """Read a joint table CSV file (module docstring).

    Parameters
    ----------
    path : the csv file (UTF-8, a byte-order mark allowed).
    num_frames : int >= 0, number of frames T of the recording; every row's frame must be in [0, T).
    kind : "groundtruth" or "tracks" (`KINDS`): the header expected.
    allow_unmarked : read a file of a kind written with an end line (tracks) that has
        none, with an `UnmarkedTableWarning` (a file another program wrote); by default
        it is an error, since a file cut short at a line boundary looks the same.

    Returns
    -------
    ``{id: (joints (T, 15, 3) float64 metres, visible (T, 15) bool)}``, ids in the order
    of their first row; joints without a row are NaN and not visible.

    Raises
    ------
    FileNotFoundError when the file is missing; JointTableError, naming the file and
    line, for a file that cannot be read (a folder, a device, permission denied) or is
    not UTF-8 CSV, a wrong header or column count, a non-integer frame or id, a frame
    out of range, an unknown joint, a non-numeric or non-finite coordinate, a
    ``visible`` other than 0/1, a repeated row, and an end line (`END_LINE`) missing
    (tracks, unless allowed), not last or with another number of rows.
    """
    spec = _kind(kind)
    if isinstance(num_frames, bool) or not isinstance(num_frames, (int, np.integer)) or num_frames < 0:
        raise ValueError(f"num_frames must be an integer >= 0, got {num_frames!r}")
    path = Path(path)
    try:
        data = read_file_bytes(path, JointTableError, f"a {spec.name} CSV file")
    except FileNotFoundError:
        raise FileNotFoundError(f"{path}: no such {spec.name} file") from None
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as error:
        raise JointTableError(
            f"{path}: not a readable UTF-8 CSV file ({error.reason} at byte {error.start})"
        ) from None
    reader = csv.reader(io.StringIO(text, newline=""))
    try:
        table, rows, end = _read_rows(reader, path, int(num_frames), spec)
    except csv.Error as error:
        raise JointTableError(f"{path}, line {reader.line_num}: not a readable UTF-8 CSV file ({error})") from None
    if end is None and spec.end_line:
        message = (f"{path}: no end line ('{END_LINE.format(rows=rows)}') after its {rows} rows; occupose ends "
                   f"every {spec.name} file it writes with one, and a file cut short at a line boundary looks "
                   "like this")
        if not allow_unmarked:
            raise JointTableError(f"{message}. A file another program wrote can be read without it "
                                  "(allow_unmarked, occupose score --unmarked)")
        warnings.warn(f"{message}: read as it is", UnmarkedTableWarning, stacklevel=2)
    if end is not None and end != rows:
        raise JointTableError(f"{path}: its end line says {end} rows, the file has {rows}: rows are missing "
                              "or were added")
    return table


def read_tracks_csv(path: str | os.PathLike, num_frames: int, *, allow_unmarked: bool = False) -> JointTable:
    """Read a tracker's ``tracks.csv``: `read_joint_table` of kind "tracks"."""
    return read_joint_table(path, num_frames, "tracks", allow_unmarked=allow_unmarked)


def _read_rows(reader, path: Path, num_frames: int, spec: TableKind) -> tuple[JointTable, int, int | None]:
    """(the table, its number of rows, the number of rows its end line gives or None)."""
    header = next(reader, None)
    columns = [cell.strip() for cell in header] if header is not None else []
    allowed = [list(spec.columns)] + ([list(spec.columns[:-1])] if spec.visible_optional else [])
    if columns not in allowed:
        raise JointTableError(
            f"{path}: bad header {columns}{' (an empty file)' if header is None else ''}; expected columns "
            f"{','.join(spec.columns)}{' (visible optional)' if spec.visible_optional else ''}"
        )
    has_visible = len(columns) == len(spec.columns)
    rows: dict[int, tuple[list[int], list[int], list[list[float]], list[bool]]] = {}
    seen: set[tuple[int, int, int]] = set()
    end = None
    while True:
        first = reader.line_num + 1  # a row's first line: a quoted cell can span lines
        cells = next(reader, None)
        if cells is None:
            break
        if not cells:
            continue
        where = f"{path}, line {first}" if first == reader.line_num else f"{path}, lines {first}-{reader.line_num}"
        if end is not None:
            raise JointTableError(f"{where}: text after the end line; it must be the last line")
        if cells[0].startswith("#"):
            marker = _END_PATTERN.fullmatch(",".join(cells).strip())
            if marker is None:
                raise JointTableError(f"{where}: a comment line; the only one allowed is the last line, "
                                      f"'{END_LINE.format(rows='N')}', got {','.join(cells)!r}")
            end = int(marker.group(1))
            continue
        if len(cells) != len(columns):
            raise JointTableError(f"{where}: expected {len(columns)} columns, got {len(cells)}: {_SHOWN.repr(cells)}")
        frame = _integer(cells[0], "frame", where)
        ident = _integer(cells[1], spec.id_column, where)
        if not 0 <= frame < num_frames:
            raise JointTableError(
                f"{where}: frame {frame} out of range; the recording has frames 0..{num_frames - 1}"
            )
        name = cells[2].strip()
        joint = JOINT_INDEX.get(name)
        if joint is None:
            raise JointTableError(f"{where}: unknown joint {name!r}; valid joints: {', '.join(JOINTS)}")
        position = [_coordinate(cells[3 + k], axis, where) for k, axis in enumerate("xyz")]
        flag = True
        if has_visible:
            flag_text = cells[6].strip()
            if flag_text not in ("0", "1"):
                raise JointTableError(f"{where}: visible must be 0 or 1, got {cells[6]!r}")
            flag = flag_text == "1"
        key = (frame, ident, joint)
        if key in seen:
            raise JointTableError(
                f"{where}: duplicate row for frame {frame}, {spec.id_column} {ident}, joint {name}"
            )
        seen.add(key)
        frames, joints, positions, flags = rows.setdefault(ident, ([], [], [], []))
        frames.append(frame)
        joints.append(joint)
        positions.append(position)
        flags.append(flag)
    table: JointTable = {}
    for ident, (frames, joints, positions, flags) in rows.items():
        points = np.full((num_frames, NUM_JOINTS, 3), np.nan)
        points[frames, joints] = np.array(positions, dtype=np.float64)
        visible = np.zeros((num_frames, NUM_JOINTS), dtype=bool)
        visible[frames, joints] = flags
        table[ident] = (points, visible)
    return table, len(seen), end


def _integer(text: str, name: str, where: str) -> int:
    try:
        return int(text)
    except ValueError:
        raise JointTableError(f"{where}: {name} must be an integer, got {text!r}") from None


def _coordinate(text: str, name: str, where: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise JointTableError(f"{where}: {name} must be a number, got {text!r}") from None
    if not math.isfinite(value):
        raise JointTableError(f"{where}: {name} must be finite, got {text!r}")
    return value
