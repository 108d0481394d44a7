"""Provenance records: what produced an output, from which inputs, and when.

Every output file records the software version, the git commit when the code
runs from a checkout, the resolved configuration, the input files with their
hashes, and UTC start and end times.

Each input's record names its hash algorithm by its key: ``{"name", "size_bytes",
"sha256": hex}``, ``{"name", "size_bytes", "blake3": hex}`` or ``{"name", "size_bytes",
"xxh3_128": hex}``. SHA-256 is the default. Videos are hashed with XXH3-128 (the
``xxhash`` package; the digest ``xxh128sum`` prints), an identity check rather than a
cryptographic one: 0.35 ms of CPU per 2 MB frame read from the page cache against BLAKE3's
0.95 ms here (``benchmarks/input_hash.py``), so that hashing a recording does not cap the
tracking throughput. Records written with SHA-256 or BLAKE3 (earlier versions) read as
before, with the algorithm they name.
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
from concurrent.futures import Future, ThreadPoolExecutor
from functools import lru_cache
from pathlib import Path
from typing import Any

from cageless._version import __version__
from cageless.atomic import atomic_write_text

__all__ = ["InputFile", "Provenance", "sha256_file", "hash_file", "prefetch_hash", "HASH_ALGORITHMS", "VIDEO_HASH", "git_commit",
           "cache_dir", "code_digest"]

_CHUNK = 1 << 20
#: The hash algorithms an input can be recorded with (BLAKE3: videos hashed by earlier versions).
HASH_ALGORITHMS = ("sha256", "blake3", "xxh3_128")
#: The algorithm videos are hashed with: XXH3-128, the fastest of the three (see the module's docstring).
VIDEO_HASH = "xxh3_128"
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
    """Return the hex SHA-256 of a file, read in 1 MiB chunks (see :func:`hash_file`)."""
    return hash_file(path, "sha256", cache)


def hash_file(path: str | Path, algorithm: str = "sha256", cache: bool = True) -> str:
    """Return the hex digest of a file with ``algorithm`` (one of :data:`HASH_ALGORITHMS`).

    For a folder (an image sequence) the hash covers the sorted file names and contents.
    With ``cache`` the result is remembered under :func:`cache_dir` (one folder per algorithm),
    keyed by the path, size, modification time and inode of every file, so an unchanged video
    is hashed once. The file is read in 1 MiB blocks into one reused buffer, so memory stays
    flat; the hashers release the GIL, so hashing in a thread overlaps other work. Measured here
    (CPU time, one core, a 2 MB frame from the page cache, read included): SHA-256 about 1.7 ms,
    BLAKE3 about 0.95 ms, XXH3-128 about 0.35 ms (``benchmarks/input_hash.py``). Hashing from a memory
    map instead cost as much or more (XXH3-128 0.43 ms) and was not kept.

    Raises
    ------
    ValueError
        For an algorithm not in :data:`HASH_ALGORITHMS`.
    """
    if algorithm not in HASH_ALGORITHMS:
        raise ValueError(f"hash algorithm {algorithm!r}: use one of {', '.join(HASH_ALGORITHMS)}")
    path = Path(path)
    key = _stat_key(path) if cache else ""
    store = cache_dir() / algorithm
    if cache:
        # in flight first: a job leaves _INFLIGHT only after it has written the cache, so no moment falls between
        # the two checks (cache first, a job finishing in between was hashed twice: seen once under load)
        with _INFLIGHT_LOCK:
            running = _INFLIGHT.get((key, algorithm))
        if running is not None:  # prefetch_hash started it: wait instead of hashing twice
            return str(running.result())
        if (store / key).is_file():
            return (store / key).read_text().strip()
    return _hash_and_store(path, algorithm, key if cache else None)


def _hash_and_store(path: Path, algorithm: str, key: str | None) -> str:
    value = _hash_uncached(path, algorithm)
    if key is not None:
        try:
            with _CACHE_LOCK:
                atomic_write_text(cache_dir() / algorithm / key, value)
        except OSError:  # a read-only home is no reason to fail
            pass
    return value


_INFLIGHT: dict[tuple[str, str], Future[str]] = {}
_INFLIGHT_LOCK = threading.Lock()


def prefetch_hash(path: str | Path, algorithm: str = "sha256") -> None:
    """Start hashing ``path`` in a background thread now (e.g. while the modules that will use it load).

    A later :func:`hash_file` of the same, unchanged file with the same algorithm waits for this
    result instead of reading the file again. A hash already in the cache is not recomputed.
    """
    path = Path(path)
    key = (_stat_key(path), algorithm)
    if (cache_dir() / algorithm / key[0]).is_file():
        return
    with _INFLIGHT_LOCK:
        if key in _INFLIGHT:
            return
        future = _POOL.submit(_hash_and_store, path, algorithm, key[0])
        _INFLIGHT[key] = future
    future.add_done_callback(lambda _: _forget(key))


def _forget(key: tuple[str, str]) -> None:
    with _INFLIGHT_LOCK:
        _INFLIGHT.pop(key, None)


def _new_digest(algorithm: str) -> Any:
    if algorithm == "xxh3_128":
        import xxhash

        return xxhash.xxh3_128()
    if algorithm == "blake3":
        from blake3 import blake3

        return blake3()
    return hashlib.sha256()


def _hash_uncached(path: Path, algorithm: str) -> str:
    digest = _new_digest(algorithm)
    buf = bytearray(_CHUNK)  # one buffer, refilled: the memory used does not grow with the file
    view = memoryview(buf)
    files = sorted(p for p in path.rglob("*") if p.is_file()) if path.is_dir() else [path]
    for p in files:
        if path.is_dir():
            digest.update(str(p.relative_to(path)).encode())
        with open(p, "rb", buffering=0) as fh:
            while n := fh.readinto(buf):
                digest.update(view[:n])  # the hashers release the GIL on large buffers
    return str(digest.hexdigest())


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


#: The packages whose sources decide results (the science packages install as sub-packages of cageless).
_CODE_PACKAGES = ("cageless", "cageless.tracking", "cageless.simulation", "cageless.comparison")


@lru_cache(maxsize=1)
def code_digest() -> str:
    """SHA-256 over the relative path and bytes of every ``.py`` file of cageless and its science packages.

    Read once per process without importing the packages. A report's job cache keys on it, so work done
    by other code (an edited checkout, an upgrade under the same version) is redone, not reused.
    """
    import importlib.util

    h = hashlib.sha256()
    for name in _CODE_PACKAGES:
        spec = importlib.util.find_spec(name)
        for root in sorted(spec.submodule_search_locations or []) if spec else []:
            for path in sorted(Path(root).rglob("*.py")):
                h.update(f"{name}/{path.relative_to(root).as_posix()}".encode())
                h.update(path.read_bytes())
    return h.hexdigest()


def _utc_now() -> str:
    return datetime.now(UTC).isoformat(timespec="microseconds")


@dataclass(frozen=True)
class InputFile:
    """One input file: its name, size and hash (hex ``digest`` by ``algorithm``)."""

    name: str
    size_bytes: int
    digest: str
    algorithm: str = "sha256"

    @property
    def sha256(self) -> str | None:
        """The SHA-256 digest, or ``None`` when the file was hashed with another algorithm."""
        return self.digest if self.algorithm == "sha256" else None

    @classmethod
    def from_path(cls, path: str | Path, algorithm: str = "sha256") -> InputFile:
        """Hash a file (or image-sequence folder) and record it."""
        path = Path(path)
        size = (
            sum(p.stat().st_size for p in path.rglob("*") if p.is_file())
            if path.is_dir() else path.stat().st_size
        )
        return cls(name=str(path), size_bytes=size, digest=hash_file(path, algorithm), algorithm=algorithm)

    @classmethod
    def from_dict(cls, record: Mapping[str, Any]) -> InputFile:
        """Read a record of :meth:`to_dict` (the key that names an algorithm holds the digest)."""
        algorithm = next((a for a in HASH_ALGORITHMS if a in record), "sha256")
        return cls(name=str(record["name"]), size_bytes=int(record["size_bytes"]),
                   digest=str(record.get(algorithm, "")), algorithm=algorithm)

    def to_dict(self) -> dict[str, Any]:
        """``{"name", "size_bytes", <algorithm>: digest}``: the key names the hash algorithm."""
        return {"name": self.name, "size_bytes": self.size_bytes, self.algorithm: self.digest}


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
        hash_algorithm: str = "sha256",
    ) -> Provenance:
        """Begin a record now, hashing the given input files with ``hash_algorithm``.

        With ``background=True`` the hashing runs in a thread (hashlib, blake3 and xxhash release the GIL),
        overlapping the caller's work; :meth:`finish` (or :attr:`inputs`) waits for it.
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
            record._pending = _POOL.submit(lambda: [InputFile.from_path(p, hash_algorithm) for p in paths])
        else:
            record.inputs = [InputFile.from_path(p, hash_algorithm) for p in paths]
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
        out = {k: v for k, v in asdict(self).items() if not k.startswith("_")}
        out["inputs"] = [f.to_dict() for f in self.inputs]
        return out
