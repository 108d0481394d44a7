"""numba's caches of the simulation package are keyed on the digest of all its sources (simulation._cache)."""

from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace

import numba
import pytest

from cageless.simulation import _cache


def test_the_key_follows_the_sources_the_kernels_import(tmp_path):
    """Editing a module a kernel imports (here a callee in models/, reached through a relative import) changes the
    digest every kernel's cache is stamped with; editing a file no kernel imports (a benchmark helper) does not."""
    (tmp_path / "models").mkdir()
    (tmp_path / "models" / "__init__.py").write_text("")
    model = tmp_path / "models" / "planar.py"
    model.write_text("K = 1\n")
    (tmp_path / "kernels.py").write_text("import numba\nfrom .models import planar\n\n\n@numba.njit\n"
                                         "def f(x):\n    return planar.K * x\n")
    helper = tmp_path / "bench.py"
    helper.write_text("from .kernels import f\n")
    before = _cache._digest.__wrapped__(tmp_path)
    assert _cache._digest.__wrapped__(tmp_path) == before  # same sources, same key
    helper.write_text("from .kernels import f\nN = 2\n")
    assert _cache._digest.__wrapped__(tmp_path) == before  # not imported by a kernel: no recompile
    model.write_text("K = 2\n")
    assert _cache._digest.__wrapped__(tmp_path) != before


def test_the_closure_of_the_simulator_kernels():
    """The models, forces and slot constants are in the closure, and so are the shared modules outside the package
    that the kernels import (their constants compile in); the Python drivers are not."""
    from cageless import numba_cache

    root = Path(_cache.__file__).resolve().parent
    closure = numba_cache.kernel_sources(root)
    rel = {p.relative_to(root).as_posix() for p in closure if p.is_relative_to(root)}
    outside = {p.name for p in closure if not p.is_relative_to(root)}
    assert {"models/base.py", "models/planar.py", "forces.py", "traction.py", "kernels.py",
            "integrators/dp5.py", "integrators/ark.py"} <= rel
    assert not {"bench.py", "solve.py", "auto_switch.py", "run.py", "sweep.py"} & rel
    assert "units.py" in outside  # cageless/units.py, outside the package folder


def test_package_kernels_carry_the_digest_and_others_do_not():
    from cageless.simulation.models import planar

    locator = planar.planar_rhs._cache._impl.locator
    assert isinstance(locator, _cache.PackageSourcesLocator)
    assert locator.get_source_stamp()[1] == _cache.source_digest()

    @numba.njit(cache=True)
    def outside(x):  # pragma: no cover - compiled; this test file is not in the package
        return x

    assert not isinstance(outside._cache._impl.locator, _cache.PackageSourcesLocator)


def test_clear_cache_removes_the_package_caches_only(tmp_path, monkeypatch):
    monkeypatch.setattr(numba.config, "CACHE_DIR", str(tmp_path))
    stub = SimpleNamespace(__code__=SimpleNamespace(co_firstlineno=0))
    planar = Path(_cache.__file__).parent / "models" / "planar.py"
    where = Path(_cache.PackageSourcesLocator.from_function(stub, str(planar)).get_cache_path())
    assert where.is_relative_to(tmp_path)  # NUMBA_CACHE_DIR is honoured
    ours = [where / "planar.planar_rhs-1.py311.nbi", where / "planar.planar_rhs-1.py311.1.nbc"]
    other = where / "unrelated.f-1.py311.nbi"
    for f in [*ours, other]:
        f.write_text("")
    assert _cache.clear_cache() >= 2
    assert not any(f.exists() for f in ours) and other.exists()


def test_is_compiled_reads_the_on_disk_cache(tmp_path, monkeypatch):
    """A cached function whose index is missing will compile (False); once called and saved it is compiled (True),
    and a fresh dispatcher over the same source finds it on disk; an object without numba's cache gives None."""
    import importlib.util
    import sys

    monkeypatch.setattr(numba.config, "CACHE_DIR", str(tmp_path / "cache"))
    src = tmp_path / "somekernel.py"
    src.write_text("import numba\n\n@numba.njit(cache=True)\ndef f(x):\n    return x + 1.0\n")

    def load():
        spec = importlib.util.spec_from_file_location("somekernel", src)
        module = importlib.util.module_from_spec(spec)
        sys.modules.pop("somekernel", None)
        spec.loader.exec_module(module)
        return module.f

    f = load()
    assert _cache.is_compiled(f) is False
    assert f(1.0) == 2.0
    assert _cache.is_compiled(f) is True
    assert _cache.is_compiled(load()) is True  # a new process would load it from the index on disk
    assert _cache.is_compiled(object()) is None


def test_the_compile_notice_is_silent_when_the_integrator_is_cached():
    from cageless.simulation.integrators.ark import ark_integrate
    from cageless.simulation.integrators.dp5 import dp5_integrate

    cached = _cache.is_compiled(dp5_integrate) and _cache.is_compiled(ark_integrate)
    notice = _cache.compile_notice()
    assert (notice is None) if cached else ("compiling the simulator" in notice)


@pytest.mark.parametrize(("missing", "words"), [
    ({"dp5_integrate", "ark_integrate"}, "first run after an install"),
    ({"ark_integrate"}, "implicit solver when the run first switches to it"),
    (set(), None),
])
def test_the_compile_notice_names_what_compiles(monkeypatch, missing, words):
    """The implicit solver (ark4) compiles when `auto` first switches to it, mid-run: the notice says so
    before the run, not only when the explicit integrator is missing (a new user saw the bar stand still)."""
    monkeypatch.setattr(_cache, "is_compiled", lambda f: f.__name__ not in missing)
    notice = _cache.compile_notice()
    assert notice is None if words is None else words in notice
