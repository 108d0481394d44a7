"""The ``film_traction`` effect in the models against the regime traction law computed by hand.

Sources of the law (written out here, not the project's functions):

* film parameter Lambda = h_min / sigma (Tallian, ASLE Trans. 10 (1967) 418-439); boundary below 1, full film
  above 3, the cubic smoothstep w = 3x^2 - 2x^3 between (x = (Lambda - 1) / 2);
* full film: Bair & Winer, J. Lubr. Technol. 101 (1979) 258-264, tau = tau_L [1 - exp(-eta_e u_s / (h tau_L))],
  tau_L = Lambda_LSS p, so F = Lambda_LSS Q [1 - exp(-|u_s| / u_L)], u_L = Lambda_LSS p h / eta_e;
* eta_e: Roelands at the mean Hertz pressure p = Q / (pi a b) (Hamrock, Schmid & Jacobson, *Fundamentals of
  Fluid Film Lubrication*, 2004, eqs. 4.7, 4.9), eta at the oil temperature eta_0 exp[-beta (T - T_0)] with the
  paper's beta = 0.027 1/K (Wang et al. 2026, Table 1);
* boundary: mu_b Q tanh(u_s / v_reg);
* Hamrock-Dowson films (J. Lubr. Technol. 99 (1977) 264-276): h_c = R_x 2.69 U^0.67 G^0.53 W^-0.067
  (1 - 0.61 e^-0.73 k), h_min = R_x 3.63 U^0.68 G^0.49 W^-0.073 (1 - e^-0.68 k).

One ball on the outer race, the rest at rest; the planar and spatial right-hand sides with race traction on and
off differ by the traction alone, which is compared with the hand value.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

from cageless.conditions import OperatingConditions
from cageless.simulation.hertz import compliance, hertz_contact, race_curvatures
from cageless.simulation.models import planar as P
from cageless.simulation.models import spatial as S
from cageless.simulation.parameters import ModelParameters
from cageless.simulation.run import initial_state
from cageless.simulation.scene import Scene

sys.path.insert(0, str(Path(__file__).parent))
from effect_helpers import effect_contribution  # noqa: E402

H0 = 0.2e-6  # fixed film: Lambda = 2 with sigma = 0.1 um, the middle of the mixed band (w = 1/2)


def _by_hand(q, u_s, u_r, h_c, h_m, eta_t, par, a_b):
    """The traction of the regime law (N) on a contact of load q, sliding u_s, films h_c and h_min."""
    lam = h_m / par.surface_roughness_m
    x = min(max((lam - 1.0) / 2.0, 0.0), 1.0)
    w = x * x * (3 - 2 * x)
    p = q / a_b
    ln_r = math.log(eta_t) + 9.67
    z = 1.5e-8 * 1.96e8 / ln_r
    eta_e = eta_t * math.exp(ln_r * ((1 + p / 1.96e8) ** z - 1))
    u_l = max(par.limiting_shear_coefficient * p * h_c / eta_e, 0.01)
    full = par.limiting_shear_coefficient * q * (1 - math.exp(-abs(u_s) / u_l)) * math.copysign(1, u_s)
    bound = par.boundary_friction_coefficient * q * math.tanh(u_s / par.boundary_slip_speed_m_s)
    return w * full + (1 - w) * bound, w, eta_e


def _setup(level, film, temperature_c=20.0):
    scene = Scene(conditions=OperatingConditions(3000.0, 500.0))
    th, r, ring = initial_state(scene)
    on = {"race_contact": True, "race_traction": True, "film_traction": True, "ehl_film": film}
    par = ModelParameters(film_thickness_m=H0, oil_temperature_c=temperature_c)
    kw = {"inner_speed_rad_s": scene.conditions.speed_rad_s, "effects": on, "parameters": par}
    build = S.spatial_problem if level == "spatial" else P.planar_problem
    extra = {"strips": 1} if level == "spatial" else {}
    return scene, par, build(scene.bearing, th, r, ring, 500.0, **kw, **extra)


def _traction_only(pr, y):
    return effect_contribution(pr, y, "F_TRAC")


@pytest.mark.parametrize("level", ["planar", "spatial"])
@pytest.mark.parametrize("film,temperature_c", [(False, 20.0), (True, 20.0), (True, 60.0)])
def test_outer_race_traction_matches_the_regime_law_by_hand(level, film, temperature_c):
    scene, par, pr = _setup(level, film, temperature_c)
    b = scene.bearing
    g, lub = b.geometry, b.lubricant
    z, d, dm = g.n_balls, g.ball_diameter_m, g.pitch_diameter_m
    half, m = 0.5 * d, b.masses.ball_mass_kg
    y = pr.y0.copy()
    y[5 * z:5 * z + 4] = 0.0
    y[:z] = 0.25 * (g.inner_race_diameter_m + g.outer_race_diameter_m)  # the others touch nothing
    j, thd, om = 3, 121.0, -500.0
    delta = 2e-6
    r = 0.5 * g.outer_race_diameter_m - half + delta
    y[j], y[z + j], y[2 * z + j], y[3 * z + j], y[4 * z + j] = r, 1.234, 0.0, thd, om
    k_o = hertz_contact(*race_curvatures(g)["outer"], compliance(b.material))
    q = k_o.stiffness * delta**1.5
    u_s = r * thd + half * om  # ball surface against the fixed race
    u_r = 0.5 * abs(r * thd + half * om - g.outer_race_diameter_m * thd)
    eta_t = lub.dynamic_viscosity_pa_s * math.exp(-0.027 * (temperature_c - 20.0))
    if film:
        e_red = 208e9 / (1 - 0.3**2)
        r_x = 0.5 * d * (dm + d) / dm
        uu, gg, ww = eta_t * u_r / (e_red * r_x), 1.5e-8 * e_red, q / (e_red * r_x**2)
        h_c = r_x * 2.69 * uu**0.67 * gg**0.53 * ww**-0.067 * (1 - 0.61 * math.exp(-0.73 * k_o.kappa))
        h_m = r_x * 3.63 * uu**0.68 * gg**0.49 * ww**-0.073 * (1 - math.exp(-0.68 * k_o.kappa))
    else:
        h_c = h_m = H0
    a, bb = k_o.semi_axes(q)
    f, w, eta_e = _by_hand(q, u_s, u_r, h_c, h_m, eta_t, par, math.pi * a * bb)
    assert 0.0 < w < 1.0 or film  # the fixed film sits in the mixed band
    assert eta_e > 100 * eta_t  # the pressure raises the film's viscosity
    diff = _traction_only(pr, y)
    # on the ball: -f along e_theta (against the sliding u_s), moment -(D/2) f on the spin
    np.testing.assert_allclose(diff[3 * z + j] * m * r, -f, rtol=1e-7)
    np.testing.assert_allclose(diff[4 * z + j] * 0.1 * m * d * d, -half * f, rtol=1e-7)
    np.testing.assert_allclose(diff[5 * z + 5], f * u_s, rtol=1e-7)  # its power is dissipated


def test_temperature_thins_the_oil_in_every_lubricant_slot():
    """At 60 degC the oil is exp(-0.027 x 40) = 0.3396 of its 20 degC viscosity in the squeeze film (ETA0), the
    rolling losses and the traction (ETA_T) alike (eq. V4, the paper's beta)."""
    _, _, cold = _setup("planar", True, 20.0)
    _, _, hot = _setup("planar", True, 60.0)
    for slot in ("ETA0", "ETA_T"):
        assert hot.parameter(slot) / cold.parameter(slot) == pytest.approx(math.exp(-0.027 * 40.0), rel=1e-12)
