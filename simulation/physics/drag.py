"""Drag of the oil-air mixture on a ball: translational drag with a Reynolds-dependent C_D, and the churning
moment on its spin.

Translational drag on a sphere of diameter D moving at V through a fluid of density rho and viscosity mu:

    F = 1/2 C_D(Re) rho A V |V|,   A = pi D^2 / 4,   Re = rho |V| D / mu,                  (D1)

with the drag coefficient of Schiller & Naumann, "Ueber die grundlegenden Berechnungen bei der
Schwerkraftaufbereitung", Z. Ver. Dtsch. Ing. 77 (1933) 318-320 (as given by Clift, Grace & Weber, *Bubbles,
Drops and Particles*, 1978, Table 5.2, valid up to Re ~ 800-1000), joined to Newton's regime:

    C_D = max(24/Re (1 + 0.15 Re^0.687), 0.44).                                          (D2)

24/Re (1 + 0.15 Re^0.687) decreases monotonically and reaches 0.44 at Re = 988.95 (the conventional switch at 1000
leaves a 0.001 jump), so the max is continuous, with one kink. As Re -> 0, C_D -> 24/Re: Stokes' drag
F = 3 pi mu D V (Stokes 1851).

Churning moment on a ball spinning at omega (rad/s) in the mixture: the torque coefficient
C_M = M / (1/2 rho omega^2 R^5), R = D/2, of a sphere rotating in a fluid at rest, joined from its two limits:

    C_M = 16 pi / Re_w + 6.45 / sqrt(Re_w),   Re_w = rho omega R^2 / mu,                   (D3)

* 16 pi / Re_w is Kirchhoff's / Lamb's creeping-flow torque M = 8 pi mu R^3 omega (Lamb, *Hydrodynamics*,
  6th ed., 1932, §334), exact as Re_w -> 0;
* 6.45 / sqrt(Re_w) is the laminar boundary-layer torque of a rotating sphere (Howarth, "Note on the boundary
  layer on a rotating sphere", Phil. Mag. 42 (1951) 1308-1315; the coefficient as measured by Sawatzki, Acta
  Mech. 9 (1970) 159-214, for Re_w from ~10 up to the transition near 1e5).

The sum is an interpolation between the two limits (it overestimates both by the other term, at most ~20 % near
Re_w ~ 30): a choice, stated here, for a moment that matters only in the unloaded zone.

Oil-air mixture density. In a splash- or jet-lubricated bearing the cavity holds a small volume fraction X of
oil, rho_mix = X rho_oil + (1 - X) rho_air. Parker, "Prediction of lubricant-air mixture flow properties in
high-speed ball bearings" (NASA TP-2275, 1984), finds X of order 1-10 % in jet-lubricated bearings, and Harris
& Kotzalas (*Advanced Concepts of Bearing Technology*, 5th ed., 2007, ch. 3) use X ~ 0.05 for drag in the
absence of data. :data:`DEFAULT_OIL_FRACTION` = 0.05 with the paper's oil (826 kg/m^3) gives
rho_mix = 42.4 kg/m^3 (:func:`mixture_density`). The mixture's viscosity is taken as the same volume-weighted
mean, mu_mix = X mu_oil + (1 - X) mu_air (a choice: Parker's effective viscosity lies between the two).
"""

from __future__ import annotations

import math

import numba

__all__ = ["AIR_DENSITY_KG_M3", "AIR_VISCOSITY_PA_S", "DEFAULT_OIL_FRACTION", "OIL_FRACTION_RANGE", "RE_NEWTON",
           "mixture_density", "mixture_viscosity", "drag_coefficient", "drag_force", "churning_coefficient",
           "churning_moment"]

#: Air at 20 degC and 1 atm (kg/m^3, Pa s).
AIR_DENSITY_KG_M3 = 1.204
AIR_VISCOSITY_PA_S = 1.81e-5
#: Oil volume fraction X of the oil-air mixture: Parker (1984) 1-10 %; Harris & Kotzalas' working value 5 %.
DEFAULT_OIL_FRACTION = 0.05
OIL_FRACTION_RANGE = (0.01, 0.1)
#: Reynolds number at which (D2) reaches Newton's 0.44.
RE_NEWTON = 988.9478531195837


def mixture_density(oil_density_kg_m3: float, oil_fraction: float = DEFAULT_OIL_FRACTION) -> float:
    """rho_mix = X rho_oil + (1 - X) rho_air (kg/m^3)."""
    return oil_fraction * oil_density_kg_m3 + (1.0 - oil_fraction) * AIR_DENSITY_KG_M3


def mixture_viscosity(oil_viscosity_pa_s: float, oil_fraction: float = DEFAULT_OIL_FRACTION) -> float:
    """mu_mix = X mu_oil + (1 - X) mu_air (Pa s), a volume-weighted mean (see the module docstring)."""
    return oil_fraction * oil_viscosity_pa_s + (1.0 - oil_fraction) * AIR_VISCOSITY_PA_S


@numba.njit(cache=True)
def drag_coefficient(re: float) -> float:  # pragma: no cover - compiled
    """Schiller-Naumann C_D joined to Newton's 0.44, eq. (D2); ``re`` > 0."""
    return max(24.0 / re * (1.0 + 0.15 * re ** 0.687), 0.44)


@numba.njit(cache=True)
def drag_force(v: float, d: float, rho: float, mu: float) -> float:  # pragma: no cover - compiled
    """Signed drag (N) against the velocity ``v`` (m/s) of a sphere of diameter ``d`` (m), eq. (D1).

    Written as (pi/8) rho D^2 V^2 C_D, with C_D Re finite as Re -> 0, so the force is continuous and smooth
    through V = 0 (Stokes' 3 pi mu D V).
    """
    if v == 0.0 or rho <= 0.0:
        return 0.0
    speed = abs(v)
    re = rho * speed * d / mu
    # 1/2 C_D rho A V^2 with C_D = 24/Re (1 + 0.15 Re^0.687) = 3 pi mu D V (1 + 0.15 Re^0.687) below Re_N
    if re < RE_NEWTON:
        f = 3.0 * math.pi * mu * d * speed * (1.0 + 0.15 * re ** 0.687)
    else:
        f = 0.125 * math.pi * 0.44 * rho * d * d * speed * speed
    return -math.copysign(f, v)


@numba.njit(cache=True)
def churning_coefficient(re_w: float) -> float:  # pragma: no cover - compiled
    """Torque coefficient C_M of a rotating sphere, eq. (D3); ``re_w`` = rho omega R^2 / mu > 0."""
    return 16.0 * math.pi / re_w + 6.45 / math.sqrt(re_w)


@numba.njit(cache=True)
def churning_moment(omega: float, d: float, rho: float, mu: float) -> float:  # pragma: no cover - compiled
    """Signed moment (N m) against the spin ``omega`` (rad/s) of a ball of diameter ``d``, eq. (D3).

    M = 1/2 C_M rho omega^2 R^5 = 8 pi mu R^3 omega + 3.225 sqrt(rho mu) R^4 |omega|^1.5 (written so that
    omega -> 0 is finite and smooth).
    """
    if omega == 0.0 or rho <= 0.0:
        return 0.0
    r = 0.5 * d
    w = abs(omega)
    m = 8.0 * math.pi * mu * r ** 3 * w + 3.225 * math.sqrt(rho * mu) * r ** 4 * w * math.sqrt(w)
    return -math.copysign(m, omega)
