"""Scoring tracked skeletons against ground truth, and the evaluation that runs and reports it.

- `errors`: joint and frame errors, the FAIL rule, Table I rows (`table_row`, `TableRow`).
- `matching`: tracks matched to ground-truth people, identity switches, `score` of a sequence.
- `pixels`: pixel assignment accuracy, foreground scores, the second paper's arm error.
- `robustness`: per person-run figures (joints within 10 cm, track counts) and their aggregates
  per condition bucket, for the robustness benchmark.
- `report`: the one markdown table writer, Table I, results.csv, report.md and its plots.
- `evaluate`: methods x scenarios x seeds on a worker pool. Its function of the same name
  is not exported here, so that ``occupose.evaluation.evaluate`` stays the module:
  ``from occupose.evaluation.evaluate import evaluate``.

Example: ``score(gt.joints, gt.visible, {track: joints}, fps)`` returns a `Score` with the
Table I rows of every ground-truth person.
"""

from occupose.evaluation.errors import (
    TableRow,
    fail_curve,
    fail_frame,
    frame_errors,
    is_fail,
    joint_errors,
    per_joint_errors,
    rolling_mean,
    table_row,
)
from occupose.evaluation.evaluate import Evaluation, run_method
from occupose.evaluation.matching import (
    PersonScore,
    Score,
    evaluated_joints,
    identity_switches,
    match_tracks,
    person_errors,
    score,
)
from occupose.evaluation.pixels import (
    arm_epsilons,
    foreground_scores,
    pixel_assignment_accuracy,
    segment_distances,
)
from occupose.evaluation.report import (
    RunResult,
    markdown_table,
    mean_row,
    per_joint_table,
    report_markdown,
    results_table,
    speed_table,
    table_i_cells,
    table_i_markdown,
    table_rows,
    write_plots,
    write_results_csv,
)

__all__ = [
    # errors
    "TableRow", "fail_curve", "fail_frame", "frame_errors", "is_fail", "joint_errors", "per_joint_errors",
    "rolling_mean", "table_row",
    # matching
    "PersonScore", "Score", "evaluated_joints", "identity_switches", "match_tracks", "person_errors",
    "score",
    # pixels
    "arm_epsilons", "foreground_scores", "pixel_assignment_accuracy", "segment_distances",
    # report
    "markdown_table", "mean_row", "per_joint_table", "report_markdown", "results_table", "speed_table",
    "table_i_cells", "table_i_markdown", "table_rows", "write_plots", "write_results_csv",
    # evaluate
    "Evaluation", "RunResult", "run_method",
]
