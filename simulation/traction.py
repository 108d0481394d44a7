"""Tangential force laws of the contacts: lubricated traction and dry Coulomb friction.

Lubricated traction follows the regression form that bearing-dynamics codes fit
to twin-disc traction measurements (Sakaguchi & Harada, J. Tribol. 128 (2006)
604-611, the paper's reference [22]; Gupta, Advanced Dynamics of Rolling
Elements, 1984, the paper's reference [23]):

    mu(s) = sign(s) [(A + B |s|) exp(-C |s|) + D],    s = u_s / u_r,

with u_s the sliding speed of the two surfaces, u_r their mean (entrainment)
speed, floored at ``u_floor`` so a contact that barely rolls is sliding. The
curve starts at mu(0) = 0 (A = -D), rises steeply to a peak mu_peak at a
slide-to-roll ratio s_peak and falls to the sliding value D as s grows.
:func:`regression_coefficients` turns those three readable quantities into
(A, B, C, D), so the defaults of :class:`~cageless.simulation.parameters.ModelParameters`
are stated in the units a tribologist reads off a traction curve.

Dry contacts use Coulomb friction with the Stribeck effect, regularised over a sliding speed v_reg:

    mu(u_s) = [mu_c + (mu_s - mu_c) exp(-(u_s / v_s)^2)] tanh(u_s / v_reg),

the static coefficient mu_s falling to the Coulomb (kinetic) coefficient mu_c over the Stribeck speed
v_s. The bracket is the Stribeck curve of Olsson, Åström, Canudas de Wit, Gäfvert & Lischinsky,
"Friction models and friction compensation", Eur. J. Control 4 (1998) 176-195, with their exponent
2 (Armstrong-Hélouvry's Gaussian); the tanh makes it continuous at zero speed, as in the combined
models of Andersson, Söderberg & Björklund, Tribol. Int. 40 (2007) 580-587. With mu_s = mu_c it is
the regularised Coulomb law.

The compiled functions allocate nothing and return the signed tangential force
(N) with the sign of the sliding speed.
"""

from __future__ import annotations

import math

import numba
from scipy import optimize

from cageless.errors import ParameterError
from cageless.simulation.film import hamrock_dowson
from cageless.simulation.hertz import HertzContact

__all__ = ["regression_traction", "dry_friction", "regression_coefficients", "traction_coefficient",
           "film_coefficient"]


@numba.njit(cache=True, inline="always")
def regression_traction(u_s, u_r, q, a, b, c, d, u_floor):  # pragma: no cover - compiled
    """Signed traction force (N) of a lubricated contact under normal load ``q`` (N)."""
    if q <= 0.0 or u_s == 0.0:
        return 0.0
    s = abs(u_s) / max(abs(u_r), u_floor)
    mu = (a + b * s) * math.exp(-c * s) + d
    return math.copysign(mu * q, u_s)


@numba.njit(cache=True, inline="always")
def dry_friction(u_s, q, mu_c, v_reg, mu_s, v_s):  # pragma: no cover - compiled
    """Signed Coulomb-Stribeck friction force (N): static ``mu_s`` falling to ``mu_c`` over the Stribeck
    speed ``v_s`` (m/s), regularised over ``v_reg`` (m/s)."""
    if q <= 0.0:
        return 0.0
    mu = mu_c
    if mu_s != mu_c:
        x = u_s / v_s
        mu += (mu_s - mu_c) * math.exp(-x * x)
    return mu * q * math.tanh(u_s / v_reg)


def regression_coefficients(peak_coefficient: float, peak_slide_roll: float,
                            sliding_coefficient: float) -> tuple[float, float, float, float]:
    """(A, B, C, D) of the traction curve with mu(0) = 0, peak ``peak_coefficient`` at ``peak_slide_roll``.

    With A = -D and x = C s_peak, mu'(s_peak) = 0 gives B = C D / (x - 1) and the peak value
    gives exp(-x) / (x - 1) = mu_peak / D - 1, which has one root x > 1.
    """
    if not 0 < sliding_coefficient < peak_coefficient < 1:
        raise ParameterError("traction_peak_coefficient", "must exceed traction_sliding_coefficient, both in (0, 1)",
                             (peak_coefficient, sliding_coefficient))
    if not 0 < peak_slide_roll < 1:
        raise ParameterError("traction_peak_slide_roll", "must lie in (0, 1)", peak_slide_roll)
    rho = peak_coefficient / sliding_coefficient - 1.0
    x = optimize.brentq(lambda v: math.exp(-v) / (v - 1.0) - rho, 1.0 + 1e-12, 60.0, xtol=1e-14)
    c = x / peak_slide_roll
    return -sliding_coefficient, c * sliding_coefficient / (x - 1.0), c, sliding_coefficient


def traction_coefficient(slide_roll: float, coefficients: tuple[float, float, float, float]) -> float:
    """mu at the slide-to-roll ratio ``slide_roll`` (for plots, tests and reports)."""
    a, b, c, d = coefficients
    return regression_traction(slide_roll, 1.0, 1.0, a, b, c, d, 1e-300)


def film_coefficient(contact: HertzContact, rx_m: float, viscosity_pa_s: float, pressure_viscosity_1_pa: float,
                     reduced_modulus_pa: float) -> float:
    """c_h in the Hamrock-Dowson central film h = c_h u^0.67 Q^-0.067 (SI units) for this contact."""
    return hamrock_dowson(1.0, 1.0, rx_m, contact.kappa, viscosity_pa_s, pressure_viscosity_1_pa,
                          reduced_modulus_pa).central_m
