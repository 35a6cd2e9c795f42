"""What a random suite (``--suite random:N``) holds: how often each condition value occurs
among the scenes of seeds 0..N-1, against how often it was drawn, and which draws could
not be placed (``docs/robustness.md`` shows it for 60 seeds). Regenerate that section with::

    python -c "from occupose.evaluation.random_suite import suite_counts, counts_markdown as m; print(m(suite_counts(60)))"

Building a scene draws it without rendering: about a second a scene, so 60 take about a minute.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from occupose.evaluation.report import markdown_table
from occupose.synth.random_scenes import SCENE_TRIES, draw_random_scenario, seed_of, suite

#: Conditions drawn with a scene's design (kept while its geometry is drawn again).
DESIGN_KEYS = ("view", "camera", "people", "start", "furniture", "motion")
#: Conditions drawn once every person is placed.
SCENE_KEYS = ("noise", "dark_clothes", "back_wall")
#: Bin edges of the front cameras' table: height (m) and tilt (degrees).
FRONT_HEIGHT_BINS = (0.8, 1.4, 2.0, 2.6)
FRONT_TILT_BINS = (0.0, 10.0, 20.0, 30.0, 40.0)


@dataclass(frozen=True)
class SuiteCounts:
    """The draws of a random suite (:func:`suite_counts`).

    seeds : the suite's scenes are those of seeds 0..seeds-1
    scenes : per scene, its :data:`DESIGN_KEYS` and :data:`SCENE_KEYS` conditions
        (``motion``: the first person's motion family, "sit" for the procedural sitting)
    designs : per design drawn (the kept ones too), its :data:`DESIGN_KEYS` and ``kept``
    geometries : per geometry draw, ``view``, ``camera``, ``camera_height_m``, ``tilt_deg``,
        ``kept`` (whether its people could be placed) and ``design_kept`` (whether its
        design was, at this or a later geometry draw)
    """

    seeds: int
    scenes: tuple[dict, ...]
    designs: tuple[dict, ...]
    geometries: tuple[dict, ...]


def _family(conditions: dict) -> str:
    """The first person's motion family as the design drew it: a clip family, or the
    procedural action ("sit" with the shared clips; walk, gesture or sit without them)."""
    return conditions["persons"][0]["action"] if conditions["motion"] == "procedural" else conditions["motion"]


def suite_counts(count: int, use_mocap: bool = True, frames: int | None = None) -> SuiteCounts:
    """Draw the random scenes of seeds 0..count-1 (no rendering) and collect their
    conditions and the draws given up on (:class:`SuiteCounts`); ``use_mocap`` and
    ``frames`` as :func:`occupose.synth.random_scenes.random_scenario`'s."""
    scenes, designs, geometries = [], [], []
    for name in suite(count):  # ValueError unless count >= 1
        draw = draw_random_scenario(seed_of(name), use_mocap=use_mocap, frames=frames)
        conditions = draw.scenario.conditions
        kept = {**{key: conditions[key] for key in DESIGN_KEYS}, "motion": _family(conditions)}
        scenes.append({**kept, **{key: conditions[key] for key in SCENE_KEYS}})
        given_up = {r["design"]: r for r in draw.rejected if r["design"] < draw.designs - 1}
        designs += [{**{key: given_up[i][key] for key in DESIGN_KEYS}, "kept": False} for i in sorted(given_up)]
        designs.append({**kept, "kept": True})
        geometries += [{key: r[key] for key in ("view", "camera", "camera_height_m", "tilt_deg")}
                       | {"kept": False, "design_kept": r["design"] == draw.designs - 1} for r in draw.rejected]
        geometries.append({"view": conditions["view"], "camera": conditions["camera"], "kept": True, "design_kept": True,
                           "camera_height_m": conditions["camera_height_m"], "tilt_deg": conditions["tilt_deg"]})
    return SuiteCounts(int(count), tuple(scenes), tuple(designs), tuple(geometries))


def _tally(items: Sequence[dict], key: str) -> list[tuple[str, int]]:
    """(value, count) of ``key`` over ``items``, most frequent first, ties by value."""
    counter = Counter(str(item[key]) for item in items)
    return sorted(counter.items(), key=lambda pair: (-pair[1], pair[0]))


def _kept_of(items: Sequence[dict]) -> str:
    """"kept/drawn" of ``items`` (dicts with ``kept``), "-" when there are none."""
    return f"{sum(item['kept'] for item in items)}/{len(items)}" if items else "-"


def _binned(items: Sequence[dict], key: str, edges: Sequence[float]) -> list[list[dict]]:
    """``items`` split by ``key`` into the bins of ``edges`` (the last bin closed)."""
    values = np.array([item[key] for item in items], np.float64)
    index = np.clip(np.searchsorted(edges, values, side="right") - 1, 0, len(edges) - 2)
    return [[item for item, i in zip(items, index) if i == b] for b in range(len(edges) - 1)]


def _bin_names(edges: Sequence[float]) -> list[str]:
    return [f"{lo:g}-{hi:g}" for lo, hi in zip(edges[:-1], edges[1:])]


def counts_markdown(counts: SuiteCounts) -> str:
    """Markdown: the conditions' tallies (scenes, and designs drawn), the designs kept by
    view and start and by view and people, and the front cameras placed by height and tilt."""
    scenes, designs, geometries = counts.scenes, counts.designs, counts.geometries
    rows = []
    for key in DESIGN_KEYS:
        drawn = dict(_tally(designs, key))
        rows.append([key, ", ".join(f"{value} {n} ({drawn[value]})" for value, n in _tally(scenes, key))
                     + "".join(f", {value} 0 ({n})" for value, n in drawn.items()
                               if value not in {str(s[key]) for s in scenes})])
    rows += [[key, ", ".join(f"{value} {n}" for value, n in _tally(scenes, key))] for key in SCENE_KEYS]
    lost = [g for g in geometries if not g["kept"]]
    given_up = sum(not d["kept"] for d in designs)
    parts = [
        f"{counts.seeds} scenes; each value's count, then in brackets how often it was drawn: a design "
        f"(view, camera, people, start, furniture, first person's motion) whose people cannot be placed "
        f"in {SCENE_TRIES} geometry draws is drawn again. {given_up} of {len(designs)} designs were given up "
        f"on, and {len(lost)} of {len(geometries)} geometry draws.",
        markdown_table(["condition", "scenes (designs drawn)"], rows),
    ]
    views = sorted({d["view"] for d in designs})
    starts = [value for value, _ in _tally(designs, "start")]
    people = sorted({d["people"] for d in designs})
    cross = [[view] + [_kept_of([d for d in designs if d["view"] == view and d["start"] == s]) for s in starts]
             + [_kept_of([d for d in designs if d["view"] == view and d["people"] == p]) for p in people]
             for view in views]
    parts += ["Designs kept of those drawn, by view and the first person's start, and by view and people:",
              markdown_table(["view"] + [f"start {s}" for s in starts] + [f"people {p}" for p in people], cross),
              "The geometry draws of the designs kept: their camera's share placed (a design given up on "
              "would count its every camera as a failure)."]
    placeable = [g for g in geometries if g["design_kept"]]
    front = [g for g in placeable if g["view"] == "front"]
    table = [[f"{name} m"] + [_kept_of(cell) for cell in _binned(row, "tilt_deg", FRONT_TILT_BINS)]
             for name, row in zip(_bin_names(FRONT_HEIGHT_BINS), _binned(front, "camera_height_m", FRONT_HEIGHT_BINS))]
    parts += ["Front views, placed of drawn, by camera height and tilt:",
              markdown_table(["height"] + [f"tilt {name} deg" for name in _bin_names(FRONT_TILT_BINS)], table)]
    return "\n\n".join(parts) + "\n"


__all__ = ["DESIGN_KEYS", "SCENE_KEYS", "SuiteCounts", "counts_markdown", "suite_counts"]
