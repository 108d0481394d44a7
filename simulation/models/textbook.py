"""Textbook test problems for the integrators, with exact solutions.

* harmonic oscillator x'' = -w^2 x: x(t) = cos(w t) from x = 1, x' = 0;
* Riccati equation y' = k y^2: y(t) = y0 / (1 - k y0 t), which blows up at t = 1 / (k y0).
"""

from __future__ import annotations

import numba
import numpy as np

from cageless.simulation.problem import Problem

__all__ = ["oscillator_problem", "riccati_problem", "OSCILLATOR", "RICCATI"]

OSCILLATOR, RICCATI = 2, 3


@numba.njit(cache=True, inline="always")  # compiled into the kernels' switch
def oscillator_rhs(t, y, p, log, dydt):  # pragma: no cover - compiled
    dydt[0] = y[1]
    dydt[1] = -p[0] * p[0] * y[0]


@numba.njit(cache=True, inline="always")  # compiled into the kernels' switch
def riccati_rhs(t, y, p, log, dydt):  # pragma: no cover - compiled
    dydt[0] = p[0] * y[0] * y[0]


def oscillator_problem(w: float) -> Problem:
    """x'' = -w^2 x from x = 1, x' = 0."""
    return Problem(model_id=OSCILLATOR, params=np.array([w]), log=np.zeros(1), y0=np.array([1.0, 0.0]), t0=0.0,
                   atol=np.array([1e-12, 1e-12 * w]), name="harmonic oscillator")


def riccati_problem(k: float, y0: float) -> Problem:
    """y' = k y^2 from y0 (blows up at t = 1 / (k y0))."""
    return Problem(model_id=RICCATI, params=np.array([k]), log=np.zeros(1), y0=np.array([y0]), t0=0.0,
                   atol=np.array([1e-9]), name="Riccati")
