"""The key of numba's on-disk caches of this package: the digest of the sources its kernels import.

numba keys a cached function on its own source file's timestamp. The compiled integrator
(``integrators/dp5.py``) and the model switch (``kernels.py``) call, and inline, functions of other
modules (``models/*``, ``forces.py``, ``traction.py``) and compile in their slot constants
(``models/base.py``), so editing one of those would leave the callers' caches stale: they would run
the old physics. So every kernel of this package is cached under an explicit key: its own file's
stamp together with the SHA-256 of the package's kernel closure: every file that defines a kernel and every
module of ``cageless`` those import, transitively (:func:`source_digest`; see
:func:`cageless.numba_cache.kernel_sources`; a driver such as ``solve.py`` or ``bench.py`` is outside it and is
edited without a recompile) and the digest of the race-contact laws
registered at run time (:func:`cageless.simulation.models.race_laws.key`). A cache written under another digest no
longer matches; numba recompiles and overwrites it. Nothing is deleted behind the user's back:
:func:`clear_cache` removes the package's cache files when asked.

:func:`install` registers the package with :mod:`cageless.numba_cache`, whose locator adds the key in front
of numba's own; ``simulation/__init__.py`` calls it before any kernel is decorated. The caches stay where
numba puts them (``NUMBA_CACHE_DIR``, else ``__pycache__`` beside the sources, else numba's user-wide
cache directory).
"""

from __future__ import annotations

from collections.abc import Hashable
from pathlib import Path

from cageless import numba_cache
from cageless.numba_cache import _digest, is_compiled  # noqa: F401 - _digest: for the tests of the key

__all__ = ["PackageSourcesLocator", "clear_cache", "compile_notice", "install", "is_compiled", "source_digest"]

_ROOT = Path(__file__).resolve().parent
#: The locator that adds the key (shared with the tracking package: :mod:`cageless.numba_cache`).
PackageSourcesLocator = numba_cache.SourcesLocator


def source_digest() -> str:
    """SHA-256 over the relative path and bytes of every ``.py`` file of the package (read once per process)."""
    return numba_cache.source_digest(_ROOT)


def _laws_key() -> Hashable:
    from cageless.simulation.models import race_laws  # laws registered at run time compile into the race contacts

    return race_laws.key()


def install() -> None:
    """Key this package's kernels on its sources and its registered race laws (idempotent)."""
    numba_cache.register(_ROOT, _laws_key)


def clear_cache() -> int:
    """Delete the numba cache files (``*.nbi``, ``*.nbc``) of this package's kernels wherever numba keeps them
    now; returns how many were deleted. The next run recompiles (about a minute)."""
    return numba_cache.clear(_ROOT)


def compile_notice() -> str | None:
    """A line for the user when the next simulation compiles the integrator first (after an install or an
    upgrade, about one to five minutes on two idle cores, up to ten on a busy machine), else ``None``."""
    from cageless.simulation.integrators.ark import ark_integrate
    from cageless.simulation.integrators.dp5 import dp5_integrate

    if is_compiled(dp5_integrate) is False:
        return ("compiling the simulator (first run after an install or upgrade only; 1-5 min, up to 10 on a busy "
                "machine, then it is cached; the progress bar stands still meanwhile, also when the run first "
                "changes solver)")
    if is_compiled(ark_integrate) is False:  # compiled when `auto` first switches to it, mid-run
        return ("compiling the simulator's implicit solver when the run first switches to it (after an install "
                "or upgrade only; 1-3 min, then it is cached; the progress bar stands still meanwhile)")
    return None
