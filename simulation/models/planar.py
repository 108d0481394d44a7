"""The planar cageless-bearing model (pure radial load on an aligned bearing).

States (n = 5 Z + 6): per ball j the orbital radius r_j, angle theta_j, their
rates, and the spin omega_j about the shaft axis; then the inner-ring centre
(y, z) and its velocity; then the work put in by the ring's drive and the energy
dissipated so far (J), so the energy balance can be checked: kinetic + potential
energy + dissipated - input work stays constant. The ring's rotation is
prescribed (with an optional linear ramp from rest).

Effects, each gated by its flag so that an effect that is off is never evaluated:

* race contact: Hertz, ball to outer groove delta = r + D/2 - d_o/2, ball to the
  displaced inner groove delta = d_i/2 + D/2 - |P - C|;
* lubricant damping C_ho d(delta)/dt at the race contacts, the total normal
  force never tensile (default C_ho from :class:`~cageless.simulation.parameters.ModelParameters`); or, opt-in
  for reproducing the paper, its strip formulation (:mod:`cageless.simulation.models.strip_damping`);
* race traction: the tangential force of :mod:`cageless.simulation.traction` against the
  sliding of the ball surface on the race surface, with its moment on the spin;
  the ring's share is the drive's input power;
* EHL film: the Hamrock-Dowson film feeds the traction law (off: a fixed film h_0);
* ball-ball contact: Hertz with restitution-calibrated damping
  (:func:`cageless.simulation.forces.hertz_damped`) and friction from the sliding of the
  two surfaces (the same traction law, or dry Coulomb friction);
* ball-ball film: squeeze film 6 pi eta (D/4)^2 (-dh/dt) / h between approaching
  neighbours with a gap below 4/3 Delta_r, h floored at Delta_r (= h_0), handed over smoothly to zero
  around the cut-off and to the Hertz contact around a gap of zero
  (:func:`cageless.simulation.forces.squeeze_film`);
* gravity on balls and ring, the radial load on the ring (toward -z);
* drag 1/2 C_D rho A V^2 against the orbital motion.

The centrifugal force is not an effect: it comes out of the polar equations,
r'' = F_r / m + r theta'^2. Every ball-ball contact episode is logged after each
accepted step (:func:`contact_events`): onset, pair, orbital angle at the peak,
peak force and duration, classed as rubbing when it lasts more than
:data:`RUBBING_FACTOR` Hertz impact durations at its approach speed, else impact.
"""

from __future__ import annotations

import math

import numba
import numpy as np
import numpy.typing as npt

from cageless.bearing import Bearing
from cageless.errors import ParameterError
from cageless.simulation.forces import (FASTMATH, SQUEEZE_CUTOFF, SQUEEZE_TAPER, damping_factor, hertz_damped,
                                       hertz_impact_duration, squeeze_film)
from cageless.simulation.hertz import ball_ball_contact, compliance, hertz_contact, race_curvatures
from cageless.simulation import effects as effects_table
from cageless.simulation.effects import check_lubricant, effect_flags
from cageless.simulation.parameters import ModelParameters
from cageless.simulation.problem import Problem
from cageless.simulation.models.base import (LAYOUT, OBS_BB_NORMAL, OBS_BB_TRACTION, OBS_INNER_ENTRAIN,
                                             OBS_INNER_NORMAL, OBS_INNER_SLIDE, OBS_INNER_TRACTION,
                                             OBS_OUTER_ENTRAIN, OBS_OUTER_NORMAL, OBS_OUTER_SLIDE,
                                             OBS_OUTER_TRACTION, P_CHI, P_CHO, P_D, P_DI, P_DO, P_DRY, P_ETA0,
                                             P_FR, P_F_BB, P_F_BBFILM, P_F_BBFRIC, P_F_DRAG, P_F_GRAV, P_F_LUB,
                                             P_F_RACE, P_F_ROLL, P_F_TRAC, P_G, P_H0, P_I, P_KB, P_KI, P_KO, P_M,
                                             P_MR, P_RAMP, P_RHO_MIX, P_V_IN_MIN, P_WI, P_Z, signature_add)
from cageless.simulation.models.energy import planar_energy
from cageless.simulation.models.planar_layout import PlanarLayout
from cageless.simulation.models.contact_log import (EVENT_FIELDS, ONSET_RESOLUTION, RUBBING_FACTOR, contact_events,
                                                     empty_log, log_size, planar_post)
from cageless.simulation.models.contact_laws import RACE_LAWS, ball_churning, ball_drag, race_extra, tangential
from cageless.simulation.models.regime import (film_logs, oil_viscosity as par_viscosity, race_tangential,
                                               race_tangential_logs, regime_slots)
from cageless.simulation.models.rolling import race_rolling_logs, rolling_slots
from cageless.simulation.models.strip_damping import P_F_STRIP, strip_normal, strip_slots

__all__ = [
    "PlanarLayout", "planar_problem", "planar_energy", "packed_start", "contact_events", "DEFAULT_CHO_N_S_M",
    "RUBBING_FACTOR", "planar_observe", "planar_ring_share", "planar_ring_rows", "planar_gaps", "planar_post", "log_size", "EVENT_FIELDS",
    "ONSET_RESOLUTION",
]

#: Id of this model in :mod:`cageless.simulation.kernels`.
MODEL_ID = 0

#: Lubricant damping coefficient at the race contacts (N s/m): the middle of the paper's 2500-7500 range.
DEFAULT_CHO_N_S_M = ModelParameters().cho_n_s_m


@numba.njit(cache=True, fastmath=FASTMATH)
def _race_forces(y, p, j, z, w_i, c, s, obs):  # pragma: no cover - compiled
    """Race forces on ball j: (f_y, f_z, spin torque, ring f_y, ring f_z, input power, dissipated power); with
    ``obs`` (an array, None in the right-hand side) its race observables are written there too."""
    fy, fz, torque, p_diss = _outer_race(y, p, j, z, c, s, obs)
    return _inner_race(y, p, j, z, w_i, c, s, fy, fz, torque, p_diss, obs)


@numba.njit(cache=True, fastmath=FASTMATH, inline="always")
def _outer_race(y, p, j, z, c, s, obs):  # pragma: no cover - compiled
    """Ball j against the fixed outer race: (f_y, f_z, spin torque, dissipated power)."""
    d = p[P_D]
    half = 0.5 * d
    r, rd, thd, om = y[j], y[2 * z + j], y[3 * z + j], y[4 * z + j]
    fy = fz = torque = p_diss = 0.0
    trac = p[P_F_TRAC] > 0.5
    d_o = r + half - 0.5 * p[P_DO]
    if d_o > 0.0:
        q = p[P_KO] * d_o * np.sqrt(d_o)
        if obs is not None:
            obs[OBS_OUTER_NORMAL] = q
        if p[P_F_LUB] > 0.5:
            if p[P_F_STRIP] > 0.5:  # the paper's strips (models/strip_damping.py), opt-in
                q_d = strip_normal(q, d_o, rd, 0.5 * (r * thd + half * om - p[P_DO] * thd), False, p)
            else:
                q_d = max(q + p[P_CHO] * rd, 0.0)  # d(delta_o)/dt = r'; never tensile
            p_diss += (q_d - q) * rd
            q = q_d
        if RACE_LAWS:
            f_x = race_extra(d_o, rd, q, p)
            p_diss += f_x * rd
            q += f_x
        f_t = 0.0
        u_e = 0.5 * (r * thd + half * om - p[P_DO] * thd)  # entraining speed along e_theta: film, rolling losses
        lu = lq = 0.0
        if trac or p[P_F_ROLL] > 0.5:
            lu, lq = film_logs(abs(u_e), q, p)
        if trac:
            u = r * thd + half * om  # ball surface against the fixed outer race, along e_theta
            u_r = abs(u_e)
            f_t = -race_tangential_logs(u, u_r, q, lu, lq, False, p)
            if obs is not None:  # the law on the elastic normal force
                obs[OBS_OUTER_TRACTION] = -race_tangential(u, u_r, obs[OBS_OUTER_NORMAL], False, p)
                obs[OBS_OUTER_ENTRAIN] = u_r
                obs[OBS_OUTER_SLIDE] = u
            p_diss -= f_t * u
            torque += half * f_t
        if p[P_F_ROLL] > 0.5:  # rolling losses (models/rolling.py): pressure on the centre, shear at the surface
            f_p, f_s = race_rolling_logs(u_e, q, lu, lq, False, p)
            torque += half * f_s
            p_diss -= f_p * r * thd + f_s * (r * thd + half * om)
            f_t += f_p + f_s
        fy += -q * c - f_t * s
        fz += -q * s + f_t * c
    return fy, fz, torque, p_diss


@numba.njit(cache=True, fastmath=FASTMATH, inline="always")
def _inner_race(y, p, j, z, w_i, c, s, fy, fz, torque, p_diss, obs):  # pragma: no cover - compiled
    """Ball j against the driven inner ring, added to the outer race's (f_y, f_z, spin torque, dissipated
    power): the race forces of :func:`_race_forces`."""
    d = p[P_D]
    half = 0.5 * d
    r, rd, thd, om = y[j], y[2 * z + j], y[3 * z + j], y[4 * z + j]
    cy, cz, cvy, cvz = y[5 * z], y[5 * z + 1], y[5 * z + 2], y[5 * z + 3]
    ry = rz = p_in = 0.0
    trac = p[P_F_TRAC] > 0.5
    sx, sz = r * c - cy, r * s - cz
    ln = np.sqrt(sx * sx + sz * sz)
    d_i = 0.5 * p[P_DI] + half - ln
    if d_i > 0.0:
        nx, nz = sx / ln, sz / ln
        tx, tz = -nz, nx
        vx = rd * c - r * thd * s - cvy
        vz = rd * s + r * thd * c - cvz
        q = p[P_KI] * d_i * np.sqrt(d_i)
        if obs is not None:
            obs[OBS_INNER_NORMAL] = q
        q, p_diss = _inner_normal(q, d_i, (vx, vz, nx, nz, tx, tz), ln, half, om, w_i, p, p_diss)
        f_t = 0.0
        r_i, vt = 0.5 * p[P_DI], vx * tx + vz * tz
        u_e = 0.5 * (vt * (1.0 - 2.0 * r_i / ln) - half * om + w_i * r_i)  # entraining speed along t
        lu = lq = 0.0
        if trac or p[P_F_ROLL] > 0.5:
            lu, lq = film_logs(abs(u_e), q, p)
        if trac:
            u = vt - half * om - w_i * r_i  # ball surface against the ring surface, along t
            u_r = abs(u_e)
            f_t = -race_tangential_logs(u, u_r, q, lu, lq, True, p)
            if obs is not None:  # the law on the elastic normal force
                obs[OBS_INNER_TRACTION] = -race_tangential(u, u_r, obs[OBS_INNER_NORMAL], True, p)
                obs[OBS_INNER_ENTRAIN] = u_r
                obs[OBS_INNER_SLIDE] = u
            p_diss -= f_t * u
            p_in += w_i * r_i * f_t
            torque -= half * f_t
        if p[P_F_ROLL] > 0.5:
            f_p, f_s = race_rolling_logs(u_e, q, lu, lq, True, p)
            torque -= half * f_s
            p_diss -= f_p * vt + f_s * (vt - half * om - w_i * r_i)
            p_in += w_i * r_i * f_s
            f_t += f_p + f_s
        gy, gz = q * nx + f_t * tx, q * nz + f_t * tz
        fy += gy
        fz += gz
        ry -= gy
        rz -= gz
    return fy, fz, torque, ry, rz, p_in, p_diss


@numba.njit(cache=True, fastmath=FASTMATH, inline="always")
def _inner_normal(q, d_i, vn, ln, half, om, w_i, p, p_diss):  # pragma: no cover - compiled
    """:func:`_inner_race`'s normal force from its elastic part ``q``: the lubricant damping (or the paper's
    strips), never tensile, and the added race laws, with ``p_diss`` (the dissipated power) increased by their
    work. ``vn`` holds the contact's relative velocity and its normal and tangent (vx, vz, nx, nz, tx, tz)."""
    vx, vz, nx, nz, tx, tz = vn
    if p[P_F_LUB] > 0.5:
        ddot = -(vx * nx + vz * nz)
        if p[P_F_STRIP] > 0.5:
            r_i, vt = 0.5 * p[P_DI], vx * tx + vz * tz
            q_d = strip_normal(q, d_i, ddot, 0.5 * (vt * (1.0 - 2.0 * r_i / ln) - half * om + w_i * r_i), True, p)
        else:
            q_d = max(q + p[P_CHO] * ddot, 0.0)
        p_diss += (q_d - q) * ddot
        q = q_d
    if RACE_LAWS:
        ddot = -(vx * nx + vz * nz)
        f_x = race_extra(d_i, ddot, q, p)
        p_diss += f_x * ddot
        q += f_x
    return q, p_diss


@numba.njit(cache=True, fastmath=FASTMATH)
def _pair_forces(y, p, log, j, k, z, cj, sj, ck, sk, obs):  # pragma: no cover - compiled
    """Forces between balls j and k: (f_y on k, f_z on k, spin torque on both, dissipated power); with ``obs``
    (None in the right-hand side) the pair's observables are written there too."""
    d = p[P_D]
    rj, rk = y[j], y[k]
    dx = rk * ck - rj * cj
    dz = rk * sk - rj * sj
    ln = np.sqrt(dx * dx + dz * dz)
    delta = d - ln
    film = p[P_F_BBFILM] > 0.5 and -delta < (SQUEEZE_CUTOFF + SQUEEZE_TAPER) * p[P_H0]
    if delta <= 0.0 and not film:
        return 0.0, 0.0, 0.0, 0.0
    nx, nz = dx / ln, dz / ln
    vjx = y[2 * z + j] * cj - rj * y[3 * z + j] * sj
    vjz = y[2 * z + j] * sj + rj * y[3 * z + j] * cj
    vkx = y[2 * z + k] * ck - rk * y[3 * z + k] * sk
    vkz = y[2 * z + k] * sk + rk * y[3 * z + k] * ck
    delta_dot = -((vkx - vjx) * nx + (vkz - vjz) * nz)
    if delta <= 0.0:
        f = squeeze_film(-delta, delta_dot, p[P_ETA0], 0.25 * d, p[P_H0])  # between the approaching balls
        return f * nx, f * nz, 0.0, f * delta_dot
    # approach speed at onset: recorded after the first accepted step in contact (planar_post); until
    # then the current approach speed, so the force depends on no trial stage of any step
    # (floored: see ModelParameters.min_approach_speed_m_s)
    v_in = max(log[j] if log[j] > 0.0 else delta_dot, p[P_V_IN_MIN])
    f = hertz_damped(delta, delta_dot, v_in, p[P_KB], p[P_CHI])
    elastic = p[P_KB] * delta * np.sqrt(delta)
    # the squeeze film fading out over the first overlap (squeeze_film), on the normal force, not on friction's load
    f_film = squeeze_film(-delta, delta_dot, p[P_ETA0], 0.25 * d, p[P_H0]) if p[P_F_BBFILM] > 0.5 else 0.0
    p_diss = (f - elastic + f_film) * delta_dot
    if obs is not None:
        obs[OBS_BB_NORMAL] = elastic
    f_t = torque = 0.0
    if p[P_F_BBFRIC] > 0.5:
        tx, tz = -nz, nx
        om_j, om_k = y[4 * z + j], y[4 * z + k]
        u = (vjx - vkx) * tx + (vjz - vkz) * tz + 0.5 * d * (om_j + om_k)  # surface of j against k, along t
        u_r = 0.25 * d * abs(om_j - om_k)
        f_t = -tangential(u, u_r, f, p)  # on j, along t
        if obs is not None:  # the law on the elastic normal force
            obs[OBS_BB_TRACTION] = abs(tangential(u, u_r, elastic, p))
        p_diss -= f_t * u
        torque = 0.5 * d * f_t
        return (f + f_film) * nx - f_t * tx, (f + f_film) * nz - f_t * tz, torque, p_diss
    return (f + f_film) * nx, (f + f_film) * nz, torque, p_diss


@numba.njit(cache=True, fastmath=FASTMATH)
def planar_rhs(t, y, p, log, dydt):  # pragma: no cover - compiled
    """dy/dt at (t, y) into ``dydt``; the cos and sin of every ball's angle go to the log's scratch."""
    planar_rhs_trig(t, y, p, log, dydt, False)


@numba.njit(cache=True, fastmath=FASTMATH)
def planar_rhs_trig(t, y, p, log, dydt, trig_ready):  # pragma: no cover - compiled
    """:func:`planar_rhs`; with ``trig_ready`` the cos and sin of the balls' angles at ``y`` are already in the
    log's scratch (:func:`cageless.simulation.models.implicit_normal.planar_stage` puts them there)."""
    z = int(p[P_Z])
    m, m_ring, g = p[P_M], p[P_MR], p[P_G]
    grav_on = p[P_F_GRAV] > 0.5
    ramp = p[P_RAMP]
    w_i = p[P_WI] * (min(t / ramp, 1.0) if ramp > 0.0 else 1.0)
    power_in, power = 0.0, 0.0
    fy_ring, fz_ring = 0.0, -p[P_FR] - (m_ring * g if grav_on else 0.0)
    trig = log.shape[0] - 2 * z  # scratch: cos and sin of every ball's angle, computed once per call
    for j in range(z):
        if not trig_ready:
            log[trig + j] = np.cos(y[z + j])
            log[trig + z + j] = np.sin(y[z + j])
        dydt[j] = y[2 * z + j]
        dydt[z + j] = y[3 * z + j]
        dydt[2 * z + j] = 0.0  # force accumulators (Cartesian y, z) held in the acceleration slots for now
        dydt[3 * z + j] = -m * g if grav_on else 0.0
        dydt[4 * z + j] = 0.0  # torque accumulator
    if p[P_F_RACE] > 0.5:
        for j in range(z):  # the two halves of _race_forces, called directly: the loop runs faster fully inlined
            c, s = log[trig + j], log[trig + z + j]
            fy, fz, torque, p_diss = _outer_race(y, p, j, z, c, s, None)
            fy, fz, torque, ry, rz, p_in, p_diss = _inner_race(y, p, j, z, w_i, c, s, fy, fz, torque, p_diss, None)
            dydt[2 * z + j] += fy
            dydt[3 * z + j] += fz
            dydt[4 * z + j] += torque
            fy_ring += ry
            fz_ring += rz
            power_in += p_in
            power += p_diss
    if p[P_F_BB] > 0.5:
        for j in range(z):
            k = j + 1 if j + 1 < z else 0
            fy, fz, torque, p_diss = _pair_forces(y, p, log, j, k, z, log[trig + j], log[trig + z + j], log[trig + k],
                                                 log[trig + z + k], None)
            dydt[2 * z + j] -= fy
            dydt[3 * z + j] -= fz
            dydt[2 * z + k] += fy
            dydt[3 * z + k] += fz
            dydt[4 * z + j] += torque
            dydt[4 * z + k] += torque
            power += p_diss
    power = _ball_accelerations(y, p, log, dydt, z, trig, power)
    dydt[5 * z] = y[5 * z + 2]
    dydt[5 * z + 1] = y[5 * z + 3]
    dydt[5 * z + 2] = fy_ring / m_ring
    dydt[5 * z + 3] = fz_ring / m_ring
    dydt[5 * z + 4] = power_in
    dydt[5 * z + 5] = power


@numba.njit(cache=True, fastmath=FASTMATH, inline="always")
def _ball_accelerations(y, p, log, dydt, z, trig, power):  # pragma: no cover - compiled
    """The accumulated forces and torques (with the drag) to the balls' polar accelerations and spin rates;
    the dissipated power, updated."""
    m, inertia = p[P_M], p[P_I]
    drag = p[P_F_DRAG] > 0.5
    for j in range(z):
        r = y[j]
        c, s = log[trig + j], log[trig + z + j]
        fy, fz = dydt[2 * z + j], dydt[3 * z + j]
        rd, thd = y[2 * z + j], y[3 * z + j]
        f_rad = fy * c + fz * s
        f_tan = -fy * s + fz * c
        if drag:  # the mixture's drag on the orbital motion and churning moment on the spin
            f_d, m_c = ball_drag(r * thd, p), ball_churning(y[4 * z + j], p)
            f_tan += f_d
            dydt[4 * z + j] += m_c
            power -= f_d * r * thd + m_c * y[4 * z + j]
        dydt[2 * z + j] = f_rad / m + r * thd * thd
        dydt[3 * z + j] = (f_tan / m - 2.0 * rd * thd) / r
        dydt[4 * z + j] /= inertia
    return power


@numba.njit(cache=True)
def planar_ring_share(t, y, p, log, j, out):  # pragma: no cover - compiled
    """Ball j's share of the rows every ball reaches (see :mod:`cageless.simulation.jacobian`), in the order of
    :func:`planar_ring_rows`: its inner-race force on the ring over the ring's mass (y'', z''), its
    race input power, and the dissipation that depends on its state (its race contacts, its drag and
    the two ball-ball contacts it takes part in)."""
    z = int(p[P_Z])
    for i in range(4):
        out[i] = 0.0
    th = y[z + j]
    c, s = np.cos(th), np.sin(th)
    if p[P_F_RACE] > 0.5:
        ramp = p[P_RAMP]
        w_i = p[P_WI] * (min(t / ramp, 1.0) if ramp > 0.0 else 1.0)
        _, _, _, ry, rz, p_in, p_diss = _race_forces(y, p, j, z, w_i, c, s, None)
        out[0], out[1], out[2], out[3] = ry / p[P_MR], rz / p[P_MR], p_in, p_diss
    if p[P_F_BB] > 0.5:
        for a, b in ((j - 1 if j > 0 else z - 1, j), (j, j + 1 if j + 1 < z else 0)):
            ca, sa, cb, sb = np.cos(y[z + a]), np.sin(y[z + a]), np.cos(y[z + b]), np.sin(y[z + b])
            out[3] += _pair_forces(y, p, log, a, b, z, ca, sa, cb, sb, None)[3]
    if p[P_F_DRAG] > 0.5:
        v, om = y[j] * y[3 * z + j], y[4 * z + j]
        out[3] -= ball_drag(v, p) * v + ball_churning(om, p) * om


def planar_ring_rows(n_balls: int) -> list[int]:
    """State indices of the rows :func:`planar_ring_share` fills: the ring's y'' and z'', the input work
    and the dissipated energy."""
    return [5 * n_balls + 2, 5 * n_balls + 3, 5 * n_balls + 4, 5 * n_balls + 5]


def planar_state_blocks(n_balls: int) -> tuple[list[list[int]], list[int], list[int], list[int]]:
    """The state layout as the Jacobian's structure needs it: each per-ball field's indices (r, theta, r',
    theta', spin), the rows :func:`planar_ring_share` fills, the ring's own states and the two energy counters."""
    z = n_balls
    return ([list(range(f * z, (f + 1) * z)) for f in range(5)], planar_ring_rows(z),
            list(range(5 * z, 5 * z + 4)), [5 * z + 4, 5 * z + 5])


@numba.njit(cache=True, inline="always")
def planar_observe(t, y, p, log, out):  # pragma: no cover - compiled
    """The observables of state ``y`` at time t from the right-hand side's own force functions: per ball j,
    ``out[:, j]`` gets the fields of :data:`cageless.simulation.models.base.OBSERVABLES` (films excluded)."""
    z = int(p[P_Z])
    out[:, :] = 0.0
    ramp = p[P_RAMP]
    w_i = p[P_WI] * (min(t / ramp, 1.0) if ramp > 0.0 else 1.0)
    for j in range(z):
        k = j + 1 if j + 1 < z else 0
        c, s = np.cos(y[z + j]), np.sin(y[z + j])
        if p[P_F_RACE] > 0.5:
            _race_forces(y, p, j, z, w_i, c, s, out[:, j])
        if p[P_F_BB] > 0.5:
            _pair_forces(y, p, log, j, k, z, c, s, np.cos(y[z + k]), np.sin(y[z + k]), out[:, j])


@numba.njit(cache=True, inline="always")
def _overlaps(y, p, j, z):  # pragma: no cover - compiled
    """Ball j's contacts, each > 0 when closed: outer and inner race overlap (m), and D^2 - |c_k - c_j|^2
    with its neighbour k = j + 1 (m^2)."""
    d = p[P_D]
    r, th = y[j], y[z + j]
    sx, sz = r * np.cos(th) - y[5 * z], r * np.sin(th) - y[5 * z + 1]
    k = j + 1 if j + 1 < z else 0
    dx = y[k] * np.cos(y[z + k]) - r * np.cos(th)
    dz = y[k] * np.sin(y[z + k]) - r * np.sin(th)
    return (r + 0.5 * d - 0.5 * p[P_DO], 0.5 * p[P_DI] + 0.5 * d - np.sqrt(sx * sx + sz * sz),
            d * d - (dx * dx + dz * dz))


@numba.njit(cache=True)
def planar_signature(y, p):  # pragma: no cover - compiled
    """Which contacts are closed, as a number: sum over contacts of (its index + 1) when closed."""
    z = int(p[P_Z])
    sig = 0.0
    for j in range(z):
        outer, inner, pair = _overlaps(y, p, j, z)
        sig = signature_add(sig, j, z, outer, inner, pair)
    return sig * (sig + 1.0)  # spreads sums so that one contact swapping for another rarely keeps the value


@numba.njit(cache=True)
def planar_gaps(y, p, out):  # pragma: no cover - compiled
    """Every contact's overlap (m; > 0 closed; :func:`_overlaps`), the quantities :func:`planar_signature`
    tests: outer race j at ``out[j]``, inner race j at ``out[z + j]``, balls j and j + 1 at
    ``out[2 z + j]``. CVODE's steps are stopped ahead of their predicted sign changes
    (:mod:`cageless.simulation.solve`), so it does not step over a contact onset."""
    z = int(p[P_Z])
    d = p[P_D]
    for j in range(z):
        out[j], out[z + j], pair = _overlaps(y, p, j, z)
        out[2 * z + j] = d - np.sqrt(d * d - pair)  # in metres, as the race overlaps, so they extrapolate alike


def _contact_params(bearing: Bearing) -> dict[str, float]:
    """Hertz stiffnesses of the inner, outer and ball-ball contacts, and the lubricant's viscosity."""
    g, mat = bearing.geometry, bearing.material
    eta = compliance(mat)
    rc = race_curvatures(g)
    out = {"KI": hertz_contact(*rc["inner"], eta).stiffness, "KO": hertz_contact(*rc["outer"], eta).stiffness,
           "KB": ball_ball_contact(g, mat).stiffness}
    if bearing.lubricant is not None:
        out["ETA0"] = bearing.lubricant.dynamic_viscosity_pa_s
    return out


def _params(bearing: Bearing, radial_load_n: float, gravity_m_s2: float, inner_speed: float,
            effects: dict[str, bool], par: ModelParameters, speed_ramp_s: float,
            oil_air_density_kg_m3: float | None) -> npt.NDArray[np.float64]:
    """The parameter vector: the named slots of :data:`LAYOUT` filled from the bearing, the scene and ``par``;
    the effect flags from ``effects`` alone (an effect it does not name is off)."""
    g, masses = bearing.geometry, bearing.masses
    lubricated = bearing.lubricant is not None
    check_lubricant(effects, lubricated)
    p = LAYOUT.zeros()
    LAYOUT.fill(p, {"Z": g.n_balls, "D": g.ball_diameter_m, "M": masses.ball_mass_kg,
                    "I": 0.1 * masses.ball_mass_kg * g.ball_diameter_m**2, "MR": masses.ring_translational_mass_kg,
                    "DI": g.inner_race_diameter_m, "DO": g.outer_race_diameter_m})
    LAYOUT.fill(p, _contact_params(bearing))
    LAYOUT.fill(p, {"CHI": damping_factor(par.restitution), "G": gravity_m_s2, "FR": radial_load_n,
                    "WI": inner_speed, "RAMP": speed_ramp_s})
    LAYOUT.fill(p, effect_flags(effects))
    for spec in effects_table.EFFECTS:  # rows registered with their own parameters (models/race_laws.py)
        if spec.fill is not None:
            LAYOUT.fill(p, spec.fill(par))
    ta, tb, tc, td = par.traction_coefficients
    LAYOUT.fill(p, {"CHO": par.cho_n_s_m, "H0": par.film_thickness_m, "TA": ta, "TB": tb, "TC": tc, "TD": td,
                    "V_REG": par.slip_regularisation_m_s, "U_FLOOR": par.min_entrainment_m_s,
                    "CD": par.drag_coefficient or 0.0, "V_IN_MIN": par.min_approach_speed_m_s})
    if p[P_DRY] and (p[P_F_TRAC] or p[P_F_BBFRIC]):
        if par.dry_friction_coefficient is None:
            raise ParameterError("dry_friction_coefficient", "a dry scene needs the Coulomb friction of the bare "
                                 "steel contacts, which has no cited default: give it with "
                                 "--set dry_friction_coefficient=VALUE (or add a lubricant)")
        LAYOUT.fill(p, {"MU_DRY": par.dry_friction_coefficient,
                        "MU_STATIC": par.dry_static_coefficient or par.dry_friction_coefficient,
                        "V_STRIBECK": par.stribeck_speed_m_s})
    if p[P_F_ROLL]:
        LAYOUT.fill(p, rolling_slots(bearing, par))
    if p[P_F_STRIP]:
        LAYOUT.fill(p, strip_slots(bearing))
    if lubricated:  # the oil at its temperature; the regime traction's constants (models/regime.py)
        LAYOUT.fill(p, {"ETA0": par_viscosity(bearing, par)})
        if p[LAYOUT.index("F_FTRAC")]:
            LAYOUT.fill(p, regime_slots(bearing, par))
    if p[P_F_DRAG]:
        if oil_air_density_kg_m3 is None and lubricated:  # the default mixture of a lubricated scene
            from cageless.simulation.physics.drag import mixture_density

            oil_air_density_kg_m3 = mixture_density(bearing.lubricant.density_kg_m3)
        if not oil_air_density_kg_m3:
            raise ParameterError("oil_air_density_kg_m3", "drag is on but no oil-air mixture density is given")
        p[P_RHO_MIX] = oil_air_density_kg_m3
        p[LAYOUT.index("MU_MIX")] = mixture_viscosity_for(bearing, oil_air_density_kg_m3)
    return p


def mixture_viscosity_for(bearing: Bearing, rho_mix: float) -> float:
    """Viscosity (Pa s) of an oil-air mixture of density ``rho_mix``: the oil's volume fraction from the density,
    then the volume-weighted mean (:func:`cageless.simulation.physics.drag.mixture_viscosity`); air when dry."""
    from cageless.simulation.physics import drag

    lub = bearing.lubricant
    if lub is None:
        return drag.AIR_VISCOSITY_PA_S
    x = (rho_mix - drag.AIR_DENSITY_KG_M3) / (lub.density_kg_m3 - drag.AIR_DENSITY_KG_M3)
    return drag.mixture_viscosity(lub.dynamic_viscosity_pa_s, min(max(x, 0.0), 1.0))


def planar_problem(bearing: Bearing, theta0: npt.ArrayLike, radius0: npt.ArrayLike, ring0: tuple[float, float],
                   radial_load_n: float, restitution: float | None = None, gravity_m_s2: float = 9.81,
                   inner_speed_rad_s: float = 0.0, effects: dict[str, bool] | None = None,
                   atol_scale: float = 1.0, cho_n_s_m: float | None = None,
                   theta_dot0: npt.ArrayLike | None = None, event_capacity: int = 10_000,
                   parameters: ModelParameters | None = None, speed_ramp_s: float = 0.0,
                   oil_air_density_kg_m3: float | None = None, spin0: npt.ArrayLike | None = None) -> Problem:
    """The planar model from a given state, as a :class:`~cageless.simulation.solve.Problem`.

    ``effects`` (name -> on, names of :data:`cageless.simulation.effects.EFFECTS`) says which effects are on; an
    effect it does not name is off (:func:`cageless.simulation.effects.choose_model` gives a scene's choice). ``parameters`` holds
    the open model parameters; ``restitution`` and ``cho_n_s_m``, when given, replace theirs.
    The absolute tolerances (0.1 nm on positions, 0.1 um/s on speeds) are multiplied by ``atol_scale``;
    contact overlaps are micrometres, so energy-level checks want a smaller scale.
    """
    par = parameters or ModelParameters()
    over = {k: v for k, v in (("restitution", restitution), ("cho_n_s_m", cho_n_s_m)) if v is not None}
    par = par.with_overrides(over) if over else par
    g = bearing.geometry
    lay = PlanarLayout(g.n_balls)
    sl = lay.slices()
    y0 = np.zeros(lay.size)
    y0[sl["theta"]] = theta0
    y0[sl["r"]] = radius0
    y0[5 * g.n_balls:5 * g.n_balls + 2] = ring0
    if theta_dot0 is not None:
        y0[sl["theta_dot"]] = theta_dot0
    if spin0 is not None:
        y0[sl["spin"]] = spin0
    atol = np.empty(lay.size)
    atol[sl["r"]] = 1e-10
    atol[sl["theta"]] = 1e-10 / (0.5 * g.pitch_diameter_m)
    atol[sl["r_dot"]] = 1e-7
    atol[sl["theta_dot"]] = 1e-7 / (0.5 * g.pitch_diameter_m)
    atol[sl["spin"]] = 1e-7 / (0.5 * g.ball_diameter_m)
    atol[sl["ring"]] = [1e-10, 1e-10, 1e-7, 1e-7]
    atol[sl["input_work"]] = 1e-9
    atol[sl["dissipated"]] = 1e-9
    atol *= atol_scale
    p = _params(bearing, radial_load_n, gravity_m_s2, inner_speed_rad_s, effects or {}, par, speed_ramp_s,
                oil_air_density_kg_m3)
    log = empty_log(g.n_balls, event_capacity)
    # An impact at 1 m/s approach lasts t_H; contact onsets are resolved to t_H / ONSET_RESOLUTION.
    onset = hertz_impact_duration(1.0, 0.5 * p[P_M], p[P_KB]) / ONSET_RESOLUTION
    on = frozenset(name for name, value in (effects or {}).items() if value)
    return Problem(model_id=MODEL_ID, params=p, log=log, y0=y0, t0=0.0, atol=atol, name="planar cageless bearing",
                   onset_step=onset, jump_floor=planar_jump_floor(p, lay), layout=LAYOUT, effects=on,
                   n_balls=g.n_balls, n_gaps=3 * g.n_balls)


def planar_jump_floor(p: npt.NDArray[np.float64], lay: PlanarLayout) -> npt.NDArray[np.float64]:
    """The accelerations a 1 N force (or a 1 N force at the ball's surface) gives each body: the floor of
    the force-jump test on every velocity state, zero on the rest (see :class:`~cageless.simulation.problem.Problem`)."""
    sl = lay.slices()
    z = lay.n_balls
    floor = np.zeros(lay.size)
    floor[sl["r_dot"]] = 1.0 / p[P_M]
    floor[sl["theta_dot"]] = 1.0 / (p[P_M] * 0.25 * (p[P_DI] + p[P_DO]))
    floor[sl["spin"]] = 0.5 * p[P_D] / p[P_I]
    floor[5 * z + 2:5 * z + 4] = 1.0 / p[P_MR]
    return floor


def packed_start(bearing: Bearing, seed: int = 0, spread: float = 0.05) -> npt.NDArray[np.float64]:
    """Ball angles packed around the loaded zone (270 deg) with the one free gap at the top.

    Adjacent balls start ``spread`` of the free space apart (seeded), so nothing overlaps.
    """
    g = bearing.geometry
    z = g.n_balls
    phi = 2 * math.asin(g.ball_diameter_m / g.pitch_diameter_m)
    free = 2 * math.pi - z * phi
    extra = np.random.default_rng(seed).dirichlet(np.ones(z - 1)) * free * spread
    gaps = phi + extra
    span = gaps.sum()
    return 1.5 * math.pi - 0.5 * span + np.concatenate([[0.0], np.cumsum(gaps)])

