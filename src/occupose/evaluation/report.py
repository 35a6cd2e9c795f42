"""Tables of the evaluation: Table I as plain text and as markdown."""

from __future__ import annotations

import math
from typing import Mapping

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



def _cell(value: float) -> str:
    return "n/a" if math.isnan(value) else f"{value:.2f}"


def _cells(row: TableRow) -> list[str]:
    return [
        ("FAIL" if row.fail else "ok") if name == "fail" else _cell(getattr(row, name))
        for name, _ in _COLUMN_FIELDS
    ]


def format_table(rows: Mapping[str, TableRow], *, name_header: str = "method") -> str:
    """Plain-text table in the layout of Table I, columns aligned.

    Parameters
    ----------
    rows : ``{name: TableRow}`` in display order.
    name_header : heading of the first column.

    Returns
    -------
    The table as lines joined by newlines (no trailing newline).
    """
    header = [name_header, *TABLE_COLUMNS]
    body = [[str(name), *_cells(row)] for name, row in rows.items()]
    widths = [max(len(line[i]) for line in [header, *body]) for i in range(len(header))]

    def line(cells: list[str]) -> str:
        first = cells[0].ljust(widths[0])
        rest = (cell.rjust(width) for cell, width in zip(cells[1:], widths[1:]))
        return "  ".join([first, *rest]).rstrip()

    return "\n".join([line(header), *(line(cells) for cells in body)])


def markdown_table(
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
    The markdown table (no trailing newline).
    """
    header = [group_header, name_header, *TABLE_COLUMNS]
    rule = ["---"] * 2 + ["---:"] * len(TABLE_COLUMNS)
    lines = ["| " + " | ".join(header) + " |", "|" + "|".join(rule) + "|"]
    for group, rows in groups.items():
        cells = {name: _cells(row) for name, row in rows.items()}
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
            first = str(group) if index == 0 else ""
            lines.append("| " + " | ".join([first, str(name), *row_cells]) + " |")
    return "\n".join(lines)
