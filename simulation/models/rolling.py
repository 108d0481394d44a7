"""The ``rolling_losses`` effect: hydrodynamic rolling force and moment at both race contacts, for both models.

The physics is :mod:`cageless.simulation.physics.rolling_force` (Chiu, J. Lubr. Technol. 96 (1974) 237-246, as
used by Gupta's ADORE; the curve fits as written in the public implementation YUXinluhk/BallBearing-Dynamics,
``calcRacePumpingForce.m``). This module joins it to the models' named parameter slots and to their contact
kinematics:

* the entraining speed u_e is the mean of the ball's and the race's surface speeds along the rolling direction
  t, relative to the contact point (which moves with the ball's orbit);
* the film is the Hamrock-Dowson central film of the contact at the inlet viscosity (the ``ehl_film``
  effect on), or the fixed film h_0 (``ehl_film`` off);
* the inlet pressure f_p acts through the ball centre along t; the film shear f_s acts on the ball surface at
  the contact point, so its moment about the centre is (D/2) n x (f_s t);
* the race gets the reactions: the shear at its surface point, the pressure along the line through the ring's
  axis (the race's normals in the rolling plane pass through it), so the pressure puts no moment on the ring
  about its axis and takes no power from the drive.

The power of both forces on every body (ball translation and spin, ring translation, tilt and the drive) is
booked, so the energy balance closes: dissipated = -(f_p (v_ball - v_axis) . t + f_s (u_ball - u_race) . t),
drive input = shear moment on the ring x the ring's spin.
"""

from __future__ import annotations

import math

import numba

from cageless.simulation.forces import FASTMATH
from cageless.simulation.models.regime import film_logs
from cageless.simulation.models.base import (P_D, P_ETA0, P_F_FILM, P_LT_FILM_I, P_LT_FILM_O, P_LT_FIX_I, P_LT_FIX_O,
                                             P_RC_I, P_RC_O, P_RH_I, P_RH_O)

__all__ = ["race_rolling", "race_rolling_logs", "spatial_rolling", "rolling_slots"]


@numba.njit(cache=True, fastmath=FASTMATH, inline="always")
def race_rolling(u_e, q, inner, p):  # pragma: no cover - compiled
    """Signed (pressure, shear) forces (N) on the ball along t at a race contact with entraining speed ``u_e``
    (m/s, signed along t) and normal force ``q`` (N); (0, 0) when the contact carries no load.

    :func:`cageless.simulation.physics.rolling_force.rolling_force_along` with u_eta = 0, its film from
    :func:`cageless.simulation.physics.film_traction.hd_central_film`, written in logarithms so that a call costs
    two logarithms, ln |u| and ln Q, which the planar model shares with the traction's film
    (:func:`race_rolling_logs`; the contact's constants are in the slots, :func:`rolling_slots`):
    h = C |u|^0.67 Q^-0.067, ln t = ln r_s - ln(2 R_x h) / 2, C_0 = eta |u| sqrt(R_x R_y) / (3 + 2k).
    """
    lu, lq = film_logs(abs(u_e), q, p)
    return race_rolling_logs(u_e, q, lu, lq, inner, p)


@numba.njit(cache=True, fastmath=FASTMATH, inline="always")
def race_rolling_logs(u_e, q, lu, lq, inner, p):  # pragma: no cover - compiled
    """:func:`race_rolling` with the contact's :func:`cageless.simulation.models.regime.film_logs` of |u_e| and q
    (``lu``, ``lq``) given: the traction's film and this one from the same two logarithms."""
    if q <= 0.0 or u_e == 0.0:
        return 0.0, 0.0
    if inner:
        rc, rh, lt_film, lt_fix = p[P_RC_I], p[P_RH_I], p[P_LT_FILM_I], p[P_LT_FIX_I]
    else:
        rc, rh, lt_film, lt_fix = p[P_RC_O], p[P_RH_O], p[P_LT_FILM_O], p[P_LT_FIX_O]
    au = abs(u_e)
    if p[P_F_FILM] > 0.5:
        ln_t = lt_film - 0.5 * (0.67 * lu - 0.067 * lq)
    else:
        ln_t = lt_fix
    fbar = max(28.59 * ln_t - 10.10, 36.57 * ln_t - 22.85, 0.0)  # chiu_coefficient
    c = p[P_ETA0] * au * fbar
    sgn = 1.0 if u_e > 0.0 else -1.0
    return sgn * c * rh, -sgn * c * rc


@numba.njit(cache=True, fastmath=FASTMATH, inline="always")
def _cross(a0, a1, a2, b0, b1, b2):  # pragma: no cover - compiled
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


@numba.njit(cache=True, fastmath=FASTMATH)
def spatial_rolling(p, inner, q, rv, n, t, om, w, xr, axis, wt, r_c, rq):  # pragma: no cover - compiled
    """The rolling force at one race contact of the spatial model.

    ``rv`` is the ball centre's velocity relative to the race's surface point's carrier (the ring centre plus
    the tilting at ``xr``), ``n`` the unit normal from the ball centre to the contact, ``t`` the rolling
    direction, ``om`` the ball's spin, ``w`` the ring's drive spin, ``xr`` the race's contact point from the ring
    centre, ``axis`` the ring's axis, ``wt`` its tilting rate, ``r_c`` and ``rq`` the contact point's and the
    ball centre's distance from the axis (all 3-tuples in the fixed frame).

    Returns
    -------
    force (3) on the ball centre, moment (3) about it, drive power, dissipated power, moment (3) on the ring
    about its centre.
    """
    half = 0.5 * p[P_D]
    bs = _cross(om[0], om[1], om[2], half * n[0], half * n[1], half * n[2])  # ball surface at the contact
    rs = _cross(w[0], w[1], w[2], xr[0], xr[1], xr[2])  # race surface (the drive's spin)
    vt = rv[0] * t[0] + rv[1] * t[1] + rv[2] * t[2]
    bst = bs[0] * t[0] + bs[1] * t[1] + bs[2] * t[2]
    rst = rs[0] * t[0] + rs[1] * t[1] + rs[2] * t[2]
    f_p, f_s = race_rolling(0.5 * (vt * (1.0 - 2.0 * r_c / rq) + bst + rst), q, inner, p)
    f = f_p + f_s
    mx, my, mz = _cross(half * n[0], half * n[1], half * n[2], f_s * t[0], f_s * t[1], f_s * t[2])
    # the pressure's reaction acts at the point of the axis level with the contact: its velocity differs from
    # the race point's by the tilting wt x (xr - xa axis)
    xa = xr[0] * axis[0] + xr[1] * axis[1] + xr[2] * axis[2]
    lx, ly, lz = xr[0] - xa * axis[0], xr[1] - xa * axis[1], xr[2] - xa * axis[2]
    dv = _cross(wt[0], wt[1], wt[2], lx, ly, lz)
    vpt = vt + dv[0] * t[0] + dv[1] * t[1] + dv[2] * t[2]
    p_diss = -(f_p * vpt + f_s * (vt + bst - rst))
    sx, sy, sz = _cross(xr[0], xr[1], xr[2], f_s * t[0], f_s * t[1], f_s * t[2])
    p_in = sx * w[0] + sy * w[1] + sz * w[2]
    px, py, pz = _cross(xa * axis[0], xa * axis[1], xa * axis[2], f_p * t[0], f_p * t[1], f_p * t[2])
    return f * t[0], f * t[1], f * t[2], mx, my, mz, p_in, p_diss, -(sx + px), -(sy + py), -(sz + pz)


def rolling_slots(bearing, parameters) -> dict[str, float]:  # type: ignore[no-untyped-def]
    """The ``rolling_losses`` slots for ``bearing`` and the run's parameters, per race (suffix _I, _O):

    * RC = sqrt(R_x R_y) / (2 (3 + 2k)): F_R = eta |u| Fbar RC;
    * RH = 2 sqrt(R_x R_y) R_x / ((3 + 2k) D): F_H = eta |u| Fbar RH;
    * LT_FILM = ln r_s - ln(2 R_x C) / 2, with the Hamrock-Dowson film h = C |u|^0.67 Q^-0.067,
      C = R_x 2.69 (eta / (E' R_x))^0.67 (alpha E')^0.53 (E' R_x^2)^0.067 (1 - 0.61 exp(-0.73 kappa));
    * LT_FIX = ln r_s - ln(2 R_x h_0) / 2 (the fixed film, ``ehl_film`` off);

    R_x = (D/2)(d_m +- D)/d_m along the rolling direction, R_y = f D / (2 f - 1) across it, k = R_x / R_y,
    kappa the ellipticity of the Hertz contact, E' = E / (1 - nu^2).
    """
    from cageless.simulation.hertz import compliance, hertz_contact, race_curvatures

    g, mat, lub = bearing.geometry, bearing.material, bearing.lubricant
    d, dm = g.ball_diameter_m, g.pitch_diameter_m
    rc = race_curvatures(g)
    eta_c = compliance(mat)
    e_red = mat.youngs_modulus_pa / (1.0 - mat.poisson_ratio ** 2)
    from cageless.simulation.models.regime import oil_viscosity

    eta, alpha, r_s = oil_viscosity(bearing, parameters), lub.pressure_viscosity_coefficient_1_pa, \
        parameters.meniscus_distance_m
    out = {}
    for tag, r_x, f, race in (("I", 0.5 * d * (dm - d) / dm, g.inner_curvature_factor, "inner"),
                              ("O", 0.5 * d * (dm + d) / dm, g.outer_curvature_factor, "outer")):
        r_y = f * d / (2.0 * f - 1.0)
        k = r_x / r_y
        kappa = hertz_contact(*rc[race], eta_c).kappa
        c_film = (r_x * 2.69 * (eta / (e_red * r_x)) ** 0.67 * (alpha * e_red) ** 0.53
                  * (e_red * r_x * r_x) ** 0.067 * (1.0 - 0.61 * math.exp(-0.73 * kappa)))
        root = math.sqrt(r_x * r_y) / (3.0 + 2.0 * k)
        out.update({f"RC_{tag}": 0.5 * root, f"RH_{tag}": 2.0 * root * r_x / d,
                    f"LT_FILM_{tag}": math.log(r_s) - 0.5 * math.log(2.0 * r_x * c_film),
                    f"LT_FIX_{tag}": math.log(r_s) - 0.5 * math.log(2.0 * r_x * parameters.film_thickness_m)})
    if not all(math.isfinite(v) for v in out.values()):
        raise ValueError("rolling_losses: non-finite contact constants")
    return out
