"""The tallies of a random suite: every scene, design and geometry draw counted, and the
markdown's numbers are those counts."""

import pytest

from occupose.evaluation.random_suite import counts_markdown, suite_counts
from occupose.synth.random_scenes import SCENE_TRIES, draw_random_scenario

FRAMES = 40
SEEDS = 4  # procedural, 40 frames: seed 3's first design cannot be placed


@pytest.fixture(scope="module")
def counted():
    return suite_counts(SEEDS, use_mocap=False, frames=FRAMES), [
        draw_random_scenario(seed, use_mocap=False, frames=FRAMES) for seed in range(SEEDS)]


def test_every_scene_design_and_geometry_draw_is_counted(counted):
    counts, draws = counted
    assert counts.seeds == SEEDS and len(counts.scenes) == SEEDS
    for scene, draw in zip(counts.scenes, draws):
        conditions = draw.scenario.conditions
        assert {k: scene[k] for k in ("view", "camera", "people", "start", "noise")} == \
            {k: conditions[k] for k in ("view", "camera", "people", "start", "noise")}
        assert scene["motion"] == conditions["persons"][0]["action"]  # procedural: the action is the family
    assert len(counts.designs) == sum(d.designs for d in draws) > SEEDS  # some design was given up on
    assert sum(d["kept"] for d in counts.designs) == SEEDS
    assert len(counts.geometries) == sum(len(d.rejected) + 1 for d in draws)
    assert sum(g["kept"] for g in counts.geometries) == SEEDS
    given_up = [g for g in counts.geometries if not g["design_kept"]]
    assert len(given_up) == SCENE_TRIES * (len(counts.designs) - SEEDS)


def test_the_markdown_shows_the_counts(counted):
    counts, draws = counted
    text = counts_markdown(counts)
    front = sum(s["view"] == "front" for s in counts.scenes)
    assert text.startswith(f"{SEEDS} scenes;")
    given_up = len(counts.designs) - SEEDS
    assert f"{given_up} of {len(counts.designs)} designs were given up on" in text
    view_row = next(line for line in text.splitlines() if line.startswith("| view |"))
    assert f"front {front} (" in view_row or front == 0
    # the front cameras' table: placed draws add up to the front scenes
    table = text[text.index("| height |"):].splitlines()[2:5]
    placed = sum(int(cell.split("/")[0]) for line in table for cell in line.strip("|").split("|")[1:]
                 if "/" in cell)
    assert placed == front


def test_a_suite_needs_a_count():
    with pytest.raises(ValueError, match="a random suite needs a count >= 1"):
        suite_counts(0)
