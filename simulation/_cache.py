"""Keep numba's on-disk caches of this package consistent with its sources.

numba keys a cached function on its own file's timestamp only. The compiled integrator
(``integrators/dp5.py``) and the model switch (``kernels.py``) call, and inline, functions of
other modules (``models/*``, ``forces.py``, ``traction.py``), so editing one of those would leave
the callers' caches stale: they would run the old physics. :func:`check` stamps a digest of every
source of the package beside the caches and, when it changes, drops all of the package's caches,
so the next call recompiles. It runs once when ``simulation`` is imported, before anything compiles.
Read-only installs (no writable ``__pycache__``) are left alone.
"""

from __future__ import annotations

import hashlib
import os
from pathlib import Path

__all__ = ["check"]

_ROOT = Path(__file__).resolve().parent
_STAMP = "cageless-numba-sources.sha256"


def _digest() -> str:
    h = hashlib.sha256()
    for path in sorted(_ROOT.rglob("*.py")):
        h.update(path.relative_to(_ROOT).as_posix().encode())
        h.update(path.read_bytes())
    return h.hexdigest()


def check() -> None:
    """Drop the package's numba caches if any of its sources changed since they were written."""
    cache = _ROOT / "__pycache__"
    stamp = cache / _STAMP
    try:
        digest = _digest()
        if stamp.is_file() and stamp.read_text() == digest:
            return
        for pattern in ("*.nbi", "*.nbc"):
            for stale in _ROOT.rglob(pattern):
                stale.unlink(missing_ok=True)
        cache.mkdir(exist_ok=True)
        tmp = stamp.with_name(f"{_STAMP}.{os.getpid()}.tmp")
        tmp.write_text(digest)
        tmp.replace(stamp)
    except OSError:  # a read-only install, or another process doing the same: nothing to keep consistent
        return
