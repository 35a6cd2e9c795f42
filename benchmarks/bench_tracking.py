"""Single-person tracking: joint error versus time per frame for each filter and budget.

The second paper's Fig. 5 (arm error versus computing time per frame, 3D model versus
part-based) as a table and a plot, for every filter of occupose.filters on two scenes:
``no_occlusion`` (front view, ``full`` model) and ``top_view_arms`` (ceiling camera,
``upper`` model), with three errors: the mean joint error, the arm joints' error (elbows
and wrists) and the paper's own arm error epsilon (occupose.evaluation.pixels.arm_epsilons: the
mean distance from the arm points to the arm bones; ``truth_eps_cm`` is the ground-truth
skeleton's, the floor). As in issue 4's check:
the ground-truth start pose, the person's own pixels from the renderer's person-id image
(the upper model gets the upper-body pixels only, as the second paper thresholds its
images), the model sized from the ground-truth joints, ``points+free``, 1000 points.
Motion is the shared mocap when present, procedural otherwise (column ``motion``).

Budgets are likelihood evaluations per frame (particles x likelihood calls): sir and
part-based use all of them as particles, apf 5 layers, ps one call per partitioned-sampling
stage (3 full, 2 upper), apf+ps 5 layers over the stages ([3, 1, 1] full, [3, 2] upper).
Time per frame is the median of ``PoseEstimator.step`` (likelihood and filter; the
observation is built beforehand); other processes share the 2 cores, so read it with the
load column. Errors are means over seeds of the per-run mean; ``fails``
counts the runs with the FAIL status (occupose.evaluation.errors). The plot is saved as
results/fig5_error_vs_time.png.
"""

from __future__ import annotations

import os
import time
from pathlib import Path

import numpy as np

from occupose.body import body_model, joints_from_pose, pose_from_joints
from occupose.joints import JOINT_INDEX
from occupose.evaluation.evaluate import ARM_SAMPLE
from occupose.evaluation.errors import frame_errors, is_fail, joint_errors
from occupose.evaluation.pixels import ARM_PARTS, arm_epsilons
from occupose.paths import mocap_dir
from occupose.pose.estimator import PoseEstimator
from occupose.pose.problem import PoseProblem
from occupose.body.dims import dims_from_joints
from occupose.synth.scenarios import build_scenario
from occupose.testing import UPPER_BODY_PARTS, person_observations

TITLE = "Single-person tracking: error versus time per frame (the second paper's Fig. 5; cm, ms)"
PLOT = Path(__file__).parent / "results" / "fig5_error_vs_time.png"

FILTERS = ("sir", "apf", "ps", "apf+ps", "part-based")
BUDGETS = (250, 500, 1000, 2000)
SCENES = (  # scene, model, the body parts observed (None: all)
    ("no_occlusion", "full", None),
    ("top_view_arms", "upper", UPPER_BODY_PARTS),
)
NUM_FRAMES = 120
SEEDS = (0, 1)
MAX_POINTS = 1000
ARMS = [JOINT_INDEX[name] for name in ("left_elbow", "left_wrist", "right_elbow", "right_wrist")]


def _scene(name: str, parts):
    """(scenario, ground-truth joints (T, 15, 3) metres, [Observation] * T of person 1's
    pixels of ``parts``, [(N, 3) metres] * T of its arm points)."""
    scenario = build_scenario(name, use_mocap=mocap_dir() is not None)
    observations = person_observations(scenario, NUM_FRAMES, parts=parts, max_points=MAX_POINTS)
    arms = person_observations(scenario, NUM_FRAMES, parts=ARM_PARTS, max_points=ARM_SAMPLE)
    return scenario, scenario.people[0].joints[:NUM_FRAMES], observations, [o.points for o in arms]


def _setting(filter_name: str, budget: int, num_stages: int) -> tuple[int, dict, str]:
    """(particles, filter options, label of the layers) spending ``budget`` evaluations per frame."""
    if filter_name == "apf":
        return budget // 5, {"num_layers": 5}, "5"
    if filter_name == "ps":
        return budget // num_stages, {}, f"{num_stages} stages"
    if filter_name == "apf+ps":
        layers = [3, 1, 1] if num_stages == 3 else [3, 2]
        return budget // 5, {"num_layers": layers}, str(layers)
    return budget, {}, "1"


def _track(model_name, gt, observations, filter_name, particles, options, seed):
    """Estimated joints (T - 1, 15, 3) metres, step seconds (T - 1,) and evaluations per
    frame of one run."""
    model = body_model(model_name, dims=dims_from_joints(gt))
    estimator = PoseEstimator(PoseProblem(model, "points+free"), filter_name, particles,
                              np.random.default_rng(seed), **options)
    estimator.initialise(pose_from_joints(model, gt[0]), 0.0)
    estimates, seconds = [], []
    for observation in observations[1:]:
        start = time.perf_counter()
        pose = estimator.step(observation)
        seconds.append(time.perf_counter() - start)
        estimates.append(joints_from_pose(model, pose))
    return np.array(estimates), np.array(seconds), estimator.filter.diagnostics["likelihood_evaluations"]


def run() -> list[dict]:
    """One row per scene, filter and budget (and the apf+ps 200 x 5 step row): particles,
    layers, evaluations per frame, ms per frame (median and min over frames and seeds), mean joint
    error, arm joints' error and epsilon (cm, mean over seeds), FAIL runs, load; saves the plot."""
    rows = []
    for scene, model_name, parts in SCENES:
        scenario, gt, observations, arms = _scene(scene, parts)
        truth_eps = 100 * float(np.nanmean(arm_epsilons(arms[1:], gt[1:])))
        motion = "mocap" if "mocap" in scenario.motion_source else "procedural"
        num_stages = 3 if model_name == "full" else 2
        for filter_name in FILTERS:
            for budget in BUDGETS:
                particles, options, layers = _setting(filter_name, budget, num_stages)
                means, arm_errors, epsilons, fails, seconds = [], [], [], 0, []
                for seed in SEEDS:
                    joints, step_seconds, evaluations = _track(model_name, gt, observations, filter_name,
                                                               particles, options, seed)
                    errors = joint_errors(gt[1:], joints)
                    per_frame = frame_errors(errors)
                    means.append(np.nanmean(per_frame))
                    arm_errors.append(np.nanmean(errors[:, ARMS]))
                    epsilons.append(np.nanmean(arm_epsilons(arms[1:], joints)))
                    fails += is_fail(per_frame, scenario.fps)
                    seconds.append(step_seconds)
                rows.append({"scene": scene, "model": model_name, "motion": motion, "frames": NUM_FRAMES,
                             "filter": filter_name, "particles": particles, "layers": layers,
                             "evaluations": evaluations, "ms_per_frame": 1e3 * float(np.median(seconds)),
                             "ms_min": 1e3 * float(np.min(seconds)), "mean_cm": 100 * float(np.mean(means)),
                             "arm_cm": 100 * float(np.mean(arm_errors)),
                             "eps_cm": 100 * float(np.mean(epsilons)), "truth_eps_cm": truth_eps,
                             "fails": f"{fails}/{len(SEEDS)}", "load_1min": os.getloadavg()[0]})
        if model_name == "full":
            rows.append(_step_row(scene, motion, gt, observations, arms, truth_eps))
    _plot(rows)
    return rows


def _step_row(scene, motion, gt, observations, arms, truth_eps) -> dict:
    """The issue's timing target: one apf+ps step, 200 particles x [3, 1, 1], full model,
    1000 points (target <= 8 ms); median and min over the frames of one run."""
    joints, seconds, evaluations = _track("full", gt, observations, "apf+ps", 200, {"num_layers": [3, 1, 1]}, 0)
    errors = joint_errors(gt[1:], joints)
    return {"scene": scene, "model": "full", "motion": motion, "frames": NUM_FRAMES,
            "filter": "apf+ps step (target <= 8 ms)", "particles": 200, "layers": "[3, 1, 1]",
            "evaluations": evaluations, "ms_per_frame": 1e3 * float(np.median(seconds)),
            "ms_min": 1e3 * float(seconds.min()), "mean_cm": 100 * float(np.nanmean(frame_errors(errors))),
            "arm_cm": 100 * float(np.nanmean(errors[:, ARMS])),
            "eps_cm": 100 * float(np.nanmean(arm_epsilons(arms[1:], joints))), "truth_eps_cm": truth_eps,
            "fails": f"{int(is_fail(frame_errors(errors), 30.0))}/1", "load_1min": os.getloadavg()[0]}


def _plot(rows: list[dict]) -> None:
    """Error versus ms per frame, one line per filter (points at the budgets), per scene."""
    import matplotlib
    import matplotlib.ticker

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    panels = (("mean_cm", "mean joint error [cm]"), ("arm_cm", "arm joints' error [cm]"),
              ("eps_cm", "arm error epsilon [cm] (dotted: ground truth's)"))
    fig, axes = plt.subplots(len(panels), len(SCENES), figsize=(11, 11), squeeze=False)
    times = [r["ms_per_frame"] for r in rows]
    ticks = [t for t in (1, 2, 5, 10, 20, 50, 100, 200) if min(times) / 2 <= t <= 2 * max(times)]
    for column, (scene, model_name, _) in enumerate(SCENES):
        for row_index, (key, label) in enumerate(panels):
            ax = axes[row_index, column]
            if key == "eps_cm":
                ax.axhline(next(r["truth_eps_cm"] for r in rows if r["scene"] == scene), color="k", ls=":", lw=1)
            for filter_name in FILTERS:
                points = [(r["ms_per_frame"], r[key], r["evaluations"]) for r in rows
                          if r["scene"] == scene and r["filter"] == filter_name]
                x, y, evaluations = zip(*points)
                ax.plot(x, y, marker="o", label=filter_name)
                for xi, yi, e in zip(x, y, evaluations):
                    ax.annotate(str(e), (xi, yi), textcoords="offset points", xytext=(3, 3), fontsize=7)
            motion = next(r["motion"] for r in rows if r["scene"] == scene)
            ax.set_title(f"{scene} ({model_name} model, {motion} motion)", fontsize=10)
            ax.set_xscale("log")
            ax.set_xticks(ticks)
            ax.xaxis.set_major_formatter(matplotlib.ticker.ScalarFormatter())
            ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
            ax.set_xlabel("time per frame [ms] (labels: likelihood evaluations)")
            ax.set_ylabel(label)
            ax.set_yscale("log")
            ax.set_yticks([2, 5, 10, 20, 50, 100])
            ax.yaxis.set_major_formatter(matplotlib.ticker.ScalarFormatter())
            ax.grid(True, which="both", alpha=0.3)
            ax.legend(fontsize=8)
    loads = [r["load_1min"] for r in rows]
    fig.suptitle("Error versus time per frame (cf. Fig. 5 of the top-view part-based paper); "
                 f"2 cores, load {min(loads):.1f}-{max(loads):.1f}")
    fig.tight_layout()
    PLOT.parent.mkdir(exist_ok=True)
    fig.savefig(PLOT, dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    from benchmarks import print_table

    print_table(TITLE, run())
