"""The text of ``docs/configuration.md``, made from the fields of the configuration tree
(:mod:`occupose.config`); a test checks the file against it. Regenerate it with::

    python -c "from occupose.config_docs import configuration_markdown as m; print(m(), end='')" > docs/configuration.md
"""

from __future__ import annotations

import dataclasses
import json

from occupose.config import METHODS, TrackerConfig


def configuration_markdown() -> str:
    """The text of ``docs/configuration.md``: every field, section by section (a test checks
    the file against it)."""
    lines = ["# Configuration", "",
             "Every setting of a tracking run is a field of `occupose.config.TrackerConfig`, grouped in",
             "sections. Give them in a TOML or JSON file (`occupose track REC --out OUT --config FILE`), one",
             "at a time (`--set section.field=value`, TOML syntax, `none` for none), or in Python",
             "(`TrackerConfig.from_dict({...})`, `config.with_values({\"section.field\": value})`). A file",
             "may name the `method` it starts from (`ours`, `apf`, `ps`, `part-based`; default `ours`);",
             "`occupose config --method NAME` prints every setting as such a file. Every value is checked",
             "when the config is built. `summary.json` holds the whole resolved config of a run.",
             "", "```toml", 'method = "ours"', "", "[pose]", "particles = 300", "", "[start]", "look_back_s = 0.5",
             "```", "",
             "The defaults are the values the results in [results.md](results.md) were measured with;",
             "[notes/](notes/README.md) says why. This page is generated from the code:",
             "`python -c \"from occupose.config_docs import configuration_markdown as m; print(m(), end='')\" > "
             "docs/configuration.md`.", ""]
    for section in dataclasses.fields(TrackerConfig):
        about = " ".join((section.default_factory.__doc__ or "").split()).replace("``", "`")
        lines += [f"## `{section.name}`", "", about, "", "| setting | default | unit | meaning |", "|---|---|---|---|"]
        lines += [f"| `{name}` | `{default}` | {unit} | {doc} |" for name, default, unit, doc in fields_table()
                  if name.split(".")[0] == section.name]
        lines.append("")
    lines += ["## Methods", "", "| method | what differs from `ours` |", "|---|---|"]
    ours = METHODS["ours"].to_dict()
    for method, config in METHODS.items():
        changed = [f"`{s}.{k}` = `{json.dumps(v)}`" for s, values in config.to_dict().items()
                   for k, v in values.items() if v != ours[s][k]]
        lines.append(f"| `{method}` | {', '.join(changed) or 'the defaults'} |")
    return "\n".join(lines) + "\n"


def fields_table() -> list[tuple[str, str, str, str]]:
    """(dotted name, default as TOML-like text, unit, meaning) of every field, section by
    section: the rows of ``docs/configuration.md``."""
    rows = []
    for section in dataclasses.fields(TrackerConfig):
        for f in dataclasses.fields(section.default_factory):
            default = f.default
            text = ("none" if default is None else str(default).lower() if isinstance(default, bool)
                    else json.dumps(list(default)) if isinstance(default, tuple) else json.dumps(default)
                    if isinstance(default, str) else repr(default))
            rows.append((f"{section.name}.{f.name}", text, f.metadata["unit"], f.metadata["doc"]))
    return rows
