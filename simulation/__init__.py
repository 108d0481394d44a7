"""simulation: the nonlinear dynamics of a cageless ball bearing (DESIGN §6-§7).

The model lands with the simulator issues; this package imports only the
shared core :mod:`cageless` and never ``tracking`` or ``comparison``.
"""

from simulation import _cache

_cache.check()  # before anything compiles: numba's caches must match these sources
