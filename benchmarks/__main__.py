"""Run every benchmark, print its table and save them all to benchmarks/results/latest.md."""

from __future__ import annotations

import os
import platform
import time
from pathlib import Path

from benchmarks import (
    bench_against,
    bench_bag,
    bench_blobs,
    bench_body,
    bench_fit,
    bench_filters,
    bench_grid,
    bench_likelihood,
    bench_mkv,
    bench_render,
    bench_robustness,
    bench_speed,
    bench_stages,
    bench_startup,
    bench_tracking,
    format_table,
)

BENCHMARKS = [bench_render, bench_grid, bench_blobs, bench_body, bench_likelihood, bench_filters, bench_tracking, bench_speed, bench_stages, bench_startup,
              bench_robustness, bench_fit, bench_bag, bench_mkv, bench_against]


def machine() -> str:
    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return f"{cpu}, {os.cpu_count()} cores, Python {platform.python_version()}, {platform.system()}"


def main() -> None:
    sections = [f"# occupose benchmarks\n\nMachine: {machine()}  \nDate: {time.strftime('%Y-%m-%d')}\n"]
    for module in BENCHMARKS:
        tables = [(module.TITLE, module.run)]
        if hasattr(module, "ACCURACY_TITLE"):  # a second, accuracy table
            tables.append((module.ACCURACY_TITLE, module.run_accuracy))
        for title, run in tables:
            table = format_table(title, run())
            print(table + "\n", flush=True)
            sections.append(table + "\n")
    out = Path(__file__).parent / "results" / "latest.md"
    out.parent.mkdir(exist_ok=True)
    out.write_text("\n".join(sections))
    print(f"saved {out}")


if __name__ == "__main__":
    main()
