"""Input files checked before they are read (private): a missing file, a folder, a device
or a symbolic-link loop where a file should be, and an OS error (permission denied), are
each an error naming the path, never a traceback or a read that does not end.
"""

from __future__ import annotations

import os
import stat
from pathlib import Path


def check_regular_file(path: Path, error: type[ValueError], what: str) -> None:
    """Raise unless ``path`` (symbolic links followed) is a regular file.

    path : the file; error : the ValueError subclass raised (the reader's own);
    what : what the file should be, for the messages (``"a PNG frame"``).
    Raises FileNotFoundError when nothing is there (a dangling link included), ``error``
    for a folder, device, pipe or socket, and for an OS error (its reason, e.g.
    permission denied on the folder above, too many levels of symbolic links).
    """
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        raise FileNotFoundError(f"{path}: no such file; expected {what}") from None
    except OSError as problem:
        raise error(f"{path}: cannot read it ({problem.strerror or problem}); expected {what}") from None
    if not stat.S_ISREG(mode):
        kind = "a folder" if stat.S_ISDIR(mode) else "a device, pipe or socket"
        raise error(f"{path}: is {kind}; expected {what}")


def read_file_bytes(path: Path, error: type[ValueError], what: str) -> bytes:
    """The bytes of the regular file ``path`` (`check_regular_file`), an OS error while
    reading it (permission denied) raised as ``error`` naming the path."""
    check_regular_file(path, error, what)
    try:
        return path.read_bytes()
    except OSError as problem:
        raise error(f"{path}: cannot read it ({problem.strerror or problem}); expected {what}") from None
