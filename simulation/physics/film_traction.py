"""Traction of a lubricated race contact by lubrication regime, set by the film parameter Lambda = h / sigma.

Regimes (the film parameter of Tallian, ASLE Trans. 10 (1967) 418-439; the bands as in Hamrock, Schmid &
Jacobson, *Fundamentals of Fluid Film Lubrication*, 2nd ed., 2004, §1.3 and Harris & Kotzalas, *Essential
Concepts of Bearing Technology*, 5th ed., 2007, ch. 4): boundary lubrication below Lambda ~ 1, mixed between
1 and ~3, full film above. With h_min the minimum film and sigma = sqrt(sigma_1^2 + sigma_2^2) the composite
rms roughness:

    Lambda = h_min / sigma.                                                          (T1)

Full film: the steady-state limiting-shear-stress law of Bair & Winer, "A rheological model for
elastohydrodynamic contacts based on primary laboratory data", J. Lubr. Technol. 101 (1979) 258-264, their
constitutive law at constant shear rate (no elastic transient):

    tau = tau_L [1 - exp(-eta_e |u_s| / (h tau_L))] sign(u_s),   tau_L = Lambda_LSS p,     (T2)

u_s the sliding speed, h the film, eta_e the effective viscosity of the film (for example
:func:`cageless.simulation.physics.viscosity.roelands` at the mean Hertz pressure), p the mean contact pressure. Over
the contact, with p = Q / A:

    F_film = Lambda_LSS Q [1 - exp(-|u_s| / u_L)] sign(u_s),   u_L = max(tau_L h / eta_e, u_min),   (T3)

u_L being the sliding speed at which the Newtonian stress eta_e u_s / h would reach the limit. For Lambda -> inf
and |u_s| >> u_L the traction coefficient is Lambda_LSS (limiting-shear-stress-limited full film).

**u_min** caps the stiffness. With the paper's oil at contact pressure, eta_e is 1e2-1e5 Pa s and u_L falls to
1e-7-1e-4 m/s: a physical but very stiff law (slope Lambda_LSS Q / u_L up to ~1e9 N s/m). u_min (default
:data:`DEFAULT_MIN_SLIP_SPEED_M_S`) floors u_L; the force is then within Lambda_LSS Q exp(-|u_s|/u_min) of
(T3) and equal to it for |u_s| >> u_min. ``docs/physics/lubricant.md`` gives the measured slopes.

Boundary: Coulomb friction with mu_b, regularised over v_reg (as :func:`cageless.simulation.traction.dry_friction`):

    F_b = mu_b Q tanh(u_s / v_reg).                                                  (T4)

Mixed: the share of the load the film carries rises from 0 at Lambda_b to 1 at Lambda_f; as a C1 blend, the
cubic smoothstep w(x) = 3x^2 - 2x^3, x = (Lambda - Lambda_b) / (Lambda_f - Lambda_b) clipped to [0, 1]:

    F = w F_film + (1 - w) F_b.                                                      (T5)

Smoothness: F is C1 in Lambda (w' = 0 at both ends), C-infinity in Q and h for Q > 0, and C1 in u_s: (T3) is
odd in u_s with slope Lambda_LSS Q / u_L from both sides and a second derivative that jumps at u_s = 0; (T4) is
C-infinity.

The film thickness: Hamrock & Dowson, "Isothermal elastohydrodynamic lubrication of point contacts, Part
III - Fully flooded results", J. Lubr. Technol. 99 (1977) 264-276, eqs. for H_c and H_min (as in
:mod:`cageless.simulation.film`), compiled here for the right-hand sides.
"""

from __future__ import annotations

import math

import numba

__all__ = ["DEFAULT_LSS_COEFFICIENT", "LSS_COEFFICIENT_RANGE", "DEFAULT_BOUNDARY_COEFFICIENT",
           "DEFAULT_ROUGHNESS_M", "ROUGHNESS_RANGE_M", "DEFAULT_MIN_SLIP_SPEED_M_S", "LAMBDA_BOUNDARY",
           "LAMBDA_FULL", "hd_central_film", "hd_minimum_film", "film_parameter", "regime_weight",
           "full_film_traction", "boundary_traction", "film_traction", "film_traction_slope"]

#: Limiting shear stress over pressure, Lambda_LSS. Bair & Winer (1979) found the limiting shear stress to grow
#: about in proportion to pressure; coefficients of 0.04-0.1 are typical of mineral oils, and they match the
#: traction plateaus of twin-disc tests (Evans & Johnson, Proc. IMechE C 200 (1986) 303-312). 0.07 is a choice.
DEFAULT_LSS_COEFFICIENT = 0.07
LSS_COEFFICIENT_RANGE = (0.04, 0.1)
#: Boundary friction of lubricated bearing steel, ~0.1 (Harris & Kotzalas, ch. 4; Hamrock et al. §1.3).
DEFAULT_BOUNDARY_COEFFICIENT = 0.1
#: Composite rms roughness sigma (m): the paper does not give it. 0.1 um is representative of a ground race
#: (Rq 0.05-0.1 um) against a finished ball (Rq ~0.02 um); the accepted range is 0.02-0.3 um.
DEFAULT_ROUGHNESS_M = 0.1e-6
ROUGHNESS_RANGE_M = (0.02e-6, 0.3e-6)
#: Floor u_min (m/s) on the limiting sliding speed u_L of (T3): a numerical choice that bounds the stiffness.
DEFAULT_MIN_SLIP_SPEED_M_S = 0.01
#: Film-parameter bounds of the mixed regime (T5).
LAMBDA_BOUNDARY = 1.0
LAMBDA_FULL = 3.0


@numba.njit(cache=True)
def hd_central_film(eta: float, alpha: float, e_red: float, u: float, q: float, r_x: float,
                    k: float) -> float:  # pragma: no cover - compiled
    """Hamrock-Dowson central film (m): R_x 2.69 U^0.67 G^0.53 W^-0.067 (1 - 0.61 exp(-0.73 k)).

    U = eta u / (E' R_x), G = alpha E', W = Q / (E' R_x^2); ``u`` the mean entraining speed (m/s, its
    magnitude is used), ``k`` = a / b the ellipticity. 0 when u or Q is 0.
    """
    if q <= 0.0 or u == 0.0:
        return 0.0
    uu = eta * abs(u) / (e_red * r_x)
    w = q / (e_red * r_x * r_x)
    return r_x * 2.69 * uu ** 0.67 * (alpha * e_red) ** 0.53 * w ** -0.067 * (1.0 - 0.61 * math.exp(-0.73 * k))


@numba.njit(cache=True)
def hd_minimum_film(eta: float, alpha: float, e_red: float, u: float, q: float, r_x: float,
                    k: float) -> float:  # pragma: no cover - compiled
    """Hamrock-Dowson minimum film (m): R_x 3.63 U^0.68 G^0.49 W^-0.073 (1 - exp(-0.68 k))."""
    if q <= 0.0 or u == 0.0:
        return 0.0
    uu = eta * abs(u) / (e_red * r_x)
    w = q / (e_red * r_x * r_x)
    return r_x * 3.63 * uu ** 0.68 * (alpha * e_red) ** 0.49 * w ** -0.073 * (1.0 - math.exp(-0.68 * k))


@numba.njit(cache=True)
def film_parameter(h: float, sigma: float) -> float:  # pragma: no cover - compiled
    """Lambda = h / sigma, eq. (T1)."""
    return h / sigma


@numba.njit(cache=True)
def regime_weight(lam: float, lam_b: float, lam_f: float) -> float:  # pragma: no cover - compiled
    """Share w of the full-film law in (T5): 0 for Lambda <= lam_b, 1 for Lambda >= lam_f, C1 smoothstep."""
    x = (lam - lam_b) / (lam_f - lam_b)
    if x <= 0.0:
        return 0.0
    if x >= 1.0:
        return 1.0
    return x * x * (3.0 - 2.0 * x)


@numba.njit(cache=True)
def full_film_traction(u_s: float, q: float, area: float, h: float, eta_e: float, lss: float,
                       u_min: float) -> float:  # pragma: no cover - compiled
    """Signed full-film traction (N), eq. (T3): limiting shear stress ``lss`` x mean pressure Q / A.

    ``area`` is the contact area pi a b (m^2), ``h`` the film (m), ``eta_e`` the film's effective viscosity
    (Pa s), ``u_min`` the floor on the limiting sliding speed u_L (m/s).
    """
    if q <= 0.0 or u_s == 0.0:
        return 0.0
    tau_l = lss * q / area
    u_l = max(tau_l * h / eta_e, u_min)
    return math.copysign(lss * q * (1.0 - math.exp(-abs(u_s) / u_l)), u_s)


@numba.njit(cache=True)
def boundary_traction(u_s: float, q: float, mu_b: float, v_reg: float) -> float:  # pragma: no cover - compiled
    """Signed boundary friction (N), eq. (T4)."""
    if q <= 0.0:
        return 0.0
    return mu_b * q * math.tanh(u_s / v_reg)


@numba.njit(cache=True)
def film_traction(u_s: float, q: float, area: float, h_min: float, h_c: float, sigma: float, eta_e: float,
                  lss: float, u_min: float, mu_b: float, v_reg: float, lam_b: float,
                  lam_f: float) -> float:  # pragma: no cover - compiled
    """Signed traction (N) of a race contact in any regime, eq. (T5).

    The regime follows Lambda = h_min / sigma (T1); the full-film shear uses the central film ``h_c``.
    """
    if q <= 0.0:
        return 0.0
    w = regime_weight(h_min / sigma, lam_b, lam_f)
    f = 0.0
    if w > 0.0:
        f += w * full_film_traction(u_s, q, area, h_c, eta_e, lss, u_min)
    if w < 1.0:
        f += (1.0 - w) * boundary_traction(u_s, q, mu_b, v_reg)
    return f


@numba.njit(cache=True)
def film_traction_slope(q: float, area: float, h_min: float, h_c: float, sigma: float, eta_e: float, lss: float,
                        u_min: float, mu_b: float, v_reg: float, lam_b: float,
                        lam_f: float) -> float:  # pragma: no cover - compiled
    """dF/du_s at u_s = 0 (N s/m), the largest slope of (T5): w lss Q / u_L + (1 - w) mu_b Q / v_reg."""
    if q <= 0.0:
        return 0.0
    w = regime_weight(h_min / sigma, lam_b, lam_f)
    u_l = max(lss * q / area * h_c / eta_e, u_min)
    return w * lss * q / u_l + (1.0 - w) * mu_b * q / v_reg
