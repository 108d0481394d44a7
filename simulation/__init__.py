"""simulation: the nonlinear dynamics of a cageless ball bearing.

The model lands with the simulator issues; this package imports only the
shared core :mod:`cageless` and never ``tracking`` or ``comparison``.

Its compiled kernels are cached by numba under an explicit key, the digest of
the package's sources (:mod:`cageless.simulation._cache`); :func:`clear_cache` deletes
those caches.
"""

from cageless.simulation import _cache

_cache.install()  # registers the cache key before any kernel of the package is decorated
clear_cache = _cache.clear_cache

__all__ = ["clear_cache"]
