"""occupose: occlusion-aware 3D skeleton tracking of people in depth-camera recordings."""

import os as _os
from pathlib import Path as _Path

# Numba compiles kernels on first use; cache them in a writable folder so the cost is
# paid once per machine, not once per process. Must be set before numba is imported.
_os.environ.setdefault(
    "NUMBA_CACHE_DIR",
    str(_Path(_os.environ.get("XDG_CACHE_HOME", _Path.home() / ".cache")) / "occupose" / "numba"),
)

# Parallel numba kernels: idle OpenMP threads sleep instead of spinning, so a busy core
# (another process, or the tracker's other stage) does not slow every kernel down.
_os.environ.setdefault("OMP_WAIT_POLICY", "PASSIVE")

__version__ = "0.1.0"
