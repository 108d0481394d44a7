"""The compiled Rosenbrock-W method (simulation.integrators.rosw): its order, its agreement with DP5 on the bearing
and on the hard cases, and its determinism."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from cageless.conditions import OperatingConditions
from cageless.simulation.effects import choose_model
from cageless.simulation.hertz import compliance, hertz_contact, race_curvatures
from cageless.simulation.integrators.rosw import transformed_tableau
from cageless.simulation.kernels import model_gaps
from cageless.simulation.models.textbook import oscillator_problem
from cageless.simulation.run import energy_balance, simulate
from cageless.simulation.scene import Scene
from cageless.simulation.solve import _rosw


def _fixed_step_error(h: float, jac_every: int) -> float:
    """x'' = -w^2 x over one second in fixed steps h (a huge atol: the error test never rejects); error against
    the closed form cos(w t)."""
    w = 2.0
    pr = replace(oscillator_problem(w), atol=np.full(2, 1e6))
    sol = _rosw(pr, np.array([1.0]), 0.5, h, h, 10**7, 0.0, jac_every=jac_every)
    assert sol.success
    return abs(sol.y[-1, 0] - np.cos(w))


@pytest.mark.parametrize("jac_every", [1, 0])
def test_rosw_is_third_order_whatever_w(jac_every):
    """ROS34PW2 is a W-method of order 3 (Rang & Angermann, BIT 45 (2005) 761, Table 4.2): order 3 with the exact
    Jacobian (jac_every=1) and with W = 0 (jac_every=0, an explicit 4-stage method then). Halving h divides the
    error by 2^3 = 8."""
    errors = [_fixed_step_error(h, jac_every) for h in (0.05, 0.025, 0.0125)]
    ratios = [a / b for a, b in zip(errors, errors[1:], strict=False)]
    assert all(6.0 < r < 11.0 for r in ratios), (errors, ratios)


def test_rosw_tableau_is_consistent():
    """The transformed coefficients reproduce the method's order-1 and stiff-accuracy conditions: sum b_i = 1 and
    b equal to the last row of (alpha + Gamma) (stiffly accurate, Rang & Angermann 2005), in the transformed
    form m = b Gamma^-1 (Hairer & Wanner II, IV.7)."""
    a, c, m, e, alpha = transformed_tableau()
    assert alpha[0] == 0.0 and abs(alpha[-1] - 1.0) < 1e-15
    # y1 = y0 + sum m_j u_j with u = Gamma k: for f = const (u_i = h gamma_i. f), y1 - y0 = h f (order 1)
    gamma = np.array([[0.43586652150845900, 0, 0, 0], [-0.87173304301691801, 0.43586652150845900, 0, 0],
                      [-0.90338057013044082, 0.054180672388095326, 0.43586652150845900, 0],
                      [0.24212380706095346, -1.2232505839045147, 0.54526025533510214, 0.43586652150845900]])
    assert abs(m @ gamma.sum(axis=1) - 1.0) < 1e-14
    assert abs(e @ gamma.sum(axis=1)) < 1e-14  # the embedded method is consistent too


def _scene(rpm: float, load_n: float, duration_s: float) -> Scene:
    return Scene(conditions=OperatingConditions(rpm, load_n), duration_s=duration_s)


def _overlap_ok(pr, y) -> float:
    """The largest contact overlap over the samples (m)."""
    gaps = np.empty(pr.n_gaps)
    worst = 0.0
    for row in y:
        model_gaps(pr.model_id, row, pr.params, gaps)
        worst = max(worst, float(gaps.max()))
    return worst


@pytest.mark.parametrize("rpm, load_n", [(1800, 500), (3000, 20000)])
def test_rosw_hard_cases(rpm, load_n):
    """1800 rpm bunching and 20 kN, 10 ms from the packed start: finite, the energy balance closes to 1e-5 of
    the input work (the hard cases' bound), no overlap beyond the Hertz scale of the load (at most 2 x the
    20 kN static outer deflection, from the Hertz constant of the textbook contact), and the slip of the
    first 0.3 ms agrees with DP5's within 2 % (trajectories of the violent start-up part soon after)."""
    scene = _scene(rpm, load_n, 0.01)
    runs = {m: simulate(scene, choose_model(scene), method=m, progress=False) for m in ("dp5", "rosw")}
    sol, pr = runs["rosw"].solution, runs["rosw"].problem
    assert sol.success and np.all(np.isfinite(sol.y)), sol.message
    energy = energy_balance(pr, sol.y)
    assert energy.input_work[-1] > 0 and abs(energy.drift) < 1e-5 * energy.input_work[-1]
    g = scene.bearing.geometry
    k_o = hertz_contact(*race_curvatures(g)["outer"], compliance(scene.bearing.material)).stiffness
    assert _overlap_ok(pr, sol.y) < 2 * (20000 / k_o) ** (2 / 3)
    z = pr.n_balls
    early = runs["rosw"].trace.time <= 0.0003
    ref = runs["dp5"].solution.y[early, 3 * z:4 * z]
    assert np.abs(sol.y[early, 3 * z:4 * z] - ref).max() < 0.02 * np.abs(ref).max()


def test_rosw_is_deterministic():
    scene = _scene(3000, 500, 0.003)
    a, b = (simulate(scene, choose_model(scene), method="rosw", progress=False).solution for _ in range(2))
    assert np.array_equal(a.y, b.y) and a.n_steps == b.n_steps
