"""The race lubricant damping as the implicit part of an IMEX split, per ball, in closed form.

The damping part of the normal force of a closed race contact k of ball j is
``max(C_ho d(delta_k)/dt, -q_k) n_k`` with ``d(delta_k)/dt = -(v - v_race_k) . n_k`` (``n_k`` the direction
of the normal force on the ball, ``v_race_k`` the velocity of the race surface, ``q_k`` the Hertz force):
the models' "never tensile" total ``max(q_k + C_ho d(delta_k)/dt, 0)`` minus ``q_k``. Written this way the
implicit part is continuous and monotone in ``v`` (the Hertz force, smooth, stays explicit); splitting off
the damping as ``C_ho d(delta)/dt`` or 0 instead would make both parts jump by ``q_k`` where the clamp
engages, which the two tables of an additive method do not cancel (measured: steps of 0.2 us with every
other one rejected while a ball left the inner race). With the positions, the normals, the race
velocities and ``q_k`` frozen at a stage, it is piecewise linear in the ball's velocity ``v``, so an
implicit stage ``v = v_Z + h gamma F(v) / m`` is, for a given set of damping (unclamped) contacts, the
small linear system

    (I + (h gamma / m) sum_damping C_ho n_k n_k^T) v
        = v_Z + (h gamma / m) (sum_damping C_ho (v_race_k . n_k) n_k - sum_clamped q_k n_k),

2 x 2 in the planar model (the polar components (r', r theta') of the ball's velocity), 3 x 3 in the spatial
one (its Cartesian velocity), solved by Cramer's rule. Which contacts damp (the "never tensile" clamp) is
decided at the solution itself: the set is re-solved until it agrees with the clamp evaluated at the new
velocity (at most a few passes, two contacts per ball), so the implicit part is a well-defined function
of the state and the explicit part is ``f - f_I`` of the same state.

Nothing else moves: the positions of a stage are explicit (the implicit part has no position rows), and
the ring's share of the damping stays in the explicit part (its rate ``sum_k c_k / M`` is about 1e-2 of a
ball's ``2 C_ho / m``). The contact geometry is the models' own: the spatial model's contact frame
(:func:`cageless.simulation.models.spatial._race_frame`), the planar model's overlaps as in
:func:`cageless.simulation.models.planar._outer_race` and ``_inner_race``.

Each function writes the implicit part ``f_I`` (accelerations, zero on every other row) into ``k_i``. With
``hg > 0`` it first replaces the ball velocities of ``y`` (the stage predictor Z) by the solution of the
stage equation; with ``hg == 0`` it only evaluates ``f_I(y)``.
"""

from __future__ import annotations

import math

import numba

from cageless.simulation.models import base as B
from cageless.simulation.models.spatial import _race_frame
from cageless.simulation.models.spatial_layout import P_TILT_Z, _groove, _tilt

__all__ = ["planar_implicit", "spatial_implicit"]

_PASSES = 4  # active-set passes per ball (two contacts: at most three changes are ever needed)


@numba.njit(cache=True, inline="always")
def _clear(k_i):  # pragma: no cover - compiled
    for i in range(k_i.shape[0]):
        k_i[i] = 0.0


@numba.njit(cache=True, inline="always")
def _solve3(a00, a01, a02, a11, a12, a22, b0, b1, b2):  # pragma: no cover - compiled
    """x = A^-1 b for the symmetric positive definite A (upper triangle given), by Cramer's rule."""
    c00 = a11 * a22 - a12 * a12
    c01 = a02 * a12 - a01 * a22
    c02 = a01 * a12 - a02 * a11
    det = a00 * c00 + a01 * c01 + a02 * c02
    c11 = a00 * a22 - a02 * a02
    c12 = a01 * a02 - a00 * a12
    c22 = a00 * a11 - a01 * a01
    return ((c00 * b0 + c01 * b1 + c02 * b2) / det, (c01 * b0 + c11 * b1 + c12 * b2) / det,
            (c02 * b0 + c12 * b1 + c22 * b2) / det)


@numba.njit(cache=True, inline="always")
def _ball_solve(v, w, cho, g, passes):  # pragma: no cover - compiled
    """The stage solution of one ball from its velocity ``v`` (3; the predictor) and its two contacts in ``w``:
    unit normals (the direction of the normal force on the ball) w[0:3] and w[3:6], the race surface's speeds
    along them w[6:8], Hertz forces w[8:10], closed (1.0) or open w[10:12]; ``g = h gamma C_ho / m`` (0: no
    solve, only the clamp at ``v``). Returns (the new velocity (3), the damping force over C_ho (3))."""
    on0, on1 = w[10] > 0.5, w[11] > 0.5
    x0, x1, x2 = v[0], v[1], v[2]
    for _ in range(passes):
        a00 = a11 = a22 = 1.0
        a01 = a02 = a12 = 0.0
        b0, b1, b2 = v[0], v[1], v[2]
        for k in range(2):
            n0, n1, n2 = w[3 * k], w[3 * k + 1], w[3 * k + 2]
            if on0 if k == 0 else on1:
                gv = g * w[6 + k]
                a00 += g * n0 * n0
                a01 += g * n0 * n1
                a02 += g * n0 * n2
                a11 += g * n1 * n1
                a12 += g * n1 * n2
                a22 += g * n2 * n2
                b0, b1, b2 = b0 + gv * n0, b1 + gv * n1, b2 + gv * n2
            elif w[10 + k] > 0.5:  # clamped: the damping part is -q, so the normal force is zero
                gv = -g * w[8 + k] / cho
                b0, b1, b2 = b0 + gv * n0, b1 + gv * n1, b2 + gv * n2
        if g > 0.0:
            x0, x1, x2 = _solve3(a00, a01, a02, a11, a12, a22, b0, b1, b2)
        want0 = w[10] > 0.5 and w[8] - cho * (x0 * w[0] + x1 * w[1] + x2 * w[2] - w[6]) > 0.0
        want1 = w[11] > 0.5 and w[9] - cho * (x0 * w[3] + x1 * w[4] + x2 * w[5] - w[7]) > 0.0
        if want0 == on0 and want1 == on1:
            break
        on0, on1 = want0, want1
    f0 = f1 = f2 = 0.0
    for k in range(2):
        if w[10 + k] > 0.5:  # the closing speed d(delta)/dt, or -q / C_ho where the clamp holds
            d = -(x0 * w[3 * k] + x1 * w[3 * k + 1] + x2 * w[3 * k + 2] - w[6 + k]) if (on0 if k == 0 else on1) \
                else -w[8 + k] / cho
            f0, f1, f2 = f0 + d * w[3 * k], f1 + d * w[3 * k + 1], f2 + d * w[3 * k + 2]
    return x0, x1, x2, f0, f1, f2


@numba.njit(cache=True)
def planar_implicit(y, p, hg, k_i, w):  # pragma: no cover - compiled
    """The planar model's implicit part (see the module); ``w`` (12) is scratch. Velocities in the ball's
    polar frame (r', r theta', 0)."""
    _clear(k_i)
    if p[B.P_F_RACE] < 0.5 or p[B.P_F_LUB] < 0.5 or p[B.P_CHO] <= 0.0:
        return
    z = int(p[B.P_Z])
    m, cho, half = p[B.P_M], p[B.P_CHO], 0.5 * p[B.P_D]
    g = hg * cho / m
    cy, cz, cvy, cvz = y[5 * z], y[5 * z + 1], y[5 * z + 2], y[5 * z + 3]
    for j in range(z):
        r, th = y[j], y[z + j]
        c, s = math.cos(th), math.sin(th)
        d_o = r + half - 0.5 * p[B.P_DO]  # as planar._outer_race: the force pushes the ball inward
        w[10] = 1.0 if d_o > 0.0 else 0.0
        w[8] = p[B.P_KO] * d_o * math.sqrt(d_o) if d_o > 0.0 else 0.0
        w[0], w[1], w[2], w[6] = -1.0, 0.0, 0.0, 0.0
        sx, sz = r * c - cy, r * s - cz  # as planar._inner_race: from the ring centre, pushing outward
        ln = math.sqrt(sx * sx + sz * sz)
        d_i = 0.5 * p[B.P_DI] + half - ln
        w[11] = 1.0 if d_i > 0.0 else 0.0
        w[9] = p[B.P_KI] * d_i * math.sqrt(d_i) if d_i > 0.0 else 0.0
        nx, nz = sx / ln, sz / ln
        w[3], w[4], w[5], w[7] = nx * c + nz * s, -nx * s + nz * c, 0.0, cvy * nx + cvz * nz
        if d_o <= 0.0 and d_i <= 0.0:
            continue
        x0, x1, _, f0, f1, _ = _ball_solve((y[2 * z + j], r * y[3 * z + j], 0.0), w, cho, g,
                                           _PASSES if g > 0.0 else 1)
        if g > 0.0:
            y[2 * z + j], y[3 * z + j] = x0, x1 / r
        k_i[2 * z + j] = cho * f0 / m
        k_i[3 * z + j] = cho * f1 / (m * r)


@numba.njit(cache=True)
def spatial_implicit(y, p, hg, k_i, w):  # pragma: no cover - compiled
    """The spatial model's implicit part (see the module), from the model's own contact frames; ``w`` (12) is
    scratch. Velocities Cartesian (x along the shaft)."""
    _clear(k_i)
    if p[B.P_F_RACE] < 0.5 or p[B.P_F_LUB] < 0.5 or p[B.P_CHO] <= 0.0:
        return
    z = int(p[B.P_Z])
    m, cho = p[B.P_M], p[B.P_CHO]
    g = hg * cho / m
    rot = _tilt(y, p)
    tb = y.shape[0] - 4  # as spatial_rhs: the ring's tilting angular velocity
    s_bz, c_bz = math.sin(p[P_TILT_Z] + y[tb + 1]), math.cos(p[P_TILT_Z] + y[tb + 1])
    wt = (-s_bz * y[tb + 2], c_bz * y[tb + 2], y[tb + 3])
    for j in range(z):
        _spatial_ball(y, p, j, z, rot, wt, cho, g, k_i, w)


@numba.njit(cache=True, inline="always")
def _spatial_ball(y, p, j, z, rot, wt, cho, g, k_i, w):  # pragma: no cover - compiled
    """:func:`spatial_implicit` for ball j."""
    b = 5 * z + 6
    m = p[B.P_M]
    c, s = math.cos(y[z + j]), math.sin(y[z + j])
    r, rd, thd = y[j], y[2 * z + j], y[3 * z + j]
    v = (y[b + z + j], rd * c - r * thd * s, rd * s + r * thd * c)
    for k in range(2):
        inner = k == 1
        rk = rot if inner else (1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0)  # as spatial._race
        rq, cq, sq, ex, er, ln, delta, rho, rg = _groove(y, p, j, z, inner, rk, c, s)
        w[10 + k] = 0.0
        if delta <= 0.0:
            continue
        n, _, _, rv, _, k_n, _ = _race_frame(y, p, j, z, inner, rk, c, s, wt, rq, cq, sq, ex, er, ln, rho, rg)
        w[10 + k] = 1.0
        w[8 + k] = k_n * delta * math.sqrt(delta)
        # the force on the ball is -q n, the closing speed rv . n; in the convention of _ball_solve the normal
        # is -n and the race surface's speed along it -(v - rv) . n
        w[3 * k], w[3 * k + 1], w[3 * k + 2] = -n[0], -n[1], -n[2]
        w[6 + k] = -((v[0] - rv[0]) * n[0] + (v[1] - rv[1]) * n[1] + (v[2] - rv[2]) * n[2])
    if w[10] < 0.5 and w[11] < 0.5:
        return
    x0, x1, x2, f0, f1, f2 = _ball_solve(v, w, cho, g, _PASSES if g > 0.0 else 1)
    if g > 0.0:
        y[b + z + j] = x0
        y[2 * z + j] = x1 * c + x2 * s
        y[3 * z + j] = (-x1 * s + x2 * c) / r
    k_i[b + z + j] = cho * f0 / m
    k_i[2 * z + j] = cho * (f1 * c + f2 * s) / m
    k_i[3 * z + j] = cho * (-f1 * s + f2 * c) / (m * r)
