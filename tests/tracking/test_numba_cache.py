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


def test_an_installed_package_is_not_cached_beside_its_sources(tmp_path, monkeypatch):
    """A package under ``site-packages`` caches in numba's user-wide folder: cache files beside its sources
    outlived ``pip uninstall`` and made the emptied folder a namespace package that hid a later editable
    install (found by a new user running the README's two commands in one environment). A source checkout
    keeps ``__pycache__`` beside its sources."""
    import numba
    from numba.core import caching

    monkeypatch.setattr(numba.config, "CACHE_DIR", "")  # no NUMBA_CACHE_DIR: numba's own order applies
    stub = type("F", (), {"__code__": type("C", (), {"co_firstlineno": 1})})()
    user_wide = getattr(caching, "UserWideCacheLocator", None) or getattr(caching, "_UserWideCacheLocator")
    for folder, first in (("site-packages", user_wide), ("checkout", numba_cache._IN_TREE)):
        source = tmp_path / "lib" / folder / "pkg" / "kernels.py"
        source.parent.mkdir(parents=True)
        source.write_text("x = 1\n")
        assert numba_cache.installed(source) is (folder == "site-packages")
        locators = numba_cache.SourcesLocator.base_locators(stub, str(source))
        assert type(locators[0]) is first
        assert not Path(locators[0].get_cache_path()).is_relative_to(tmp_path / "lib" / "site-packages")
