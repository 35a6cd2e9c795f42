"""Where occupose finds the optional shared data (real mocap clips, sensor files).

The data never ships with the package. It is found through the environment variable
``OCCUPOSE_DATA``; when that is unset, ``../shared/data`` beside the project's checkout
(or beside the current working directory) is used if it exists. Everything that uses it
falls back to built-in procedural data when it is absent.
"""

from __future__ import annotations

import os
from pathlib import Path

_PROJECT_ROOT = Path(__file__).resolve().parents[2]


def shared_data_dir() -> Path | None:
    """Return the shared data folder, or None when there is none.

    An ``OCCUPOSE_DATA`` that names a missing folder is an error, not a silent fallback.
    """
    env = os.environ.get("OCCUPOSE_DATA")
    if env:
        path = Path(env).expanduser()
        if not path.is_dir():
            raise FileNotFoundError(f"OCCUPOSE_DATA={env!r} is not a folder")
        return path
    for base in (_PROJECT_ROOT, Path.cwd()):
        candidate = base.parent / "shared" / "data"
        if candidate.is_dir():
            return candidate
    return None


def mocap_dir() -> Path | None:
    """Return the folder of real mocap clips (``<shared>/mocap``), or None."""
    data = shared_data_dir()
    if data is None or not (data / "mocap").is_dir():
        return None
    return data / "mocap"
