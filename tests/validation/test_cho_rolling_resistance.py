"""Damped (Kelvin-Voigt) rolling resistance as the way C_ho could reach the slip: its closed forms and its size.

The model is benchmarks/cho_rolling_resistance.py: the race damping C_ho spread evenly over the Hertz ellipse
(semi-axes a across, b along the rolling direction) as a Winkler foundation p = k'' w + c'' dw/dt that carries no
tension (Johnson, *Contact Mechanics*, 1985, sec. 9.2-9.4, for the elastic foundation and viscoelastic rolling).

Closed forms (our derivations, which the numerical solution must meet):

* slow rolling (De = L / b -> 0, L = c'' V / k''): the damping pressure c'' V x / R_x is a small odd addition
  to the static one, so M = (C_ho / (pi a b)) (V / R_x) int x^2 dA = (C_ho V / (pi a b R_x)) (pi a b^3 / 4)
  = C_ho V delta / 2, with b^2 = 2 R_x delta (the law M ~ damping x rolling speed x approach of multibody codes,
  whose rolling-friction coefficient grows as relaxation time x V / R: Brilliantov & Poeschel, Europhys. Lett.
  42 (1998) 511, valid while the relaxation time is short against the transit time b / V);
* fast rolling (De -> infinity): the trailing edge x_t = L - sqrt(L^2 + b_y^2) -> 0 and the damping pressure
  carries the load on the leading half of every strip, p = c'' V x / R_x over 0 < x < b_y, whose centroid is
  at 2 b_y / 3; weighting by the strip loads b_y^2 over the ellipse, x_bar = (2/3) b int (1 - s^2)^(3/2) ds /
  int (1 - s^2) ds = (2/3) b (3 pi / 8) / (4 / 3) = (3 pi / 16) b, the shrunken contact's semi-axis b.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))
from effect_helpers import benchmark_module  # noqa: E402



@pytest.fixture(scope="module")
def mod():
    with benchmark_module("cho_rolling_resistance") as module:
        yield module


# an arbitrary contact: 1 N on a 0.1 mm x 20 um ellipse at 0.1 um approach, rolling at 1 m/s
Q, A, B, DELTA_H, V = 1.0, 1.0e-4, 2.0e-5, 1.0e-7, 1.0


def test_slow_rolling_meets_the_linear_law(mod):
    cho = 1.0e-3  # De = C V delta_H / (2 Q b) = 2.5e-6
    r = mod.winkler_kv_rolling(Q, A, B, DELTA_H, cho, V)
    assert r["de"] == pytest.approx(2.5e-6, rel=1e-9)
    assert r["moment"] == pytest.approx(cho * V * r["delta"] / 2.0, rel=1e-4)
    assert r["delta"] == pytest.approx(DELTA_H, rel=1e-5)  # the static Winkler contact carries Q at delta_H


def test_fast_rolling_puts_the_centroid_at_three_pi_over_sixteen_b(mod):
    r = mod.winkler_kv_rolling(Q, A, B, DELTA_H, 1.0e7, V)  # De = 2.5e4
    assert r["x_bar"] / r["b_eff"] == pytest.approx(3.0 * math.pi / 16.0, rel=1e-5)
    assert r["b_eff"] < 0.1 * B  # the contact shrinks: the moment no longer grows with C_ho


def test_the_solution_depends_on_the_deborah_number_alone(mod):
    # x_bar / b is the same for two contacts of different size and load at the same De = C V delta_H / (2 Q b)
    r1 = mod.winkler_kv_rolling(Q, A, B, DELTA_H, 400.0, V)
    r2 = mod.winkler_kv_rolling(5.0 * Q, 3.0 * A, 2.0 * B, 4.0 * DELTA_H, 400.0 * 5.0 * 2.0 / 4.0 / 2.0, 2.0 * V)
    assert r1["de"] == pytest.approx(r2["de"], rel=1e-12)
    assert r1["x_bar"] / B == pytest.approx(r2["x_bar"] / (2.0 * B), rel=1e-6)


def test_in_the_unloaded_zone_the_term_is_saturated_small_and_falls_with_cho(mod):
    # 1800 rpm, 500 N, the paper's C_ho range (Wang et al. 2026, sec. 4): measured with the benchmark,
    # De 24-73, x_bar 3.1 -> 2.1 um, power 1.73 -> 1.21 mW beside the Chiu rolling loss's 27.7 mW (default r_s 0.210 mm)
    rows = [r for r in mod.contact_rows() if r["contact"] == "unloaded outer" and r["cho"] > 0]
    assert [r["cho"] for r in rows] == [2500.0, 5000.0, 7500.0]
    assert min(r["de"] for r in rows) > 20.0
    powers = [r["p_h_mw"] for r in rows]
    assert powers[0] > powers[1] > powers[2]
    assert powers[0] < 0.07 * rows[0]["p_chiu_mw"]  # 6.3 %
    assert (powers[0] - powers[2]) < 0.02 * rows[0]["p_chiu_mw"]  # 1.9 %


def test_in_the_loaded_zone_the_term_exceeds_the_catalogue_friction_tenfold(mod):
    # SKF's catalogue coefficient of an open deep-groove ball bearing, mu = 0.0015 (M = 0.5 mu P d, d the bore;
    # the pitch diameter is used, so the bound is generous): 0.0173 N m at 500 N. Measured: 0.295 N m at 2500 N s/m.
    from cageless.bearing import default_bearing

    bound = 0.5 * mod.SKF_MU_DEEP_GROOVE * 500.0 * default_bearing().geometry.pitch_diameter_m
    assert bound == pytest.approx(0.0173, abs=1e-4)
    assert mod.bearing_torque(2500.0) > 10.0 * bound


def test_no_damping_makes_the_unloaded_term_more_than_a_tenth_of_the_chiu_loss(mod):
    # x_bar / b = phi(De) peaks near De ~ 1.7 (C_ho ~ 180 N s/m here): measured 3.38 mW, 12.2 % of 27.7 mW. So no
    # C_ho range can move the unloaded-zone losses, which set the slip beyond gravity's 5.6 %, by more than ~13 %.
    scan = tuple(float(c) for c in __import__("numpy").geomspace(10.0, 10000.0, 13))
    rows = [r for r in mod.contact_rows(cho_values=scan) if r["contact"] == "unloaded outer"]
    ratio = max(r["p_h_mw"] / r["p_chiu_mw"] for r in rows)
    assert 0.10 < ratio < 0.13, ratio
