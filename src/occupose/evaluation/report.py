"""Tables of the evaluation, all written by one markdown table writer (`markdown_table`).

Table I of the occupancy paper is `table_i_markdown`: one line per sequence and method, the
columns `TABLE_COLUMNS` (a `TableRow`'s cells, `table_i_cells`), the best value of each
column per sequence in bold. Numbers are printed with `number_cell` ("n/a" for NaN).
"""

from __future__ import annotations

import math
from typing import Iterable, Mapping, Sequence

from occupose.evaluation.errors import TableRow

#: Column headings of Table I, plus the coverage of the frames with ground truth.
TABLE_COLUMNS: tuple[str, ...] = (
    "<10cm [%]", "<15cm [%]", "<20cm [%]", ">20cm [%]",
    "Avg Err [cm]", "Std Dev [cm]", "Status", "Coverage [%]",
)
# TableRow attribute behind each column, and whether a higher value is better (None: not ranked).
_COLUMN_FIELDS: tuple[tuple[str, bool | None], ...] = (
    ("under10", True), ("under15", True), ("under20", True), ("over20", False),
    ("mean_cm", False), ("std_cm", False), ("fail", None), ("coverage", True),
)


# --------------------------------------------------------------------------- the table writer


def markdown_table(header: Sequence[str], rows: Iterable[Sequence[str]], *, text_columns: int | None = None) -> str:
    """A markdown table: the header line, the rule, one line per row (no trailing newline).

    Parameters
    ----------
    header : the column headings.
    rows : the cells of each row, as strings, one per heading.
    text_columns : the first ``text_columns`` columns hold text (rule ``---``), the others
        numbers, right-aligned (rule ``---:``); None: no alignment (every rule ``---``).
    """
    header = [str(cell) for cell in header]
    rule = ["---"] * len(header) if text_columns is None else \
        ["---"] * text_columns + ["---:"] * (len(header) - text_columns)
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join(rule) + "|"]
    for row in rows:
        if len(row) != len(header):
            raise ValueError(f"a row of {len(header)} columns {header} has {len(row)} cells: {list(row)}")
        lines.append("| " + " | ".join(row) + " |")
    return "\n".join(lines)


def number_cell(value: float, digits: int = 2) -> str:
    """``value`` with ``digits`` decimals, or "n/a" for NaN."""
    return "n/a" if math.isnan(value) else f"{value:.{digits}f}"


# --------------------------------------------------------------------------- Table I


def table_i_cells(row: TableRow) -> list[str]:
    """The cells of ``row`` under `TABLE_COLUMNS`: percentages and centimetres with 2
    decimals, "n/a" where NaN, the status "ok" or "FAIL"."""
    return [
        ("FAIL" if row.fail else "ok") if name == "fail" else number_cell(getattr(row, name))
        for name, _ in _COLUMN_FIELDS
    ]


def table_i_markdown(
    groups: Mapping[str, Mapping[str, TableRow]],
    *,
    group_header: str = "sequence",
    name_header: str = "method",
) -> str:
    """Markdown table in the layout of Table I, the best value of each group in bold.

    Parameters
    ----------
    groups : ``{group: {name: TableRow}}``, e.g. sequences, each holding the methods
        compared on it. Within a group, the best value of each column is bold (every
        row that ties on the printed value): lowest for ``>20cm``, ``Avg Err`` and
        ``Std Dev``, highest for ``<10/15/20cm`` and ``Coverage``. Status is not ranked.
    group_header, name_header : headings of the first two columns.

    Returns
    -------
    The markdown table (no trailing newline); a group's name only on its first line.
    """
    lines = []
    for group, rows in groups.items():
        cells = {name: table_i_cells(row) for name, row in rows.items()}
        for column, (field, higher_better) in enumerate(_COLUMN_FIELDS):
            if higher_better is None:
                continue
            printed = {
                name: round(getattr(row, field), 2)
                for name, row in rows.items()
                if not math.isnan(getattr(row, field))
            }
            if not printed:
                continue
            best = max(printed.values()) if higher_better else min(printed.values())
            for name, value in printed.items():
                if value == best:
                    cells[name][column] = f"**{cells[name][column]}**"
        for index, (name, row_cells) in enumerate(cells.items()):
            lines.append([str(group) if index == 0 else "", str(name), *row_cells])
    return markdown_table([group_header, name_header, *TABLE_COLUMNS], lines, text_columns=2)
