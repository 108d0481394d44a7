"""Provenance records: what produced an output, from which inputs, and when.

Every output file records the software version, the git commit when the code
runs from a checkout, the resolved configuration, the input files with their
SHA-256 hashes, and UTC start and end times.
"""

from __future__ import annotations

import hashlib
import platform
import subprocess
import sys
from collections.abc import Iterable, Mapping
from dataclasses import asdict, dataclass, field
from datetime import UTC, datetime
from functools import lru_cache
from pathlib import Path
from typing import Any

from cageless._version import __version__

__all__ = ["InputFile", "Provenance", "sha256_file", "git_commit"]

_CHUNK = 1 << 20


def sha256_file(path: str | Path) -> str:
    """Return the hex SHA-256 of a file, read in 1 MiB chunks.

    For a folder (an image sequence) the hash covers the sorted file names and contents.
    """
    path = Path(path)
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
        cls, config: Mapping[str, Any] | None = None, inputs: Iterable[str | Path] = ()
    ) -> Provenance:
        """Begin a record now, hashing the given input files."""
        return cls(
            software_version=__version__,
            git_commit=git_commit(),
            python_version=sys.version.split()[0],
            platform=platform.platform(),
            config=dict(config or {}),
            inputs=[InputFile.from_path(p) for p in inputs],
            started_utc=_utc_now(),
        )

    def finish(self) -> Provenance:
        """Stamp the end time and return ``self``."""
        self.finished_utc = _utc_now()
        return self

    def to_dict(self) -> dict[str, Any]:
        """Return the record as a JSON-ready dict."""
        return asdict(self)
