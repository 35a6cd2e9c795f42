"""Process-wide numba settings, applied by the entry points (the command line, the
evaluation's workers, the benchmarks and the tests), never on ``import occupose``.

Must run before numba is first imported to take effect.
"""

from __future__ import annotations

import os
from pathlib import Path


def configure(threads: int | None = None) -> None:
    """Cache compiled kernels in ``$XDG_CACHE_HOME/occupose/numba`` (default
    ``~/.cache/occupose/numba``) so the cost is paid once per machine, not once per process;
    let idle OpenMP threads sleep instead of spin (a busy core, another process or the
    tracker's other stage, does not slow every kernel down); ``threads``: numba's thread
    count (None: numba's default, one per core). Settings the user made in the environment
    are kept."""
    cache = Path(os.environ.get("XDG_CACHE_HOME", Path.home() / ".cache")) / "occupose" / "numba"
    os.environ.setdefault("NUMBA_CACHE_DIR", str(cache))
    os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")
    if threads is not None:
        os.environ["NUMBA_NUM_THREADS"] = str(int(threads))
