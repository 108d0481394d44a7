"""Hertz contact of the paper bearing from the exact elliptic-integral solution.

Sources: Harris & Kotzalas, *Rolling Bearing Analysis*, 5th ed., vol. 1 (2006), ch. 2 (curvatures) and
ch. 6 (contact); Hamrock & Brewe, "Simplified solution for stresses and deformations", J. Lubr. Technol.
105 (1983) 171-177 (closed-form fits, claimed within a few per cent). Bearing: Wang et al. 2026, Table 1.
"""

from __future__ import annotations

import math

import pytest
from scipy import special

from cageless.parameter_sets import wang2026
from cageless.simulation.hertz import ball_ball_contact, compliance, hamrock_brewe, hertz_contact, race_curvatures

G, M = wang2026.geometry(), wang2026.material()


def test_race_curvatures_by_hand():
    # gamma = 0.2070427; 2 gamma/(1 - gamma) = 0.5222060; 2 gamma/(1 + gamma) = 0.3430575.
    # Inner: sum_rho D = 4 - 1/0.515 + 0.5222060 = 4 - 1.9417476 + 0.5222060 = 2.5804584
    #        F = (1.9417476 + 0.5222060) / 2.5804584 = 0.9548511
    # Outer: sum_rho D = 4 - 1/0.52 - 0.3430575 = 4 - 1.9230769 - 0.3430575 = 1.7338656
    #        F = (1.9230769 - 0.3430575) / 1.7338656 = 0.9112698
    rc = race_curvatures(G)
    assert rc["inner"][0] * G.ball_diameter_m == pytest.approx(2.5804584, rel=1e-6)
    assert rc["inner"][1] == pytest.approx(0.9548511, rel=1e-6)
    assert rc["outer"][0] * G.ball_diameter_m == pytest.approx(1.7338656, rel=1e-6)
    assert rc["outer"][1] == pytest.approx(0.9112698, rel=1e-6)


def test_sphere_on_sphere_is_the_closed_form():
    """Two equal steel balls: Hertz's closed form a = (3 Q R / (4 E*))^(1/3), delta = (9 Q^2/(16 E*^2 R))^(1/3)
    with R = D/4 and E* = E / (2 (1 - nu^2)); and K = E sqrt(D) / (3 (1 - nu^2)) as DESIGN §6 states."""
    c = ball_ball_contact(G, M)
    q, d = 50.0, G.ball_diameter_m
    r, e_star = d / 4, M.youngs_modulus_pa / (2 * (1 - M.poisson_ratio**2))
    assert c.kappa == 1.0
    assert c.semi_axes(q)[0] == pytest.approx((3 * q * r / (4 * e_star)) ** (1 / 3), rel=1e-12)
    assert c.deflection(q) == pytest.approx((9 * q**2 / (16 * e_star**2 * r)) ** (1 / 3), rel=1e-12)
    assert c.stiffness == pytest.approx(M.youngs_modulus_pa * math.sqrt(d) / (3 * (1 - M.poisson_ratio**2)),
                                        rel=1e-12)


@pytest.mark.parametrize("race", ["inner", "outer"])
def test_race_contacts_solve_the_hertz_equations(race):
    sum_rho, f_rho = race_curvatures(G)[race]
    c = hertz_contact(sum_rho, f_rho, compliance(M))
    m = 1 - 1 / c.kappa**2
    ek, ee = special.ellipk(m), special.ellipe(m)
    # The ellipticity satisfies F(rho) = ((k^2 + 1) E - 2 K) / ((k^2 - 1) E) (Harris & Kotzalas eq. 6.21).
    assert ((c.kappa**2 + 1) * ee - 2 * ek) / ((c.kappa**2 - 1) * ee) == pytest.approx(f_rho, rel=1e-10)
    # Load-deflection consistency: Q = K delta^1.5 at 1000 N.
    assert c.stiffness * c.deflection(1000.0) ** 1.5 == pytest.approx(1000.0, rel=1e-12)
    # The mean pressure over the ellipse times its area is the load.
    a, b = c.semi_axes(1000.0)
    assert (2 / 3) * c.max_pressure(1000.0) * math.pi * a * b == pytest.approx(1000.0, rel=1e-12)


@pytest.mark.parametrize(("race", "rel_k"), [("inner", 0.03), ("outer", 0.03)])
def test_exact_solution_agrees_with_hamrock_brewe(race, rel_k):
    d, gam = G.ball_diameter_m, G.ball_diameter_m / G.pitch_diameter_m
    if race == "inner":
        rx = 1 / (2 / d + 2 / d * gam / (1 - gam))
        ry = 1 / (2 / d - 1 / (G.inner_curvature_factor * d))
    else:
        rx = 1 / (2 / d - 2 / d * gam / (1 + gam))
        ry = 1 / (2 / d - 1 / (G.outer_curvature_factor * d))
    c = hertz_contact(*race_curvatures(G)[race], compliance(M))
    k_fit, e_fit, f_fit = hamrock_brewe(rx, ry)
    assert c.kappa == pytest.approx(k_fit, rel=rel_k)
    assert c.ellip_e == pytest.approx(e_fit, rel=0.005)
    assert c.ellip_k == pytest.approx(f_fit, rel=0.005)
