"""Hertz point contact from the exact elliptic-integral solution.

For two bodies with principal curvatures rho_11, rho_12 (body I) and rho_21,
rho_22 (body II), Harris & Kotzalas (*Rolling Bearing Analysis*, 5th ed.,
vol. 1, ch. 6) define the curvature sum and difference

    sum_rho = rho_11 + rho_12 + rho_21 + rho_22,
    F(rho)  = ((rho_11 - rho_12) + (rho_21 - rho_22)) / sum_rho,

and the ellipticity kappa = a / b of the contact ellipse solves

    F(rho) = ((kappa^2 + 1) E(m) - 2 K(m)) / ((kappa^2 - 1) E(m)),   m = 1 - 1 / kappa^2,

with K and E the complete elliptic integrals of the first and second kind. Then,
with eta = (1 - nu_I^2) / E_I + (1 - nu_II^2) / E_II,

    a = a* (3 Q eta / (2 sum_rho))^(1/3),  a* = (2 kappa^2 E / pi)^(1/3),
    b = b* (3 Q eta / (2 sum_rho))^(1/3),  b* = (2 E / (pi kappa))^(1/3),
    delta = delta* (3 Q eta / (2 sum_rho))^(2/3) sum_rho / 2,
    delta* = (2 K / pi) (pi / (2 kappa^2 E))^(1/3),

so that Q = K_n delta^1.5. :func:`hamrock_brewe` gives the closed-form fits of
Hamrock & Brewe (1983) for comparison.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from scipy import optimize, special

from cageless.bearing import Geometry, Material
from cageless.errors import ParameterError

__all__ = ["HertzContact", "hertz_contact", "race_curvatures", "ball_ball_contact", "hamrock_brewe"]


@dataclass(frozen=True)
class HertzContact:
    """One Hertz point contact.

    Attributes
    ----------
    sum_rho
        Curvature sum (1/m).
    f_rho
        Curvature difference F(rho), in [0, 1).
    kappa
        Ellipticity a / b (>= 1).
    ellip_k, ellip_e
        Complete elliptic integrals K(m) and E(m), m = 1 - 1/kappa^2.
    stiffness
        K_n in Q = K_n delta^1.5 (N/m^1.5).
    a_coeff, b_coeff
        Semi-axes per cube root of load: a = a_coeff Q^(1/3), b = b_coeff Q^(1/3) (m/N^(1/3)).
    """

    sum_rho: float
    f_rho: float
    kappa: float
    ellip_k: float
    ellip_e: float
    stiffness: float
    a_coeff: float
    b_coeff: float

    def deflection(self, load_n: float) -> float:
        """Approach delta (m) under load Q (N)."""
        return (max(load_n, 0.0) / self.stiffness) ** (2.0 / 3.0)

    def semi_axes(self, load_n: float) -> tuple[float, float]:
        """Semi-axes (a, b) of the contact ellipse (m) under load Q (N)."""
        c = max(load_n, 0.0) ** (1.0 / 3.0)
        return self.a_coeff * c, self.b_coeff * c

    def max_pressure(self, load_n: float) -> float:
        """Peak Hertz pressure 3 Q / (2 pi a b) (Pa)."""
        a, b = self.semi_axes(load_n)
        return 0.0 if a * b == 0 else 1.5 * load_n / (math.pi * a * b)


def _f_of_kappa(kappa: float) -> float:
    if kappa <= 1.0 + 1e-12:
        return 0.0
    m = 1.0 - 1.0 / kappa**2
    ek, ee = special.ellipk(m), special.ellipe(m)
    return ((kappa**2 + 1.0) * ee - 2.0 * ek) / ((kappa**2 - 1.0) * ee)


def hertz_contact(sum_rho: float, f_rho: float, eta: float) -> HertzContact:
    """Solve the exact Hertz point contact.

    Parameters
    ----------
    sum_rho
        Curvature sum (1/m), > 0.
    f_rho
        Curvature difference F(rho), in [0, 1).
    eta
        Compliance (1 - nu_I^2)/E_I + (1 - nu_II^2)/E_II (1/Pa), > 0.
    """
    if not (sum_rho > 0 and math.isfinite(sum_rho)):
        raise ParameterError("sum_rho", "must be a finite number > 0 (the bodies must be convex together)", sum_rho)
    if not 0.0 <= f_rho < 1.0:
        raise ParameterError("f_rho", "must lie in [0, 1)", f_rho)
    if f_rho < 1e-12:
        kappa = 1.0
    else:
        hi = 2.0
        while _f_of_kappa(hi) < f_rho:
            hi *= 2.0
        kappa = optimize.brentq(lambda k: _f_of_kappa(k) - f_rho, 1.0 + 1e-12, hi, xtol=1e-14, rtol=1e-14)
    m = 1.0 - 1.0 / kappa**2
    ek, ee = float(special.ellipk(m)), float(special.ellipe(m))
    a_star = (2.0 * kappa**2 * ee / math.pi) ** (1.0 / 3.0)
    b_star = (2.0 * ee / (math.pi * kappa)) ** (1.0 / 3.0)
    d_star = (2.0 * ek / math.pi) * (math.pi / (2.0 * kappa**2 * ee)) ** (1.0 / 3.0)
    c = 3.0 * eta / (2.0 * sum_rho)
    # delta = d_star * (c Q)^(2/3) * sum_rho / 2  =>  Q = K delta^1.5
    stiffness = 1.0 / (c * (d_star * sum_rho / 2.0) ** 1.5)
    return HertzContact(sum_rho=sum_rho, f_rho=f_rho, kappa=kappa, ellip_k=ek, ellip_e=ee, stiffness=stiffness,
                        a_coeff=a_star * c ** (1.0 / 3.0), b_coeff=b_star * c ** (1.0 / 3.0))


def race_curvatures(geometry: Geometry, contact_angle_rad: float = 0.0) -> dict[str, tuple[float, float]]:
    """Curvature sum and difference of the inner and outer race contacts (Harris & Kotzalas, ch. 2).

    With gamma = D cos(alpha) / d_m:
    inner: sum_rho D = 4 - 1/f_i + 2 gamma/(1 - gamma),  F = (1/f_i + 2 gamma/(1 - gamma)) / (sum_rho D);
    outer: sum_rho D = 4 - 1/f_o - 2 gamma/(1 + gamma),  F = (1/f_o - 2 gamma/(1 + gamma)) / (sum_rho D).
    """
    d = geometry.ball_diameter_m
    g = d * math.cos(contact_angle_rad) / geometry.pitch_diameter_m
    si = 4.0 - 1.0 / geometry.inner_curvature_factor + 2.0 * g / (1.0 - g)
    so = 4.0 - 1.0 / geometry.outer_curvature_factor - 2.0 * g / (1.0 + g)
    return {
        "inner": (si / d, (1.0 / geometry.inner_curvature_factor + 2.0 * g / (1.0 - g)) / si),
        "outer": (so / d, (1.0 / geometry.outer_curvature_factor - 2.0 * g / (1.0 + g)) / so),
    }


def compliance(material: Material) -> float:
    """eta = 2 (1 - nu^2) / E for two bodies of the same material (1/Pa)."""
    return 2.0 * (1.0 - material.poisson_ratio**2) / material.youngs_modulus_pa


def ball_ball_contact(geometry: Geometry, material: Material) -> HertzContact:
    """Two equal balls: a circular contact with sum_rho = 8 / D."""
    return hertz_contact(8.0 / geometry.ball_diameter_m, 0.0, compliance(material))


def hamrock_brewe(rx: float, ry: float) -> tuple[float, float, float]:
    """Hamrock & Brewe (1983) fits for the ellipticity k, E and F from the effective radii (ry >= rx):
    k = 1.0339 (ry/rx)^0.6360, E = 1.0003 + 0.5968 rx/ry, F = 1.5277 + 0.6023 ln(ry/rx)."""
    r = ry / rx
    return 1.0339 * r**0.6360, 1.0003 + 0.5968 / r, 1.5277 + 0.6023 * math.log(r)
