"""The ``film_traction`` effect: race traction by lubrication regime, for both models.

The physics is :mod:`cageless.simulation.physics.film_traction` (the film parameter Lambda = h_min / sigma of
Tallian 1967; boundary friction below Lambda_b, full film above Lambda_f, a C1 blend between; full-film shear
limited by the limiting shear stress Lambda_LSS p of Bair & Winer, J. Lubr. Technol. 101 (1979) 258-264). This
module joins it to the models' named parameter slots and contact kinematics, in the way the public
implementation YUXinluhk/BallBearing-Dynamics (``calcEHLFriction.m``, read with the project's fetch tool)
lets the film and the viscosity into traction: the Newtonian shear eta_e u_s / h_c of the central film, with
eta_e the pressure-raised viscosity at the contact pressure, capped by a limiting shear stress proportional
to the pressure (0.1 p there). Our own choices (see ``docs/physics/lubricant.md``): eta_e is Roelands at the
mean Hertz pressure (Barus there gives 1e2-1e5 Pa s and a ~100x stiffer law), the shear saturates
exponentially instead of by a ``min``, and the regime bands of Lambda add boundary friction.

At a race contact of normal force Q with entraining speed u_r (the mean surface speed, as for the film):

* the Hamrock-Dowson central and minimum films h_c = C_c u_r^0.67 Q^-0.067, h_min = C_m u_r^0.68 Q^-0.073
  (the ``ehl_film`` effect on), or the fixed film h_c = h_min = h_0 (off: how the paper's model uses h_0);
* the mean Hertz pressure p = Q / (pi a b) = Q^(1/3) / (pi a* b*), a = a* Q^(1/3), b = b* Q^(1/3);
* eta_e = Roelands(eta(T), alpha, p), eta(T) = eta_0 exp[-beta (T - T_0)] at the oil temperature T;
* the regime weight w(Lambda) and the limiting sliding speed u_L = max(Lambda_LSS p h_c / eta_e, u_min) are
  computed once per contact (:func:`race_regime`); the force of a sliding speed u_s (a whole contact, or
  one strip of the spatial model's ellipse with its share of Q) is :func:`regime_force`.

A contact's law costs two logarithms (ln u_r, ln Q: :func:`film_logs`, shared with the rolling losses' film in the
planar model), three exponentials (h_min, Roelands' power as exp(Z ln(1 + p / p_0)), and h_c / eta_e as one) and a
cube root; Roelands' power was ``**`` (glibc's pow) and h_c and eta_e two exponentials, 14 % of the CPU time of a
settled planar ``ark4`` run in pow alone (perf; docs/imex.md, the tenth step).

It replaces the traction curve mu(slide-to-roll) at the race contacts (the ball-ball contacts keep the
curve). The force acts where the curve's acted and is booked the same way (the models' traction power), so the
energy balance is unchanged in form.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from cageless.simulation.forces import FASTMATH
from cageless.simulation.models.base import LAYOUT, P_F_FILM, P_H0
from cageless.simulation.models.contact_laws import tangential
from cageless.simulation.physics.viscosity import ROELANDS_LN_POLE, ROELANDS_P0_PA

__all__ = ["race_regime", "race_regime_logs", "film_logs", "regime_force", "race_tangential", "race_tangential_logs",
           "strip_tangential", "regime_slots", "oil_viscosity", "race_tangential_array"]

(P_F_FTRAC, P_SIGMA, P_LSS, P_MU_B, P_V_REG_B, P_U_MIN, P_LAM_B, P_LAM_F, P_ETA_T, P_ROE_LN, P_ROE_Z,
 P_LHC_I, P_LHM_I, P_AB_I, P_LHC_O, P_LHM_O, P_AB_O) = LAYOUT.slots(
    "F_FTRAC", "SIGMA", "LSS", "MU_B", "V_REG_B", "U_MIN", "LAM_B", "LAM_F", "ETA_T", "ROE_LN", "ROE_Z",
    "LHC_I", "LHM_I", "AB_I", "LHC_O", "LHM_O", "AB_O")


@numba.njit(cache=True, fastmath=FASTMATH, inline="always")
def film_logs(u, q, p):  # pragma: no cover - compiled
    """(ln u, ln q) of a race contact's entraining speed ``u`` (m/s, >= 0) and normal force ``q`` (N) where the
    ``ehl_film`` effect computes the film from them (on, u > 0, q > 0), else (0, 0), which are then not used: the
    film of :func:`race_regime_logs` and the rolling losses' (:func:`cageless.simulation.models.rolling.
    race_rolling_logs`) from one pair of logarithms per contact."""
    if p[P_F_FILM] > 0.5 and u > 0.0 and q > 0.0:
        return math.log(u), math.log(q)
    return 0.0, 0.0


@numba.njit(cache=True, fastmath=FASTMATH, inline="always")
def race_regime(u_r, q, inner, p):  # pragma: no cover - compiled
    """(w, u_L) at a race contact: the full film's share w in [0, 1] and its limiting sliding speed (m/s);
    (-1, 0) when the ``film_traction`` effect is off (the traction curve applies)."""
    if p[P_F_FTRAC] < 0.5:
        return -1.0, 0.0
    lu, lq = film_logs(u_r, q, p)
    return race_regime_logs(u_r, q, lu, lq, inner, p)


@numba.njit(cache=True, fastmath=FASTMATH, inline="always")
def race_regime_logs(u_r, q, lu, lq, inner, p):  # pragma: no cover - compiled
    """:func:`race_regime` with the contact's :func:`film_logs` (``lu``, ``lq``) given."""
    if p[P_F_FTRAC] < 0.5:
        return -1.0, 0.0
    if q <= 0.0:
        return 0.0, 1.0
    if inner:
        lhc, lhm, ab = p[P_LHC_I], p[P_LHM_I], p[P_AB_I]
    else:
        lhc, lhm, ab = p[P_LHC_O], p[P_LHM_O], p[P_AB_O]
    if p[P_F_FILM] > 0.5:
        if u_r <= 0.0:
            return 0.0, 1.0  # no entrainment, no film: boundary friction
        ln_hc = lhc + 0.67 * lu - 0.067 * lq
        h_m = math.exp(lhm + 0.68 * lu - 0.073 * lq)
    else:
        h_m = p[P_H0]
        ln_hc = math.log(h_m)
    x = (h_m / p[P_SIGMA] - p[P_LAM_B]) / (p[P_LAM_F] - p[P_LAM_B])
    if x <= 0.0:
        return 0.0, 1.0
    w = 1.0 if x >= 1.0 else x * x * (3.0 - 2.0 * x)  # regime_weight
    pm = np.cbrt(q) / ab  # mean Hertz pressure Q / (pi a b)
    # Roelands, ln(eta_e / eta_T) = ln(eta_T / eta_pole) ((1 + p / p_0)^Z - 1), its power as exp(Z ln(.)), and
    # h_c / eta_e in one exponential: u_L = L_SS p_m h_c / eta_e
    ln_roe = p[P_ROE_LN] * (math.exp(p[P_ROE_Z] * math.log(1.0 + pm / ROELANDS_P0_PA)) - 1.0)
    return w, max(p[P_LSS] * pm / p[P_ETA_T] * math.exp(ln_hc - ln_roe), p[P_U_MIN])


@numba.njit(cache=True, fastmath=FASTMATH, inline="always")
def regime_force(u_s, q, w, u_l, p):  # pragma: no cover - compiled
    """Signed traction (N) of sliding speed ``u_s`` under load ``q``: eq. (T5) of
    :mod:`cageless.simulation.physics.film_traction` with the contact's (w, u_L) from :func:`race_regime`."""
    if q <= 0.0:
        return 0.0
    f = 0.0
    if w > 0.0:
        f += w * math.copysign(p[P_LSS] * q * (1.0 - math.exp(-abs(u_s) / u_l)), u_s)
    if w < 1.0:
        f += (1.0 - w) * p[P_MU_B] * q * math.tanh(u_s / p[P_V_REG_B])
    return f


@numba.njit(cache=True, fastmath=FASTMATH, inline="always")
def race_tangential(u_s, u_r, q, inner, p):  # pragma: no cover - compiled
    """Signed tangential force (N) at a race contact: the regime law when ``film_traction`` is on, else the
    models' :func:`~cageless.simulation.models.contact_laws.tangential` (traction curve or dry friction)."""
    w, u_l = race_regime(u_r, q, inner, p)
    if w < 0.0:
        return tangential(u_s, u_r, q, p)
    return regime_force(u_s, q, w, u_l, p)


@numba.njit(cache=True, fastmath=FASTMATH, inline="always")
def race_tangential_logs(u_s, u_r, q, lu, lq, inner, p):  # pragma: no cover - compiled
    """:func:`race_tangential` with the contact's :func:`film_logs` (``lu``, ``lq``) given."""
    w, u_l = race_regime_logs(u_r, q, lu, lq, inner, p)
    if w < 0.0:
        return tangential(u_s, u_r, q, p)
    return regime_force(u_s, q, w, u_l, p)


@numba.njit(cache=True, fastmath=FASTMATH, inline="always")
def strip_tangential(u_s, u_r, q, w, u_l, p):  # pragma: no cover - compiled
    """:func:`race_tangential` for one strip of load ``q`` with the contact's (w, u_L) computed once."""
    if w < 0.0:
        return tangential(u_s, u_r, q, p)
    return regime_force(u_s, q, w, u_l, p)


def oil_viscosity(bearing, parameters) -> float:  # type: ignore[no-untyped-def]
    """eta(T) (Pa s) of the bearing's oil at ``parameters.oil_temperature_c`` at ambient pressure, eq. (V4) of
    :mod:`cageless.simulation.physics.viscosity` with the lubricant's beta and reference temperature."""
    lub = bearing.lubricant
    t_k = parameters.oil_temperature_c + 273.15
    if abs(t_k - lub.reference_temperature_k) < 1e-9:  # the reference temperature: eta_0 exactly
        return lub.dynamic_viscosity_pa_s
    return lub.dynamic_viscosity_pa_s * math.exp(-lub.temperature_viscosity_coefficient_1_k
                                                  * (t_k - lub.reference_temperature_k))


def regime_slots(bearing, parameters) -> dict[str, float]:  # type: ignore[no-untyped-def]
    """The ``film_traction`` slots for ``bearing`` and the run's parameters.

    Per race (suffix _I, _O): LHC = ln C_c and LHM = ln C_m of the Hamrock-Dowson films at eta(T)
    (h_c = C_c u^0.67 Q^-0.067, h_min = C_m u^0.68 Q^-0.073, :func:`cageless.simulation.physics.film_traction.
    hd_central_film`, ``hd_minimum_film``), AB = pi a* b* (so the mean pressure is Q^(1/3) / AB); and the
    Roelands constants of eta(T): ROE_LN = ln eta(T) + 9.67, ROE_Z = alpha p_0 / ROE_LN (eq. V3).
    """
    from cageless.simulation.hertz import compliance, hertz_contact, race_curvatures
    from cageless.simulation.physics import film_traction as ft

    g, mat, lub = bearing.geometry, bearing.material, bearing.lubricant
    d, dm = g.ball_diameter_m, g.pitch_diameter_m
    rc = race_curvatures(g)
    eta_c = compliance(mat)
    e_red = mat.youngs_modulus_pa / (1.0 - mat.poisson_ratio ** 2)
    eta_t, alpha = oil_viscosity(bearing, parameters), lub.pressure_viscosity_coefficient_1_pa
    roe_ln = math.log(eta_t) + ROELANDS_LN_POLE
    if roe_ln <= 0.0:
        raise ValueError("film_traction: the oil's viscosity at this temperature is below Roelands' pole "
                         "(6.31e-5 Pa s); raise the viscosity or lower oil_temperature_c")
    out = {"SIGMA": parameters.surface_roughness_m, "LSS": parameters.limiting_shear_coefficient,
           "MU_B": parameters.boundary_friction_coefficient, "V_REG_B": parameters.boundary_slip_speed_m_s,
           "U_MIN": ft.DEFAULT_MIN_SLIP_SPEED_M_S, "LAM_B": ft.LAMBDA_BOUNDARY, "LAM_F": ft.LAMBDA_FULL,
           "ETA_T": eta_t, "ROE_LN": roe_ln, "ROE_Z": alpha * ROELANDS_P0_PA / roe_ln}
    for tag, r_x, race in (("I", 0.5 * d * (dm - d) / dm, "inner"), ("O", 0.5 * d * (dm + d) / dm, "outer")):
        hc = hertz_contact(*rc[race], eta_c)
        out[f"LHC_{tag}"] = math.log(ft.hd_central_film(eta_t, alpha, e_red, 1.0, 1.0, r_x, hc.kappa))
        out[f"LHM_{tag}"] = math.log(ft.hd_minimum_film(eta_t, alpha, e_red, 1.0, 1.0, r_x, hc.kappa))
        out[f"AB_{tag}"] = math.pi * hc.a_coeff * hc.b_coeff
    if not all(math.isfinite(v) for v in out.values()):
        raise ValueError("film_traction: non-finite contact constants")
    return out


@numba.njit(cache=True)
def _race_tangential_loop(u_s, u_r, q, inner, p, out):  # pragma: no cover - compiled
    for i in range(out.shape[0]):
        out[i] = race_tangential(u_s[i], u_r[i], q[i], inner, p)


def race_tangential_array(u_s: np.ndarray, u_r: np.ndarray, q: np.ndarray, inner: bool,
                          p: np.ndarray) -> np.ndarray:
    """:func:`race_tangential` over arrays (for the observables along the samples): the compiled law itself, so
    the reported traction is the force the model integrated."""
    a, b, c = np.broadcast_arrays(np.asarray(u_s, float), np.asarray(u_r, float), np.asarray(q, float))
    out = np.empty(a.size)
    _race_tangential_loop(np.ascontiguousarray(a).ravel(), np.ascontiguousarray(b).ravel(),
                          np.ascontiguousarray(c).ravel(), inner, p, out)
    return out.reshape(a.shape)
