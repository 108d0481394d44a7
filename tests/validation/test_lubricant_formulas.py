"""The lubricant physics units (simulation.physics) against hand computations from their cited formulas.

Each reference number below is worked by hand in the comment from the source equation named there; the
equation labels (V1)-(V4), (R1)-(R6), (T1)-(T5), (D1)-(D3) are those of the modules' docstrings, which give
the sources:

* viscosity: Barus (1893); Roelands (1966) as in Hamrock, Schmid & Jacobson, *Fundamentals of Fluid Film
  Lubrication* (2004) eqs. 4.7 and 4.9; the paper's Table 1 (eta_0 = 0.04 Pa s, alpha = 1.5e-8 1/Pa,
  beta = 0.027 1/K);
* rolling force: Chiu, J. Lubr. Technol. 96 (1974) 237-246, in the fitted form of the public implementation
  YUXinluhk/BallBearing-Dynamics ``calcRacePumpingForce.m`` (eqs. 2-41 to 2-48 there), whose steps are
  followed by hand for the same inputs;
* traction: Tallian's film parameter, Bair & Winer (1979) limiting shear stress, Hamrock & Dowson (1977) film;
* drag: Schiller & Naumann (1933), Stokes (1851), Lamb (1932) §334.

Geometry: the paper's bearing (Table 1): D = 9.525 mm, d_m = 46.005 mm, f_o = 0.52, so at the outer race
R_xi = (D/2)(d_m + D)/d_m = 4.7625 mm x 51.530/46.005 = 5.748541 mm (Harris & Kotzalas, Essential Concepts,
eq. 2.27 with the outer-race sign), R_eta = f_o D / (2 f_o - 1) = 0.52 x 9.525 / 0.04 = 123.825 mm, and
k = R_xi / R_eta = 0.0464247.
"""

from __future__ import annotations

import math

import pytest

from cageless.simulation.film import hamrock_dowson
from cageless.simulation.physics import drag, film_traction as ft, rolling_force as rf, viscosity as vis

D = 9.525e-3
RX = 0.5 * D * (46.005e-3 + D) / 46.005e-3
RY = 0.52 * D / (2 * 0.52 - 1)
ETA0, ALPHA, BETA, T0 = 0.04, 1.5e-8, 0.027, 293.15
E_RED = 208e9 / (1 - 0.3**2)  # E' = 2 / (2 (1 - nu^2) / E) for two steel bodies: 228.571 GPa


def test_geometry_of_the_outer_contact():
    assert RX == pytest.approx(5.748541e-3, rel=1e-6)
    assert RY == pytest.approx(0.123825, rel=1e-9)


# ---------------------------------------------------------------- viscosity


def test_barus_hand_value():
    # (V1): 0.04 exp(1.5e-8 x 1e9) = 0.04 e^15 = 0.04 x 3,269,017.37 = 130,760.69 Pa s
    assert vis.barus(ETA0, ALPHA, 1e9) == pytest.approx(130760.69, rel=1e-7)
    assert vis.barus(ETA0, ALPHA, -5e6) == ETA0  # cavitated (negative gauge) pressure: ambient viscosity


def test_roelands_hand_value_and_barus_slope():
    # (V3): Z = 1.5e-8 x 1.96e8 / (ln 0.04 + 9.67) = 2.94 / (-3.218876 + 9.67) = 2.94 / 6.451124 = 0.4557345
    assert vis.roelands_index(ETA0, ALPHA) == pytest.approx(0.4557345, rel=1e-6)
    # (V2) at 1 GPa: (1 + 1e9 / 1.96e8)^Z = 6.1020408^0.4557345 = 2.280175;
    # eta = 0.04 exp(6.451124 x 1.280175) = 0.04 exp(8.258570) = 0.04 x 3860.55 = 154.42 Pa s,
    # three orders below Barus' 1.3e5 (Hamrock et al. §4.6: Barus overpredicts at contact pressures)
    assert vis.roelands(ETA0, ALPHA, 1e9) == pytest.approx(154.42, rel=1e-4)
    # d(ln eta)/dp at p = 0 is alpha by construction of Z (Hamrock et al. eq. 4.9)
    dp = 1e3
    slope = (math.log(vis.roelands(ETA0, ALPHA, dp)) - math.log(ETA0)) / dp
    assert slope == pytest.approx(ALPHA, rel=1e-4)
    # both laws agree at low pressure (1 MPa: within 0.1 %) and Roelands lies below Barus above
    assert vis.roelands(ETA0, ALPHA, 1e6) == pytest.approx(vis.barus(ETA0, ALPHA, 1e6), rel=1e-3)
    assert vis.roelands(ETA0, ALPHA, 3e8) < vis.barus(ETA0, ALPHA, 3e8)


def test_temperature_viscosity():
    # (V4) at 40 degC: 0.04 exp(-0.027 x 20) = 0.04 e^-0.54 = 0.04 x 0.582748 = 0.0233099 Pa s
    assert vis.viscosity(ETA0, ALPHA, BETA, 0.0, T0 + 20.0, T0, False) == pytest.approx(0.0233099, rel=1e-5)
    # at the reference temperature and 1 GPa it is the pressure law alone
    assert vis.viscosity(ETA0, ALPHA, BETA, 1e9, T0, T0, True) == pytest.approx(154.42, rel=1e-4)


# ---------------------------------------------------------------- rolling force (Chiu 1974)


def test_chiu_coefficient_matches_the_published_fit():
    # (R4) by hand: t = 2: 28.59 ln 2 - 10.10 = 28.59 x 0.693147 - 10.10 = 9.7171
    #               t = 10: 36.57 ln 10 - 22.85 = 36.57 x 2.302585 - 22.85 = 61.3555
    assert rf.chiu_coefficient(2.0) == pytest.approx(9.7171, abs=1e-4)
    assert rf.chiu_coefficient(10.0) == pytest.approx(61.3555, abs=1e-4)
    for t in (1.5, 2.0, 3.0, 4.5, 6.0, 10.0, 30.0, 100.0):  # outside (4.94, 5] the two forms are equal
        # equal to the last bit or two: the compiled code may fuse the multiply-add when it is compiled inside
        # a fastmath model kernel first
        assert rf.chiu_coefficient(t) == pytest.approx(rf.chiu_coefficient_published(t), rel=1e-14, abs=1e-14)
    # below t = exp(10.10 / 28.59) = exp(0.353270) = 1.42372 the starved inlet gives no rolling force
    assert rf.T_ZERO == pytest.approx(1.42372, rel=1e-5)
    assert rf.chiu_coefficient(1.4) == 0.0 and rf.chiu_coefficient(1.45) > 0.0


def test_chiu_coefficient_is_continuous_where_the_published_fit_jumps():
    # as printed, (R4) jumps at t = 5 by (36.57 - 28.59) ln 5 - 12.75 = 7.98 x 1.609438 - 12.75 = 0.0933
    eps = 1e-9
    jump = rf.chiu_coefficient_published(5.0 + eps) - rf.chiu_coefficient_published(5.0)
    assert jump == pytest.approx(0.0933, abs=2e-4)
    # ours is continuous there, at the branch crossing t = exp(12.75 / 7.98) = exp(1.597744) = 4.94170, and where
    # the force starts, t = 1.42372
    for t in (5.0, math.exp(12.75 / 7.98), rf.T_ZERO):
        assert abs(rf.chiu_coefficient(t * (1 + 1e-9)) - rf.chiu_coefficient(t * (1 - 1e-9))) < 1e-6
    # and it departs from the printed fit by at most that jump, only on (4.94, 5]
    assert 0.0 < rf.chiu_coefficient(4.97) - rf.chiu_coefficient_published(4.97) <= 0.0934


def test_rolling_force_pure_rolling_hand_value():
    # eta 0.04 Pa s, u = 2 m/s, h = 0.2 um, r_s = 0.5 mm, outer race of the paper's bearing:
    # (R1) C_0 = 0.04 x 2 x sqrt(5.748541e-3 x 0.123825) / (3 + 2 x 0.0464247)
    #          = 0.08 x 0.0266799 / 3.0928494 = 6.90103e-4 N
    # (R3) t = 0.5e-3 / sqrt(2 x 0.2e-6 x 5.748541e-3) = 0.5e-3 / 4.79522e-5 = 10.42704
    # (R4) Fbar_R = 36.57 ln 10.42704 - 22.85 = 36.57 x 2.344398 - 22.85 = 62.8848
    # (R5) F_R = 0.5 x 6.90103e-4 x 62.8848 = 0.0216985 N
    # (R6) F_H = 2 x 6.90103e-4 x 62.8848 x 5.748541e-3 / 9.525e-3 = 0.0523821 N
    f_r, f_r_eta, f_h, f_h_eta = rf.chiu_rolling_forces(ETA0, 2.0, 0.0, 0.2e-6, RX, RY, 0.5e-3, D)
    assert f_r == pytest.approx(0.0216985, rel=1e-5)
    assert f_h == pytest.approx(0.0523821, rel=1e-5)
    assert f_r_eta == 0.0 and f_h_eta == 0.0
    # the pressure resultant is 4 R_xi / D times the shear (module docstring), 2.41412 here
    assert f_h / f_r == pytest.approx(4 * RX / D, rel=1e-12)
    # a ball on a flat race (R_xi = D/2): F_H = 2 F_R, the energy balance F_H v = 2 F_R u of the derivation
    f_r2, _, f_h2, _ = rf.chiu_rolling_forces(ETA0, 2.0, 0.0, 0.2e-6, D / 2, RY, 0.5e-3, D)
    assert f_h2 == pytest.approx(2.0 * f_r2, rel=1e-12)


def test_rolling_force_with_side_entrainment_follows_the_published_steps():
    # calcRacePumpingForce.m, same inputs: u = (2, 0.5) m/s, others as above.
    # eq. 2-44: term1 = (3 + 2k)^-2 = 3.0928494^-2 = 0.1045400
    #           term2 = 0.25^2 (3 + 2 / 0.0464247)^-2 / 0.0464247 = 0.0625 x 46.0805^-2 / 0.0464247 = 6.34010e-4
    #           C_0 = 0.08 x 0.0266799 x sqrt(0.1051740) = 6.92193e-4 N
    # eq. 2-45: theta = atan(3.0928494 / (0.215464 x 46.0805) x 0.25) = atan(0.0778764) = 0.0777197 rad
    # eq. 2-46: t = 0.5e-3 sqrt((cos^2 + sin^2 / k) / (2 h R_xi)) = 11.05375
    # eq. 2-47: Fbar_R = 36.57 ln 11.05375 - 22.85 = 65.0193
    # eq. 2-41: F_R = (0.5 C_0 Fbar_R cos theta, 0.5 C_0 Fbar_R sqrt(R_xi R_eta) sin theta)
    #               = (0.0224350, 4.66140e-5)
    # eq. 2-43: F_H = (2 C_0 Fbar_R R_xi cos theta / D, 2 C_0 Fbar_R R_eta sqrt(R_xi R_eta) sin theta / D)
    #               = (0.0541601, 2.42393e-3)
    out = rf.chiu_rolling_forces(ETA0, 2.0, 0.5, 0.2e-6, RX, RY, 0.5e-3, D)
    for got, want in zip(out, (0.0224350, 4.66140e-5, 0.0541601, 2.42393e-3), strict=True):
        assert got == pytest.approx(want, rel=1e-5)


def test_rolling_force_directions_and_limits():
    f_p, f_s = rf.rolling_force_along(ETA0, -2.0, 0.2e-6, RX, RY, 0.5e-3, D)
    # surfaces moving along -t: the inlet pressure pushes the ball along -t, the backflow shear along +t
    assert f_p == pytest.approx(-0.0523821, rel=1e-5) and f_s == pytest.approx(0.0216985, rel=1e-5)
    assert rf.rolling_force_along(ETA0, 0.0, 0.2e-6, RX, RY, 0.5e-3, D) == (0.0, 0.0)
    # on the centre: F_H - F_R = 0.0523821 - 0.0216985 = 0.0306836 N against the ball's travel (along u_e);
    # moment of the shear about the centre: (D/2) F_R = 4.7625e-3 x 0.0216985 = 1.033391e-4 N m
    f_c, m = rf.rolling_force_and_moment(ETA0, -2.0, 0.2e-6, RX, RY, 0.5e-3, D)
    assert f_c == pytest.approx(-0.0306836, rel=1e-5) and m == pytest.approx(1.033391e-4, rel=1e-5)
    # linear in eta at fixed film; more starved (smaller r_s) gives less force; none when fully starved
    a = rf.rolling_force_along(0.02, 2.0, 0.2e-6, RX, RY, 0.5e-3, D)[0]
    b = rf.rolling_force_along(0.06, 2.0, 0.2e-6, RX, RY, 0.5e-3, D)[0]
    assert b == pytest.approx(3 * a, rel=1e-12)
    lo, hi = rf.MENISCUS_RANGE_M
    assert rf.rolling_force_along(ETA0, 2.0, 0.2e-6, RX, RY, hi, D)[0] > \
        rf.rolling_force_along(ETA0, 2.0, 0.2e-6, RX, RY, 0.5e-3, D)[0] > \
        rf.rolling_force_along(ETA0, 2.0, 0.2e-6, RX, RY, lo, D)[0] == 0.0  # t = 1.04 < 1.42 at 0.05 mm
    # units: N = Pa s x m/s x m (C_0 is eta u times a length), so scaling every length by 2 at fixed t
    # (h by 2 too) doubles the force
    f1 = rf.chiu_rolling_forces(ETA0, 2.0, 0.0, 0.2e-6, RX, RY, 0.5e-3, D)[2]
    f2 = rf.chiu_rolling_forces(ETA0, 2.0, 0.0, 0.4e-6, 2 * RX, 2 * RY, 1.0e-3, 2 * D)[2]
    assert f2 == pytest.approx(2 * f1, rel=1e-12)


# ---------------------------------------------------------------- film and traction


def test_compiled_film_matches_hand_value_and_the_project_film():
    # Hamrock & Dowson (1977) central film, outer race, Q = 10 N, u = 2 m/s, k = 8 (an ellipticity; the
    # film formula takes it as input):
    # U = 0.04 x 2 / (2.285714e11 x 5.748541e-3) = 6.088501e-11, G = 1.5e-8 x 2.285714e11 = 3428.571,
    # W = 10 / (2.285714e11 x 3.304572e-5) = 1.323923e-6
    # H_c = 2.69 U^0.67 G^0.53 W^-0.067 (1 - 0.61 e^-5.84)
    #     = 2.69 x 1.430942e-7 x 74.74979 x 2.476482 x 0.998226 = 7.112924e-5;  h_c = H_c R_x = 0.408889 um
    h_c = ft.hd_central_film(ETA0, ALPHA, E_RED, 2.0, 10.0, RX, 8.0)
    peer = hamrock_dowson(10.0, 2.0, RX, 8.0, ETA0, ALPHA, E_RED)
    assert h_c == pytest.approx(peer.central_m, rel=1e-12)
    assert ft.hd_minimum_film(ETA0, ALPHA, E_RED, 2.0, 10.0, RX, 8.0) == pytest.approx(peer.minimum_m, rel=1e-12)
    assert h_c == pytest.approx(0.408889e-6, rel=1e-5)


def test_regime_weight_is_c1_at_both_bounds():
    lb, lf = ft.LAMBDA_BOUNDARY, ft.LAMBDA_FULL
    assert ft.regime_weight(0.5, lb, lf) == 0.0 and ft.regime_weight(5.0, lb, lf) == 1.0
    assert ft.regime_weight(2.0, lb, lf) == 0.5  # x = 1/2: 3/4 - 2/8 = 1/2
    assert ft.regime_weight(1.5, lb, lf) == pytest.approx(0.15625)  # x = 1/4: 3/16 - 2/64 = 0.15625
    e = 1e-6
    for lam in (lb, lf):  # value and slope continuous: one-sided difference quotients ~ 0 at both ends
        assert abs(ft.regime_weight(lam + e, lb, lf) - ft.regime_weight(lam - e, lb, lf)) < 1e-10
        assert abs(ft.regime_weight(lam + e, lb, lf) - ft.regime_weight(lam, lb, lf)) / e < 1e-5


ARGS = dict(q=100.0, area=math.pi * 0.4e-3 * 0.06e-3, sigma=0.1e-6, eta_e=150.0, lss=0.07, u_min=0.01, mu_b=0.1,
            v_reg=1e-3, lam_b=1.0, lam_f=3.0)


def _traction(u_s: float, h_min: float, h_c: float | None = None, **kw: float) -> float:
    a = {**ARGS, **kw}
    h_shear = h_min if h_c is None else h_c
    return ft.film_traction(u_s, a["q"], a["area"], h_min, h_shear, a["sigma"], a["eta_e"], a["lss"], a["u_min"],
                            a["mu_b"], a["v_reg"], a["lam_b"], a["lam_f"])


def test_traction_limits_full_film_and_boundary():
    # Lambda = 100 (h_min 10 um), |u_s| = 10 m/s >> u_L = 0.1238 m/s (shear film 0.2 um, worked below):
    # LSS-limited, F = Lambda_LSS Q (1 - e^-80.8) = 0.07 x 100 = 7 N (T3)
    assert _traction(10.0, 10e-6, 0.2e-6) == pytest.approx(7.0, rel=1e-12)
    assert _traction(-10.0, 10e-6, 0.2e-6) == pytest.approx(-7.0, rel=1e-12)
    # Lambda -> 0: boundary, mu_b Q tanh(u_s / v_reg) = 0.1 x 100 x tanh(1) = 7.615942 N at u_s = 1 mm/s (T4)
    assert _traction(1e-3, 0.01e-6) == pytest.approx(7.615942, rel=1e-6)
    # Lambda = 2: half of each (T5), at u_s = 0.01 m/s. Full film: tau_L = 0.07 x 100 / 7.5398e-8 m^2 = 92.84 MPa,
    # u_L = max(92.84e6 x 0.2e-6 / 150, 0.01) = max(0.1238, 0.01) = 0.1238 m/s,
    # F_film = 7 (1 - exp(-0.01 / 0.12379)) = 7 x 0.077602 = 0.543214 N; F_b = 10 tanh(10) = 10.0000 N;
    # F = 0.5 x 0.543214 + 0.5 x 10.0 = 5.271607 N
    assert _traction(0.01, 0.2e-6) == pytest.approx(5.271607, rel=1e-5)


def test_traction_is_continuous_across_regimes_and_c1_in_slip():
    for lam in (1.0, 3.0):
        h = lam * ARGS["sigma"]
        assert abs(_traction(0.05, h * (1 + 1e-9)) - _traction(0.05, h * (1 - 1e-9))) < 1e-6
    for h in (0.05e-6, 0.2e-6, 1e-6):  # odd in u_s, equal slopes from both sides of 0
        e = 1e-9
        right = (_traction(e, h) - _traction(0.0, h)) / e
        left = (_traction(0.0, h) - _traction(-e, h)) / e
        assert right == pytest.approx(left, rel=1e-6)
        slope = ft.film_traction_slope(ARGS["q"], ARGS["area"], h, h, ARGS["sigma"], ARGS["eta_e"], ARGS["lss"],
                                       ARGS["u_min"], ARGS["mu_b"], ARGS["v_reg"], 1.0, 3.0)
        assert right == pytest.approx(slope, rel=1e-4)


def test_min_slip_speed_caps_the_full_film_slope():
    # eta_e = 1.3e5 Pa s (Barus at 1 GPa): u_L = 92.84e6 x 1e-6 / 1.3e5 = 7.14e-4 m/s < u_min = 0.01, so the
    # slope is Lambda_LSS Q / u_min = 7 / 0.01 = 700 N s/m instead of 7 / 7.14e-4 = 9.8e3 N s/m
    s = ft.film_traction_slope(100.0, ARGS["area"], 1e-6, 1e-6, 0.1e-6, 1.3e5, 0.07, 0.01, 0.1, 1e-3, 1.0, 3.0)
    assert s == pytest.approx(700.0, rel=1e-12)
    s = ft.film_traction_slope(100.0, ARGS["area"], 1e-6, 1e-6, 0.1e-6, 1.3e5, 0.07, 1e-6, 0.1, 1e-3, 1.0, 3.0)
    assert s == pytest.approx(7.0 / (0.07 * 100.0 / ARGS["area"] * 1e-6 / 1.3e5), rel=1e-12)


# ---------------------------------------------------------------- drag and churning


def test_drag_coefficient_limits_and_hand_value():
    for re in (1e-6, 1e-4):  # Re -> 0: Stokes, C_D Re -> 24
        assert drag.drag_coefficient(re) * re == pytest.approx(24.0, rel=1e-3)
    # Re = 100: 24/100 (1 + 0.15 x 100^0.687) = 0.24 (1 + 0.15 x 23.65920) = 0.24 x 4.548880 = 1.091731
    assert drag.drag_coefficient(100.0) == pytest.approx(1.091731, rel=1e-6)
    assert drag.drag_coefficient(1e4) == 0.44
    re_n = drag.RE_NEWTON  # continuous where Schiller-Naumann meets Newton
    assert drag.drag_coefficient(re_n * (1 - 1e-9)) == pytest.approx(0.44, abs=1e-8)


def test_drag_force_stokes_newton_and_units():
    mu, rho = 0.002, 42.4
    # Stokes: F = 3 pi mu D V = 3 pi x 0.002 x 9.525e-3 x 1e-6 = 1.79542e-10 N (Re = 2e-4) against V
    assert drag.drag_force(1e-6, D, rho, mu) == pytest.approx(-3 * math.pi * mu * D * 1e-6, rel=1e-3)
    # (D1) at V = 2 m/s: Re = 42.4 x 2 x 9.525e-3 / 0.002 = 403.86; C_D = 24/403.86 (1 + 0.15 x 403.86^0.687)
    re = rho * 2.0 * D / mu
    cd = 24 / re * (1 + 0.15 * re**0.687)
    want = 0.5 * cd * rho * math.pi * D**2 / 4 * 4.0
    assert drag.drag_force(2.0, D, rho, mu) == pytest.approx(-want, rel=1e-12)
    assert drag.drag_force(-2.0, D, rho, mu) == pytest.approx(want, rel=1e-12)
    # Newton regime: 1/2 0.44 x 42.4 x pi/4 x D^2 x 30^2 = 0.599069 N  (Re = 6058)
    assert drag.drag_force(30.0, D, rho, mu) == pytest.approx(-0.5 * 0.44 * rho * math.pi / 4 * D**2 * 900, rel=1e-12)
    # continuous at the switch
    v_n = drag.RE_NEWTON * mu / (rho * D)
    assert drag.drag_force(v_n * (1 - 1e-10), D, rho, mu) == pytest.approx(drag.drag_force(v_n * (1 + 1e-10), D, rho,
                                                                                         mu), rel=1e-7)


def test_churning_moment_limits_and_mixture_density():
    mu, rho, r = 0.002, 42.4, D / 2
    # Re_w -> 0: Lamb's M = 8 pi mu R^3 omega = 8 pi x 0.002 x (4.7625e-3)^3 x 1e-3 = 5.4292e-12 N m (against)
    w = 1e-3
    assert drag.churning_moment(w, D, rho, mu) == pytest.approx(-8 * math.pi * mu * r**3 * w, rel=1e-3)
    # (D3) at omega = 1000 rad/s: Re_w = 42.4 x 1000 x 4.7625e-3^2 / 0.002 = 480.84,
    # C_M = 16 pi / 480.84 + 6.45 / sqrt(480.84) = 0.104535 + 0.294142 = 0.398677;
    # M = 0.5 x 0.398677 x 42.4 x 1e6 x 4.7625e-3^5 = 2.1191e-5 N m
    re_w = rho * 1000 * r**2 / mu
    assert re_w == pytest.approx(480.84, rel=1e-4)
    assert drag.churning_coefficient(re_w) == pytest.approx(0.398677, rel=1e-5)
    assert drag.churning_moment(1000.0, D, rho, mu) == pytest.approx(-0.5 * 0.398677 * rho * 1e6 * r**5, rel=1e-5)
    # oil-air mixture: 0.05 x 826 + 0.95 x 1.204 = 42.4438 kg/m^3 (Parker 1984; Harris & Kotzalas X ~ 5 %)
    assert drag.mixture_density(826.0) == pytest.approx(42.4438, rel=1e-9)


def test_units_compose_inside_compiled_code():
    """The units are numba functions that a model's compiled right-hand side can call (no Python objects)."""
    import numba

    @numba.njit
    def rhs_like(u_e: float, q: float) -> float:
        eta = vis.viscosity(ETA0, ALPHA, BETA, 0.0, T0, T0, True)
        h = ft.hd_central_film(eta, ALPHA, E_RED, u_e, q, RX, 8.0)
        f, m = rf.rolling_force_and_moment(eta, u_e, h, RX, RY, 0.5e-3, D)
        f += ft.film_traction(0.01, q, 1e-7, h, h, 0.1e-6, 100.0, 0.07, 0.01, 0.1, 1e-3, 1.0, 3.0)
        f += drag.drag_force(1.7, D, 42.4, 0.002)
        return f + m / (0.5 * D) + drag.churning_moment(400.0, D, 42.4, 0.002)

    h = ft.hd_central_film(ETA0, ALPHA, E_RED, -2.0, 10.0, RX, 8.0)
    f, m = rf.rolling_force_and_moment(ETA0, -2.0, h, RX, RY, 0.5e-3, D)
    parts = (f, ft.film_traction(0.01, 10.0, 1e-7, h, h, 0.1e-6, 100.0, 0.07, 0.01, 0.1, 1e-3, 1.0, 3.0),
             drag.drag_force(1.7, D, 42.4, 0.002), m / (0.5 * D), drag.churning_moment(400.0, D, 42.4, 0.002))
    assert all(x != 0.0 for x in parts)
    assert rhs_like(-2.0, 10.0) == pytest.approx(sum(parts), rel=1e-12)
