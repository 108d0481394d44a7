"""Shared by the validation tests: what one effect adds to a model's right-hand side, and the benchmark scripts
(``benchmarks/*.py``) imported by name."""

from __future__ import annotations

import contextlib
import importlib
import sys
from collections.abc import Iterator
from pathlib import Path
from types import ModuleType

import numpy as np

#: The repository's benchmark scripts, which some validation tests check against their hand computations.
BENCHMARKS = Path(__file__).resolve().parents[2] / "benchmarks"


@contextlib.contextmanager
def benchmark_module(name: str) -> Iterator[ModuleType]:
    """``benchmarks/<name>.py`` imported by name, with ``benchmarks/`` on ``sys.path`` while the block runs (so
    spawned worker processes find its functions)."""
    sys.path.insert(0, str(BENCHMARKS))
    try:
        yield importlib.import_module(name)
    finally:
        sys.path.remove(str(BENCHMARKS))


def effect_contribution(pr, y: np.ndarray, flag: str) -> np.ndarray:  # type: ignore[no-untyped-def]
    """dy/dt of ``pr`` at ``y`` with the effect slot ``flag`` (e.g. ``"F_TRAC"``) on, minus with it off."""
    off = pr.params.copy()
    off[pr.layout.index(flag)] = 0.0
    on = pr.rhs(0.0, y)
    saved = pr.params.copy()
    pr.params[:] = off
    try:
        base = pr.rhs(0.0, y)
    finally:
        pr.params[:] = saved
    return on - base
