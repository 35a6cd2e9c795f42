"""The configuration tree: built from files and values, checked, written into summary.json and read back."""

import dataclasses
import json
from pathlib import Path

import pytest

from occupose.config import (
    FILTER_NAMES,
    LIKELIHOOD_NAMES,
    METHODS,
    NOISE_MODEL_NAMES,
    PART_WEIGHT_NAMES,
    RESAMPLING_NAMES,
    ConfigError,
    PoseConfig,
    TrackerConfig,
    method_config,
)
from occupose.config_docs import configuration_markdown
from occupose.run import TrackingResult, summary_of

DOCS = Path(__file__).resolve().parents[1] / "docs" / "configuration.md"


def test_the_default_is_ours_and_the_methods_differ_only_in_pose_and_occlusion():
    assert TrackerConfig() == METHODS["ours"] == method_config("ours")
    assert list(METHODS) == ["ours", "apf", "ps", "part-based"]
    ours = METHODS["ours"].to_dict()
    for name, config in METHODS.items():
        changed = {s for s, fields in config.to_dict().items() if fields != ours[s]}
        assert changed <= {"pose", "occlusion"}, name
    assert (METHODS["apf"].pose.filter, METHODS["apf"].pose.layers, METHODS["apf"].occlusion.enabled) == ("apf", 10, False)
    assert METHODS["ps"].pose.particles == 2000 and METHODS["part-based"].pose.model == "upper"
    with pytest.raises(ConfigError, match="unknown method 'fast'; valid names: ours, apf, ps, part-based"):
        method_config("fast")


def test_a_toml_file_becomes_a_config_that_summary_json_holds_whole(tmp_path):
    """TOML -> config -> summary.json -> config: equal."""
    toml = ('method = "apf"\n[pose]\nparticles = 300\nlayers = 7\n[grid]\ncell = 0.04\ninitial = [0.5, 0, 0.5]\n'
            '[start]\nlook_back_s = 0\n[priors]\nfloor_cost = 25\n')
    path = tmp_path / "settings.toml"
    path.write_text(toml)
    config = TrackerConfig.from_file(path)
    assert (config.pose.filter, config.pose.particles, config.pose.layers) == ("apf", 300, 7)
    assert config.grid.initial == (0.5, 0.0, 0.5) and isinstance(config.priors.floor_cost, float)
    assert config.occlusion.enabled is False and config.start.look_back_s == 0.0  # apf's, and the file's
    summary = json.loads(json.dumps(summary_of(TrackingResult({}, config=config, seed=3, model="full"), "rec", "apf")))
    assert summary["method"] == "apf" and summary["seed"] == 3 and summary["model"] == "full"
    assert summary["overlap"] is False
    assert TrackerConfig.from_dict(summary["config"]) == config
    assert TrackerConfig.from_dict(summary["config"] | {"method": "ps"}) == config  # every field is given


@pytest.mark.parametrize("values, message", [
    ({"occlusion.enabled": "false"}, "occlusion.enabled must be true or false, got 'false' (str)"),
    ({"pose.particles": 2.5}, "pose.particles must be an integer, got 2.5 (float)"),
    ({"pose.particles": True}, "pose.particles must be an integer, got True (bool)"),
    ({"pose.particles": 0}, "pose.particles must be >= 1, got 0"),
    ({"pose.particles": 3_000_000}, "gives 15,000,000 likelihood evaluations per person and frame"),
    ({"grid.cell": 0.0}, "grid.cell must be >= 0.001"),
    ({"grid.cell": float("nan")}, "grid.cell must be a finite number"),
    ({"grid.initial": [0.5, 0.5]}, "grid.initial must be a list of 3 values, got 2"),
    ({"grid.initial": [0.5, 0.2, 0.5]}, "grid.initial must sum to 1"),
    ({"pose.filter": "kalman"}, "pose.filter must be one of sir, apf, ps, apf+ps, part-based; got 'kalman'"),
    ({"pose.layers": [2, "x", 2]}, "pose.layers"),
    ({"pose.layers": None}, "pose.layers must be set for the 'apf+ps' filter"),
    ({"pose.filter": "ps"}, "pose.layers must be none for the 'ps' filter"),
    ({"pose.gate": 0.3}, "unknown setting 'pose.gate'; pose has: model, "),
    ({"poses.gate_m": 0.3}, "unknown section 'poses'"),
    ({"start.look_back_s": 1e6}, "start.look_back_s must be <= 10"),
])
def test_a_value_of_the_wrong_type_or_out_of_range_is_refused_by_name(values, message):
    with pytest.raises(ConfigError, match=message.replace("(", r"\(").replace(")", r"\)").replace("+", r"\+")):
        TrackerConfig().with_values(values)


def test_files_with_bad_contents_name_the_file(tmp_path):
    for text, suffix, message in [("[1, 2]", ".json", "a config must be a table of sections"),
                                  ("pose = [", ".toml", "not valid TOML"),
                                  ("{", ".json", "not valid JSON"),
                                  ('{"pose": 3}', ".json", "section 'pose' must be a table of settings"),
                                  ('{"method": "fast"}', ".json", "unknown method 'fast'")]:
        path = tmp_path / f"c{suffix}"
        path.write_text(text)
        with pytest.raises(ConfigError, match=message) as error:
            TrackerConfig.from_file(path)
        assert str(path) in str(error.value)
    with pytest.raises(ConfigError, match="cannot read the config"):
        TrackerConfig.from_file(tmp_path / "missing.toml")


def test_configs_are_frozen_and_compare_by_value():
    config = TrackerConfig()
    with pytest.raises(dataclasses.FrozenInstanceError):
        config.pose.particles = 10
    assert config.with_values({"pose.particles": 200}) == config  # 200 is ours' already
    assert config.with_values({"pose.particles": 201}) != config
    assert PoseConfig(particles=201) == config.with_values({"pose.particles": 201}).pose


def test_the_names_of_strategies_are_the_registries():
    from occupose.filters import FILTERS, RESAMPLING
    from occupose.likelihood import LIKELIHOODS
    from occupose.pose.problem import PART_WEIGHTS
    from occupose.sensors import depth_std_coefficients

    assert FILTER_NAMES == tuple(FILTERS) and RESAMPLING_NAMES == tuple(RESAMPLING)
    assert LIKELIHOOD_NAMES == tuple(LIKELIHOODS) and PART_WEIGHT_NAMES == tuple(PART_WEIGHTS)
    for name in NOISE_MODEL_NAMES:
        depth_std_coefficients(name)  # raises for an unknown one


def test_every_field_has_a_meaning_and_the_docs_list_them_all():
    for section in dataclasses.fields(TrackerConfig):
        for f in dataclasses.fields(section.default_factory):
            assert f.metadata.get("doc"), f"{section.name}.{f.name} has no meaning"
    assert DOCS.read_text() == configuration_markdown(), (
        "docs/configuration.md is out of date: python -c \"from occupose.config_docs import configuration_markdown "
        "as m; print(m(), end='')\" > docs/configuration.md")
