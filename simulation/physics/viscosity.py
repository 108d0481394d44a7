"""Lubricant viscosity against pressure and temperature.

Pressure (isothermal):

* Barus (1893), Am. J. Sci. 45, 87-96:

      eta(p) = eta_0 exp(alpha p)                                                  (V1)

* Roelands (1966), *Correlational aspects of the viscosity-temperature-pressure relationship of lubricating
  oils*, thesis, TH Delft, in the form of Hamrock, Schmid & Jacobson, *Fundamentals of Fluid Film
  Lubrication*, 2nd ed. (2004), eq. (4.7):

      eta(p) = eta_0 exp{ (ln eta_0 + 9.67) [ (1 + p / p_0)^Z - 1 ] },  p_0 = 1.96e8 Pa,     (V2)

  with the pressure-viscosity index Z chosen so that (V2) has the Barus slope at p = 0,
  d(ln eta)/dp = (ln eta_0 + 9.67) Z / p_0 = alpha (Hamrock et al., eq. 4.9):

      Z = alpha p_0 / (ln eta_0 + 9.67).                                           (V3)

  The constant 9.67 is ln(1 / 6.31e-5 Pa s): Roelands' pole viscosity (eta_inf = 6.31e-5 Pa s). At contact
  pressures (0.5-2 GPa) Roelands grows far more slowly than Barus, which overpredicts viscosity there
  (Hamrock et al., §4.6).

Temperature (the exponential law with the paper's temperature-viscosity coefficient beta; Wang, Zhao, Wang &
Jin, Appl. Sci. 16 (2026) 9284, Table 1: beta = 0.027 1/K at 20 degC; Hamrock et al. eq. 4.3, Reynolds'
exponential form):

      eta(T) = eta_0 exp[-beta (T - T_0)].                                         (V4)

The paper's oil (Table 1): eta_0 = 0.04 Pa s, alpha = 1.5e-8 1/Pa, beta = 0.027 1/K, T_0 = 293.15 K.
"""

from __future__ import annotations

import math

import numba

__all__ = ["ROELANDS_P0_PA", "ROELANDS_LN_POLE", "barus", "roelands", "roelands_index", "temperature_factor",
           "viscosity"]

#: Roelands' reference pressure p_0 (Pa), Hamrock, Schmid & Jacobson (2004) eq. (4.7).
ROELANDS_P0_PA = 1.96e8
#: ln(1 / eta_inf) with Roelands' pole viscosity eta_inf = 6.31e-5 Pa s (same source).
ROELANDS_LN_POLE = 9.67


@numba.njit(cache=True)
def barus(eta0: float, alpha: float, p: float) -> float:  # pragma: no cover - compiled
    """Barus viscosity (Pa s), eq. (V1): ``eta0`` (Pa s) at pressure ``p`` (Pa), ``alpha`` (1/Pa).

    Negative (sub-ambient) gauge pressures are clipped to 0: cavitated oil is not thinner than at ambient.
    """
    return eta0 * math.exp(alpha * max(p, 0.0))


@numba.njit(cache=True)
def roelands_index(eta0: float, alpha: float) -> float:  # pragma: no cover - compiled
    """Roelands' pressure-viscosity index Z matched to the Barus slope ``alpha`` at p = 0, eq. (V3)."""
    return alpha * ROELANDS_P0_PA / (math.log(eta0) + ROELANDS_LN_POLE)


@numba.njit(cache=True)
def roelands(eta0: float, alpha: float, p: float) -> float:  # pragma: no cover - compiled
    """Roelands viscosity (Pa s), eq. (V2), with Z from eq. (V3).

    Valid for eta0 above Roelands' pole, 6.31e-5 Pa s (ln eta0 + 9.67 > 0); pressures below 0 are clipped.
    """
    ln_ratio = math.log(eta0) + ROELANDS_LN_POLE
    z = alpha * ROELANDS_P0_PA / ln_ratio
    return eta0 * math.exp(ln_ratio * ((1.0 + max(p, 0.0) / ROELANDS_P0_PA) ** z - 1.0))


@numba.njit(cache=True)
def temperature_factor(beta: float, t: float, t0: float) -> float:  # pragma: no cover - compiled
    """eta(T) / eta(T_0) = exp[-beta (T - T_0)], eq. (V4); ``beta`` in 1/K, temperatures in K."""
    return math.exp(-beta * (t - t0))


@numba.njit(cache=True)
def viscosity(eta0: float, alpha: float, beta: float, p: float, t: float, t0: float,
              use_roelands: bool) -> float:  # pragma: no cover - compiled
    """Viscosity (Pa s) at pressure ``p`` (Pa) and temperature ``t`` (K): eq. (V4) times (V1) or (V2).

    The temperature factor scales eta_0 before the pressure law (the pressure-viscosity coefficient is held at
    its reference value: Table 1 gives alpha at one temperature only).
    """
    e0 = eta0 * temperature_factor(beta, t, t0)
    if use_roelands:
        return roelands(e0, alpha, p)
    return barus(e0, alpha, p)
