"""The 6000 rpm / 500 N unloaded-zone slip against a hand integration of the losses (issue "lubricant physics").

At 6000 rpm the peak unloaded-zone slip is 3.27 % whatever the seed, the race damping or the solver: the ring of
balls is not chaotic there (seeds 0 and 1: 3.266 and 3.271 %; C_ho = 2500 N s/m: 3.265 %), and the slip is set
by the losses alone. Only the loss terms move it (drag off: 1.90 %, rolling losses off: 2.05 %, a flooded inlet
r_s = 2 mm: 15.2 %; measured, 0.05 s after the start-up). This test checks that value against a hand estimate.

**The hand estimate.** A ball leaves the loaded zone at theta = 0, rolling on the outer race. From there it
touches only the outer race, so its energy of rolling 0.7 m v^2 (homogeneous sphere, I = m D^2 / 10) changes only
by gravity and by the power of the losses:

    d/dt (0.7 m v^2 + m g r sin(theta)) = -(F_H v + F_D v + M_C w),   w = 2 v / D,          (H1)

(energy theorem; a ball rolling without sliding on a fixed race, Meriam & Kraige, *Engineering Mechanics:
Dynamics*, §6/6) with

* F_H, the hydrodynamic rolling force of the outer-race contact (Chiu, J. Lubr. Technol. 96 (1974) 237-246; the
  fit Fbar(t) as written in YUXinluhk/BallBearing-Dynamics ``calcRacePumpingForce.m``): for a ball rolling on a
  race the whole rolling loss is F_H v (the net force F_H - F_R on the centre plus the shear moment F_R D / 2,
  docs/physics/lubricant.md). Entraining speed u = r_o theta', load Q = m r theta'^2 - m g sin(theta),
  Hamrock-Dowson central film (Hamrock & Dowson, J. Lubr. Technol. 99 (1977) 264) with the ellipticity of
  Hamrock & Brewe (J. Lubr. Technol. 105 (1983) 171), kappa = (R_y / R_x)^(2/pi);
* F_D, the drag 1/2 C_D rho A v^2 with Schiller & Naumann's C_D joined to Newton's 0.44 (Clift, Grace & Weber,
  *Bubbles, Drops and Particles*, 1978, Table 5.2), in the oil-air mixture of 5 % oil (Parker, NASA TP-2275);
* M_C, the churning moment 1/2 C_M rho w^2 R^5, C_M = 16 pi / Re_w + 6.45 / sqrt(Re_w) (Lamb 1932 §334; Howarth
  1951, Sawatzki 1970).

Integrated in theta from the exit speed, 1 - v / v_exit at theta = 90 and 179 deg is the slip the losses and
gravity add over the unloaded zone; the model's rise of the mean slip profile from its exit bin (0-1 deg) must
match it. The hand integration leaves out what the model has besides: the ball-ball contacts, the inner ring
approaching near 180 deg, the slip of the spin against the race. Measured, rise to 90 / 179 deg in pp:

| losses | model | hand |
|---|---|---|
| all on (default) | 1.99 / 2.59 | 1.88 / 2.75 |
| drag off | 1.33 / 1.30 | 1.27 / 1.56 |
| rolling losses off | 1.35 / 1.28 | 1.10 / 1.21 |

so the 3.27 % is the exit slip (0.67 %) plus 2.6 pp of losses, as computed by hand. The contacts are in full
film at this speed (Lambda = h_min / sigma about 8 at the unloaded outer contact, 5 at the loaded inner one), so
the traction holds the ball at 0.03-0.07 % slip through the loaded zone.
"""

from __future__ import annotations

import math

import pytest

from cageless.bearing import default_bearing
from cageless.kinematics import theoretical_cage_speed

G = 9.81
#: Oil volume fraction of the oil-air mixture (Parker, NASA TP-2275, 1984; the model's default).
OIL_FRACTION = 0.05
AIR_DENSITY, AIR_VISCOSITY = 1.204, 1.81e-5


def _hand_rise(rpm: float, rolling: bool = True, drag: bool = True, meniscus_m: float | None = None,
               angles_deg: tuple[float, ...] = (90.0, 179.0)) -> dict[float, float]:
    """1 - v / v_exit (fraction) at ``angles_deg`` by integrating (H1) from theta = 0 at the pure-rolling speed."""
    from cageless.simulation.parameters import ModelParameters

    b = default_bearing()
    g, lub, mat = b.geometry, b.lubricant, b.material
    d, dm, m = g.ball_diameter_m, g.pitch_diameter_m, b.masses.ball_mass_kg
    r, r_o = 0.5 * dm, 0.5 * g.outer_race_diameter_m
    e_red = mat.youngs_modulus_pa / (1.0 - mat.poisson_ratio ** 2)
    eta, alpha = lub.dynamic_viscosity_pa_s, lub.pressure_viscosity_coefficient_1_pa
    r_x = 0.5 * d * (dm + d) / dm
    r_y = g.outer_curvature_factor * d / (2.0 * g.outer_curvature_factor - 1.0)
    k, kappa = r_x / r_y, (r_y / r_x) ** (2.0 / math.pi)
    r_s = meniscus_m if meniscus_m is not None else ModelParameters().meniscus_distance_m
    rho = OIL_FRACTION * lub.density_kg_m3 + (1.0 - OIL_FRACTION) * AIR_DENSITY
    mu = OIL_FRACTION * eta + (1.0 - OIL_FRACTION) * AIR_VISCOSITY

    def f_h(u: float, q: float) -> float:
        h = (2.69 * (eta * u / (e_red * r_x)) ** 0.67 * (alpha * e_red) ** 0.53 * (q / (e_red * r_x ** 2)) ** -0.067
             * (1.0 - 0.61 * math.exp(-0.73 * kappa)) * r_x)
        ln_t = math.log(r_s / math.sqrt(2.0 * h * r_x))
        fbar = max(28.59 * ln_t - 10.10, 36.57 * ln_t - 22.85, 0.0)
        return 2.0 * eta * u * math.sqrt(r_x * r_y) / (3.0 + 2.0 * k) * fbar * r_x / d

    def f_d(v: float) -> float:
        re = rho * v * d / mu
        return 0.5 * max(24.0 / re * (1.0 + 0.15 * re ** 0.687), 0.44) * rho * 0.25 * math.pi * d * d * v * v

    def m_c(w: float) -> float:
        re_w = rho * w * (0.5 * d) ** 2 / mu
        return 0.5 * (16.0 * math.pi / re_w + 6.45 / math.sqrt(re_w)) * rho * w * w * (0.5 * d) ** 5

    v0 = r * theoretical_cage_speed(g, rpm * math.pi / 30.0)
    v, th, dth, out = v0, 0.0, 1e-4, {}
    for target in sorted(angles_deg):
        while th < math.radians(target):
            rate = v / r
            p_loss = ((f_h(r_o * rate, m * r * rate ** 2 - m * G * math.sin(th)) * v if rolling else 0.0)
                      + ((f_d(v) * v + m_c(2.0 * v / d) * 2.0 * v / d) if drag else 0.0))
            energy = (0.7 * m * v * v - p_loss * dth / rate
                      - m * G * r * (math.sin(th + dth) - math.sin(th)))
            v, th = math.sqrt(energy / (0.7 * m)), th + dth
        out[target] = 1.0 - v / v0
    return out


def test_hand_integration_ingredients():
    # At 6000 rpm the pure-rolling orbit is v = 0.0230025 x 249.10 = 5.730 m/s; the outer contact entrains at
    # u = 27.765 mm x 249.10 rad/s = 6.916 m/s under Q = m r w^2 = 5.07 N. Without losses the ball only trades
    # speed for height: at 90 deg 1 - sqrt(1 - g r / (0.7 v^2)) = 0.4921 % (the gravity value of
    # test_unloaded_zone_energy), and at 179 deg, sin(1 deg) = 0.01745 of that height left,
    # 0.00982 x 0.01745 / 2 = 8.6e-5.
    none = _hand_rise(6000.0, rolling=False, drag=False)
    assert none[90.0] == pytest.approx(0.004921, abs=2e-6)
    assert abs(none[179.0]) < 1e-4
    # the losses: more rolling force with a better-fed inlet (Fbar grows as ln r_s), each term adds slip
    full = _hand_rise(6000.0)
    assert full[179.0] == pytest.approx(0.02405, abs=5e-4)  # 2.405 % (r_s 0.2103 mm, dtheta 1e-4)
    assert _hand_rise(6000.0, meniscus_m=2e-3)[179.0] > 2.0 * full[179.0]
    assert _hand_rise(6000.0, drag=False)[179.0] < full[179.0]
    assert _hand_rise(6000.0, rolling=False)[179.0] < full[179.0]


def _model_rise(effects: dict[str, bool], seed: int = 0) -> tuple[dict[float, float], float]:
    """(rise of the model's mean slip profile from its 0-1 deg bin to the bins at 90 and 179 deg, its peak in the
    unloaded zone), as fractions, 0.05 s after the start-up at 6000 rpm, 500 N."""
    from cageless.profiles import angle_profile
    from cageless.simulation.run import peak_unloaded_slip
    from cageless.simulation.sweep import simulate_point, sweep_base

    trace, sol, settle, err = simulate_point({"seed": seed}, sweep_base(6000.0, 500.0, duration_s=0.05,
                                                                        effects=effects))
    assert trace is not None and sol.success, err
    keep = (trace.time >= settle)[:, None] & trace.valid
    prof = angle_profile(trace.angle, trace.slip, 1.0, valid=keep).set_index("angle_deg")["mean"]
    return ({a: float(prof.loc[a + 0.5] - prof.loc[0.5]) for a in (90.0, 179.0)},
            peak_unloaded_slip(trace, settle_s=settle))


@pytest.mark.slow
@pytest.mark.parametrize("effects", [{}, {"drag": False}, {"rolling_losses": False}],
                         ids=["all-losses", "drag-off", "rolling-off"])
def test_6000_rpm_unloaded_slip_rise_is_the_hand_integration(effects):
    rise, _ = _model_rise(effects)
    hand = _hand_rise(6000.0, rolling=effects.get("rolling_losses", True), drag=effects.get("drag", True))
    for angle in (90.0, 179.0):
        assert abs(rise[angle] - hand[angle]) < 0.0035, (angle, rise, hand)  # 0.35 pp; measured <= 0.26 pp


@pytest.mark.slow
def test_6000_rpm_peak_does_not_depend_on_the_seed():
    # not chaotic at 6000 rpm: two seeds give the same peak within 0.05 pp (measured 3.266 and 3.271 %)
    assert abs(_model_rise({}, seed=0)[1] - _model_rise({}, seed=1)[1]) < 5e-4
