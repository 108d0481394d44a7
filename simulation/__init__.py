"""simulation: the nonlinear dynamics of a cageless ball bearing.

The model lands with the simulator issues; this package imports only the
shared core :mod:`cageless` and never ``tracking`` or ``comparison``.

Its compiled kernels are cached by numba under an explicit key, the digest of
the package's sources (:mod:`cageless.simulation._cache`); :func:`clear_cache` deletes
those caches. Race-contact force laws installed as packages (entry-point group
``cageless.race_laws``) are registered on import (:mod:`cageless.simulation.models.race_laws`).
"""

from cageless.simulation import _cache

_cache.install()  # registers the cache key before any kernel of the package is decorated

from importlib.metadata import entry_points as _entry_points  # noqa: E402

if _entry_points(group="cageless.race_laws"):  # race_laws.ENTRY_POINT_GROUP; numba is imported only if needed
    from cageless.simulation.models import race_laws as _race_laws

    _race_laws.load_installed()  # installed race-contact laws join the effects table before the models import
clear_cache = _cache.clear_cache

__all__ = ["clear_cache"]
