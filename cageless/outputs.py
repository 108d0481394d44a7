"""Where outputs may go: checks of ``-o`` targets, the output-folder lock, and stale temporary files.

* :func:`check_output_file` and :func:`check_output_dir` refuse, before any work, a target that is a
  device, a folder where a file is wanted (or a file where a folder is wanted), a path under a file,
  a folder that cannot be created, and a file of the wrong kind; each with what was expected.
* :func:`output_lock` takes an exclusive lock on an output folder, so a second run into the same folder
  is refused with a clear message instead of mixing its results in. The lock is an OS file lock
  (the ``filelock`` package): it is released when the process ends, even by ``kill -9``.
* :func:`clean_stale_parts` removes the temporary ``.part`` files that killed runs left behind: only
  files named the way :func:`cageless.atomic.atomic_path` names them, and only old ones.
"""

from __future__ import annotations

import json
import logging
import os
import re
import stat
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from datetime import UTC, datetime
from pathlib import Path
from typing import TYPE_CHECKING

from cageless.atomic import is_abandoned
from cageless.errors import CagelessError, UsageError

if TYPE_CHECKING:
    import pandas as pd

__all__ = ["versioned_csv", "check_output_file", "check_output_dir", "output_lock", "clean_stale_parts", "LOCK_NAME",
           "FolderInUseError", "PART_RE"]

log = logging.getLogger(__name__)

LOCK_NAME = ".cageless.lock"
#: The temporary names of :func:`cageless.atomic.atomic_path`: ``.<final name>.<8 random chars>.part``.
PART_RE = re.compile(r"^\..+\.[a-z0-9_]{8}\.part$")
_HDF5_MAGIC = b"\x89HDF\r\n\x1a\n"


class FolderInUseError(CagelessError):
    """Another cageless run holds the output folder's lock."""


def _kind(mode: int) -> str:
    for test, name in ((stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
                       (stat.S_ISFIFO, "a named pipe"), (stat.S_ISSOCK, "a socket"), (stat.S_ISDIR, "a folder")):
        if test(mode):
            return name
    return "not a regular file"


def _check_parents(path: Path, option: str, shown: Path | None = None) -> None:
    """Refuse a path under a file, and a parent folder that cannot be created or written; messages name
    ``shown`` (default ``path``)."""
    shown = path if shown is None else shown
    for parent in reversed(path.parents):
        if parent.exists() and not parent.is_dir():
            what = "a file" if parent.is_file() else _kind(parent.stat().st_mode)
            raise UsageError(f"{option} {shown}: {parent} is {what}, not a folder. Choose another path.")
    existing = next((p for p in path.parents if p.exists()), Path("."))
    try:  # a real probe: access() says yes to root on read-only and virtual file systems such as /proc
        with tempfile.TemporaryFile(dir=existing):
            pass
    except OSError as exc:
        raise UsageError(f"{option} {shown}: cannot write in {existing} ({exc.strerror}). "
                         "Choose another path.") from None


def _trace_source(path: Path) -> str | None:
    """``"video"`` or ``"simulation"`` for a cageless trace, ``"damaged"`` for a damaged HDF5 file under a
    trace name (ours to replace), None for anything else."""
    try:
        with open(path, "rb") as fh:
            head = fh.read(8)
    except OSError:
        return None
    if head != _HDF5_MAGIC:
        return None
    try:
        import h5py

        with h5py.File(path, "r") as f:
            if not str(f.attrs.get("schema", "")).startswith("cageless-trace/"):
                return None
            return str(f.attrs.get("source", "damaged"))
    except (OSError, RuntimeError):
        return "damaged"


def _is_cageless_trace(path: Path) -> bool:
    return _trace_source(path) is not None


def is_foreign_file(path: str | Path) -> bool:
    """True when ``path`` is an existing file that is not a cageless trace: cageless does not replace it."""
    path = Path(path)
    return path.is_file() and not _is_cageless_trace(path)


def check_products(folder: str | Path, names: tuple[str, ...], marker: str, option: str = "-o") -> None:
    """Refuse to write a command's named products into ``folder`` when files of those names are there
    and the folder holds no ``marker`` of an earlier cageless run (so cageless did not write them).

    Raises
    ------
    UsageError
        Naming the files found.
    """
    folder = Path(folder)
    if not folder.is_dir() or (folder / marker).exists():
        return
    found = [n for n in names if (folder / n).exists()]
    if found:
        raise UsageError(f"{option} {folder}: already holds {', '.join(found)}, which cageless did not write "
                         "there and would replace. Choose another folder, or move those files.")


def check_output_file(path: str | Path, option: str = "-o", suffixes: tuple[str, ...] = (".h5",),
                      example: str = "result.trace.h5", overwrite: bool = False) -> Path:
    """Check a file target before any work; return it as a :class:`~pathlib.Path`.

    Refused: a device, pipe or socket (never renamed over), a folder, a path under a file, a folder
    that cannot be written, a name not ending in one of ``suffixes`` (the file is HDF5 whatever its
    name), and, without ``overwrite``, an existing file that is not a cageless trace.

    Raises
    ------
    UsageError
        Saying what was found and what was expected.
    """
    path = Path(path)
    want = " or ".join(f"'{s}'" for s in suffixes)
    if path.exists() or path.is_symlink():
        try:
            mode = path.stat().st_mode
        except OSError:
            mode = path.lstat().st_mode
        if stat.S_ISDIR(mode):
            raise UsageError(f"{option} {path}: is a folder; give a file name ending in {want}, "
                             f"e.g. {path / example}.")
        if not stat.S_ISREG(mode):
            raise UsageError(f"{option} {path}: is {_kind(mode)}, not a regular file; cageless writes only "
                             "regular files. Choose another path.")
    if not path.name.lower().endswith(suffixes):
        raise UsageError(f"{option} {path}: the output is an HDF5 trace; give a name ending in {want}, "
                         f"e.g. {path.with_name(path.name.split('.')[0] + '.trace.h5')}.")
    _check_parents(path, option)
    source = _trace_source(path) if path.is_file() else "absent"
    if path.is_file() and not overwrite and source is None:
        raise UsageError(f"{option} {path}: exists and is not a cageless trace; cageless does not overwrite "
                         "files it did not write. Choose another name, or pass --overwrite.")
    if source == "video" and not overwrite:
        raise UsageError(f"{option} {path}: holds a measured (video) trace, which a simulation would replace. "
                         "Choose another name, or pass --overwrite.")
    return path


def check_output_dir(path: str | Path, option: str = "-o") -> Path:
    """Check a folder target (it may not exist yet) before any work; return it.

    Raises
    ------
    UsageError
        When it is a file or device, lies under a file, or cannot be created or written.
    """
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise UsageError(f"{option} {path}: is {_kind(path.stat().st_mode) if not path.is_file() else 'a file'}, "
                         "not a folder. Give a folder (it is created if needed).")
    _check_parents(path / "x", option, shown=path)
    return path


@contextmanager
def output_lock(folder: str | Path, what: str = "output folder") -> Iterator[None]:
    """Hold an exclusive lock on ``folder`` (created if needed) for the duration of the block.

    A folder this call created is removed again when the run wrote nothing into it.

    Raises
    ------
    FolderInUseError
        When another process holds it, naming that process when it said who it is.
    UsageError
        When the folder cannot be created.
    """
    from filelock import FileLock, Timeout

    folder = Path(folder)
    created = [p for p in (folder, *folder.parents) if not p.exists()]
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise UsageError(f"{folder}: cannot create the folder ({exc.strerror}). Choose another path.") from None
    lock_path = folder / LOCK_NAME
    info_path = folder / (LOCK_NAME + ".json")
    lock = FileLock(str(lock_path), timeout=0)
    try:
        lock.acquire()
    except Timeout:
        holder = ""
        try:
            info = json.loads(info_path.read_text())
            holder = f" (pid {info['pid']}, started {info['started_utc']})"
        except (OSError, ValueError, KeyError):
            pass
        raise FolderInUseError(
            f"{folder}: this {what} is in use by another cageless run{holder}. Wait for it to finish, "
            "or choose another -o folder.") from None
    try:
        try:
            info_path.write_text(json.dumps({"pid": os.getpid(),
                                             "started_utc": datetime.now(UTC).isoformat(timespec="seconds")}))
        except OSError:
            pass
        yield
    finally:
        info_path.unlink(missing_ok=True)
        try:  # no stray lock file is left in the user's folder (removed while still held: no other run saw it free)
            lock_path.unlink(missing_ok=True)
        except OSError:  # Windows: an open file cannot be removed; it stays, empty, as filelock leaves it
            pass
        lock.release()
        _remove_if_empty(created, lock_path)


def _remove_if_empty(created: list[Path], lock_path: Path) -> None:
    """Remove the folders this run created when it wrote nothing into them (no empty output is left)."""
    if not created or any(p != lock_path for p in created[0].iterdir()):
        return
    lock_path.unlink(missing_ok=True)
    for p in created:
        try:
            p.rmdir()
        except OSError:
            return


def clean_stale_parts(folder: str | Path, min_age_s: float = 2.0, recursive: bool = True) -> list[Path]:
    """Delete the ``.part`` files of killed runs under ``folder``.

    Only our temporary names, only files at least ``min_age_s`` old, and only those whose writer is gone:
    a live writer holds an advisory lock on its temporary file (:func:`cageless.atomic.atomic_path`).

    Returns
    -------
    list of pathlib.Path
        The files removed.
    """
    folder = Path(folder)
    if not folder.is_dir():
        return []
    removed = []
    for p in folder.rglob("*.part") if recursive else folder.glob("*.part"):
        try:
            if PART_RE.match(p.name) and p.is_file() and not p.is_symlink() and is_abandoned(p, min_age_s):
                p.unlink()
                removed.append(p)
        except OSError:
            continue
    if removed:
        log.info("removed %d temporary files left by interrupted runs in %s", len(removed), folder)
    return removed


def versioned_csv(frame: pd.DataFrame, float_format: str = "%.6g") -> str:
    """``frame`` as CSV text with a last column ``software_version`` (the cageless version that wrote it), so a
    table read back with ``pandas.read_csv`` says where it came from, as a trace's ``software_version`` does."""
    from cageless._version import __version__

    return frame.assign(software_version=__version__).to_csv(index=False, float_format=float_format)
