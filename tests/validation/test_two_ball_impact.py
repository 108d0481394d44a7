"""A free head-on impact of two paper-bearing balls (DESIGN §6, simulator issue "Two-ball impact").

Restitution: the damping factor is calibrated (simulation.forces.damping_factor) so the rebound equals the
configured R; measured here on the compiled integrator at rtol 1e-9, it must match R to 1e-3 at every
speed (the impact is self-similar in the approach speed, so the error is the integrator's alone). R = 0 (perfectly plastic) is represented by a rebound below
1e-3 (simulation.forces.PLASTIC_CHI), so the same tolerance holds for it.
Contact duration of an elastic impact (R = 1): Hertz impact theory, Johnson, *Contact Mechanics* (1985),
sect. 11.4: t_c = 2 (delta_max / v) * integral_0^1 (1 - x^(5/2))^(-1/2) dx = 2.943 delta_max / v, with
delta_max = (5 m* v^2 / (4 K))^(2/5) and m* = m/2.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad

from cageless.parameter_sets import wang2026
from cageless.simulation.hertz import ball_ball_contact
from cageless.simulation.models.two_balls import two_ball_problem
from cageless.simulation.solve import solve

G, MAT, MASS = wang2026.geometry(), wang2026.material(), wang2026.masses().ball_mass_kg
K = ball_ball_contact(G, MAT).stiffness


def _impact(restitution: float, speed: float, n: int = 40001):
    dmax = (5 * (MASS / 2) * speed**2 / (4 * K)) ** 0.4
    t_end = 12 * dmax / speed
    pr = two_ball_problem(G.ball_diameter_m, MASS, K, restitution, speed, gap_m=0.05 * dmax)
    t = np.linspace(0.0, t_end, n)
    sol = solve(pr, t, rtol=1e-9, max_step=dmax / speed / 200)
    assert sol.success, sol.message
    return t, sol, dmax


@pytest.mark.parametrize("restitution", [0.0, 0.05, 0.3, 0.7, 0.95, 1.0])
@pytest.mark.parametrize("speed", [0.05, 0.5, 2.0])
def test_rebound_matches_the_configured_restitution(restitution, speed):
    _, sol, _ = _impact(restitution, speed)
    v_out = sol.y[-1, 3] - sol.y[-1, 2]
    assert v_out / speed == pytest.approx(restitution, abs=1e-3)


def test_elastic_contact_duration_matches_hertz_theory():
    speed = 0.5
    t, sol, dmax = _impact(1.0, speed, n=400001)
    overlap = G.ball_diameter_m - (sol.y[:, 1] - sol.y[:, 0])
    inside = t[overlap > 0]
    duration = inside[-1] - inside[0]
    integral, _ = quad(lambda x: (1 - x**2.5) ** -0.5, 0, 1)
    theory = 2 * integral * dmax / speed
    assert 2 * integral == pytest.approx(2.943, abs=1e-3)  # Johnson's 2.94
    assert duration == pytest.approx(theory, rel=2e-3)
    assert overlap.max() == pytest.approx(dmax, rel=1e-4)
    # Energy is conserved by the elastic impact.
    ke = 0.5 * MASS * (sol.y[:, 2] ** 2 + sol.y[:, 3] ** 2)
    assert ke[-1] == pytest.approx(ke[0], rel=1e-7)
    assert math.isfinite(duration)
