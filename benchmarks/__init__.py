"""Speed and accuracy benchmarks (``make bench``): printed as tables, saved under results/."""

from __future__ import annotations

import time

from occupose._numba import configure

configure()  # before any benchmark imports numba: kernels cached, idle OpenMP threads asleep

from occupose.evaluation.report import markdown_table  # noqa: E402


def median_seconds(function, repeats: int, warmup: int = 3, clock=time.perf_counter) -> tuple[float, float]:
    """(median, min) seconds of ``repeats`` calls of ``function()`` after ``warmup`` calls."""
    for _ in range(warmup):
        function()
    times = []
    for _ in range(repeats):
        start = clock()
        function()
        times.append(clock() - start)
    times.sort()
    return times[len(times) // 2], times[0]


def median_ms(function, repeats: int, warmup: int = 3, clock=time.perf_counter) -> tuple[float, float]:
    """(median, min) milliseconds per call, as :func:`median_seconds`."""
    median, best = median_seconds(function, repeats, warmup, clock)
    return 1e3 * median, 1e3 * best


def format_table(title: str, rows: list[dict]) -> str:
    """A markdown section: the title as a heading, then the table (occupose.evaluation.report's
    writer) of benchmark rows (dicts with the same keys), floats to 2 decimals."""
    cells = [[f"{v:.2f}" if isinstance(v, float) else str(v) for v in row.values()] for row in rows]
    return f"### {title}\n\n" + markdown_table(list(rows[0]), cells)


def print_table(title: str, rows: list[dict]) -> None:
    print(format_table(title, rows))
