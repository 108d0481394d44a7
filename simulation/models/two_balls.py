"""Two free balls colliding head-on: the validation problem for the ball-ball contact law.

States: x1, x2, v1, v2 (m, m/s); ball 2 starts to the right of ball 1 and they
approach. ``log[0]`` holds the approach speed recorded when contact begins
(reset when it ends), for the Flores damping term.
"""

from __future__ import annotations

import numba
import numpy as np

from cageless.simulation.forces import damping_factor, hertz_damped
from cageless.simulation.problem import Problem

__all__ = ["two_ball_problem", "MODEL_ID"]

#: Id of this model in :mod:`cageless.simulation.kernels`.
MODEL_ID = 1


@numba.njit(cache=True, inline="always")  # compiled into the kernels' switch
def two_ball_rhs(t, y, p, log, dydt):  # pragma: no cover - compiled
    diameter, mass1, mass2, stiffness, chi = p[0], p[1], p[2], p[3], p[4]
    delta = diameter - (y[1] - y[0])
    delta_dot = y[2] - y[3]
    if delta > 0.0 and log[0] <= 0.0:
        log[0] = max(delta_dot, 1e-12)
    elif delta <= 0.0:
        log[0] = 0.0
    f = hertz_damped(delta, delta_dot, log[0], stiffness, chi)
    dydt[0] = y[2]
    dydt[1] = y[3]
    dydt[2] = -f / mass1
    dydt[3] = f / mass2


@numba.njit(cache=True, inline="always")  # compiled into the kernels' switch
def two_ball_post(t, y, p, log):  # pragma: no cover - compiled
    if p[0] - (y[1] - y[0]) <= 0.0:
        log[0] = 0.0


def two_ball_problem(diameter_m: float, mass_kg: float, stiffness: float, restitution: float,
                     approach_speed_m_s: float, gap_m: float = 1e-6) -> Problem:
    """Two equal balls ``gap_m`` apart, approaching at ``approach_speed_m_s``."""
    v = 0.5 * approach_speed_m_s
    y0 = np.array([0.0, diameter_m + gap_m, v, -v])
    p = np.array([diameter_m, mass_kg, mass_kg, stiffness, damping_factor(restitution)])
    atol = np.array([1e-12, 1e-12, 1e-9, 1e-9])
    return Problem(model_id=MODEL_ID, params=p, log=np.zeros(1), y0=y0, t0=0.0, atol=atol, name="two balls")
