"""The opt-in ``strip_damping`` effect in the planar model against the hand computation of the paper's strips.

Source of the formulation: Wang, Zhao, Wang, Jin, Appl. Sci. 2026, 16, 9284, sec. 2.2 (reference/paper.txt):
F_bn^k = K delta_k + C_ho v_n per strip (line 72), F_n = sum_k F_bn^k (line 78), the contact-point velocity
omega_b x r_x^bc + v_b (line 69), the strips along the X_c axis, the ellipse's short half-axis (lines 51, 74).
The hand computation is benchmarks/paper_strip_damping.py (:func:`strip_forces`, checked against closed forms
in test_paper_strip_damping.py): strips along the rolling direction, normal speed d(delta)/dt + u x / R_x, no
strip tensile, with the textbook R_x = (D/2)(d_m +- D)/d_m and the Hertz semi-axis b of the contact's load.

One ball touches one race, the others rest on the outer race unloaded; the planar right-hand side is evaluated
with the effect on and off, and the difference in the radial force must be the strips' sum minus the lumped
damper's.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

from cageless.conditions import OperatingConditions
from cageless.errors import ParameterError, UsageError
from cageless.simulation.effects import choose_model, removable_effects
from cageless.simulation.hertz import compliance, hertz_contact, race_curvatures
from cageless.simulation.models import planar as P
from cageless.simulation.models import spatial as S
from cageless.simulation.run import energy_balance, initial_state
from cageless.simulation.scene import Scene
from cageless.simulation.solve import solve

sys.path.insert(0, str(Path(__file__).parent))
from effect_helpers import benchmark_module, effect_contribution  # noqa: E402

ON = {"race_contact": True, "lubricant_damping": True, "strip_damping": True}


@pytest.fixture(scope="module")
def hand():
    with benchmark_module("paper_strip_damping") as module:
        yield module


def _problem(effects=ON):
    scene = Scene(conditions=OperatingConditions(1800.0, 500.0))
    th, r, ring = initial_state(scene)
    return scene, P.planar_problem(scene.bearing, th, r, ring, 500.0, inner_speed_rad_s=scene.conditions.speed_rad_s,
                                   effects=effects)


@pytest.mark.parametrize("race", ["outer", "inner"])
@pytest.mark.parametrize("delta_m, rd", [(50e-9, 0.0), (50e-9, -2e-5), (2e-6, 1e-4)])
def test_radial_force_is_the_hand_computed_strip_sum(hand, race, delta_m, rd):
    scene, pr = _problem()
    g = scene.bearing.geometry
    z, d, dm = g.n_balls, g.ball_diameter_m, g.pitch_diameter_m
    half, m, cho = 0.5 * d, scene.bearing.masses.ball_mass_kg, pr.params[pr.layout.index("CHO")]
    w_i = scene.conditions.speed_rad_s
    y = pr.y0.copy()
    y[5 * z:5 * z + 4] = 0.0  # ring centred, at rest
    y[:z] = 0.25 * (g.inner_race_diameter_m + g.outer_race_diameter_m)  # the others touch no race
    y[2 * z:5 * z] = 0.0
    j, thd, om = 3, 80.0, -400.0
    y[z + j], y[2 * z + j], y[3 * z + j], y[4 * z + j] = 1.234, rd, thd, om
    hc = hertz_contact(*race_curvatures(g)[race], compliance(scene.bearing.material))
    if race == "outer":
        y[j] = 0.5 * g.outer_race_diameter_m - half + delta_m
        r_x, ddot, sign = 0.5 * d * (dm + d) / dm, rd, -1.0
        u = 0.5 * (y[j] * thd + half * om - g.outer_race_diameter_m * thd)
    else:
        y[j] = 0.5 * g.inner_race_diameter_m + half - delta_m
        r_x, ddot, sign = 0.5 * d * (dm - d) / dm, -rd, 1.0
        r_i = 0.5 * g.inner_race_diameter_m
        u = 0.5 * (y[j] * thd * (1.0 - 2.0 * r_i / y[j]) - half * om + w_i * r_i)
    q = hc.stiffness * delta_m ** 1.5
    b = hc.b_coeff * q ** (1.0 / 3.0)
    strips = hand.strip_forces(q, b, r_x, u, cho, ddot, 5).sum()
    lumped = max(q + cho * ddot, 0.0)
    assert abs(strips - lumped) > 1e-3 * q  # a real change (u b / R_x = 0.3-6 mm/s against these approach speeds)
    diff = effect_contribution(pr, y, "F_STRIP")
    np.testing.assert_allclose(diff[2 * z + j] * m, sign * (strips - lumped), rtol=1e-9)
    others = np.delete(diff[:5 * z], [2 * z + j])
    assert np.max(np.abs(others)) < 1e-9 * abs(strips - lumped) / m
    np.testing.assert_allclose(diff[5 * z + 5], (strips - lumped) * ddot, rtol=1e-9, atol=1e-15)


def test_without_rolling_and_closing_it_is_the_lumped_damper():
    """u = 0 and d(delta)/dt > 0: every strip is compressed and the strips' shares of the load and of C_ho sum
    to 1, so the sum is Q + C_ho d(delta)/dt."""
    scene, pr = _problem()
    g = scene.bearing.geometry
    z, half = g.n_balls, 0.5 * g.ball_diameter_m
    y = pr.y0.copy()
    y[5 * z:5 * z + 4] = 0.0
    y[:z] = 0.5 * g.outer_race_diameter_m - half + 1e-7
    y[2 * z:5 * z] = 0.0
    y[2 * z:3 * z] = 3e-4
    assert np.max(np.abs(effect_contribution(pr, y, "F_STRIP"))) < 1e-9


def test_it_is_opt_in_planar_only_and_out_of_the_ablation():
    scene = Scene(conditions=OperatingConditions(1800.0, 500.0))
    assert not {e.name: e.on for e in choose_model(scene).effects}["strip_damping"]
    on = {e.name: e for e in choose_model(scene, effects={"strip_damping": True}).effects}["strip_damping"]
    assert on.on and not on.forced and "not the default physics" in on.reason
    assert "strip_damping" not in removable_effects()
    spatial = Scene(conditions=OperatingConditions(1800.0, 500.0, 100.0))
    with pytest.raises(UsageError, match="planar model only"):
        choose_model(spatial, effects={"strip_damping": True})
    with pytest.raises(UsageError, match="lubricant_damping is off"):
        choose_model(scene, effects={"strip_damping": True, "lubricant_damping": False}, force=True)
    th, r, ring = initial_state(scene)
    with pytest.raises(ParameterError, match="planar"):
        S.spatial_problem(scene.bearing, th, r, ring, 500.0, effects=ON)


def test_energy_balance_closes_with_the_strips():
    """The strips' force depends on the rolling speed; its power (F_n - Q) d(delta)/dt is booked, so kinetic +
    potential + dissipated - input stays constant to the tolerance, as with the lumped damper."""
    scene = Scene(conditions=OperatingConditions(1800.0, 500.0))
    th, r, ring = initial_state(scene)
    on = {**ON, "ball_ball_contact": True, "gravity": True, "race_traction": True, "ehl_film": True,
          "film_traction": True, "rolling_losses": True}
    pr = P.planar_problem(scene.bearing, th, r, ring, 500.0, inner_speed_rad_s=scene.conditions.speed_rad_s,
                          effects=on, atol_scale=1e-3)
    sol = solve(pr, np.linspace(0, 3e-3, 31), rtol=1e-10, max_step=5e-7)
    assert sol.success
    energy = energy_balance(pr, sol.y)
    assert energy.input_work[-1] > 1e-4
    assert energy.drift < 1e-6 * energy.input_work[-1]
    assert math.isfinite(energy.dissipated[-1])
