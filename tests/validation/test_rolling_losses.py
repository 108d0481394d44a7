"""The ``rolling_losses`` effect in the models against Chiu's rolling force computed by hand.

Source: Y. P. Chiu, "A theory of hydrodynamic friction forces in starved point contacts considering
cavitation", J. Lubr. Technol. 96 (1974) 237-246, in the curve-fitted form of the public implementation
YUXinluhk/BallBearing-Dynamics (``calcRacePumpingForce.m``, eqs. 2-41 to 2-47 of its source thesis), for pure
rolling (u_eta = 0):

    C_0 = eta |u| sqrt(R_x R_y) / (3 + 2 k),  k = R_x / R_y,
    t = r_s / sqrt(2 h R_x),  Fbar = max(28.59 ln t - 10.10, 36.57 ln t - 22.85, 0),
    F_R = C_0 Fbar / 2 (shear on the ball surface, against u),  F_H = 2 C_0 Fbar R_x / D (pressure, along u).

The test puts one ball on one race (the other contacts open), evaluates the planar right-hand side with the
effect on and off, and compares the difference with these formulas written out here (not the project's
functions): the tangential force on the ball centre, the moment on its spin, the drive's power and the
dissipation. The radii are the textbook ones (Harris & Kotzalas, *Essential Concepts of Bearing Technology*,
5th ed., ch. 6): R_x = (D/2)(d_m +- D)/d_m (outer +, inner -), R_y = f D / (2 f - 1).
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

from cageless.conditions import OperatingConditions
from cageless.simulation.models import planar as P
from cageless.simulation.models import spatial as S
from cageless.simulation.parameters import ModelParameters
from cageless.simulation.run import initial_state
from cageless.simulation.scene import Scene

sys.path.insert(0, str(Path(__file__).parent))
from effect_helpers import effect_contribution  # noqa: E402

R_S = 0.4e-3
H0 = 0.2e-6


def _chiu_by_hand(eta, u, r_x, r_y, d):
    """(f_pressure, f_shear) on the ball along the direction in which u is signed."""
    k = r_x / r_y
    c0 = eta * abs(u) * math.sqrt(r_x * r_y) / (3.0 + 2.0 * k)
    t = R_S / math.sqrt(2.0 * H0 * r_x)
    fbar = max(28.59 * math.log(t) - 10.10, 36.57 * math.log(t) - 22.85, 0.0)
    sgn = math.copysign(1.0, u)
    return sgn * 2.0 * c0 * fbar * r_x / d, -sgn * 0.5 * c0 * fbar


def _problem(level="planar"):
    scene = Scene(conditions=OperatingConditions(3000.0, 500.0))
    th, r, ring = initial_state(scene)
    on = {"race_contact": True, "rolling_losses": True}  # ehl_film off: the film is the fixed h_0
    kw = {"inner_speed_rad_s": scene.conditions.speed_rad_s, "effects": on,
          "parameters": ModelParameters(meniscus_distance_m=R_S, film_thickness_m=H0)}
    if level == "spatial":
        return scene, S.spatial_problem(scene.bearing, th, r, ring, 500.0, **kw)
    return scene, P.planar_problem(scene.bearing, th, r, ring, 500.0, **kw)


def _difference(pr, y):
    return effect_contribution(pr, y, "F_ROLL")


@pytest.mark.parametrize("level", ["planar", "spatial"])
@pytest.mark.parametrize("race", ["outer", "inner"])
def test_rolling_force_and_moment_match_chiu_by_hand(level, race):
    scene, pr = _problem(level)
    g = scene.bearing.geometry
    z, d, dm = g.n_balls, g.ball_diameter_m, g.pitch_diameter_m
    half, m, inertia = 0.5 * d, scene.bearing.masses.ball_mass_kg, 0.1 * scene.bearing.masses.ball_mass_kg * d * d
    eta = scene.bearing.lubricant.dynamic_viscosity_pa_s
    w_i = scene.conditions.speed_rad_s
    y = pr.y0.copy()
    y[5 * z:5 * z + 4] = 0.0  # ring centred, at rest
    j, thd, om = 3, 121.0, -590.0
    # the other balls at rest, pressed 0.1 um into the outer race: no entrainment, no rolling force
    y[:z] = 0.25 * (g.inner_race_diameter_m + g.outer_race_diameter_m) + 1e-7
    y[z + j], y[2 * z + j], y[3 * z + j], y[4 * z + j] = 1.234, 0.0, thd, om
    if race == "outer":
        r = 0.5 * g.outer_race_diameter_m - half + 2e-6
        r_x, f = 0.5 * d * (dm + d) / dm, g.outer_curvature_factor
        u = 0.5 * (r * thd + half * om - g.outer_race_diameter_m * thd)
        sign_m = 1.0
    else:
        r = 0.5 * g.inner_race_diameter_m + half - 2e-6
        r_x, f = 0.5 * d * (dm - d) / dm, g.inner_curvature_factor
        r_i = 0.5 * g.inner_race_diameter_m
        u = 0.5 * (r * thd * (1.0 - 2.0 * r_i / r) - half * om + w_i * r_i)
        sign_m = -1.0
    y[j] = r
    f_p, f_s = _chiu_by_hand(eta, u, r_x, f * d / (2.0 * f - 1.0), d)
    assert abs(f_p) > 1e-3 and f_p * f_s < 0  # a real force; pressure along u, shear against it
    diff = _difference(pr, y)
    np.testing.assert_allclose(diff[3 * z + j] * m * r, f_p + f_s, rtol=1e-9)  # along e_theta
    np.testing.assert_allclose(diff[4 * z + j] * inertia, sign_m * half * f_s, rtol=1e-9)
    others = np.delete(diff[:5 * z], [3 * z + j, 4 * z + j])
    assert np.max(np.abs(others)) < 1e-9
    # power: the drive pays for the shear on the ring's surface; the rest of the work is dissipated
    u_slide = r * thd + half * om if race == "outer" else r * thd - half * om - w_i * r_i
    drive = 0.0 if race == "outer" else w_i * r_i * f_s
    np.testing.assert_allclose(diff[5 * z + 4], drive, rtol=1e-9, atol=1e-15)
    np.testing.assert_allclose(diff[5 * z + 5], -(f_p * r * thd + f_s * u_slide), rtol=1e-9)


def test_rolling_force_uses_the_hamrock_dowson_film_when_the_film_effect_is_on():
    """With ``ehl_film`` on, the film in t is the compiled Hamrock-Dowson central film of the contact, so the
    force differs from the fixed-film one by the ln of the film ratio alone (C_0 does not depend on h)."""
    from cageless.simulation.hertz import compliance, hertz_contact, race_curvatures
    from cageless.simulation.physics.film_traction import hd_central_film

    scene, pr = _problem()
    g = scene.bearing.geometry
    z, d = g.n_balls, g.ball_diameter_m
    y = pr.y0.copy()
    y[5 * z:5 * z + 4] = 0.0
    y[:z] = 0.25 * (g.inner_race_diameter_m + g.outer_race_diameter_m) + 1e-7
    j, thd, om = 5, 121.0, -590.0
    r = 0.5 * g.outer_race_diameter_m - 0.5 * d + 2e-6
    y[j], y[z + j], y[3 * z + j], y[4 * z + j] = r, 2.0, thd, om
    fixed = _difference(pr, y)[4 * z + j]
    pr.params[pr.layout.index("F_FILM")] = 1.0
    film = _difference(pr, y)[4 * z + j]
    lub, mat = scene.bearing.lubricant, scene.bearing.material
    u = 0.5 * (r * thd + 0.5 * d * om - g.outer_race_diameter_m * thd)
    q = pr.parameter("KO") * 2e-6 ** 1.5
    r_x = 0.5 * d * (g.pitch_diameter_m + d) / g.pitch_diameter_m
    kappa = hertz_contact(*race_curvatures(g)["outer"], compliance(mat)).kappa
    h = hd_central_film(lub.dynamic_viscosity_pa_s, lub.pressure_viscosity_coefficient_1_pa,
                        mat.youngs_modulus_pa / (1 - mat.poisson_ratio ** 2), u, q, r_x, kappa)
    assert 0.05e-6 < h < 2e-6
    t0, t1 = R_S / math.sqrt(2 * H0 * r_x), R_S / math.sqrt(2 * h * r_x)

    def fbar(t):
        return max(28.59 * math.log(t) - 10.10, 36.57 * math.log(t) - 22.85, 0.0)

    assert film / fixed == pytest.approx(fbar(t1) / fbar(t0), rel=1e-9)
