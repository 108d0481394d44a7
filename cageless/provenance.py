"""Provenance records: what produced an output, from which inputs, and when.

Every output file records the software version, the git commit when the code
runs from a checkout, the resolved configuration, the input files with their
SHA-256 hashes, and UTC start and end times.
"""

from __future__ import annotations

import hashlib
import os
import platform
import subprocess
import sys
import threading
from collections.abc import Iterable, Mapping
from dataclasses import asdict, dataclass, field
from datetime import UTC, datetime
from concurrent.futures import ThreadPoolExecutor
from functools import lru_cache
from pathlib import Path
from typing import Any

from cageless._version import __version__
from cageless.atomic import atomic_write_text

__all__ = ["InputFile", "Provenance", "sha256_file", "git_commit", "cache_dir"]

_CHUNK = 1 << 20
_POOL = ThreadPoolExecutor(max_workers=2, thread_name_prefix="cageless-hash")


def cache_dir() -> Path:
    """Where cageless keeps caches: ``$CAGELESS_CACHE_DIR``, else ``$XDG_CACHE_HOME/cageless``, else ``~/.cache/cageless``."""
    env = os.environ.get("CAGELESS_CACHE_DIR")
    if env:
        return Path(env)
    return Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "cageless"


def _stat_key(path: Path) -> str:
    files = sorted(p for p in path.rglob("*") if p.is_file()) if path.is_dir() else [path]
    parts = [str(path.resolve())]
    for f in files:
        st = f.stat()
        parts.append(f"{f.name}:{st.st_size}:{st.st_mtime_ns}:{st.st_ino}")
    return hashlib.sha256("|".join(parts).encode()).hexdigest()


_CACHE_LOCK = threading.Lock()


def sha256_file(path: str | Path, cache: bool = True) -> str:
    """Return the hex SHA-256 of a file, read in 1 MiB chunks.

    For a folder (an image sequence) the hash covers the sorted file names and contents.
    With ``cache`` the result is remembered under :func:`cache_dir`, keyed by the path, size,
    modification time and inode of every file, so an unchanged video is hashed once (hashing
    costs about 0.6 s per GB here).
    """
    path = Path(path)
    key = _stat_key(path) if cache else ""
    store = cache_dir() / "sha256"
    if cache and (store / key).is_file():
        return (store / key).read_text().strip()
    value = _sha256_uncached(path)
    if cache:
        try:
            with _CACHE_LOCK:
                atomic_write_text(store / key, value)
        except OSError:  # a read-only home is no reason to fail
            pass
    return value


def _sha256_uncached(path: Path) -> str:
    digest = hashlib.sha256()
    files = sorted(p for p in path.rglob("*") if p.is_file()) if path.is_dir() else [path]
    for p in files:
        if path.is_dir():
            digest.update(str(p.relative_to(path)).encode())
        with open(p, "rb") as fh:
            while chunk := fh.read(_CHUNK):
                digest.update(chunk)
    return digest.hexdigest()


@lru_cache(maxsize=1)
def git_commit() -> str | None:
    """Return the git commit of the cageless source tree, or ``None`` outside a checkout."""
    here = Path(__file__).resolve().parent
    try:
        out = subprocess.run(
            ["git", "-C", str(here), "rev-parse", "HEAD"],
            capture_output=True, text=True, timeout=5, check=False,
        )
    except (OSError, subprocess.SubprocessError):
        return None
    if out.returncode != 0:
        return None
    dirty = subprocess.run(
        ["git", "-C", str(here), "status", "--porcelain", "--untracked-files=no"],
        capture_output=True, text=True, timeout=5, check=False,
    )
    return out.stdout.strip() + ("-dirty" if dirty.stdout.strip() else "")


def _utc_now() -> str:
    return datetime.now(UTC).isoformat(timespec="microseconds")


@dataclass(frozen=True)
class InputFile:
    """One input file: its name, size and SHA-256."""

    name: str
    size_bytes: int
    sha256: str

    @classmethod
    def from_path(cls, path: str | Path) -> InputFile:
        """Hash a file (or image-sequence folder) and record it."""
        path = Path(path)
        size = (
            sum(p.stat().st_size for p in path.rglob("*") if p.is_file())
            if path.is_dir() else path.stat().st_size
        )
        return cls(name=str(path), size_bytes=size, sha256=sha256_file(path))


@dataclass
class Provenance:
    """What produced an output.

    Use :meth:`start` at the beginning of the work and :meth:`finish` at the end;
    :meth:`to_dict` gives the JSON-ready record that goes into output files.
    """

    software_version: str
    git_commit: str | None
    python_version: str
    platform: str
    config: dict[str, Any]
    inputs: list[InputFile] = field(default_factory=list)
    started_utc: str = ""
    finished_utc: str | None = None

    @classmethod
    def start(
        cls, config: Mapping[str, Any] | None = None, inputs: Iterable[str | Path] = (), background: bool = False,
    ) -> Provenance:
        """Begin a record now, hashing the given input files.

        With ``background=True`` the hashing runs in a thread (hashlib releases the GIL), overlapping
        the caller's work; :meth:`finish` (or :attr:`inputs`) waits for it.
        """
        paths = list(inputs)
        record = cls(
            software_version=__version__,
            git_commit=git_commit(),
            python_version=sys.version.split()[0],
            platform=platform.platform(),
            config=dict(config or {}),
            started_utc=_utc_now(),
        )
        if background and paths:
            record._pending = _POOL.submit(lambda: [InputFile.from_path(p) for p in paths])
        else:
            record.inputs = [InputFile.from_path(p) for p in paths]
        return record

    def wait(self) -> Provenance:
        """Wait for background hashing to finish; return ``self``."""
        pending = getattr(self, "_pending", None)
        if pending is not None:
            self.inputs = pending.result()
            self._pending = None
        return self

    def finish(self) -> Provenance:
        """Wait for any background hashing, stamp the end time and return ``self``."""
        self.wait()
        self.finished_utc = _utc_now()
        return self

    def to_dict(self) -> dict[str, Any]:
        """Return the record as a JSON-ready dict."""
        self.wait()
        return {k: v for k, v in asdict(self).items() if not k.startswith("_")}
