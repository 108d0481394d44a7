"""Shared by the validation tests of single effects: what one effect adds to a model's right-hand side."""

from __future__ import annotations

import numpy as np


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
