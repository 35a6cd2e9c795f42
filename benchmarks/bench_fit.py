"""Single-frame fits (``occupose.fit_frame``, issue 28) on frames of the randomized scenes.

For each scene ``random:<seed>`` (:func:`occupose.synth.random_scenes.random_scenario`, the
shared mocap clips when present) one frame is rendered: of ``CANDIDATE_FRAMES``, the one
where the people show the most joints (the ground truth's visibility). It is fitted four
ways, each with nothing but that frame:

- input ``background``: the noisy frame and a noisy frame of the empty scene (another draw
  of the same sensor noise), or ``removed``: the frame with every pixel that is not a
  person's set to 0 (the renderer's person labels), as in an export whose background was
  removed;
- pose ``given``: the camera's world pose is known, or ``found``: it is not (the floor is
  looked for in the frame; the joints come in the camera's frame and are compared there).

Fitted people are matched one to one to the people the camera shows (Hungarian, on the
mean distance of the joints both have). A person-frame is ``full`` when the ground truth
shows at least 3 of its knees and ankles (all the joints both have are scored), else
``upper`` (the 9 upper-body joints scored); only the ground truth's visible joints count.
Reported per view, furniture, input and pose: the median and mean of the per-person-frame
mean errors, the share of joints within 10 cm, people missed and extra, and milliseconds
per person. Targets (issue 28): upper median <= 8 cm and >= 75 % within 10 cm, full
median <= 9 cm, <= 200 ms per person.

The small version (``run``, ``make bench``): ``SMALL_SCENES`` scenes. The full one::

    python -m benchmarks.bench_fit --scenes 40

writes ``benchmarks/results/fit/fit.json`` (every person-frame) and ``fit.md``.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np
from scipy.optimize import linear_sum_assignment
from tqdm import tqdm

from occupose.config import as_config
from occupose.evaluation.report import markdown_table
from occupose.joints import NUM_JOINTS, UPPER_JOINTS
from occupose.pose.single import fit_frame
from occupose.synth.generate import frames
from occupose.synth.noise import apply_noise
from occupose.synth.random_scenes import random_scenario
from occupose.synth.render import render_camera

TITLE = "Single-frame fits on frames of the randomized scenes (cm, %, ms per person)"
RESULTS = Path(__file__).parent / "results" / "fit"
SMALL_SCENES = 6
#: Frames of each scene (a scene of this length is drawn) and the candidates rendered.
SCENE_FRAMES = 90
CANDIDATE_FRAMES = (30, 60, 89)
#: Knees and ankles (joint indices) and how many must show for a "full" person-frame.
LEGS = (10, 11, 13, 14)
LEGS_SHOWN = 3
WITHIN_M = 0.10
INPUTS = ("background", "removed")
POSES = ("given", "found")


def _frame(seed: int):
    """(scenario, the chosen SynthFrame, the noisy empty scene (H, W) metres)."""
    scenario = random_scenario(seed, frames=SCENE_FRAMES)
    camera = scenario.cameras[0]
    rendered = list(frames(scenario, seed, indices=CANDIDATE_FRAMES))
    chosen = max(rendered, key=lambda f: int(f.visible[f.present].sum()))
    model, options = scenario.noise[camera.name]
    empty = render_camera(scenario.static, camera)
    background = apply_noise(empty.depth, model, np.random.default_rng(seed + 1), fx=camera.fx, person=empty.person,
                             **options)
    return scenario, chosen, background


def _match(fitted: np.ndarray, truth: np.ndarray) -> list[tuple[int, int]]:
    """(fit, truth) index pairs: one to one, least total mean distance over the joints both have."""
    if not len(fitted) or not len(truth):
        return []
    cost = np.zeros((len(fitted), len(truth)))
    for i, f in enumerate(fitted):
        for j, t in enumerate(truth):
            both = np.isfinite(f).all(axis=1) & np.isfinite(t).all(axis=1)
            cost[i, j] = np.linalg.norm(f[both] - t[both], axis=1).mean() if both.any() else 1e3
    rows, cols = linear_sum_assignment(cost)
    return list(zip(rows.tolist(), cols.tolist()))


def score_scene(seed: int, config="ours", fit_seed: int = 0) -> list[dict]:
    """Every person-frame record of scene ``seed``'s four fits (module docstring) with
    ``config``, the fits seeded with ``fit_seed``."""
    scenario, frame, background = _frame(seed)
    camera = scenario.cameras[0]
    depth = frame.depth[camera.name]
    removed = np.where(frame.rendered[camera.name].person > 0, depth, 0).astype(np.float32)
    shown = np.flatnonzero(frame.present & (frame.visible.sum(axis=1) > 0))
    upper = np.zeros(NUM_JOINTS, bool)
    upper[: len(UPPER_JOINTS)] = True
    conditions = scenario.conditions
    furniture = "none" if conditions["furniture"] in (None, "none") else "furniture"
    records = []
    for kind in INPUTS:
        for pose in POSES:
            start = time.perf_counter()
            fit = fit_frame(depth if kind == "background" else removed, camera, world=pose == "given",
                            background=background if kind == "background" else None, config=config, seed=fit_seed)
            seconds = time.perf_counter() - start
            truth = frame.joints[shown]
            if fit.frame == "camera":
                truth = truth @ camera.camera_from_world[:3, :3].T + camera.camera_from_world[:3, 3]
            fitted = np.array([p.joints for p in fit.people]).reshape(-1, NUM_JOINTS, 3)
            pairs = _match(fitted, truth)
            base = {"scene": seed, "view": conditions["view"], "furniture": furniture, "input": kind, "pose": pose,
                    "people": len(shown), "fitted": len(fit.people), "ms_per_person":
                    1e3 * seconds / max(1, len(fit.people))}
            for i, j in pairs:
                legs = int(frame.visible[shown[j], list(LEGS)].sum()) >= LEGS_SHOWN
                scored = frame.visible[shown[j]] & np.isfinite(fitted[i]).all(axis=1) & (True if legs else upper)
                errors = np.linalg.norm(fitted[i][scored] - truth[j][scored], axis=1)
                records.append({**base, "body": "full" if legs else "upper", "model": fit.people[i].model,
                                "mean_cm": 100 * float(errors.mean()) if len(errors) else float("nan"),
                                "within10": float(np.mean(errors <= WITHIN_M)) if len(errors) else float("nan"),
                                "joints": int(len(errors))})
            if not pairs:
                records.append({**base, "body": "none", "model": None, "mean_cm": float("nan"),
                                "within10": float("nan"), "joints": 0})
    return records


def _row(label: dict, records: list[dict]) -> dict:
    scored = [r for r in records if r["joints"]]
    means = np.array([r["mean_cm"] for r in scored])
    joints = np.array([r["joints"] for r in scored])
    within = np.array([r["within10"] for r in scored])
    fits = {(r["scene"], r["input"], r["pose"]): r for r in records}.values()
    return {**label, "person-frames": len(scored),
            "median [cm]": float(np.median(means)) if len(means) else float("nan"),
            "mean [cm]": float(means.mean()) if len(means) else float("nan"),
            "joints <10 cm [%]": 100 * float((within * joints).sum() / joints.sum()) if len(joints) else float("nan"),
            "missed": sum(max(0, f["people"] - f["fitted"]) for f in fits),
            "extra": sum(max(0, f["fitted"] - f["people"]) for f in fits),
            "ms/person": float(np.median([f["ms_per_person"] for f in fits]))}


def table(records: list[dict]) -> list[dict]:
    """Rows: per body (upper, full) overall, then per body, view, furniture, input and pose."""
    rows = []
    for body in ("upper", "full"):
        mine = [r for r in records if r["body"] == body]
        if mine:
            rows.append(_row({"body": body, "view": "all", "furniture": "all", "input": "all", "pose": "all"}, mine))
    keys = sorted({(r["body"], r["view"], r["furniture"], r["input"], r["pose"]) for r in records
                   if r["body"] != "none"})
    for body, view, furniture, kind, pose in keys:
        mine = [r for r in records if (r["body"], r["view"], r["furniture"], r["input"], r["pose"])
                == (body, view, furniture, kind, pose)]
        rows.append(_row({"body": body, "view": view, "furniture": furniture, "input": kind, "pose": pose}, mine))
    return rows


def measure(seeds, progress: bool = False, config="ours", fit_seed: int = 0) -> list[dict]:
    records = []
    for seed in tqdm(list(seeds), desc="fit benchmark", unit="scene", disable=not progress):
        records += score_scene(seed, config, fit_seed)
    return records


def run() -> list[dict]:
    return table(measure(range(SMALL_SCENES)))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--scenes", type=int, default=40, help="scenes random:0 .. random:N-1")
    parser.add_argument("--out", type=Path, default=RESULTS)
    parser.add_argument("--set", dest="assignments", action="append", default=[], metavar="KEY=VALUE",
                        help="a setting of the fit, e.g. fit.steps=10 (repeatable), for an A/B in the same run")
    parser.add_argument("--seed", type=int, default=0, help="the fits' seed (the scenes stay the same)")
    args = parser.parse_args()
    values = {key: json.loads(value) for key, _, value in (a.partition("=") for a in args.assignments)}
    records = measure(range(args.scenes), progress=True, config=as_config("ours").with_values(values),
                      fit_seed=args.seed)
    rows = table(records)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "fit.json").write_text(json.dumps(records, indent=1) + "\n")
    cells = [[f"{v:.2f}" if isinstance(v, float) else str(v) for v in row.values()] for row in rows]
    text = f"### {TITLE}\n\n{args.scenes} scenes, settings {values or 'ours'}, fit seed {args.seed}\n\n" + markdown_table(list(rows[0]), cells)
    (args.out / "fit.md").write_text(text)
    print(text)


if __name__ == "__main__":
    main()
