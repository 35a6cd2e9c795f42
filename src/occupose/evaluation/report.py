"""What an evaluation reports: its tables, ``results.csv``, ``report.md`` and the plots.

- `markdown_table` is the one table writer; Table I of the occupancy paper is
  `table_i_markdown` (columns `TABLE_COLUMNS`, a row's cells `table_i_cells`, the best value
  of each column per sequence in bold); numbers are printed by `number_cell` ("n/a" for NaN).
- The runs of occupose.evaluation.evaluate (`RunResult`) are averaged per sequence and
  method (`mean_row`, `table_rows`, `per_joint_table`, `speed_table`), listed one row per run
  and person (`results_table`, `write_results_csv`), reported (`report_markdown`) and
  plotted (`write_plots`, with matplotlib's Figure API: no pyplot, no global backend).

Averaging rule: a row of the report's tables is the mean over the runs of each number
(mean, std, percentages, coverage; a run without any estimate has no mean or std and is
left out of those, and FAILs), and its status is FAIL when *any* run FAILs.
"""

from __future__ import annotations

import csv
import math
import os
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Iterable, Mapping, Sequence

import numpy as np

from occupose.evaluation.errors import TableRow
from occupose.evaluation.matching import Score
from occupose.evaluation.pixels import MIN_ARM_POINTS
from occupose.io.recording import Recording
from occupose.joints import JOINTS


@dataclass(frozen=True)
class RunResult:
    """One method on one scenario with one seed.

    score : the Table I scores of every ground-truth person (occupose.evaluation.matching.Score)
    person_ids : ground-truth person ids, in the order of ``score.persons``
    frame_errors : (T, P) float64, metres: D_t of each person over the joints the matched
        track reports (NaN where the person is not counted or has no estimate)
    fps : frames per second of tracking, start-up excluded
    seconds : seconds per stage, ``total``, ``startup`` and ``warm_up`` (TrackingResult.seconds)
    arm_epsilon, truth_arm_epsilon : (T, P) float64, metres, or None for a recording
        without part labels: the second paper's arm error (pixels.arm_epsilons) of each
        person's matched track (NaN without an estimate) and of its ground truth
    """

    scenario: str
    method: str
    seed: int
    score: Score
    person_ids: tuple[int, ...]
    frame_errors: np.ndarray
    fps: float
    seconds: dict[str, float] = field(default_factory=dict)
    arm_epsilon: np.ndarray | None = None
    truth_arm_epsilon: np.ndarray | None = None


#: A frame is shaded in the error plots where at least this share of a present person's
#: joints is hidden in the ground truth (light), or at least MOSTLY_HIDDEN (dark).
PARTLY_HIDDEN = 0.25
MOSTLY_HIDDEN = 0.75
#: FAIL threshold drawn in the error plots, cm (errors.is_fail).
FAIL_THRESHOLD_CM = 25.0

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
        for column, (name_of_field, higher_better) in enumerate(_COLUMN_FIELDS):
            if higher_better is None:
                continue
            printed = {
                name: round(getattr(row, name_of_field), 2)
                for name, row in rows.items()
                if not math.isnan(getattr(row, name_of_field))
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


# --------------------------------------------------------------------------- averages over runs


def mean_row(rows: Sequence[TableRow]) -> TableRow:
    """The mean of Table I rows over runs: each number averaged over the runs that have
    it (NaN when none does), FAIL when any run FAILs (at the earliest run's FAIL frame),
    frames rounded."""
    if not rows:
        raise ValueError("mean_row needs at least one row")
    values = {}
    for f in fields(TableRow):
        column = [getattr(r, f.name) for r in rows]
        if f.name == "fail":
            values[f.name] = any(column)
        elif f.name == "fail_frame":  # the earliest FAIL among the runs
            values[f.name] = min((v for v in column if v is not None), default=None)
        elif f.name == "frames":
            values[f.name] = int(round(float(np.mean(column))))
        else:
            finite = [v for v in column if not math.isnan(v)]
            values[f.name] = float(np.mean(finite)) if finite else math.nan
    return TableRow(**values)


def _groups(runs: Sequence[RunResult]) -> dict[str, dict[str, list[tuple[RunResult, int]]]]:
    """{sequence label: {method: [(run, person index)]}} in run order; a scenario with
    several people has one sequence per person ("two_people_crossing, person 2")."""
    groups: dict[str, dict[str, list]] = {}
    for run in runs:
        for index, pid in enumerate(run.person_ids):
            label = run.scenario if len(run.person_ids) == 1 else f"{run.scenario}, person {pid}"
            groups.setdefault(label, {}).setdefault(run.method, []).append((run, index))
    return groups


def table_rows(runs: Sequence[RunResult], visible: bool = False) -> dict[str, dict[str, TableRow]]:
    """{sequence: {method: TableRow averaged over the runs (mean_row)}}; ``visible``:
    over the ground-truth-visible joints only."""
    which = "visible_joints" if visible else "all_joints"
    return {label: {method: mean_row([getattr(r.score.persons[i], which) for r, i in items])
                    for method, items in methods.items()}
            for label, methods in _groups(runs).items()}


def _seconds_keys(runs: Sequence[RunResult]) -> list[str]:
    keys = []
    for run in runs:
        keys += [k for k in run.seconds if k not in keys]
    return keys


def results_table(runs: Sequence[RunResult]) -> list[dict[str, object]]:
    """One dict per scenario, method, run (seed) and ground-truth person: Table I over all
    joints and over visible joints, the arm error of the track and of the ground truth,
    identity switches, frames/s, seconds per stage."""
    stage_keys = _seconds_keys(runs)
    rows = []
    for run in runs:
        for index, (person, pid) in enumerate(zip(run.score.persons, run.person_ids)):
            row: dict[str, object] = {"scenario": run.scenario, "method": run.method, "seed": run.seed,
                                      "person": pid, "track": "" if person.track is None else person.track}
            for prefix, table in (("", person.all_joints), ("visible_", person.visible_joints)):
                row |= {f"{prefix}mean_cm": table.mean_cm, f"{prefix}std_cm": table.std_cm,
                        f"{prefix}under10": table.under10, f"{prefix}under15": table.under15,
                        f"{prefix}under20": table.under20, f"{prefix}over20": table.over20,
                        f"{prefix}fail": int(table.fail), f"{prefix}frames": table.frames,
                        f"{prefix}coverage": table.coverage}
            row |= dict(zip(("arm_eps_cm", "truth_arm_eps_cm"), _arm_errors_cm(run, index)))
            row |= {"identity_switches": person.identity_switches,
                    "unmatched_tracks": len(run.score.unmatched_tracks), "fps": run.fps}
            row |= {f"seconds_{k}": run.seconds.get(k, math.nan) for k in stage_keys}
            rows.append(row)
    return rows


def _arm_errors_cm(run: RunResult, person: int) -> tuple[float, float]:
    """Mean arm error (pixels.arm_epsilons) over the frames that have one, cm, of the
    person's track and of its ground truth; NaN without one (or without part labels)."""
    if run.arm_epsilon is None:
        return math.nan, math.nan
    means = []
    for values in (run.arm_epsilon[:, person], run.truth_arm_epsilon[:, person]):
        finite = values[np.isfinite(values)]
        means.append(100.0 * float(finite.mean()) if finite.size else math.nan)
    return means[0], means[1]


def write_results_csv(path: str | os.PathLike, runs: Sequence[RunResult]) -> Path:
    """Write :func:`results_table` as csv (numbers with 4 decimals, NaN as empty)."""
    rows = results_table(runs)
    path = Path(path)
    with path.open("w", newline="", encoding="utf-8") as handle:
        if not rows:
            return path
        writer = csv.DictWriter(handle, fieldnames=list(rows[0]))
        writer.writeheader()
        for row in rows:
            writer.writerow({k: ("" if isinstance(v, float) and math.isnan(v) else
                                 f"{v:.4f}" if isinstance(v, float) else v) for k, v in row.items()})
    return path


def per_joint_table(runs: Sequence[RunResult]) -> dict[str, dict[str, float]]:
    """{joint: {method: mean error cm over scenarios, runs and people}} (NaN where no
    run of the method reports the joint)."""
    methods = list(dict.fromkeys(r.method for r in runs))
    out = {}
    for joint in JOINTS:
        out[joint] = {}
        for method in methods:
            values = [p.per_joint_cm.get(joint, math.nan) for r in runs if r.method == method for p in r.score.persons]
            finite = [v for v in values if not math.isnan(v)]
            out[joint][method] = float(np.mean(finite)) if finite else math.nan
    return out


def speed_table(runs: Sequence[RunResult]) -> dict[str, dict[str, float]]:
    """{method: {"fps": frames/s, "ms": ms/frame, "<stage> ms": ms/frame per stage}} over
    all runs of the method pooled (all frames over all seconds); fps and ms leave out the
    first (start-up) frame of each run, the stage times include it."""
    out = {}
    for method in dict.fromkeys(r.method for r in runs):
        mine = [r for r in runs if r.method == method]
        frames = sum(len(r.frame_errors) for r in mine)
        seconds = sum(r.seconds.get("total", math.nan) for r in mine)
        ms = 1000.0 * seconds / max(frames - len(mine), 1)
        entry = {"fps": 1000.0 / ms if ms > 0 else math.nan, "ms": ms}
        for key in _seconds_keys(mine):
            if key not in ("total", "startup", "warm_up"):
                entry[f"{key} ms"] = 1000.0 * sum(r.seconds.get(key, math.nan) for r in mine) / max(frames, 1)
        out[method] = entry
    return out


def _arm_section(runs: Sequence[RunResult], methods: list[str]) -> list[str]:
    """The report's lines on the second paper's arm error (none without part labels)."""
    rows = []
    for label, by_method in _groups(runs).items():
        means = {m: [_arm_errors_cm(r, i) for r, i in items] for m, items in by_method.items()}
        if all(math.isnan(v) for pairs in means.values() for pair in pairs for v in pair):
            continue
        tracked = {m: float(np.nanmean([a for a, _ in pairs])) if any(not math.isnan(a) for a, _ in pairs)
                   else math.nan for m, pairs in means.items()}
        finite = [v for v in tracked.values() if not math.isnan(v)]
        best = min(finite) if len(finite) > 1 else math.nan
        truth = next(t for pairs in means.values() for _, t in pairs)
        rows.append([label, *(f"**{number_cell(tracked[m])}**" if round(tracked.get(m, math.nan), 2) == round(best, 2)
                              else number_cell(tracked.get(m, math.nan)) for m in methods), number_cell(truth)])
    if not rows:
        return []
    return ["## Arm error: the second paper's epsilon [cm]", "",
            "Mean over the frames with at least "
            f"{MIN_ARM_POINTS} arm points seen and an estimate, and over the runs, of the mean distance from "
            "the person's arm points (upper arms, forearms, hands in the part labels; every camera) to the "
            "nearest arm bone of the skeleton (occupose.evaluation.pixels). Lowest per sequence in bold. The points lie "
            "on the surface, so the ground truth's skeleton has an epsilon too (last column): what a perfect "
            "skeleton scores.", "",
            markdown_table(["sequence", *methods, "ground truth"], rows, text_columns=1), ""]


def report_markdown(runs: Sequence[RunResult], plots: Sequence[Path] = (), root: Path | None = None, *,
                    jobs: int | None = None, frames: dict[str, int] | None = None, procedural: bool = False) -> str:
    """The evaluation report (markdown): Table I over all joints (best value of each column
    per sequence in bold) and over visible joints, runs that FAIL, identity switches,
    per-joint errors, frames/s per method and the plots (paths relative to ``root``)."""
    seeds = sorted({r.seed for r in runs})
    methods = list(dict.fromkeys(r.method for r in runs))
    lines = ["# Evaluation", ""]
    lines.append(f"Methods {', '.join(methods)}; {len(seeds)} run(s) each (tracker seeds "
                 f"{', '.join(map(str, seeds))}); motion: {'procedural' if procedural else 'mocap where available'}.")
    if frames:
        lines.append("Frames: " + ", ".join(f"{s} {n}" for s, n in frames.items()) + ".")
    lines += ["", "Each value is the mean over the runs (runs without any estimate are left out of "
              "the mean and std); Status is FAIL when any run FAILs (the 2-second rolling mean of D_t "
              "exceeds 25 cm after the first second; occupose.evaluation.errors). Best value of each column per "
              "sequence in **bold**.", "", "## Table I: all joints", "", table_i_markdown(table_rows(runs)), "",
              "## Table I: ground-truth-visible joints only", "", table_i_markdown(table_rows(runs, visible=True)), ""]
    fails = []
    for label, by_method in _groups(runs).items():
        for method, items in by_method.items():
            failed = [r.seed for r, i in items if r.score.persons[i].all_joints.fail]
            if failed:
                fails.append(f"- {label}, {method}: {len(failed)} of {len(items)} runs (seeds "
                             f"{', '.join(map(str, failed))})")
    lines += ["Runs that FAIL:", "", *(fails or ["- none"]), ""]
    nobody = list(dict.fromkeys(r.scenario for r in runs if not r.person_ids))
    if nobody:
        lines += ["Nobody is in view in the ground truth of the frames evaluated (not scored; tracks found):", ""]
        for scenario in nobody:
            found = ", ".join(f"{r.method} seed {r.seed}: {len(r.score.unmatched_tracks)}"
                              for r in runs if r.scenario == scenario)
            lines.append(f"- {scenario} ({found})")
        lines.append("")
    switches = [[label, method, number_cell(float(np.mean([r.score.persons[i].identity_switches for r, i in items]))),
                 number_cell(float(np.mean([len(r.score.unmatched_tracks) for r, i in items])))]
                for label, by_method in _groups(runs).items() for method, items in by_method.items()]
    lines += ["## Identities", "", "Mean over the runs of the person's identity switches and of the "
              "tracks matched to no person.", "",
              markdown_table(["sequence", "method", "identity switches", "unmatched tracks"], switches, text_columns=1), ""]
    lines += _arm_section(runs, methods)
    joints = per_joint_table(runs)
    joint_rows = []
    for joint, values in joints.items():
        finite = [v for v in values.values() if not math.isnan(v)]
        best = min(finite) if finite else math.nan
        joint_rows.append([joint, *(f"**{number_cell(v)}**" if len(finite) > 1 and round(v, 2) == round(best, 2)
                                    else number_cell(v) for v in values.values())])
    lines += ["## Per-joint error [cm]", "", "Mean over scenarios, runs and people; lowest per joint in bold (when several methods report it); "
              "n/a: the method's model does not report the joint.", "",
              markdown_table(["joint", *methods], joint_rows, text_columns=1), ""]
    speeds = speed_table(runs)
    stage_columns = list(dict.fromkeys(k for v in speeds.values() for k in v if k.endswith(" ms")))
    speed_rows = [[m, number_cell(v["fps"], 1), number_cell(v["ms"], 1), *(number_cell(v.get(k, math.nan), 1) for k in stage_columns)]
                  for m, v in speeds.items()]
    timing = ("in parallel, one run per worker and core, one numba thread per worker" if (jobs or 1) > 1
              else "one run at a time with numba's default threads")
    lines += ["## Speed", "", f"Mean over all runs, timed {timing} (`occupose track` alone can be faster); "
              "the first frame (start-up, compilation) excluded; per-stage times include it.", "",
              markdown_table(["method", "frames/s", "ms/frame", *stage_columns], speed_rows, text_columns=1), ""]
    if plots:
        lines += ["## Plots", ""]
        for plot in plots:
            shown = Path(plot).relative_to(root) if root is not None else Path(plot)
            lines += [f"![{shown.stem}]({shown.as_posix()})", ""]
    return "\n".join(lines)


# --------------------------------------------------------------------------- plots


def intervals_from_mask(mask) -> list[tuple[int, int]]:
    """[start, stop) frame intervals where ``mask`` ((T,) bool) is true."""
    mask = np.asarray(mask, bool)
    if mask.ndim != 1:
        raise ValueError(f"mask must have shape (T,), got {mask.shape}")
    edges = np.diff(np.concatenate([[0], mask.astype(np.int8), [0]]))
    return list(zip(np.flatnonzero(edges == 1).tolist(), np.flatnonzero(edges == -1).tolist()))


def hidden_share(gt_joints: np.ndarray, gt_visible: np.ndarray) -> np.ndarray:
    """(T, P) share of each present person's joints hidden in the ground truth (NaN
    where the person is absent). gt_joints : (T, P, 15, 3) metres; gt_visible : (T, P, 15)."""
    present = np.any(np.all(np.isfinite(gt_joints), axis=3), axis=2)
    return np.where(present, 1.0 - gt_visible.mean(axis=2), np.nan)


def write_plots(runs: Sequence[RunResult], out: Path, recordings: Mapping[str, Path],
                events: Mapping[str, Mapping[str, tuple[int, int]]] | None = None) -> list[Path]:
    """Error over time per scenario (OUT/error_<scenario>.png) and the error-versus-time
    curve (OUT/error_vs_time.png); returns the paths written.

    recordings : {scenario: its recording folder (with ground truth)}
    events : {scenario: {event name: (start, stop) frames}}, marked on the scenario's plot
    """
    methods = list(dict.fromkeys(r.method for r in runs))
    colors = {m: f"C{i}" for i, m in enumerate(methods)}
    paths = []
    for scenario, folder in recordings.items():
        mine = [r for r in runs if r.scenario == scenario]
        if not mine:
            continue
        rec = Recording(folder)
        gt = rec.groundtruth()
        if not gt.person_ids:
            continue  # nobody in view in the frames evaluated: nothing to plot
        paths.append(_plot_errors(scenario, mine, methods, colors, hidden_share(gt.joints, gt.visible),
                                  gt.person_ids, dict((events or {}).get(scenario, {})), rec.fps,
                                  out / f"error_{scenario}.png"))
    if runs:
        paths.append(_plot_speed(runs, methods, colors, out / "error_vs_time.png"))
    return paths


def _plot_errors(scenario, runs, methods, colors, hidden, person_ids, events, fps, path: Path) -> Path:
    from matplotlib.figure import Figure

    num_people = hidden.shape[1]
    figure = Figure(figsize=(10, 3.2 * num_people))
    axes = figure.subplots(num_people, 1, squeeze=False, sharex=True)
    seconds = np.arange(hidden.shape[0]) / fps
    for p, ax in enumerate(axes[:, 0]):
        share = np.nan_to_num(hidden[:, p], nan=0.0)
        for k, (start, stop) in enumerate(intervals_from_mask(np.isnan(hidden[:, p]))):
            ax.axvspan(start / fps, stop / fps, facecolor="none", edgecolor="0.75", hatch="///", lw=0,
                       label="not in view" if k == 0 else None)
        for low, shade, label in ((PARTLY_HIDDEN, "0.88", f">= {PARTLY_HIDDEN:.0%} joints hidden"),
                                  (MOSTLY_HIDDEN, "0.7", f">= {MOSTLY_HIDDEN:.0%} joints hidden")):
            for k, (start, stop) in enumerate(intervals_from_mask(share >= low)):
                ax.axvspan(start / fps, stop / fps, color=shade, lw=0, label=label if k == 0 else None)
        top = FAIL_THRESHOLD_CM * 2
        for method in methods:
            errors = np.stack([r.frame_errors[:, p] for r in runs if r.method == method]) * 100.0
            finite = np.isfinite(errors)
            counts = finite.sum(axis=0)
            mean = np.where(counts > 0, np.where(finite, errors, 0.0).sum(axis=0) / np.maximum(counts, 1), np.nan)
            ax.plot(seconds, mean, color=colors[method], lw=1.2, label=f"{method} (mean of {len(errors)})")
            if len(errors) > 1:  # NaN bounds (no estimate) leave gaps in the band
                ax.fill_between(seconds, np.where(finite, errors, np.inf).min(axis=0),
                                np.where(finite, errors, -np.inf).max(axis=0), where=counts > 0,
                                color=colors[method], alpha=0.15, lw=0)
            if np.any(np.isfinite(mean)):
                top = max(top, min(float(np.nanmax(mean)) * 1.05, 150.0))
        ax.axhline(FAIL_THRESHOLD_CM, color="k", ls="--", lw=0.8, label="25 cm (FAIL rule)")
        for k, (name, (start, stop)) in enumerate(events.items()):
            ax.axvspan(start / fps, min(stop, hidden.shape[0]) / fps, ymin=0.96, ymax=1.0, color=f"C{k + 5}", lw=0)
            ax.text(start / fps, top * 0.93, f" {name}", fontsize=8, va="top", color=f"C{k + 5}")
        ax.set_ylim(0, top)
        ax.set_xlim(0, seconds[-1] if len(seconds) > 1 else 1)
        ax.set_ylabel(f"D_t [cm]{'' if num_people == 1 else f', person {person_ids[p]}'}")
        ax.legend(fontsize=7, loc="upper right", ncol=2)
    axes[-1, 0].set_xlabel("time [s]")
    axes[0, 0].set_title(f"{scenario}: mean joint error per frame (band: min-max over runs)")
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    return path


def _plot_speed(runs, methods, colors, path: Path) -> Path:
    from matplotlib.figure import Figure

    figure = Figure(figsize=(6, 4.2))
    ax = figure.subplots()
    rows = table_rows(runs)
    speeds = speed_table(runs)
    for method in methods:
        per_sequence = [by_method[method].mean_cm for by_method in rows.values() if method in by_method]
        per_ms = [speeds[method]["ms"]] * len(per_sequence)
        ax.scatter(per_ms, per_sequence, color=colors[method], alpha=0.3, s=14)
        finite = [v for v in per_sequence if not math.isnan(v)]
        if finite:
            x, y = speeds[method]["ms"], float(np.mean(finite))
            ax.scatter([x], [y], color=colors[method], s=60, label=method, edgecolor="k")
            ax.annotate(method, (x, y), textcoords="offset points", xytext=(6, 4), fontsize=9)
    ax.set_xlabel("time per frame [ms] (mean over runs)")
    ax.set_ylabel("mean error [cm]")
    ax.set_title("error versus time per frame\n(large: mean over sequences; small: each sequence)", fontsize=10)
    ax.set_xlim(left=0)
    ax.set_ylim(bottom=0)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    figure.tight_layout()
    figure.savefig(path, dpi=110)
    return path
