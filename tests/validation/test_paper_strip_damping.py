"""The paper's damped normal force per strip (the hypothesis for its C_ho sensitivity), checked by hand.

The script is benchmarks/paper_strip_damping.py. The formulation is the paper's (Wang, Zhao, Wang, Jin, Appl.
Sci. 2026, 16, 9284, sec. 2.2, reference/paper.txt): strip k carries F_bn^k = K delta_k + C_ho v_n (line 72), the
contact F_n = sum_k F_bn^k (line 78), each strip's friction mu_k F_bn^k (line 75). Read with the strips along the
rolling direction, v_n at a strip x ahead of the centre is d(delta)/dt + u x / R_x (lines 69-70: the contact-point
velocity omega_b x r_x^bc + v_b).

Closed forms (our derivations, from those lines and the Hertz pressure, whose line load along the minor axis is
(3 Q / 4 b)(1 - xi^2), xi = x / b; Johnson, *Contact Mechanics*, 1985, sec. 4.2):

* without a no-tension clip the damping terms C_ho s_k u xi_k b / R_x are odd in xi and cancel in pairs: F_n = Q
  whatever C_ho (the strip sum is the lumped damper, the simulator's default model);
* with the clip, ball held at its Hertz approach and E = C_ho u b / R_x >> Q: the leading half carries
  int_0^1 [(3 Q / 4)(1 - xi^2) + (2 E / pi) xi sqrt(1 - xi^2)] d xi = Q / 2 + 2 E / (3 pi), the trailing half
  a sliver -xi_0 < xi < 0, xi_0 = 3 pi Q / (8 E) to first order, whose triangle of load adds
  (3 Q / 4) xi_0 / 2 = 9 pi Q^2 / (64 E);
* with the ball free to move (the paper integrates its radial motion, line 142) the approach falls until the
  strips carry the load: F_n = Q again.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))
from effect_helpers import benchmark_module  # noqa: E402



@pytest.fixture(scope="module")
def mod():
    with benchmark_module("paper_strip_damping") as module:
        yield module


@pytest.fixture(scope="module")
def at_1800(mod):
    return mod.contacts(1800.0, 500.0)


def test_shares_are_the_hertz_line_load_and_the_chord(mod) -> None:
    xi, w, s = mod.strip_shares(4)
    assert w.sum() == pytest.approx(1.0, abs=1e-15) and s.sum() == pytest.approx(1.0, abs=1e-15)
    # outer strip [0.5, 1]: (3/4)[(1 - 1/3) - (0.5 - 0.125/3)] = 0.15625; area (1/pi)[pi/2 - (0.5 sqrt(0.75) + pi/6)]
    assert w[-1] == pytest.approx(0.15625, rel=1e-12)
    assert s[-1] == pytest.approx((math.pi / 2 - 0.5 * math.sqrt(0.75) - math.pi / 6) / math.pi, rel=1e-12)
    assert np.allclose(xi, [-0.75, -0.25, 0.25, 0.75])


def test_leading_edge_damping_is_13_and_39_n_at_the_unloaded_contact(mod, at_1800) -> None:
    cs, u, _ = at_1800
    unl = cs[0]
    # u = (d_m / 4)(1 - gamma^2) w_i with d_m = (36.48 + 55.53) / 2 mm, D = 9.525 mm (the paper's Table 1)
    dm, d = 0.5 * (36.48e-3 + 55.53e-3), 9.525e-3
    assert u == pytest.approx(0.25 * dm * (1.0 - (d / dm) ** 2) * 1800.0 * math.pi / 30.0, rel=1e-9)
    assert unl.load_n == pytest.approx(0.4563, abs=1e-4)  # m_b (d_m / 2) w_c^2, the docs' 0.456 N
    b = unl.b_coeff * unl.load_n ** (1.0 / 3.0)
    edges = [cho * u * b / unl.r_x for cho in (2500.0, 7500.0)]
    assert edges == pytest.approx([12.97, 38.9], rel=2e-3)  # docs/benchmarks.md: "13-39 N on a 0.46 N contact"


def test_without_the_clip_the_strips_sum_to_the_lumped_load(mod, at_1800) -> None:
    cs, u, _ = at_1800
    for c in cs:
        for cho in (2500.0, 7500.0):
            r = mod.evaluate(c, u, cho, 5, free=False, clip=False)
            assert r["f_n"] == pytest.approx(c.load_n, rel=1e-12)


def test_clipped_and_held_the_unloaded_contact_carries_q_half_plus_2e_over_3pi_and_its_sliver(mod, at_1800) -> None:
    cs, u, _ = at_1800
    unl = cs[0]
    b = unl.b_coeff * unl.load_n ** (1.0 / 3.0)
    for cho, ratio in ((2500.0, 6.51), (7500.0, 18.2)):
        e = cho * u * b / unl.r_x
        fine = mod.evaluate(unl, u, cho, 401, free=False)["f_n"]
        q = unl.load_n
        assert fine == pytest.approx(q / 2.0 + 2.0 * e / (3.0 * math.pi) + 9.0 * math.pi * q * q / (64.0 * e), rel=3e-4)
        five = mod.evaluate(unl, u, cho, 5, free=False)["f_n"]  # the printed table's 5 strips
        assert five / unl.load_n == pytest.approx(ratio, rel=3e-3)


def test_free_ball_lifts_until_the_strips_carry_the_load_within_72_us(mod, at_1800) -> None:
    cs, u, _ = at_1800
    unl = cs[0]
    half_orbit = math.pi / (0.5 * 1800.0 * math.pi / 30.0 * (1.0 - 9.525e-3 / (0.5 * (36.48e-3 + 55.53e-3))))
    for cho, delta_ratio, t_us in ((2500.0, 0.0289, 71.5), (7500.0, 0.00323, 48.0)):
        r = mod.evaluate(unl, u, cho, 5, free=True)
        assert r["f_n"] == pytest.approx(unl.load_n, rel=1e-7)
        assert r["delta_ratio"] == pytest.approx(delta_ratio, rel=5e-3)
        t = mod.settling_time(unl, u, cho, 5)
        assert t == pytest.approx(t_us * 1e-6, rel=0.02)
        assert t < 2e-3 * half_orbit
    for c in cs[1:]:  # the most loaded contacts: at most an 11 % rise held, none free
        held = mod.evaluate(c, u, 7500.0, 5, free=False)["f_n"] / c.load_n
        assert 1.0 <= held < 1.11
        assert mod.evaluate(c, u, 7500.0, 5, free=True)["f_n"] == pytest.approx(c.load_n, rel=1e-7)
