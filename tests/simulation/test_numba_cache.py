"""numba's caches of the simulation package follow its sources (simulation._cache), on a stand-in tree."""

from __future__ import annotations

from simulation import _cache


def test_stale_caches_are_dropped_when_a_source_changes(tmp_path, monkeypatch):
    monkeypatch.setattr(_cache, "_ROOT", tmp_path)
    (tmp_path / "models").mkdir()
    model = tmp_path / "models" / "planar.py"
    model.write_text("K = 1\n")
    caches = [tmp_path / "__pycache__" / "kernels.model_rhs-20.py311.nbi", tmp_path / "models" / "__pycache__" / "x.nbc"]

    def fill() -> None:
        for c in caches:
            c.parent.mkdir(exist_ok=True)
            c.write_text("")

    fill()
    _cache.check()  # no stamp yet: the caches cannot be trusted
    assert not any(c.exists() for c in caches)
    fill()
    _cache.check()  # sources unchanged: kept
    assert all(c.exists() for c in caches)
    model.write_text("K = 2\n")  # a callee changes: every cache of the package goes, the stamp follows
    _cache.check()
    assert not any(c.exists() for c in caches)
    assert (tmp_path / "__pycache__" / _cache._STAMP).read_text() == _cache._digest()
