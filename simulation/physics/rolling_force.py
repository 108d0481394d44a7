"""Hydrodynamic rolling force and moment at a lubricated ball-race contact (Chiu 1974, as used by ADORE).

Source
------
Y. P. Chiu, "A theory of hydrodynamic friction forces in starved point contacts considering cavitation",
J. Lubr. Technol. 96 (1974) 237-246: the hydrodynamic forces in the inlet of a rolling point contact, from the
Reynolds equation for two rigid bodies with principal radii R_xi (rolling direction) and R_eta (across it), an
exponential pressure-viscosity law and a cavitating outlet, as a function of the *dimensionless meniscus
distance* t, i.e. of how far upstream the inlet is filled (starvation). Gupta's ADORE (P. K. Gupta, *Advanced
Dynamics of Rolling Elements*, Springer 1984, ch. 4-5) takes these forces into the ball equations. The
closed forms below are the curve fits of Chiu's graphs as written in the public MATLAB implementation
YUXinluhk/BallBearing-Dynamics, ``calcRacePumpingForce.m`` (its source thesis eqs. 2-41 to 2-48), read with
the project's fetch tool; this module is our own code.

With u_xi, u_eta the entraining (mean surface) velocity components relative to the contact, h the film
thickness, k = R_xi / R_eta, and r_s the inlet meniscus distance:

    C_0   = eta_0 |u_xi| sqrt(R_xi R_eta) sqrt[(3 + 2k)^-2 + (u_eta/u_xi)^2 (3 + 2/k)^-2 / k]     (R1, eq. 2-44)
    theta = atan[(3 + 2k) / (sqrt(k) (3 + 2/k)) u_eta / u_xi]                                  (R2, eq. 2-45)
    t     = r_s sqrt[(cos^2 theta + sin^2 theta / k) / (2 h R_xi)]                             (R3, eq. 2-46)
    Fbar_R = 28.59 ln t - 10.10   (t <= 5),   36.57 ln t - 22.85   (t > 5),   floored at 0      (R4, eq. 2-47)
    F_R   = 1/2 C_0 Fbar_R (cos theta, sqrt(R_xi R_eta) sin theta)                              (R5, eq. 2-41)
    F_H   = 2 C_0 Fbar_R (R_xi cos theta, R_eta sqrt(R_xi R_eta) sin theta) / D                 (R6, eq. 2-43)

F_R is the rolling (shear) force on the ball surface at the contact; F_H is the resultant of the inlet pressure
on the ball, whose line of action passes through the ball centre. The sliding part (eq. 2-42) is taken as 0
there, as in the source. (The eta-components of (R5), (R6) carry a length factor sqrt(R_xi R_eta) as printed
in the source; for pure rolling, theta = 0, they vanish, and the models of this project use the xi-components.)

Directions (our derivation, the one the source leaves implicit). In the contact frame the surfaces move
along the entraining velocity u and the inlet lies upstream. The inlet pressure rises toward the contact, so
its Poiseuille backflow runs upstream and drags *both* surfaces upstream: the shear F_R on the ball points
against u. The pressure acts along the ball's normals, through its centre, with a tangential component along
u. On the ball:

    force on the centre  = (|F_H| - |F_R|) u / |u|          (pressure minus shear; |F_H| >= 2 |F_R|),
    moment about centre  = r_c x (-|F_R| u / |u|),           r_c: centre -> contact point, |r_c| = D / 2.

Why F_H = 4 (R_xi / D) F_R: the film h(x) = h_0 + x^2 / (2 R_xi) gives, for the Poiseuille wall shear,
2 F_R = -int h dp/dx dA = int p h'(x) dA = (1/R_xi) int p x dA, while the tangential pressure component on the
ball (radius D/2) is (2/D) int p x dA. For a ball rolling at speed v on a flat (R_xi = D/2) the ball then loses
(F_H - F_R) v + F_R (D/2) (2 v / D) = F_H v = 2 F_R u: the work of both walls on the film, as it must.

The entraining speed is the mean surface speed relative to the contact, u = (u_ball + u_race) / 2, the speed
of the Hamrock-Dowson film formula; the film h is the central film.

Meniscus distance r_s
---------------------
t is the meniscus distance in units of the inlet length sqrt(2 h R_xi). The fit (R4) gives no rolling force
below t = exp(10.10 / 28.59) = 1.42 (the inlet starts inside the pressure zone: fully starved), and grows
like ln t. For the paper's bearing (R_xi = 5.75 mm at the outer race, h = 0.1-0.35 um) sqrt(2 h R_xi) =
34-63 um. :data:`MENISCUS_RANGE_M` states the range this project accepts: from 0.05 mm (t ~ 0.8-1.5, starved,
the order of the contact semi-axes of a lightly loaded ball; the source uses the contact semi-axis as its
default) to 2.0 mm (t ~ 32-59, a well-flooded inlet whose filled length is limited by the groove and ball
geometry: the gap sqrt(2 R_xi x) reaches the ~50 um oil layers of a splash-lubricated bearing there).
"""

from __future__ import annotations

import math

import numba

__all__ = ["MENISCUS_RANGE_M", "chiu_coefficient", "chiu_coefficient_published", "meniscus_parameter",
           "chiu_rolling_forces", "rolling_force_along",
           "rolling_force_and_moment"]

#: Accepted range of the inlet meniscus distance r_s (m), see the module docstring.
MENISCUS_RANGE_M = (0.05e-3, 2.0e-3)

#: t below which the fit (R4) gives no rolling force: exp(10.10 / 28.59).
T_ZERO = math.exp(10.10 / 28.59)


@numba.njit(cache=True)
def chiu_coefficient_published(t: float) -> float:  # pragma: no cover - compiled
    """Fbar_R(t) exactly as eq. (R4) is written (piecewise at t = 5, floored at 0)."""
    t = max(t, 1e-6)
    if t <= 5.0:
        f = 28.59 * math.log(t) - 10.10
    else:
        f = 36.57 * math.log(t) - 22.85
    return max(f, 0.0)


@numba.njit(cache=True)
def chiu_coefficient(t: float) -> float:  # pragma: no cover - compiled
    """Fbar_R(t), eq. (R4) made continuous: max(28.59 ln t - 10.10, 36.57 ln t - 22.85, 0).

    The two branches cross at ln t = 12.75 / 7.98, t = 4.94, not at 5: as printed, (R4) jumps by 0.093 at t = 5
    (0.26 % of 36.0). Taking the larger branch removes the jump, differs from (R4) only for 4.94 < t <= 5 and
    there by at most 0.093. The result is continuous in t, with kinks (slope jumps) at t = 1.42 and 4.94.
    """
    ln_t = math.log(max(t, 1e-6))
    return max(28.59 * ln_t - 10.10, 36.57 * ln_t - 22.85, 0.0)


@numba.njit(cache=True)
def meniscus_parameter(r_s: float, h: float, r_xi: float, k: float, theta: float) -> float:  # pragma: no cover
    """Dimensionless meniscus distance t, eq. (R3); ``r_s``, ``h``, ``r_xi`` in m, ``theta`` in rad."""
    c, s = math.cos(theta), math.sin(theta)
    return r_s * math.sqrt((c * c + s * s / k) / (2.0 * max(h, 1e-12) * r_xi))


@numba.njit(cache=True)
def chiu_rolling_forces(eta: float, u_xi: float, u_eta: float, h: float, r_xi: float, r_eta: float, r_s: float,
                        d: float) -> tuple[float, float, float, float]:  # pragma: no cover - compiled
    """Magnitude components (F_R_xi, F_R_eta, F_H_xi, F_H_eta) in N of eqs. (R5), (R6).

    Parameters
    ----------
    eta
        Inlet viscosity (Pa s) (ambient: the inlet pressure is low).
    u_xi, u_eta
        Entraining velocity components (m/s) along and across the rolling direction.
    h
        Central film thickness (m).
    r_xi, r_eta
        Effective radii of the contact along and across the rolling direction (m).
    r_s
        Inlet meniscus distance (m), see :data:`MENISCUS_RANGE_M`.
    d
        Ball diameter (m).

    Returns
    -------
    The xi-components are >= 0 (they scale with |u_xi|); apply the directions of the module docstring. For
    u_xi = 0 all four are 0 (the source guards the division the same way).
    """
    if u_xi == 0.0 or eta <= 0.0:
        return 0.0, 0.0, 0.0, 0.0
    k = r_xi / r_eta
    ratio = u_eta / u_xi
    c0 = eta * abs(u_xi) * math.sqrt(r_xi * r_eta) * math.sqrt(
        (3.0 + 2.0 * k) ** -2 + ratio * ratio * (3.0 + 2.0 / k) ** -2 / k)
    theta = math.atan((3.0 + 2.0 * k) / (math.sqrt(k) * (3.0 + 2.0 / k)) * ratio)
    fbar = chiu_coefficient(meniscus_parameter(r_s, h, r_xi, k, theta))
    c, s = math.cos(theta), math.sin(theta)
    root = math.sqrt(r_xi * r_eta)
    return (0.5 * c0 * fbar * c, 0.5 * c0 * fbar * root * s,
            2.0 * c0 * fbar * r_xi * c / d, 2.0 * c0 * fbar * r_eta * root * s / d)


@numba.njit(cache=True)
def rolling_force_along(eta: float, u_e: float, h: float, r_xi: float, r_eta: float, r_s: float,
                        d: float) -> tuple[float, float]:  # pragma: no cover - compiled
    """Signed pressure and shear forces (N) on the ball along the rolling axis, for pure rolling (u_eta = 0).

    ``u_e`` is the signed entraining speed (m/s) along the contact tangent t. Returns ``(f_pressure, f_shear)``:

    * ``f_pressure`` = +|F_H| sign(u_e): the inlet pressure, acting through the ball centre;
    * ``f_shear`` = -|F_R| sign(u_e): the film shear on the ball surface at the contact point.

    The force on the ball centre is their sum; the moment about the centre is r_c x (f_shear t), r_c from the
    centre to the contact point (|r_c| = D / 2). The race gets -f_shear at its surface and the rest of the
    reaction, -(f_pressure + f_shear) in total (the film has no inertia).
    """
    if u_e == 0.0:
        return 0.0, 0.0
    f_r, _, f_h, _ = chiu_rolling_forces(eta, u_e, 0.0, h, r_xi, r_eta, r_s, d)
    sgn = 1.0 if u_e > 0.0 else -1.0
    return sgn * f_h, -sgn * f_r


@numba.njit(cache=True)
def rolling_force_and_moment(eta: float, u_e: float, h: float, r_xi: float, r_eta: float, r_s: float,
                             d: float) -> tuple[float, float]:  # pragma: no cover - compiled
    """Force on the ball centre (N, along t) and moment about it (N m, about n x t), for pure rolling.

    With n the unit vector from the ball centre to the contact point and t the contact tangent along which
    ``u_e`` is signed, the shear f_shear t acts at r_c = (D/2) n, so its moment is
    (D/2) n x (f_shear t) = (D/2) f_shear (n x t). The pressure passes through the centre and adds no moment.
    In a planar model whose spin axis is n x t at the contact, the moment is (D/2) f_shear; where the spin axis
    is -(n x t) (for instance the inner contact of a ball whose n points inward), it enters with a minus sign.
    """
    f_p, f_s = rolling_force_along(eta, u_e, h, r_xi, r_eta, r_s, d)
    return f_p + f_s, 0.5 * d * f_s
