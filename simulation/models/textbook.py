"""Textbook test problems for the integrators, with exact solutions.

* harmonic oscillator x'' = -w^2 x: x(t) = cos(w t) from x = 1, x' = 0;
* Riccati equation y' = k y^2: y(t) = y0 / (1 - k y0 t), which blows up at t = 1 / (k y0);
* damped oscillator x'' = -k x - c x' from x = 1, x' = 0, with its damping -c x' as the implicit part of an
  IMEX split (:func:`damped_implicit`, the structure of the bearing models' race damping); the solution is
  the sum of exp(lambda t) over the roots of lambda^2 + c lambda + k = 0 (:func:`damped_exact`).
"""

from __future__ import annotations

import numba
import numpy as np

from cageless.simulation.problem import Problem

__all__ = ["oscillator_problem", "riccati_problem", "damped_problem", "damped_exact", "OSCILLATOR", "RICCATI",
           "DAMPED"]

OSCILLATOR, RICCATI, DAMPED = 2, 3, 5


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


@numba.njit(cache=True, inline="always")  # compiled into the kernels' switch
def damped_rhs(t, y, p, log, dydt):  # pragma: no cover - compiled
    dydt[0] = y[1]
    dydt[1] = -p[0] * y[0] - p[1] * y[1]


@numba.njit(cache=True, inline="always")  # compiled into the kernels' switch
def damped_implicit(y, p, hg, k_i):  # pragma: no cover - compiled
    """The implicit part -c x' (into ``k_i``); with ``hg > 0`` first solve x' = x'_Z - hg c x' in place."""
    if hg > 0.0:
        y[1] = y[1] / (1.0 + hg * p[1])
    k_i[0] = 0.0
    k_i[1] = -p[1] * y[1]


def damped_problem(k: float, c: float) -> Problem:
    """x'' = -k x - c x' from x = 1, x' = 0."""
    return Problem(model_id=DAMPED, params=np.array([k, c]), log=np.zeros(1), y0=np.array([1.0, 0.0]), t0=0.0,
                   atol=np.array([1e-12, 1e-12]), name="damped oscillator")


def damped_exact(k: float, c: float, t: np.ndarray) -> np.ndarray:
    """(x, x') of :func:`damped_problem` at times ``t`` (n x 2), from the characteristic roots (distinct)."""
    l1, l2 = np.roots([1.0, c, k]).astype(complex)
    a1 = -l2 / (l1 - l2)  # x(0) = a1 + a2 = 1, x'(0) = a1 l1 + a2 l2 = 0
    a2 = 1.0 - a1
    e1, e2 = np.exp(np.multiply.outer(t, l1)), np.exp(np.multiply.outer(t, l2))
    return np.stack([(a1 * e1 + a2 * e2).real, (a1 * l1 * e1 + a2 * l2 * e2).real], axis=-1)
