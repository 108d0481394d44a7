"""The spatial cageless-bearing model: axial positions, full spin vectors, contact angles.

States (n = 9 Z + 12). The first 5 Z + 6 are laid out exactly as in the planar
model (r, theta, their rates, spin about the shaft axis x, the ring centre
(y, z) and its velocity, input work, dissipated energy), so everything that
reads a planar state reads the planar part of a spatial one. Then, per ball,
the axial position x and its rate and the spin components about y and z; then
the ring's axial position and rate; last the ring's tilt (beta_y, beta_z) about
the prescribed misalignment and its rates.

Contacts follow the groove-curvature-centre geometry: the inner (outer) groove
centre lies on a circle of radius rho_i = d_i/2 + f_i D (rho_o = d_o/2 - f_o D)
in the ring's mid-plane; a ball touches when its centre is farther than
(f - 1/2) D from the groove centre, along the normal through both, so contact
angles come out of the positions. The inner ring translates in x, y and z under
the radial and axial loads and gravity, and tilts about y and z under the
moments of the inner contacts and a moment load, as the paper's
I_r theta_ry'' = sum M_y, I_r theta_rz'' = sum M_z (§3.1; Lagrange's form with the
kinetic energy I_r (beta_y'^2 + beta_z'^2) / 2, no gyroscopic term for the ring,
as in the paper); a prescribed misalignment is the tilt it starts from and
swings about. The ring's tilting moves its raceway, so the contact velocities
include it. Race traction is integrated over ``m`` strips across
the major axis of the contact ellipse, each carrying its share of the Hertz load
(proportional to 1 - xi^2), so spin about the contact normal and differential
slip produce forces and moments; ``m = 1`` is a point contact. Ball-ball contact
acts along the 3-D line of centres with friction from the full relative surface
velocity.

A homogeneous sphere's spin obeys I d(omega)/dt = M in the inertial frame, with
no gyroscopic term: the gyroscopic moments of the paper appear only when the
spin is written in the rotating azimuthal frame. Under pure radial load the
model reduces exactly to the planar one (the equivalence test checks it).
"""

from __future__ import annotations

import math

import numba
import numpy as np
import numpy.typing as npt

from cageless.bearing import Bearing
from cageless.simulation.forces import FASTMATH, SQUEEZE_CUTOFF, SQUEEZE_TAPER, hertz_damped, squeeze_film
from cageless.simulation.hertz import compliance, hertz_contact, race_curvatures
from cageless.simulation.models import base as B
from cageless.simulation.models import planar as P
from cageless.simulation.models.contact_laws import RACE_LAWS, ball_churning, ball_drag, race_extra, tangential
from cageless.simulation.models.regime import race_regime, strip_tangential
from cageless.simulation.models.rolling import spatial_rolling
from cageless.simulation.models.spatial_layout import (LAYOUT, N_PARAMS, P_AI, P_AO, P_FA, P_GAX, P_IR, P_MY, P_RGI,
                                                        P_RGO, P_STRIPS, P_TILT_Y, P_TILT_Z, SpatialLayout, _cross,
                                                        _groove, _tilt, spatial_gaps, spatial_signature)
from cageless.simulation.problem import Problem

__all__ = ["MODEL_ID", "LAYOUT", "N_PARAMS", "SpatialLayout", "spatial_problem", "spatial_rhs", "spatial_signature",
           "spatial_observe", "spatial_ring_share", "spatial_ring_rows", "spatial_gaps", "ring_tilt_inertia"]

MODEL_ID = 4


@numba.njit(cache=True, fastmath=FASTMATH)
def _race(y, p, j, z, inner, w_i, rot, c, s, wt, obs):  # pragma: no cover - compiled
    """One race contact of ball j, as ((force on the ball), (torque on the ball), input power, dissipated power,
    overlap, (moment on the inner ring about its centre)), each bracket 3 components in the fixed frame.
    ``wt`` is the ring's tilting angular velocity (3). With ``obs`` (an array, None in the right-hand side) the
    contact's observables are written there too (:func:`spatial_observe`)."""
    half = 0.5 * p[B.P_D]
    if not inner:
        rot = (1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0)
    rq, cq, sq, ex, er, ln, delta, rho, rg = _groove(y, p, j, z, inner, rot, c, s)
    zero = (0.0, 0.0, 0.0)
    if delta <= 0.0:
        return zero, zero, 0.0, 0.0, 0.0, zero
    b = 5 * z + 6
    ox, oy, oz = y[4 * z + j], y[b + 2 * z + j], y[b + 3 * z + j]
    n, t, xr, rv, r_c, k_n, a_c = _race_frame(y, p, j, z, inner, rot, c, s, wt, rq, cq, sq, ex, er, ln, rho, rg)
    nx, ny, nz = n
    xrx, xry, xrz = xr
    q = k_n * delta * math.sqrt(delta)
    side = 1 if inner else 0
    if obs is not None:
        obs[B.OBS_OUTER_NORMAL + side] = q
    q, p_diss = _race_normal(p, q, delta, rv, n)
    fx, fy, fz = -q * nx, -q * ny, -q * nz
    mx = my = mz = 0.0
    t2x = t2y = t2z = 0.0
    p_in = 0.0
    if p[B.P_F_TRAC] > 0.5 and q > 0.0:
        (gsx, gsy, gsz), (t2x, t2y, t2z), (mx, my, mz), p_in, p_diss, _, _ = _race_traction(
            p, inner, q, w_i, rot, wt, (ox, oy, oz), n, t, xr, rv, a_c, r_c, rq, half, p_diss)
        fx, fy, fz = fx + gsx, fy + gsy, fz + gsz
    if obs is not None and p[B.P_F_TRAC] > 0.5:  # the law on the elastic normal force, along t as the planar one's
        g_el, _, _, _, _, u_r, u_s = _race_traction(p, inner, obs[B.OBS_OUTER_NORMAL + side], w_i, rot, wt, (ox, oy, oz), n,
                                               t, xr, rv, a_c, r_c, rq, half, 0.0)
        obs[B.OBS_OUTER_TRACTION + side] = g_el[0] * t[0] + g_el[1] * t[1] + g_el[2] * t[2]
        obs[B.OBS_OUTER_ENTRAIN + side] = u_r
        obs[B.OBS_OUTER_SLIDE + side] = u_s
    rmx = rmy = rmz = 0.0
    if inner:  # reaction on the ring: -F at the contact point, and -t2
        rmx, rmy, rmz = _cross(xrx, xry, xrz, -fx, -fy, -fz)
        rmx, rmy, rmz = rmx - t2x, rmy - t2y, rmz - t2z
    if p[B.P_F_ROLL] > 0.5 and q > 0.0:  # rolling losses (models/rolling.py); the ring takes its own reaction
        w = (w_i * rot[0], w_i * rot[3], w_i * rot[6]) if inner else (0.0, 0.0, 0.0)
        gx, gy, gz, hx, hy, hz, pin, pd, qx, qy, qz = spatial_rolling(
            p, inner, q, rv, n, t, (ox, oy, oz), w, (xrx, xry, xrz),
            (rot[0], rot[3], rot[6]), wt if inner else (0.0, 0.0, 0.0), r_c, rq)
        fx, fy, fz, mx, my, mz = fx + gx, fy + gy, fz + gz, mx + hx, my + hy, mz + hz
        p_in, p_diss = p_in + pin, p_diss + pd
        if inner:
            rmx, rmy, rmz = rmx + qx, rmy + qy, rmz + qz
    return (fx, fy, fz), (mx, my, mz), p_in, p_diss, delta, (rmx, rmy, rmz)


@numba.njit(cache=True, fastmath=FASTMATH, inline="always")
def _race_frame(y, p, j, z, inner, rot, c, s, wt, rq, cq, sq, ex, er, ln, rho, rg):  # pragma: no cover - compiled
    """The contact frame of ball j at one race (fixed frame): the normal n and rolling direction t, the race
    surface point xr along the normal (from the ring centre) and its radius r_c, the ball centre's velocity
    relative to the race surface's motion rv, and the race's Hertz stiffness and ellipse coefficient."""
    b = 5 * z + 6
    r, rd, thd = y[j], y[2 * z + j], y[3 * z + j]
    vx, vy, vz = y[b + z + j], rd * c - r * thd * s, rd * s + r * thd * c
    if inner:
        vcx, vcy, vcz = y[b + 4 * z + 1], y[5 * z + 2], y[5 * z + 3]
        k_n, a_c = p[B.P_KI], p[P_AI]
    else:
        vcx = vcy = vcz = 0.0
        k_n, a_c = p[B.P_KO], p[P_AO]
    nrx, nrr = ex / ln, er / ln
    # normal, radial and azimuthal directions in the fixed frame
    nx0, ny0, nz0 = nrx, nrr * cq, nrr * sq
    nx = rot[0] * nx0 + rot[1] * ny0 + rot[2] * nz0
    ny = rot[3] * nx0 + rot[4] * ny0 + rot[5] * nz0
    nz = rot[6] * nx0 + rot[7] * ny0 + rot[8] * nz0
    tx = rot[1] * -sq + rot[2] * cq
    ty = rot[4] * -sq + rot[5] * cq
    tz = rot[7] * -sq + rot[8] * cq
    # race surface point along the normal (relative to the ring centre, fixed frame) and its radius
    r_c = rho + rg * nrr
    xrx = (rot[0] * rg * nrx + rot[1] * r_c * cq + rot[2] * r_c * sq)
    xry = (rot[3] * rg * nrx + rot[4] * r_c * cq + rot[5] * r_c * sq)
    xrz = (rot[6] * rg * nrx + rot[7] * r_c * cq + rot[8] * r_c * sq)
    if inner:  # the ring's surface moves with its centre and its tilting
        ttx, tty, ttz = _cross(wt[0], wt[1], wt[2], xrx, xry, xrz)
        vcx, vcy, vcz = vcx + ttx, vcy + tty, vcz + ttz
    rv = (vx - vcx, vy - vcy, vz - vcz)
    return (nx, ny, nz), (tx, ty, tz), (xrx, xry, xrz), rv, r_c, k_n, a_c


@numba.njit(cache=True, fastmath=FASTMATH, inline="always")
def _race_normal(p, q, delta, rv, n):  # pragma: no cover - compiled
    """The normal force of a race contact of overlap ``delta`` and Hertz force ``q``, with the lubricant damping
    and the registered extra laws, and the power it dissipates."""
    rvx, rvy, rvz = rv
    nx, ny, nz = n
    p_diss = 0.0
    if p[B.P_F_LUB] > 0.5:
        ddot = rvx * nx + rvy * ny + rvz * nz
        q_d = max(q + p[B.P_CHO] * ddot, 0.0)
        p_diss += (q_d - q) * ddot
        q = q_d
    if RACE_LAWS:
        ddot = rvx * nx + rvy * ny + rvz * nz
        f_x = race_extra(delta, ddot, q, p)
        p_diss += f_x * ddot
        q += f_x
    return q, p_diss


@numba.njit(cache=True, fastmath=FASTMATH, inline="always")
def _race_traction(p, inner, q, w_i, rot, wt, o, n, t, xr, rv, a_c, r_c, rq, half, p_diss):  # pragma: no cover
    """Race traction integrated over the strips of the contact ellipse: the force on the ball (3), the moment
    of its spread along the major axis (3), the whole moment on the ball (3), the drive's input power, and the
    dissipated power with the traction's share added; the entrainment speed u_r, and the sliding speed of the
    ball's surface against the race at the contact centre along t (for the observables)."""
    ox, oy, oz = o
    nx, ny, nz = n
    tx, ty, tz = t
    xrx, xry, xrz = xr
    rvx, rvy, rvz = rv
    # the ring's spin vector (the drive), and its whole angular velocity
    wx, wy, wz = (w_i * rot[0], w_i * rot[3], w_i * rot[6]) if inner else (0.0, 0.0, 0.0)
    awx, awy, awz = (wx + wt[0], wy + wt[1], wz + wt[2]) if inner else (0.0, 0.0, 0.0)
    # major axis of the ellipse: across the rolling direction, in the contact plane
    ax_, ay_, az_ = _cross(nx, ny, nz, tx, ty, tz)
    a = a_c * np.cbrt(q)
    bsx, bsy, bsz = _cross(ox, oy, oz, half * nx, half * ny, half * nz)
    rsx, rsy, rsz = _cross(wx, wy, wz, xrx, xry, xrz)
    vt = rvx * tx + rvy * ty + rvz * tz
    u_r = 0.5 * abs(vt * (1.0 - 2.0 * r_c / rq) + bsx * tx + bsy * ty + bsz * tz + rsx * tx + rsy * ty + rsz * tz)
    # relative spin across the strips: slip grows linearly with the strip's offset xi along the major axis
    wax, way, waz = _cross(ox - awx, oy - awy, oz - awz, ax_, ay_, az_)
    u0x, u0y, u0z = rvx + bsx - rsx, rvy + bsy - rsy, rvz + bsz - rsz
    # A strip at offset xi slides at u0 + xi wa, projected on the contact plane. The projection is linear, so
    # u0 and wa are projected once, |u|^2 is a quadratic in xi, and the strip forces -f_k u_k sum through
    # the moments S_j = sum f_k xi_k^j (f_k: traction per unit sliding speed of strip k).
    un = u0x * nx + u0y * ny + u0z * nz
    u0x, u0y, u0z = u0x - un * nx, u0y - un * ny, u0z - un * nz
    wn = wax * nx + way * ny + waz * nz
    wax, way, waz = wax - wn * nx, way - wn * ny, waz - wn * nz
    c0 = u0x * u0x + u0y * u0y + u0z * u0z
    c1 = 2.0 * (u0x * wax + u0y * way + u0z * waz)
    c2 = wax * wax + way * way + waz * waz
    s0, s1, s2, p_diss = _strip_sums(p, q, a, u_r, inner, c0, c1, c2, p_diss)
    # traction on the ball, and its first moment along the major axis (sum of xi g)
    gsx, gsy, gsz = -(s0 * u0x + s1 * wax), -(s0 * u0y + s1 * way), -(s0 * u0z + s1 * waz)
    hx, hy, hz = -(s1 * u0x + s2 * wax), -(s1 * u0y + s2 * way), -(s1 * u0z + s2 * waz)
    t1x, t1y, t1z = _cross(half * nx, half * ny, half * nz, gsx, gsy, gsz)
    t2x, t2y, t2z = _cross(ax_, ay_, az_, hx, hy, hz)
    p_in = 0.0
    if inner:
        # drive power: the ring's spin times the moment of the ball's traction on it
        c1x, c1y, c1z = _cross(xrx, xry, xrz, gsx, gsy, gsz)
        p_in = (c1x + t2x) * wx + (c1y + t2y) * wy + (c1z + t2z) * wz
    u_s = u0x * tx + u0y * ty + u0z * tz
    return (gsx, gsy, gsz), (t2x, t2y, t2z), (t1x + t2x, t1y + t2y, t1z + t2z), p_in, p_diss, u_r, u_s


@numba.njit(cache=True, fastmath=FASTMATH, inline="always")
def _strip_sums(p, q, a, u_r, inner, c0, c1, c2, p_diss):  # pragma: no cover - compiled
    """The moments S_0, S_1, S_2 of the strips' traction per unit sliding speed over their offsets, where a strip
    at offset xi slides at sqrt(c0 + c1 xi + c2 xi^2); the dissipated power with the strips' share added."""
    s0 = s1 = s2 = 0.0
    m = int(p[P_STRIPS])
    rw, ul = race_regime(u_r, q, inner, p)  # the film regime, once per contact (models/regime.py)
    for k in range(m):
        xi0, xi1 = -1.0 + 2.0 * k / m, -1.0 + 2.0 * (k + 1) / m
        w = 0.75 * ((xi1 - xi1**3 / 3.0) - (xi0 - xi0**3 / 3.0))  # share of the Hertz load on the strip
        xi = 0.5 * (xi0 + xi1) * a
        us2 = c0 + xi * (c1 + xi * c2)
        if us2 <= 0.0:
            continue
        us = math.sqrt(us2)
        f = strip_tangential(us, u_r, w * q, rw, ul, p) / us
        s0 += f
        s1 += f * xi
        s2 += f * xi * xi
        p_diss += f * us2
    return s0, s1, s2, p_diss


@numba.njit(cache=True, fastmath=FASTMATH)
def _pair(y, p, log, j, k, z, cj, sj, ck, sk, obs):  # pragma: no cover - compiled
    """Ball j against ball k along the 3-D line of centres: force on k (3), moment on both (3), dissipated power;
    with ``obs`` (None in the right-hand side) the pair's observables are written there too."""
    d = p[B.P_D]
    half = 0.5 * d
    b = 5 * z + 6
    dx = y[b + k] - y[b + j]
    dy = y[k] * ck - y[j] * cj
    dz = y[k] * sk - y[j] * sj
    ln = math.sqrt(dx * dx + dy * dy + dz * dz)
    delta = d - ln
    zero = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    film = p[B.P_F_BBFILM] > 0.5 and -delta < (SQUEEZE_CUTOFF + SQUEEZE_TAPER) * p[B.P_H0]
    if delta <= 0.0 and not film:
        return zero
    nx, ny, nz = dx / ln, dy / ln, dz / ln
    vjx = y[b + z + j]
    vjy = y[2 * z + j] * cj - y[j] * y[3 * z + j] * sj
    vjz = y[2 * z + j] * sj + y[j] * y[3 * z + j] * cj
    vkx = y[b + z + k]
    vky = y[2 * z + k] * ck - y[k] * y[3 * z + k] * sk
    vkz = y[2 * z + k] * sk + y[k] * y[3 * z + k] * ck
    ddot = -((vkx - vjx) * nx + (vky - vjy) * ny + (vkz - vjz) * nz)
    if delta <= 0.0:
        f = squeeze_film(-delta, ddot, p[B.P_ETA0], 0.25 * d, p[B.P_H0])
        return f * nx, f * ny, f * nz, 0.0, 0.0, 0.0, f * ddot
    v_in = max(log[j] if log[j] > 0.0 else ddot, p[B.P_V_IN_MIN])
    f = hertz_damped(delta, ddot, v_in, p[B.P_KB], p[B.P_CHI])
    elastic = p[B.P_KB] * delta * math.sqrt(delta)
    # the squeeze film fading out over the first overlap (squeeze_film), on the normal force, not on friction's load
    f_film = squeeze_film(-delta, ddot, p[B.P_ETA0], 0.25 * d, p[B.P_H0]) if p[B.P_F_BBFILM] > 0.5 else 0.0
    p_diss = (f - elastic + f_film) * ddot
    if obs is not None:
        obs[B.OBS_BB_NORMAL] = elastic
    fx, fy, fz = (f + f_film) * nx, (f + f_film) * ny, (f + f_film) * nz
    mx = my = mz = 0.0
    if p[B.P_F_BBFRIC] > 0.5:
        ojx, ojy, ojz = y[4 * z + j], y[b + 2 * z + j], y[b + 3 * z + j]
        okx, oky, okz = y[4 * z + k], y[b + 2 * z + k], y[b + 3 * z + k]
        sx, sy, sz = _cross(ojx + okx, ojy + oky, ojz + okz, half * nx, half * ny, half * nz)
        ux, uy, uz = vjx - vkx + sx, vjy - vky + sy, vjz - vkz + sz  # surface of j against k
        un = ux * nx + uy * ny + uz * nz
        ux, uy, uz = ux - un * nx, uy - un * ny, uz - un * nz
        us = math.sqrt(ux * ux + uy * uy + uz * uz)
        if us > 0.0:
            rx, ry, rz = _cross(ojx - okx, ojy - oky, ojz - okz, nx, ny, nz)
            u_r = 0.25 * d * math.sqrt(rx * rx + ry * ry + rz * rz)
            g = tangential(us, u_r, f, p) / us  # friction on j is -g u
            if obs is not None:  # the law on the elastic normal force
                obs[B.OBS_BB_TRACTION] = abs(tangential(us, u_r, elastic, p))
            p_diss += g * us * us
            fx, fy, fz = fx + g * ux, fy + g * uy, fz + g * uz  # on k: +g u
            mx, my, mz = _cross(half * nx, half * ny, half * nz, -g * ux, -g * uy, -g * uz)
    return fx, fy, fz, mx, my, mz, p_diss


@numba.njit(cache=True, fastmath=FASTMATH)
def _churn(y, p, j, z, dydt):  # pragma: no cover - compiled
    """The churning moment against ball j's spin vector, added to its moment slots of ``dydt`` when given;
    returns its power (<= 0)."""
    b = 5 * z + 6
    ox, oy, oz = y[4 * z + j], y[b + 2 * z + j], y[b + 3 * z + j]
    w = math.sqrt(ox * ox + oy * oy + oz * oz)
    if w == 0.0:
        return 0.0
    k = ball_churning(w, p) / w
    if dydt is not None:
        dydt[4 * z + j] += k * ox
        dydt[b + 2 * z + j] += k * oy
        dydt[b + 3 * z + j] += k * oz
    return k * w * w


@numba.njit(cache=True, fastmath=FASTMATH)
def spatial_rhs(t, y, p, log, dydt):  # pragma: no cover - compiled
    z = int(p[B.P_Z])
    b = 5 * z + 6
    m_ring = p[B.P_MR]
    grav = p[B.P_G] if p[B.P_F_GRAV] > 0.5 else 0.0
    g_ax = p[P_GAX] if p[B.P_F_GRAV] > 0.5 else 0.0  # along the shaft (vertical shaft)
    ramp = p[B.P_RAMP]
    w_i = p[B.P_WI] * (min(t / ramp, 1.0) if ramp > 0.0 else 1.0)
    rot = _tilt(y, p)
    tb = y.shape[0] - 4  # tilt states: beta_y, beta_z, their rates
    s_bz, c_bz = math.sin(p[P_TILT_Z] + y[tb + 1]), math.cos(p[P_TILT_Z] + y[tb + 1])
    wt = (-s_bz * y[tb + 2], c_bz * y[tb + 2], y[tb + 3])  # angular velocity of the tilting: bz' z + by' Rz y
    rmx = rmy = rmz = 0.0
    trig = log.shape[0] - 2 * z  # scratch: cos and sin of every ball's angle, once per call
    _start(y, p, log, dydt, z, trig, grav, g_ax)
    rfx, rfy, rfz = p[P_FA] - m_ring * g_ax, 0.0, -p[B.P_FR] - m_ring * grav
    power_in = power = 0.0
    if p[B.P_F_RACE] > 0.5:
        for j in range(z):
            for inner in (False, True):
                f, mo, pin, pd, _, qm = _race(y, p, j, z, inner, w_i, rot, log[trig + j], log[trig + z + j], wt, None)
                for o, v in ((b + z, f[0]), (2 * z, f[1]), (3 * z, f[2]), (4 * z, mo[0]), (b + 2 * z, mo[1]),
                             (b + 3 * z, mo[2])):
                    dydt[o + j] += v
                if inner:
                    rfx, rfy, rfz = rfx - f[0], rfy - f[1], rfz - f[2]
                    rmx, rmy, rmz = rmx + qm[0], rmy + qm[1], rmz + qm[2]
                power_in += pin
                power += pd
    if p[B.P_F_BB] > 0.5:
        for j in range(z):
            k = j + 1 if j + 1 < z else 0
            fx, fy, fz, mx, my, mz, pd = _pair(y, p, log, j, k, z, log[trig + j], log[trig + z + j], log[trig + k],
                                               log[trig + z + k], None)
            for o, v in ((b + z, fx), (2 * z, fy), (3 * z, fz)):
                dydt[o + j] -= v
                dydt[o + k] += v
            for o, mo in ((4 * z, mx), (b + 2 * z, my), (b + 3 * z, mz)):
                dydt[o + j] += mo
                dydt[o + k] += mo
            power += pd
    power = _ball_accelerations(y, p, log, dydt, z, trig, power)
    dydt[5 * z], dydt[5 * z + 1] = y[5 * z + 2], y[5 * z + 3]
    dydt[5 * z + 2], dydt[5 * z + 3] = rfy / m_ring, rfz / m_ring
    dydt[5 * z + 4], dydt[5 * z + 5] = power_in, power
    dydt[b + 4 * z], dydt[b + 4 * z + 1] = y[b + 4 * z + 1], rfx / m_ring
    # tilt (Lagrange, kinetic energy I_r (by'^2 + bz'^2) / 2): generalised moments M . d(omega)/d(beta'),
    # the moment load acting on beta_y (the paper's I_r theta_ry'' = sum M_y, I_r theta_rz'' = sum M_z)
    dydt[tb], dydt[tb + 1] = y[tb + 2], y[tb + 3]
    dydt[tb + 2] = (-s_bz * rmx + c_bz * rmy + p[P_MY]) / p[P_IR]
    dydt[tb + 3] = rmz / p[P_IR]


@numba.njit(cache=True, fastmath=FASTMATH, inline="always")
def _start(y, p, log, dydt, z, trig, grav, g_ax):  # pragma: no cover - compiled
    """Zero ``dydt``, fill the trig scratch, and start the force accumulators (x in the axial slot, y and z in
    the planar acceleration slots; moments in the spin slots) with the balls' weight (``grav`` across the
    shaft, ``g_ax`` along it: both 0 when the gravity effect is off)."""
    b = 5 * z + 6
    m = p[B.P_M]
    for i in range(dydt.shape[0]):
        dydt[i] = 0.0
    for j in range(z):
        log[trig + j] = math.cos(y[z + j])
        log[trig + z + j] = math.sin(y[z + j])
    for j in range(z):
        dydt[3 * z + j] = -m * grav
        dydt[b + z + j] = -m * g_ax


@numba.njit(cache=True, fastmath=FASTMATH, inline="always")
def _ball_accelerations(y, p, log, dydt, z, trig, power):  # pragma: no cover - compiled
    """The accumulated forces and moments (with the drag and churning) to the balls' accelerations and spin
    rates, and their position rates; the dissipated power, updated."""
    b = 5 * z + 6
    m, inertia = p[B.P_M], p[B.P_I]
    drag = p[B.P_F_DRAG] > 0.5
    for j in range(z):
        r, rd, thd = y[j], y[2 * z + j], y[3 * z + j]
        c, s = log[trig + j], log[trig + z + j]
        fy, fz = dydt[2 * z + j], dydt[3 * z + j]
        f_rad, f_tan = fy * c + fz * s, -fy * s + fz * c
        if drag:
            f_d = ball_drag(r * thd, p)
            f_tan += f_d
            power -= f_d * r * thd + _churn(y, p, j, z, dydt)
        dydt[j], dydt[z + j] = rd, thd
        dydt[2 * z + j] = f_rad / m + r * thd * thd
        dydt[3 * z + j] = (f_tan / m - 2.0 * rd * thd) / r
        dydt[b + j] = y[b + z + j]
        dydt[b + z + j] /= m
        for o in (4 * z, b + 2 * z, b + 3 * z):
            dydt[o + j] /= inertia
    return power


@numba.njit(cache=True)
def spatial_ring_share(t, y, p, log, j, out):  # pragma: no cover - compiled
    """Ball j's share of the rows every ball reaches (see :mod:`cageless.simulation.jacobian`), in the order of
    :func:`spatial_ring_rows`: the ring's y'', z'', x'' and tilt accelerations from its inner-race contact,
    its race input power, and the dissipation that depends on its state (both race contacts, its drag
    and the two ball-ball contacts it takes part in)."""
    z = int(p[B.P_Z])
    for i in range(7):
        out[i] = 0.0
    th = y[z + j]
    c, s = math.cos(th), math.sin(th)
    if p[B.P_F_RACE] > 0.5:
        ramp = p[B.P_RAMP]
        w_i = p[B.P_WI] * (min(t / ramp, 1.0) if ramp > 0.0 else 1.0)
        tb = y.shape[0] - 4
        s_bz, c_bz = math.sin(p[P_TILT_Z] + y[tb + 1]), math.cos(p[P_TILT_Z] + y[tb + 1])
        wt = (-s_bz * y[tb + 2], c_bz * y[tb + 2], y[tb + 3])
        rot = _tilt(y, p)
        (fx, fy, fz), _, pin, pd, _, (qx, qy, qz) = _race(y, p, j, z, True, w_i, rot, c, s, wt, None)
        m_ring = p[B.P_MR]
        out[0], out[1], out[2] = -fy / m_ring, -fz / m_ring, -fx / m_ring
        out[3], out[4] = (-s_bz * qx + c_bz * qy) / p[P_IR], qz / p[P_IR]
        out[5], out[6] = pin, pd
        pin_o, pd_o = _race(y, p, j, z, False, w_i, rot, c, s, wt, None)[2:4]
        out[5] += pin_o
        out[6] += pd_o
    if p[B.P_F_BB] > 0.5:
        for a, b in ((j - 1 if j > 0 else z - 1, j), (j, j + 1 if j + 1 < z else 0)):
            ca, sa, cb, sb = math.cos(y[z + a]), math.sin(y[z + a]), math.cos(y[z + b]), math.sin(y[z + b])
            out[6] += _pair(y, p, log, a, b, z, ca, sa, cb, sb, None)[6]
    if p[B.P_F_DRAG] > 0.5:
        v = y[j] * y[3 * z + j]
        out[6] -= ball_drag(v, p) * v + _churn(y, p, j, z, None)


@numba.njit(cache=True, inline="always")
def spatial_observe(t, y, p, log, out):  # pragma: no cover - compiled
    """The observables of state ``y`` at time t from the right-hand side's own force functions, as
    :func:`cageless.simulation.models.planar.planar_observe` writes them (traction: its component along the
    rolling direction)."""
    z = int(p[B.P_Z])
    out[:, :] = 0.0
    ramp = p[B.P_RAMP]
    w_i = p[B.P_WI] * (min(t / ramp, 1.0) if ramp > 0.0 else 1.0)
    rot = _tilt(y, p)
    tb = y.shape[0] - 4
    s_bz, c_bz = math.sin(p[P_TILT_Z] + y[tb + 1]), math.cos(p[P_TILT_Z] + y[tb + 1])
    wt = (-s_bz * y[tb + 2], c_bz * y[tb + 2], y[tb + 3])
    for j in range(z):
        k = j + 1 if j + 1 < z else 0
        c, s = math.cos(y[z + j]), math.sin(y[z + j])
        if p[B.P_F_RACE] > 0.5:
            for inner in (False, True):
                _race(y, p, j, z, inner, w_i, rot, c, s, wt, out[:, j])
        if p[B.P_F_BB] > 0.5:
            _pair(y, p, log, j, k, z, c, s, math.cos(y[z + k]), math.sin(y[z + k]), out[:, j])


def spatial_ring_rows(n_balls: int) -> list[int]:
    """State indices of the rows :func:`spatial_ring_share` fills: ring y'', z'', x'', beta_y'', beta_z'',
    the input work and the dissipated energy."""
    b = 5 * n_balls + 6
    return [5 * n_balls + 2, 5 * n_balls + 3, b + 4 * n_balls + 1, b + 4 * n_balls + 4, b + 4 * n_balls + 5,
            5 * n_balls + 4, 5 * n_balls + 5]


def spatial_state_blocks(n_balls: int, n_states: int) -> tuple[list[list[int]], list[int], list[int], list[int]]:
    """The state layout as the Jacobian's structure needs it: each per-ball field's indices (the planar five,
    then axial position and rate and the two transverse spins), the rows :func:`spatial_ring_share` fills, the
    ring's own states and the two energy counters."""
    z, b = n_balls, 5 * n_balls + 6
    fields = [list(range(f * z, (f + 1) * z)) for f in range(5)]
    fields += [list(range(b + f * z, b + (f + 1) * z)) for f in range(4)]
    return (fields, spatial_ring_rows(z), list(range(5 * z, 5 * z + 4)) + list(range(b + 4 * z, n_states)),
            [5 * z + 4, 5 * z + 5])


def spatial_problem(bearing: Bearing, theta0: npt.ArrayLike, radius0: npt.ArrayLike, ring0: tuple[float, float],
                    radial_load_n: float, axial_load_n: float = 0.0, misalignment_rad: tuple[float, float] = (0.0, 0.0),
                    strips: int = 5, axial0: npt.ArrayLike | None = None, ring_axial0: float = 0.0,
                    moment_load_nm: float = 0.0, ring_tilt_inertia_kg_m2: float | None = None,
                    axial_gravity_m_s2: float = 0.0, **kw: object) -> Problem:
    """The spatial model from a given state; keyword arguments as :func:`~cageless.simulation.models.planar.planar_problem`.

    ``strips`` is the number m of strips across each race contact ellipse (an accuracy knob; 1 is a
    point contact). ``misalignment_rad`` tilts the inner ring about y and z; the ring then tilts further
    under the contact moments and ``moment_load_nm`` (about y), with the diametral moment of inertia
    ``ring_tilt_inertia_kg_m2`` (default :func:`ring_tilt_inertia`). ``axial_gravity_m_s2`` is gravity
    along -x (a vertical shaft); ``gravity_m_s2`` (keyword of the planar problem) acts along -z.
    """
    if not (isinstance(strips, int) and 1 <= strips <= 101):
        raise P.ParameterError("strips", "must be a whole number in 1..101", strips)
    if (kw.get("effects") or {}).get("strip_damping"):  # type: ignore[union-attr]
        raise P.ParameterError("strip_damping", "the paper's strip formulation of C_ho is built into the planar "
                               "model only: switch it off for the spatial model", True)
    flat = P.planar_problem(bearing, theta0, radius0, ring0, radial_load_n, **kw)  # type: ignore[arg-type]
    g = bearing.geometry
    z = g.n_balls
    lay = SpatialLayout(z)
    sl = lay.slices()
    y0 = np.zeros(lay.size)
    y0[: 5 * z + 6] = flat.y0
    if axial0 is not None:
        y0[sl["axial"]] = axial0
    y0[sl["ring_axial"]] = (ring_axial0, 0.0)
    atol = np.empty(lay.size)
    atol[: 5 * z + 6] = flat.atol
    scale = flat.atol[0] / 1e-10
    atol[sl["axial"]] = 1e-10 * scale
    atol[sl["axial_dot"]] = 1e-7 * scale
    atol[sl["spin_y"]] = atol[sl["spin_z"]] = flat.atol[4 * z]
    atol[sl["ring_axial"]] = (1e-10 * scale, 1e-7 * scale)
    p = LAYOUT.zeros()
    p[: len(B.LAYOUT)] = flat.params
    eta = compliance(bearing.material)
    rc = race_curvatures(g)
    p[P_RGI] = g.inner_curvature_factor * g.ball_diameter_m
    p[P_RGO] = g.outer_curvature_factor * g.ball_diameter_m
    p[P_FA], (p[P_TILT_Y], p[P_TILT_Z]), p[P_STRIPS] = axial_load_n, misalignment_rad, strips
    p[P_AI] = hertz_contact(*rc["inner"], eta).a_coeff
    p[P_AO] = hertz_contact(*rc["outer"], eta).a_coeff
    p[P_MY], p[P_GAX] = moment_load_nm, axial_gravity_m_s2
    p[P_IR] = ring_tilt_inertia(bearing) if ring_tilt_inertia_kg_m2 is None else ring_tilt_inertia_kg_m2
    r_i = 0.5 * g.inner_race_diameter_m
    atol[sl["ring_tilt"]] = (1e-10 * scale / r_i, 1e-10 * scale / r_i, 1e-7 * scale / r_i, 1e-7 * scale / r_i)
    floor = np.zeros(lay.size)
    floor[: 5 * z + 6] = P.planar_jump_floor(flat.params, P.PlanarLayout(z))
    floor[sl["axial_dot"]] = floor[sl["r_dot"]]
    floor[sl["spin_y"]] = floor[sl["spin_z"]] = floor[sl["spin"]]
    floor[sl["ring_axial"]] = (0.0, floor[5 * z + 2])
    floor[sl["ring_tilt"]] = (0.0, 0.0, r_i / p[P_IR], r_i / p[P_IR])  # 1 N at the race
    return Problem(model_id=MODEL_ID, params=p, log=flat.log, y0=y0, t0=0.0, atol=atol,
                   name="spatial cageless bearing", onset_step=flat.onset_step, jump_floor=floor, layout=LAYOUT,
                   effects=flat.effects, n_balls=z, n_gaps=flat.n_gaps)


def ring_tilt_inertia(bearing: Bearing) -> float:
    """Diametral moment of inertia (kg m^2) of the inner ring for its tilt: a thin hoop of the ring's mass
    at the inner race radius, m (D_i / 2)^2 / 2 (the paper's I_r, whose value it does not print; its
    tilt equations, §3.1, carry the inner ring alone, not the shaft)."""
    return 0.5 * bearing.masses.inner_ring_mass_kg * (0.5 * bearing.geometry.inner_race_diameter_m) ** 2
