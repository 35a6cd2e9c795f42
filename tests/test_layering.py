"""The package's layers: the core never imports the scene generator, and importing occupose sets nothing up."""

import ast
import os
import subprocess
import sys
from pathlib import Path

import occupose

PACKAGE = Path(occupose.__file__).parent
#: Modules allowed to import occupose.synth (relative to the package). warmup.py tracks a
#: rendered scene only to compile the kernels and throws its tracks away (a run's tracks are
#: the same with and without it: tests/test_warmup.py).
MAY_IMPORT_SYNTH = ("synth/", "testing.py", "evaluation/", "cli.py", "warmup.py")


def _imports(path: Path, root: Path = PACKAGE) -> list[tuple[int, str]]:
    """(line, absolute module name) of every import in ``path`` (a module of the package at
    ``root``), lazy ones inside functions too."""
    module = ".".join(("occupose", *path.relative_to(root).with_suffix("").parts))
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    out = []
    for node in ast.walk(ast.parse(path.read_text(), str(path))):
        if isinstance(node, ast.Import):
            out += [(node.lineno, alias.name) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:  # relative: from the module's package up
                parts = package.split(".")
                base = ".".join(parts[:len(parts) - node.level + 1] + ([node.module] if node.module else []))
            out.append((node.lineno, base))
            out += [(node.lineno, f"{base}.{alias.name}") for alias in node.names]  # a name may be a module
    return out


def test_nothing_in_the_core_imports_the_scene_generator():
    offenders = []
    for path in sorted(PACKAGE.rglob("*.py")):
        relative = path.relative_to(PACKAGE).as_posix()
        if relative.startswith(MAY_IMPORT_SYNTH):
            continue
        offenders += [f"{relative}:{line} imports {name}" for line, name in _imports(path)
                      if name == "occupose.synth" or name.startswith("occupose.synth.")]
    assert not offenders, "\n".join(offenders)


def test_the_import_walk_sees_absolute_relative_and_lazy_imports(tmp_path):
    package = tmp_path / "occupose"
    (package / "grid").mkdir(parents=True)
    probe = package / "grid" / "probe.py"
    probe.write_text("import numpy\nfrom .. import synth\nfrom ..synth.motion import walk\n\n\n"
                     "def f():\n    from occupose.synth import scenarios\n")
    names = [name for _, name in _imports(probe, package)]
    assert names == ["numpy", "occupose", "occupose.synth", "occupose.synth.motion", "occupose.synth.motion.walk",
                     "occupose.synth", "occupose.synth.scenarios"]


def test_importing_occupose_changes_no_environment_variable():
    code = ("import os; before = dict(os.environ); import occupose; "
            "from occupose import Tracker, TrackerConfig, open_recording, track_recording; "
            "assert dict(os.environ) == before, set(os.environ.items()) ^ set(before.items())")
    env = {k: v for k, v in os.environ.items() if not k.startswith(("NUMBA_", "OMP_"))}
    subprocess.run([sys.executable, "-c", code], check=True, env=env)
