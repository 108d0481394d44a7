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


def _package(folder: Path) -> Path:
    """A package of one kernel that imports a constant from a sibling module."""
    folder.mkdir()
    (folder / "__init__.py").write_text("")
    (folder / "consts.py").write_text("K = 1\n")
    (folder / "kernels.py").write_text("import numba\nfrom .consts import K\n\n\n@numba.njit\ndef f(x):\n    return K * x\n")
    return folder.resolve()


def _fresh(root: Path) -> str:
    """The digest computed from the sources, without the stamp (the definition :func:`source_digest` keeps)."""
    import hashlib
    import os

    h = hashlib.sha256()
    for path in numba_cache.kernel_sources(root):
        h.update(Path(os.path.relpath(path, root)).as_posix().encode())
        h.update(path.read_bytes())
    return h.hexdigest()


def test_the_closure_digest_is_remembered_until_a_file_changes(tmp_path, monkeypatch):
    """A cold process reads the kernel closure's digest from its stamp (0.1 s of CPU less for the tracking package:
    no AST walk over 20 files) only while every ``.py`` file of the package, and every file of the closure
    outside it, has the times, size and inode it had when stamped; any edit or new kernel file recomputes it."""
    import numba

    monkeypatch.setattr(numba.config, "CACHE_DIR", str(tmp_path / "numba"))
    monkeypatch.setattr(numba_cache, "_RACY_NS", 0)
    root = _package(tmp_path / "pkg")
    stamp = numba_cache._stamp(root)
    assert stamp is not None and stamp.is_relative_to(tmp_path / "numba")
    first = numba_cache._digest.__wrapped__(root)
    assert first == _fresh(root) and stamp.is_file()
    assert numba_cache._read_stamp(stamp, root) == first
    (root / "consts.py").write_text("K = 10\n")  # an edit of a module a kernel imports
    assert numba_cache._read_stamp(stamp, root) is None
    second = numba_cache._digest.__wrapped__(root)
    assert second == _fresh(root) != first
    (root / "more.py").write_text("import numba\n\n\n@numba.njit\ndef g(x):\n    return x\n")  # a new kernel file
    assert numba_cache._read_stamp(stamp, root) is None
    assert numba_cache._digest.__wrapped__(root) == _fresh(root) != second


def test_files_changed_within_the_clock_tick_are_not_stamped(tmp_path, monkeypatch):
    """A file's times have the kernel clock's tick as resolution: an edit that keeps the size within one tick would
    not show, so nothing changed in the last two seconds is stamped (git's "racy" entries)."""
    import numba

    monkeypatch.setattr(numba.config, "CACHE_DIR", str(tmp_path / "numba"))
    root = _package(tmp_path / "pkg")
    assert numba_cache._digest.__wrapped__(root) == _fresh(root)
    assert not numba_cache._stamp(root).is_file()
