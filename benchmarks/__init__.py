"""Speed and accuracy benchmarks (``make bench``): printed as tables, saved under results/."""

from __future__ import annotations


def format_table(title: str, rows: list[dict]) -> str:
    """A markdown table of benchmark rows (dicts with the same keys), floats to 2 decimals."""
    keys = list(rows[0])
    lines = [f"### {title}", "", "| " + " | ".join(keys) + " |", "|" + "---|" * len(keys)]
    for row in rows:
        cells = [f"{v:.2f}" if isinstance(v, float) else str(v) for v in row.values()]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def print_table(title: str, rows: list[dict]) -> None:
    print(format_table(title, rows))
