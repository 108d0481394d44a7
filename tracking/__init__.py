"""tracking: from bearing video to per-ball orbital-angle, speed and slip traces.

The pipeline lands with the video-input and tracking issues; this package
imports only the shared core :mod:`cageless` and never ``simulation`` or
``comparison``.

Its compiled kernels are cached by numba under the digest of the sources its kernels import
(:mod:`cageless.numba_cache`): the tracking loop (``link_kernel.py``) compiles in the centroid of
``detect.py``, and numba's own key, the caller's file stamp, would keep running an edited callee's old code.
"""

from pathlib import Path as _Path

from cageless import numba_cache as _numba_cache

_numba_cache.register(_Path(__file__).resolve().parent)


def compile_notice() -> str | None:
    """A line for the user when the next tracking run compiles the tracking loop first (after an install or an
    upgrade, one to two minutes on two cores), else ``None``."""
    from cageless.tracking.link_kernel import run_block

    if _numba_cache.is_compiled(run_block) is False:
        return "compiling the tracker (first run after an install or upgrade only; 1-3 min, then it is cached)"
    return None
