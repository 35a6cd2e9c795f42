"""Writing outputs whole or not at all, and never over what occupose did not write.

Every command that writes goes through this module, and so do the library functions that
write a command's output (``run.write_run`` and ``run.track_into``,
``synth.catalogue.render_scenario``, ``viz.show_frame``, ``evaluation.evaluate``); DESIGN.md
style rule 10. Two kinds of output:

- a *folder* (a recording, a run's ``tracks.csv`` and ``summary.json``, an evaluation):
  :func:`staged_folder` makes it in a hidden folder beside its destination and, once every
  file is written, records them in :data:`MANIFEST` and renames the whole folder into
  place. A run that fails or is interrupted leaves the destination as it was.
- a *picture* (one PNG file): :func:`staged_picture` writes it under a temporary name in
  the same folder and renames it when complete; the PNG's ``Software`` text says
  :data:`SOFTWARE`, which is how a picture of occupose is told from one of the user's.

The overwrite rule, the same for both: a destination that exists (a folder that is not
empty, or a file) is refused unless ``force``; ``force`` replaces only an output occupose
wrote (a folder with a :data:`MANIFEST` of the same kind, a picture that says
:data:`SOFTWARE`), and in a folder it replaces only the files that manifest lists: the
user's own files there are carried into the new folder (hard links; the old folder is
untouched until the swap). An output inside an input recording, or holding one, is
refused. Everything is checked, and the hidden folder or file made, before the caller
does its work, so a long run is never lost to an output it could not write.

Any refusal and any OS error on output (permissions, a full disk, a name too long, a file
where a folder should be) is an :class:`OutputError` naming the destination's path.
"""

from __future__ import annotations

import contextlib
import json
import os
import shutil
import tempfile
from collections.abc import Callable, Iterable, Iterator
from pathlib import Path

#: The file in an output folder that lists what occupose wrote there (JSON:
#: ``{"format": "occupose-output", "version": 1, "kind": ..., "files": [relative paths]}``).
MANIFEST = "occupose-manifest.json"
#: What an output folder holds, as its manifest's ``kind`` says.
KINDS = ("recording", "run", "evaluation")
#: The ``Software`` text of every PNG picture occupose writes.
SOFTWARE = "occupose"
_FORMAT = "occupose-output"
_VERSION = 1


class OutputError(ValueError):
    """An output that may not or cannot be written; the message names its path."""


# --------------------------------------------------------------------------- checks


def _real(path: Path) -> Path:
    return Path(os.path.realpath(path))


def _check_inputs(out: Path, inputs: Iterable[str | os.PathLike]) -> None:
    """Refuse ``out`` inside an input recording or holding one."""
    target = _real(out)
    for given in inputs:
        source = _real(Path(given))
        if target == source or source in target.parents:
            raise OutputError(f"{out} is inside the input recording {given}: occupose never writes into its input")
        if target in source.parents:
            raise OutputError(f"{out} holds the input recording {given}: occupose never writes over its input")


def _check_name(out: Path) -> None:
    """Refuse a name longer than the file system allows (before any work, not at the rename)."""
    folder = next((p for p in _real(out).parents if p.is_dir()), Path("/"))
    try:
        limit = os.pathconf(folder, "PC_NAME_MAX")
    except (OSError, ValueError):
        return
    for part in out.parts:
        if len(os.fsencode(part)) > limit:
            raise OutputError(f"{out}: the name {part[:40]}... is {len(os.fsencode(part))} bytes long; "
                              f"the file system takes at most {limit}")


def _check_parents(out: Path) -> None:
    """Refuse ``out`` below a file."""
    for parent in out.parents:
        if parent.exists() and not parent.is_dir():
            raise OutputError(f"{out}: {parent} is a file, not a folder")


def read_manifest(folder: str | os.PathLike) -> dict | None:
    """The :data:`MANIFEST` of ``folder`` as a dict (``kind``, ``files``), or None when there
    is none; an unreadable or malformed one is an :class:`OutputError`."""
    path = Path(folder) / MANIFEST
    if not path.is_file():
        return None
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, ValueError, RecursionError) as error:
        raise OutputError(f"{path}: unreadable ({error}); not replacing {folder}") from None
    if (not isinstance(data, dict) or data.get("format") != _FORMAT or data.get("kind") not in KINDS
            or not isinstance(data.get("files"), list) or not all(isinstance(f, str) for f in data["files"])):
        raise OutputError(f"{path}: not a manifest of occupose; not replacing {folder}")
    return data


def check_output(out: str | os.PathLike, kind: str, *, force: bool = False,
                 inputs: Iterable[str | os.PathLike] = ()) -> dict | None:
    """Check that a folder output of ``kind`` (:data:`KINDS`) may be written at ``out``
    under the overwrite rule (module docstring); nothing is touched. Returns the manifest
    of the earlier output that ``force`` will replace, or None when there is none.
    Raises :class:`OutputError` saying why not."""
    if kind not in KINDS:
        raise ValueError(f"kind must be one of {', '.join(KINDS)}, got {kind!r}")
    out = Path(out)
    _check_inputs(out, inputs)
    _check_name(out)
    if out.is_symlink() and not out.exists():
        raise OutputError(f"{out} is a broken symbolic link")
    if not out.exists():
        _check_parents(out)
        return None
    if not out.is_dir():
        raise OutputError(f"{out} exists and is not a folder")
    try:
        empty = not any(out.iterdir())
    except OSError as error:
        raise OutputError(f"{out}: cannot read it ({error.strerror})") from None
    if empty:
        return None
    if not force:
        raise OutputError(f"{out} exists and is not empty (use --force to replace an earlier output of occupose)")
    manifest = read_manifest(out)
    if manifest is None:
        raise OutputError(f"{out} was not written by occupose (no {MANIFEST}): not replacing it, even with --force")
    if manifest["kind"] != kind:
        raise OutputError(f"{out} holds an occupose {manifest['kind']}, not a {kind}: not replacing it, even with "
                          "--force")
    return manifest


# --------------------------------------------------------------------------- helpers


def _make_parents(folder: Path) -> list[Path]:
    """Make ``folder`` and its missing parents; returns those made, deepest first (on an
    OSError, those made so far are removed first)."""
    missing = []
    for path in (folder, *folder.parents):
        if path.exists():
            break
        missing.append(path)
    made = []
    try:
        for path in reversed(missing):
            path.mkdir()
            made.insert(0, path)
    except OSError:
        _remove_made(made)
        raise
    return made


def _remove_made(made: list[Path]) -> None:
    for path in made:
        with contextlib.suppress(OSError):
            path.rmdir()


def _usual_mode(path: Path, mode: int) -> None:
    """Give ``path``, made private by tempfile, the permissions ``mode`` under the umask,
    as a file or folder made the usual way would have."""
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(path, mode & ~umask)


def _os_error(error: OSError, out: Path, staging: Path | None = None) -> Exception:
    """An OSError on output as an OutputError naming the destination's path (a path inside
    ``staging``, a temporary name, is named as it will be in ``out``); an OSError about a
    path elsewhere (an input) is returned as it is. One without a path (a failed write)
    is taken to be the output's."""
    if not error.filename:
        path = out
    else:
        path = Path(error.filename)
        if staging is not None and (path == staging or staging in path.parents):
            path = out / path.relative_to(staging)
        elif path != out and out not in path.parents and path not in out.parents:
            return error
    return OutputError(f"{path}: cannot write it ({error.strerror or error})")


def _link(source, target) -> None:
    """A hard link ``target`` to the file ``source`` (a plain copy where the file system has none)."""
    try:
        os.link(source, target, follow_symlinks=False)
    except OSError:
        shutil.copy2(source, target, follow_symlinks=False)


def link_tree(source: Path, target: Path) -> None:
    """Make ``target`` a copy of the folder ``source`` of hard links (:func:`_link`), so
    that either may be removed without touching the other."""
    shutil.copytree(source, target, symlinks=True, copy_function=_link)


def _entries(folder: Path) -> tuple[list[str], list[str]]:
    """(files and symbolic links, folders) under ``folder``, as sorted relative POSIX paths."""
    files, folders = [], []
    for root, dirs, names in os.walk(folder):
        base = Path(root).relative_to(folder)
        for name in dirs:
            (files if (Path(root) / name).is_symlink() else folders).append((base / name).as_posix())
        files += [(base / name).as_posix() for name in names]
    return sorted(files), sorted(folders)


def _carry_user_files(old: Path, manifest: dict, staging: Path, out: Path) -> None:
    """Hard-link into ``staging`` what ``old`` holds that its manifest does not list."""
    ours = set(manifest["files"]) | {MANIFEST}
    files, folders = _entries(old)
    theirs = [f for f in files if f not in ours]
    theirs += [d for d in folders if not any(f.startswith(d + "/") for f in ours)]  # folders of theirs only
    for name in theirs:
        there = staging / name
        if os.path.lexists(there) and not (name in folders and there.is_dir() and not there.is_symlink()):
            raise OutputError(f"{out / name}: something occupose did not write is where the new output has a "
                              "file; move it away first")
    for name in sorted(theirs):
        if name in folders:
            (staging / name).mkdir(parents=True, exist_ok=True)
        else:
            (staging / name).parent.mkdir(parents=True, exist_ok=True)
            _link(old / name, staging / name)


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike) -> Iterator[Path]:
    """A temporary name beside ``path`` to write the file to (made empty at once, so the
    folder is known writable before the work); renamed to ``path`` when the block ends
    without an exception, removed otherwise. An OSError of a write, which names no file,
    is raised again naming ``path``."""
    path = Path(path)
    handle, temporary = tempfile.mkstemp(prefix=f".{path.name[:80]}.", suffix=".tmp", dir=path.parent)
    os.close(handle)
    temporary = Path(temporary)
    try:
        _usual_mode(temporary, 0o666)
        yield temporary
        os.replace(temporary, path)
    except OSError as error:
        temporary.unlink(missing_ok=True)
        if error.filename:
            raise
        raise OSError(error.errno, error.strerror, str(path)) from None  # a failed write: name the file
    except BaseException:
        temporary.unlink(missing_ok=True)
        raise


def write_text(path: str | os.PathLike, text: str) -> Path:
    """Write ``text`` (UTF-8) to ``path`` whole or not at all (:func:`atomic_path`)."""
    with atomic_path(path) as temporary:
        temporary.write_text(text, encoding="utf-8")
    return Path(path)


# --------------------------------------------------------------------------- folders


def _swap(staging: Path, target: Path, replacing: bool) -> None:
    """Rename ``staging`` to ``target``; an earlier folder there is renamed aside first and
    removed last, or put back if the swap does not complete."""
    if not replacing:
        os.replace(staging, target)  # onto nothing, or onto an empty folder
        return
    aside = Path(tempfile.mkdtemp(prefix=f".{target.name[:80]}.old-", dir=target.parent))
    os.rmdir(aside)
    os.rename(target, aside)
    try:
        os.rename(staging, target)
    except BaseException:
        os.rename(aside, target)
        raise
    shutil.rmtree(aside, ignore_errors=True)


@contextlib.contextmanager
def staged_folder(out: str | os.PathLike, kind: str, *, force: bool = False,
                  inputs: Iterable[str | os.PathLike] = ()) -> Iterator[Path]:
    """A hidden empty folder beside ``out`` to write a folder output of ``kind`` into; when
    the block ends without an exception it is swapped in at ``out`` (module docstring),
    else removed, with any parents of ``out`` it made, and ``out`` is left as it was.

    Checked first (:func:`check_output`), then the folder is made, both before the
    block runs. Raises :class:`OutputError` for a refusal or an OS error on output."""
    out = Path(out)
    manifest = check_output(out, kind, force=force, inputs=inputs)
    target = _real(out) if out.is_symlink() else out
    made = []
    try:
        made += _make_parents(target.parent)
        staging = Path(tempfile.mkdtemp(prefix=f".{target.name[:80]}.new-", dir=target.parent))
        _usual_mode(staging, 0o777)
    except OSError as error:
        _remove_made(made)
        raise OutputError(f"{out}: cannot write it ({error.strerror or error})") from None
    try:
        yield staging
        files, _ = _entries(staging)
        if manifest is not None:
            _carry_user_files(target, manifest, staging, out)
        write_text(staging / MANIFEST, json.dumps({"format": _FORMAT, "version": _VERSION, "kind": kind,
                                                   "files": files}, indent=1) + "\n")
        _swap(staging, target, replacing=manifest is not None)
    except OSError as error:
        shutil.rmtree(staging, ignore_errors=True)
        _remove_made(made)
        raise _os_error(error, out, staging) from None
    except BaseException:
        shutil.rmtree(staging, ignore_errors=True)
        _remove_made(made)
        raise


# --------------------------------------------------------------------------- pictures


def is_occupose_picture(path: str | os.PathLike) -> bool:
    """Whether ``path`` is a PNG whose ``Software`` text is :data:`SOFTWARE`."""
    from PIL import Image

    try:
        with Image.open(path) as image:
            return image.format == "PNG" and image.info.get("Software") == SOFTWARE
    except Exception:  # anything unreadable is not a picture of ours
        return False


def picture_path(out: str | os.PathLike) -> Path:
    """The file a picture asked for at ``out`` is written to: ``out`` with ``.png``
    appended when it has no suffix. A folder, or any suffix but ``.png``, is an
    :class:`OutputError`."""
    out = Path(out)
    if out.is_dir():
        raise OutputError(f"{out} is a folder; give the picture's file name")
    if not out.suffix:
        return out.with_name(out.name + ".png")
    if out.suffix.lower() != ".png":
        raise OutputError(f"{out}: pictures are written as PNG; give a name ending in .png")
    return out


@contextlib.contextmanager
def staged_file(out: str | os.PathLike, is_ours: Callable[[Path], bool], what: str, *, force: bool = False,
                inputs: Iterable[str | os.PathLike] = ()) -> Iterator[Path]:
    """A temporary name beside the single-file output ``out`` (a ``what``, e.g. "picture")
    to write it to, renamed to ``out`` when the block ends without an exception. Checked
    first (the overwrite rule: an existing file is refused without ``force``, and with it
    unless ``is_ours(out)``, the writer's test that occupose wrote it); parents of ``out``
    made for it are removed on failure. Raises :class:`OutputError` for a refusal or an
    OS error on output."""
    out = Path(out)
    _check_inputs(out, inputs)
    _check_name(out)
    if out.is_dir():
        raise OutputError(f"{out} is a folder; give the {what}'s file name")
    if os.path.lexists(out):
        if not force:
            raise OutputError(f"{out} exists (use --force to replace a {what} occupose made)")
        if not is_ours(out):
            raise OutputError(f"{out} was not written by occupose: not replacing it, even with --force")
    _check_parents(out)
    made = []
    try:
        made += _make_parents(out.parent)
        with atomic_path(out) as temporary:
            yield temporary
    except OSError as error:
        _remove_made(made)
        if error.filename and Path(error.filename).parent == out.parent:  # the temporary name: say out
            error = OSError(error.errno, error.strerror)
        raise _os_error(error, out) from None
    except BaseException:
        _remove_made(made)
        raise


def staged_picture(out: str | os.PathLike, *, force: bool = False,
                   inputs: Iterable[str | os.PathLike] = ()):
    """:func:`staged_file` for the picture file ``out`` (a :func:`picture_path`), ours when
    :func:`is_occupose_picture`. The writer must give the PNG the ``Software`` text
    :data:`SOFTWARE`."""
    return staged_file(out, is_occupose_picture, "picture", force=force, inputs=inputs)


__all__ = ["KINDS", "MANIFEST", "SOFTWARE", "OutputError", "atomic_path", "check_output", "is_occupose_picture",
           "link_tree", "picture_path", "read_manifest", "staged_file", "staged_folder", "staged_picture", "write_text"]
