"""Elastohydrodynamic film thickness of an elliptical contact (Hamrock & Dowson 1977).

Hamrock & Dowson, "Isothermal elastohydrodynamic lubrication of point contacts,
Part III - Fully flooded results", J. Lubr. Technol. 99 (1977) 264-276:

    H_min = h_min / R_x = 3.63 U^0.68 G^0.49 W^-0.073 (1 - exp(-0.68 k)),
    H_c   = h_c   / R_x = 2.69 U^0.67 G^0.53 W^-0.067 (1 - 0.61 exp(-0.73 k)),

with U = eta_0 u / (E' R_x), G = alpha E', W = Q / (E' R_x^2), u the mean
entraining velocity, R_x the effective radius in the rolling direction, k the
ellipticity and E' = 2 / ((1 - nu_1^2)/E_1 + (1 - nu_2^2)/E_2). The formulas are written once, compiled, in
:mod:`cageless.simulation.physics.film_traction` (``hd_central_film``, ``hd_minimum_film``); this module checks
the inputs and names the groups.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from cageless.errors import ParameterError

__all__ = ["FilmThickness", "hamrock_dowson"]


@dataclass(frozen=True)
class FilmThickness:
    """Central and minimum film thickness (m) and the dimensionless groups used."""

    central_m: float
    minimum_m: float
    speed_u: float
    material_g: float
    load_w: float


def hamrock_dowson(load_n: float, entraining_speed_m_s: float, rx_m: float, ellipticity: float,
                   viscosity_pa_s: float, pressure_viscosity_1_pa: float, reduced_modulus_pa: float) -> FilmThickness:
    """Hamrock-Dowson central and minimum film thickness.

    Parameters
    ----------
    load_n
        Contact load Q (N), > 0.
    entraining_speed_m_s
        Mean surface speed u = (u_1 + u_2) / 2 (m/s), > 0.
    rx_m
        Effective radius in the rolling direction (m).
    ellipticity
        k = a / b of the contact.
    viscosity_pa_s, pressure_viscosity_1_pa
        Ambient viscosity eta_0 and Barus coefficient alpha.
    reduced_modulus_pa
        E' = 2 / ((1 - nu_1^2)/E_1 + (1 - nu_2^2)/E_2).
    """
    for name, value in (("load_n", load_n), ("entraining_speed_m_s", entraining_speed_m_s), ("rx_m", rx_m),
                        ("ellipticity", ellipticity), ("viscosity_pa_s", viscosity_pa_s),
                        ("pressure_viscosity_1_pa", pressure_viscosity_1_pa),
                        ("reduced_modulus_pa", reduced_modulus_pa)):
        if not (math.isfinite(value) and value > 0):
            raise ParameterError(name, "must be a finite number > 0", value)
    # the formulas themselves are the compiled ones the right-hand sides use (one source)
    from cageless.simulation.physics.film_traction import hd_central_film, hd_minimum_film

    args = (viscosity_pa_s, pressure_viscosity_1_pa, reduced_modulus_pa, entraining_speed_m_s, load_n, rx_m,
            ellipticity)
    return FilmThickness(central_m=hd_central_film(*args), minimum_m=hd_minimum_film(*args),
                         speed_u=viscosity_pa_s * entraining_speed_m_s / (reduced_modulus_pa * rx_m),
                         material_g=pressure_viscosity_1_pa * reduced_modulus_pa,
                         load_w=load_n / (reduced_modulus_pa * rx_m**2))
