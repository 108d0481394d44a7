"""Atomic file output: write to a temporary name in the same folder, then rename.

A crash or exception while writing never leaves a file under the final name,
so a half-written output can never be mistaken for a complete one.
"""

from __future__ import annotations

import errno
import os
import stat
import tempfile
import time
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

from cageless.errors import CagelessError

__all__ = ["atomic_path", "atomic_write_text", "atomic_write_bytes", "OutputError", "STALE_PART_S", "is_abandoned"]

#: Where advisory locks are missing, a temporary file older than this counts as left over by a killed run.
STALE_PART_S = 3600.0
_FULL = (errno.ENOSPC, errno.EDQUOT)


class OutputError(CagelessError, OSError):
    """An output cannot be written: disk full, read-only, not a regular file, no such folder.

    It is also an :class:`OSError` carrying the original ``errno``, so callers that tolerate a failed
    write (a cache on a read-only home) still do.
    """

    def __init__(self, message: str, errno_: int | None = None) -> None:
        OSError.__init__(self, message)
        self.errno = errno_

    def __str__(self) -> str:
        return str(self.args[0])


def _refuse_non_regular(path: Path) -> None:
    try:
        mode = path.stat().st_mode
    except OSError:
        return
    if not stat.S_ISREG(mode):
        kind = "a folder" if stat.S_ISDIR(mode) else "a device or other special file"
        raise OutputError(f"{path}: is {kind}, not a regular file; cageless will not replace it.")


def _output_error(path: Path, exc: OSError) -> OutputError:
    if isinstance(exc, OutputError):
        return exc
    if exc.errno in _FULL:
        return OutputError(f"no space left on {path.parent} (writing {path.name}). Free some space and re-run.",
                           exc.errno)
    return OutputError(f"{path}: cannot write it ({exc.strerror or exc}).", exc.errno)


def _hold(fd: int) -> None:
    """Take an exclusive advisory lock on an open temporary file (POSIX; elsewhere nothing)."""
    try:
        import fcntl

        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
    except (ImportError, OSError):
        pass


def is_abandoned(part: Path, min_age_s: float) -> bool:
    """True when ``part`` is at least ``min_age_s`` old and no live writer holds its lock."""
    try:
        if time.time() - part.stat().st_mtime < min_age_s:
            return False
        import fcntl

        fd = os.open(part, os.O_RDONLY)
    except ImportError:  # pragma: no cover - no advisory locks: age alone decides
        return time.time() - part.stat().st_mtime >= max(min_age_s, STALE_PART_S)
    except OSError:
        return False
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        return True
    except OSError:
        return False
    finally:
        os.close(fd)


def _remove_stale(path: Path) -> None:
    """Remove abandoned temporaries of this very target (left by a killed writer)."""
    for p in path.parent.glob(f".{path.name}.*.part"):
        try:
            if len(p.name) == len(path.name) + 15 and is_abandoned(p, 2.0):
                p.unlink()
        except OSError:
            continue

# mkstemp creates files readable by the owner only; outputs should honour the umask like open() does.
_UMASK = os.umask(0)
os.umask(_UMASK)


@contextmanager
def atomic_path(path: str | Path) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; rename it to ``path`` on success.

    The parent folder is created if needed. On any exception the temporary
    file is removed and the exception propagates; ``path`` is left as it was.

    Parameters
    ----------
    path
        The final file name.

    Yields
    ------
    pathlib.Path
        The temporary file to write (it exists and is empty).
    """
    path = Path(path)
    _refuse_non_regular(path)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        _remove_stale(path)
        fd, name = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".part", dir=path.parent)
    except OSError as exc:
        raise _output_error(path, exc) from exc
    _hold(fd)  # a cleaner never removes a temporary file whose writer is alive
    tmp = Path(name)
    try:
        os.chmod(tmp, 0o666 & ~_UMASK)
        yield tmp
        with open(tmp, "rb+") as fh:
            os.fsync(fh.fileno())
        _refuse_non_regular(path)
        os.replace(tmp, path)
    except OSError as exc:
        tmp.unlink(missing_ok=True)
        raise _output_error(path, exc) from exc
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    finally:
        os.close(fd)


def atomic_write_bytes(path: str | Path, data: bytes) -> None:
    """Write ``data`` to ``path`` atomically."""
    with atomic_path(path) as tmp:
        tmp.write_bytes(data)


def atomic_write_text(path: str | Path, text: str, encoding: str = "utf-8") -> None:
    """Write ``text`` to ``path`` atomically."""
    atomic_write_bytes(path, text.encode(encoding))
