"""The key of numba's on-disk caches of this package: the digest of all its sources.

numba keys a cached function on its own source file's timestamp. The compiled integrator
(``integrators/dp5.py``) and the model switch (``kernels.py``) call, and inline, functions of other
modules (``models/*``, ``forces.py``, ``traction.py``) and compile in their slot constants
(``models/base.py``), so editing one of those would leave the callers' caches stale: they would run
the old physics. So every kernel of this package is cached under an explicit key: its own file's
stamp together with the SHA-256 of every ``.py`` file of the package (:func:`source_digest`, computed
once, when the first kernel of the package is decorated) and the digest of the race-contact laws
registered at run time (:func:`cageless.simulation.models.race_laws.key`). A cache written under another digest no
longer matches; numba recompiles and overwrites it. Nothing is deleted behind the user's back:
:func:`clear_cache` removes the package's cache files when asked.

:func:`install` registers the locator that adds the key (:class:`PackageSourcesLocator`) in front of
numba's own; ``simulation/__init__.py`` calls it before any kernel is decorated. The caches stay where
numba puts them (``NUMBA_CACHE_DIR``, else ``__pycache__`` beside the sources, else numba's user-wide
cache directory).
"""

from __future__ import annotations

import hashlib
from functools import lru_cache
from pathlib import Path
from types import SimpleNamespace
from typing import Any

from numba.core import caching

__all__ = ["PackageSourcesLocator", "clear_cache", "compile_notice", "install", "is_compiled", "source_digest"]

_ROOT = Path(__file__).resolve().parent
#: numba's cache implementation (renamed from ``_CacheImpl`` in numba 0.61).
_IMPL = getattr(caching, "CacheImpl", None) or getattr(caching, "_CacheImpl")


@lru_cache(maxsize=None)
def _digest(root: Path) -> str:
    h = hashlib.sha256()
    for path in sorted(root.rglob("*.py")):
        h.update(path.relative_to(root).as_posix().encode())
        h.update(path.read_bytes())
    return h.hexdigest()


def source_digest() -> str:
    """SHA-256 over the relative path and bytes of every ``.py`` file of the package (read once per process)."""
    return _digest(_ROOT)


def _inside(py_file: str) -> bool:
    try:
        return Path(py_file).resolve().is_relative_to(_ROOT)
    except OSError:
        return False


class PackageSourcesLocator(caching._CacheLocator):
    """numba's own locator for a function of this package, with the package's source digest in its stamp."""

    def __init__(self, base: Any) -> None:
        self._base = base

    def ensure_cache_path(self) -> None:
        self._base.ensure_cache_path()

    def get_cache_path(self) -> str:
        return self._base.get_cache_path()

    def get_source_stamp(self) -> Any:
        from cageless.simulation.models import race_laws  # laws registered at run time compile into the race contacts

        return (self._base.get_source_stamp(), source_digest(), race_laws.key())

    def get_disambiguator(self) -> str:
        return self._base.get_disambiguator()

    @classmethod
    def base_locators(cls, py_func: Any, py_file: str) -> list[Any]:
        """numba's own locators that accept ``py_file``, in its order of preference."""
        out = []
        for other in _IMPL._locator_classes:
            if other is not cls:
                loc = other.from_function(py_func, py_file)
                if loc is not None:
                    out.append(loc)
        return out

    @classmethod
    def from_function(cls, py_func: Any, py_file: str) -> PackageSourcesLocator | None:
        """The locator of a function of this package (None elsewhere: numba's own locators take it)."""
        if not _inside(py_file):
            return None
        for other in _IMPL._locator_classes:
            if other is not cls:
                base = other.from_function(py_func, py_file)
                if base is not None:
                    return cls(base)
        return None


def install() -> None:
    """Put :class:`PackageSourcesLocator` first among numba's cache locators (idempotent)."""
    if PackageSourcesLocator not in _IMPL._locator_classes:
        _IMPL._locator_classes.insert(0, PackageSourcesLocator)


def clear_cache() -> int:
    """Delete the numba cache files (``*.nbi``, ``*.nbc``) of this package's kernels wherever numba keeps them
    now; returns how many were deleted. The next run recompiles (about a minute)."""
    removed = 0
    for source in sorted(_ROOT.rglob("*.py")):
        stub = SimpleNamespace(__code__=SimpleNamespace(co_firstlineno=0))
        dirs = {Path(loc.get_cache_path()) for loc in PackageSourcesLocator.base_locators(stub, str(source))}
        for d in dirs:
            for pattern in (f"{source.stem}.*.nbi", f"{source.stem}.*.nbc"):
                for stale in d.glob(pattern):
                    stale.unlink(missing_ok=True)
                    removed += 1
    return removed


def is_compiled(dispatcher: Any) -> bool | None:
    """Whether ``dispatcher`` (a numba ``njit`` function with ``cache=True``) is compiled in this process or has an
    up-to-date entry in its on-disk cache; ``None`` when numba's cache cannot be read.

    numba's index file of a function records the source stamp it was written under; an index written under
    another stamp (other sources, another version) loads as empty, and the function will compile on its first
    call.
    """
    try:
        return bool(dispatcher.signatures) or bool(dispatcher._cache._cache_file._load_index())
    except Exception:  # noqa: BLE001 - a private numba interface: when it moves, say nothing rather than fail
        return None


def compile_notice() -> str | None:
    """A line for the user when the next simulation compiles the integrator first (after an install or an
    upgrade, about one to five minutes on two cores), else ``None``."""
    from cageless.simulation.integrators.dp5 import dp5_integrate

    if is_compiled(dp5_integrate) is False:
        return ("compiling the simulator (first run after an install or upgrade only; 1-5 min, then it is "
                "cached)")
    return None
