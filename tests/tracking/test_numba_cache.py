"""The tracking loop's compiled cache is keyed on all of the tracking package's sources (cageless.numba_cache).

numba keys a cached function on its own file only, and ``link_kernel.run_block`` compiles in the centroid of
``detect.py``: an edit to ``detect.py`` alone left the loop running the old centroid (seen in this project's
speed benchmark, which timed the centroid of the previous edit)."""

from __future__ import annotations

from pathlib import Path

from cageless import numba_cache


def test_the_tracking_kernels_carry_the_digest_of_the_tracking_sources():
    from cageless.tracking import detect, link_kernel

    root = Path(link_kernel.__file__).resolve().parent
    for kernel in (link_kernel.run_block, detect._centroids_core):
        locator = kernel._cache._impl.locator
        assert isinstance(locator, numba_cache.SourcesLocator)
        assert locator.get_source_stamp()[1] == numba_cache.source_digest(root)


def test_the_tracking_and_simulation_keys_are_separate():
    import cageless.simulation  # noqa: F401 - registers the simulation package
    from cageless.simulation import _cache
    from cageless.tracking import link_kernel

    tracking_root = Path(link_kernel.__file__).resolve().parent
    assert numba_cache.source_digest(tracking_root) != _cache.source_digest()
    assert link_kernel.run_block._cache._impl.locator.get_source_stamp()[2] is None  # no run-time laws
