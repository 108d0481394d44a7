"""The race contacts' whole normal force as the implicit part of an IMEX split, per ball, for the spatial
model: :mod:`cageless.simulation.models.implicit_normal` in three dimensions.

Per ball j the implicit rows are the radial and axial kinematics (r' and x' on the rows of r and x) and the
race normal forces over the mass on the rows of r', theta' and x' (each contact's ``max(q + C_ho
d(delta)/dt, 0)`` along its normal, from the model's own groove geometry and contact frame:
:func:`cageless.simulation.models.spatial_layout._groove`, :func:`cageless.simulation.models.spatial._race_frame`).
The angle, the spins and the ring stay at the predictor, so a stage is three nonlinear equations in
(r', theta', x') with ``r = r_Z + h gamma r'`` and ``x = x_Z + h gamma x'``, solved by Newton's method with a
difference-quotient Jacobian. Everything else (traction, spin, rolling losses, drag, ball-ball contacts, the
ring's share of the same normal forces) is f_E = f - f_I.
"""

from __future__ import annotations

import math

import numba

from cageless.simulation.models import base as B
from cageless.simulation.models.implicit_normal import MAX_NEWTON, TOL_V, _solve3
from cageless.simulation.models.spatial import _race_frame
from cageless.simulation.models.spatial_layout import P_TILT_Z, _groove, _tilt

__all__ = ["spatial_implicit_normal", "spatial_filter_error"]

_DV = 1e-6  # the difference quotients' step in velocity (m/s); the forces are linear in it but for the clamp


@numba.njit(cache=True, inline="always")
def _frame(y, p):  # pragma: no cover - compiled
    """The inner ring's rotation and tilting angular velocity, as spatial_rhs computes them."""
    tb = y.shape[0] - 4
    s_bz, c_bz = math.sin(p[P_TILT_Z] + y[tb + 1]), math.cos(p[P_TILT_Z] + y[tb + 1])
    return _tilt(y, p), (-s_bz * y[tb + 2], c_bz * y[tb + 2], y[tb + 3])


@numba.njit(cache=True, inline="always")
def _forces(y, p, j, z, rot, wt, c, s, r, rd, thd, x, xd):  # pragma: no cover - compiled
    """Ball j's race normal forces in (radial, azimuthal, axial) components at the given (r, r', theta', x,
    x'), which are written into ``y`` first."""
    b = 5 * z + 6
    y[j], y[2 * z + j], y[3 * z + j], y[b + j], y[b + z + j] = r, rd, thd, x, xd
    cho = p[B.P_CHO] if p[B.P_F_LUB] > 0.5 else 0.0
    fx = fy = fz = 0.0
    for k in range(2):
        inner = k == 1
        rk = rot if inner else (1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0)
        rq, cq, sq, ex, er, ln, delta, rho, rg = _groove(y, p, j, z, inner, rk, c, s)
        if delta <= 0.0:
            continue
        n, _, _, rv, _, k_n, _ = _race_frame(y, p, j, z, inner, rk, c, s, wt, rq, cq, sq, ex, er, ln, rho, rg)
        q = k_n * delta * math.sqrt(delta) + cho * (rv[0] * n[0] + rv[1] * n[1] + rv[2] * n[2])
        if q > 0.0:
            fx, fy, fz = fx - q * n[0], fy - q * n[1], fz - q * n[2]
    return fy * c + fz * s, -fy * s + fz * c, fx


@numba.njit(cache=True, inline="always")
def _jacobian(y, p, j, z, rot, wt, c, s, r, rd, thd, x, xd, hr, hx, f0):  # pragma: no cover - compiled
    """Difference quotients of (F_rad, F_tan, F_x) along r', r theta', x', with r and x moving by ``hr`` and
    ``hx`` times the velocity's step: 9 numbers, row by row."""
    f1 = _forces(y, p, j, z, rot, wt, c, s, r + hr * _DV, rd + _DV, thd, x, xd)
    f2 = _forces(y, p, j, z, rot, wt, c, s, r, rd, thd + _DV / r, x, xd)
    f3 = _forces(y, p, j, z, rot, wt, c, s, r, rd, thd, x + hx * _DV, xd + _DV)
    return ((f1[0] - f0[0]) / _DV, (f2[0] - f0[0]) / _DV, (f3[0] - f0[0]) / _DV,
            (f1[1] - f0[1]) / _DV, (f2[1] - f0[1]) / _DV, (f3[1] - f0[1]) / _DV,
            (f1[2] - f0[2]) / _DV, (f2[2] - f0[2]) / _DV, (f3[2] - f0[2]) / _DV)


@numba.njit(cache=True, inline="always")
def _ball_stage(y, p, j, z, rot, wt, c, s, hg):  # pragma: no cover - compiled
    """Newton's method on the ball's stage equations (see the module); leaves the solution in ``y``."""
    b = 5 * z + 6
    m = p[B.P_M]
    r_z, x_z = y[j], y[b + j]
    rd_z, thd_z, xd_z = y[2 * z + j], y[3 * z + j], y[b + z + j]
    rd, thd, xd = rd_z, thd_z, xd_z
    for _ in range(MAX_NEWTON):
        r, x = r_z + hg * rd, x_z + hg * xd
        f0 = _forces(y, p, j, z, rot, wt, c, s, r, rd, thd, x, xd)
        g1 = rd - rd_z - hg * f0[0] / m
        g2 = r * (thd - thd_z) - hg * f0[1] / m  # the azimuthal equation times r
        g3 = xd - xd_z - hg * f0[2] / m
        jf = _jacobian(y, p, j, z, rot, wt, c, s, r, rd, thd, x, xd, hg, hg, f0)
        gm = hg / m
        mat = (1.0 - gm * jf[0], -gm * jf[1], -gm * jf[2],
               -gm * jf[3], 1.0 - gm * jf[4], -gm * jf[5],
               -gm * jf[6], -gm * jf[7], 1.0 - gm * jf[8])
        d1, d2, d3 = _solve3(mat, g1, g2, g3)  # along (r', r theta', x')
        rd, thd, xd = rd - d1, thd - d2 / r, xd - d3
        if abs(d1) <= TOL_V and abs(d2) <= TOL_V and abs(d3) <= TOL_V:
            break
    _forces(y, p, j, z, rot, wt, c, s, r_z + hg * rd, rd, thd, x_z + hg * xd, xd)


@numba.njit(cache=True)
def spatial_implicit_normal(y, p, hg, k_i):  # pragma: no cover - compiled
    """The spatial model's implicit part (see the module) into ``k_i``; with ``hg > 0`` the stage equation
    y = y_Z + hg f_I(y) is solved first, in place on ``y``."""
    for i in range(k_i.shape[0]):
        k_i[i] = 0.0
    z = int(p[B.P_Z])
    b = 5 * z + 6
    m = p[B.P_M]
    rot, wt = _frame(y, p)
    race = p[B.P_F_RACE] > 0.5
    for j in range(z):
        c, s = math.cos(y[z + j]), math.sin(y[z + j])
        if hg > 0.0:
            if race:
                _ball_stage(y, p, j, z, rot, wt, c, s, hg)
            else:
                y[j] += hg * y[2 * z + j]
                y[b + j] += hg * y[b + z + j]
        k_i[j] = y[2 * z + j]
        k_i[b + j] = y[b + z + j]
        if race:
            fr, ft, fx = _forces(y, p, j, z, rot, wt, c, s, y[j], y[2 * z + j], y[3 * z + j], y[b + j],
                                 y[b + z + j])
            k_i[2 * z + j] = fr / m
            k_i[3 * z + j] = ft / (m * y[j])
            k_i[b + z + j] = fx / m


@numba.njit(cache=True)
def spatial_filter_error(y, p, hg, e):  # pragma: no cover - compiled
    """Each ball's rows (r, x, r', theta', x') of the error estimate ``e`` replaced by (I - hg J_I)^-1 e (see
    :func:`cageless.simulation.models.implicit_normal.planar_filter_error`): with the kinematic rows
    eliminated, (I - hg K_v - hg^2 K_x P) e_v' = e_v + hg K_x e_x, e_x' = e_x + hg P e_v'."""
    if p[B.P_F_RACE] < 0.5:
        return
    z = int(p[B.P_Z])
    b = 5 * z + 6
    gm = hg / p[B.P_M]
    rot, wt = _frame(y, p)
    for j in range(z):
        c, s = math.cos(y[z + j]), math.sin(y[z + j])
        r, rd, thd, x, xd = y[j], y[2 * z + j], y[3 * z + j], y[b + j], y[b + z + j]
        f0 = _forces(y, p, j, z, rot, wt, c, s, r, rd, thd, x, xd)
        kv = _jacobian(y, p, j, z, rot, wt, c, s, r, rd, thd, x, xd, 0.0, 0.0, f0)
        kt = _jacobian(y, p, j, z, rot, wt, c, s, r, rd, thd, x, xd, 1.0, 1.0, f0)  # d/d(pos) + d/d(vel)
        _forces(y, p, j, z, rot, wt, c, s, r, rd, thd, x, xd)  # restore y
        kr0, kr1, kr2 = kt[0] - kv[0], kt[3] - kv[3], kt[6] - kv[6]  # along r
        kx0, kx1, kx2 = kt[2] - kv[2], kt[5] - kv[5], kt[8] - kv[8]  # along x
        h2 = gm * hg
        mat = (1.0 - gm * kv[0] - h2 * kr0, -gm * kv[1], -gm * kv[2] - h2 * kx0,
               -gm * kv[3] - h2 * kr1, 1.0 - gm * kv[4], -gm * kv[5] - h2 * kx1,
               -gm * kv[6] - h2 * kr2, -gm * kv[7], 1.0 - gm * kv[8] - h2 * kx2)
        er, ex = e[j], e[b + j]
        v0, v1, v2 = _solve3(mat, e[2 * z + j] + gm * (kr0 * er + kx0 * ex),
                             r * e[3 * z + j] + gm * (kr1 * er + kx1 * ex), e[b + z + j] + gm * (kr2 * er + kx2 * ex))
        e[2 * z + j], e[3 * z + j], e[b + z + j] = v0, v1 / r, v2
        e[j], e[b + j] = er + hg * v0, ex + hg * v2
