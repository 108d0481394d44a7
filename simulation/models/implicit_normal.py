"""The race contacts' whole normal force (Hertz spring and lubricant damping) as the implicit part of an IMEX
split, per ball, for the planar model.

Why: with only the damping implicit (the split this replaced, in closed form per ball) the explicit part
keeps the Hertz oscillations of the loaded balls, |lambda| = 2.1e5 1/s at 3000 rpm, 500 N (settled), which
bound its stable step near 16 us. With the normal force and the radial kinematics implicit the fastest
explicit modes are a loaded ball's spin against the traction slope and the ring's, |lambda| <= 2.1e4 1/s,
ten times slower (benchmarks/ark_speed.py prints both). The step is then set by the error estimate, which
must be filtered through the implicit part's stiffness (:func:`planar_filter_error`) not to carry the
stiff normal modes the L-stable table damps, and by the contact changes.

The split, per ball j (polar coordinates r, theta as the planar model's state):

* f_I on the row of r is r' (the radial kinematics), on the rows of r' and theta' the race normal forces
  over the mass, ``(F_rad / m, F_tan / (m r))``, each contact's force ``max(q + C_ho d(delta)/dt, 0)``
  along its normal (the models' clamped total: continuous in the state); zero on every other row;
* f_E = f - f_I: the centripetal and Coriolis terms, traction, rolling losses, drag, ball-ball contacts,
  gravity, the ring (which feels the same normal forces explicitly), the angle rows.

An implicit stage ``Y = Z + h gamma f_I(Y)`` then moves only (r, r', theta') of each ball, theta, the spin
and the ring frozen at the predictor Z. With ``r = r_Z + h gamma r'`` substituted it is two nonlinear
equations in (r', theta'), solved by Newton's method from the predictor with an approximate Jacobian (the
inner contact's normal held at the iterate; the residual itself exact), to
:data:`TOL_V` in velocity. The race contacts are those of :func:`cageless.simulation.models.planar._outer_race`
and ``_inner_race``, term for term.

The planar solves are compiled with the model right-hand sides' fast-math flags
(:data:`cageless.simulation.forces.FASTMATH`: fused multiply-add, reciprocals, signed zeros; no reassociation, so
a fresh compile and numba's cache agree bit for bit): 2-3 % off ``ark4``'s planar CPU time, the same steps,
the samples changed at round-off (docs/imex.md, the ninth step). The spatial solves
(:mod:`cageless.simulation.models.implicit_normal_spatial`, which inline :func:`_solve3` and :func:`converged` under
their own flags) and ``ark_integrate``'s loop stay without them: with them on the loop (with or without the
spatial solves') a fresh compile and the cached code gave different round-off on the spatial model, which the
determinism rule forbids.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from cageless.simulation.forces import FASTMATH
from cageless.simulation.models import base as B
from cageless.simulation.models.planar import planar_rhs_trig

__all__ = ["planar_implicit_normal", "planar_stage", "planar_filter_error", "converged", "TOL_V", "MAX_NEWTON"]

#: Newton's tolerance on the distance of r' and r theta' from the solution (m/s): 1e-4 of the radial speeds'
#: absolute tolerance.
TOL_V = 1e-11
#: Newton iterations per ball and stage at most (the residual contracts by ~1e-3 per iteration when settled).
MAX_NEWTON = 12


@numba.njit(cache=True, fastmath=FASTMATH, inline="always")
def converged(step, last):  # pragma: no cover - compiled
    """Newton's stopping test after an update of size ``step`` (the one before: ``last``, inf at the first):
    the update itself within :data:`TOL_V`, or, from the contraction theta = step / last, the distance left to
    the solution, theta / (1 - theta) step (Hairer & Wanner, Solving ODEs II, sect. IV.8, eq. 8.10-8.11).
    Newton's method converges quadratically here (updates 1e-4, 6e-10, 1e-14 m/s per ball at a 30 us step,
    3000 rpm, 500 N, settled), so the second update already shows the third to be below the tolerance: two
    force evaluations per ball and stage instead of three."""
    if step <= TOL_V:
        return True
    if not np.isfinite(last):
        return False
    theta = step / last
    return theta < 1.0 and theta / (1.0 - theta) * step <= TOL_V


@numba.njit(cache=True, fastmath=FASTMATH, inline="always")
def _forces(r, rd, thd, c, s, ring, p, hg):  # pragma: no cover - compiled
    """Ball's race normal forces in polar components (F_rad, F_tan) at (r, r', theta') and their approximate
    derivatives along (r', theta') with r = r_Z + hg r': (F_rad, F_tan, dFr/drd, dFr/dthd, dFt/drd, dFt/dthd)."""
    half = 0.5 * p[B.P_D]
    cho = p[B.P_CHO] if p[B.P_F_LUB] > 0.5 else 0.0
    fr = ft = dfr_rd = dfr_th = dft_rd = dft_th = 0.0
    d_o = r + half - 0.5 * p[B.P_DO]  # outer race: the force pushes the ball inward
    if d_o > 0.0:
        sq = math.sqrt(d_o)
        n_o = p[B.P_KO] * d_o * sq + cho * rd
        if n_o > 0.0:
            fr -= n_o
            dfr_rd -= 1.5 * p[B.P_KO] * sq * hg + cho
    cy, cz, cvy, cvz = ring
    sx, sz = r * c - cy, r * s - cz  # inner race: from the ring centre, pushing outward
    ln = math.sqrt(sx * sx + sz * sz)
    d_i = 0.5 * p[B.P_DI] + half - ln
    if d_i > 0.0:
        nr, nt = (r - cy * c - cz * s) / ln, (cy * s - cz * c) / ln  # the normal in polar components
        v_r, v_t = rd - (cvy * c + cvz * s), r * thd - (-cvy * s + cvz * c)
        sq = math.sqrt(d_i)
        n_i = p[B.P_KI] * d_i * sq - cho * (v_r * nr + v_t * nt)
        if n_i > 0.0:
            fr += n_i * nr
            ft += n_i * nt
            dn_rd = -1.5 * p[B.P_KI] * sq * nr * hg - cho * (nr + thd * hg * nt)
            dn_th = -cho * r * nt
            dfr_rd += dn_rd * nr
            dfr_th += dn_th * nr
            dft_rd += dn_rd * nt
            dft_th += dn_th * nt
    return fr, ft, dfr_rd, dfr_th, dft_rd, dft_th


@numba.njit(cache=True, fastmath=FASTMATH, inline="always")
def _ball_stage(r_z, rd_z, thd_z, c, s, ring, p, hg):  # pragma: no cover - compiled
    """Newton's method on r' = r'_Z + hg F_rad / m, theta' = theta'_Z + hg F_tan / (m r), r = r_Z + hg r':
    the stage's (r, r', theta')."""
    m = p[B.P_M]
    rd, thd = rd_z, thd_z
    r = r_z + hg * rd
    last = np.inf
    for _ in range(MAX_NEWTON):
        fr, ft, a, b, cc, d = _forces(r, rd, thd, c, s, ring, p, hg)
        g1 = rd - rd_z - hg * fr / m
        g2 = thd - thd_z - hg * ft / (m * r)
        j11, j12 = 1.0 - hg * a / m, -hg * b / m
        j21, j22 = -hg * cc / (m * r), 1.0 - hg * d / (m * r)
        det = j11 * j22 - j12 * j21
        drd = (j22 * g1 - j12 * g2) / det
        dth = (j11 * g2 - j21 * g1) / det
        rd -= drd
        thd -= dth
        r = r_z + hg * rd
        step = max(abs(drd), abs(dth) * r)
        if converged(step, last):
            break
        last = step
    return r, rd, thd


@numba.njit(cache=True, fastmath=FASTMATH)
def planar_implicit_normal(y, p, hg, k_i):  # pragma: no cover - compiled
    """The planar model's implicit part (see the module) into ``k_i``; with ``hg > 0`` the stage equation
    y = y_Z + hg f_I(y) is solved first, in place on ``y`` (the predictor on entry)."""
    for i in range(k_i.shape[0]):
        k_i[i] = 0.0
    z = int(p[B.P_Z])
    ring = (y[5 * z], y[5 * z + 1], y[5 * z + 2], y[5 * z + 3])
    for j in range(z):
        _ball_implicit(y, p, hg, k_i, j, z, math.cos(y[z + j]), math.sin(y[z + j]), ring)


@numba.njit(cache=True, fastmath=FASTMATH, inline="always")
def _ball_implicit(y, p, hg, k_i, j, z, c, s, ring):  # pragma: no cover - compiled
    """Ball j's share of :func:`planar_implicit_normal` (c, s: the cos and sin of its angle)."""
    m = p[B.P_M]
    race = p[B.P_F_RACE] > 0.5
    r, rd, thd = y[j], y[2 * z + j], y[3 * z + j]
    if hg > 0.0:
        if race:
            r, rd, thd = _ball_stage(r, rd, thd, c, s, ring, p, hg)
        else:
            r = r + hg * rd
        y[j], y[2 * z + j], y[3 * z + j] = r, rd, thd
    k_i[j] = rd
    if race:
        fr, ft, _, _, _, _ = _forces(r, rd, thd, c, s, ring, p, 0.0)
        k_i[2 * z + j] = fr / m
        k_i[3 * z + j] = ft / (m * r)


@numba.njit(cache=True, fastmath=FASTMATH)
def planar_stage(t, y, p, log, hg, k_i, dydt):  # pragma: no cover - compiled
    """One IMEX stage of the planar model: the stage equation solved in place on ``y`` and f_I into ``k_i``
    (:func:`planar_implicit_normal`), then the whole right-hand side at the solved ``y`` into ``dydt``. The
    implicit solve leaves the balls' angles alone, so the cos and sin of each are computed once, into the log's
    scratch, for both (the same values the two computed apart: the same stage, bit for bit, for 14 fewer sine and
    cosine pairs)."""
    for i in range(k_i.shape[0]):
        k_i[i] = 0.0
    z = int(p[B.P_Z])
    trig = log.shape[0] - 2 * z
    ring = (y[5 * z], y[5 * z + 1], y[5 * z + 2], y[5 * z + 3])
    for j in range(z):
        log[trig + j] = np.cos(y[z + j])
        log[trig + z + j] = np.sin(y[z + j])
        _ball_implicit(y, p, hg, k_i, j, z, log[trig + j], log[trig + z + j], ring)
    planar_rhs_trig(t, y, p, log, dydt, True)


@numba.njit(cache=True, fastmath=FASTMATH, inline="always")
def _solve3(m, b0, b1, b2):  # pragma: no cover - compiled
    """x = M^-1 b for a general 3 x 3 M (a tuple of 9, row by row), by Cramer's rule."""
    a, b, c, d, e, f, g, h, i = m
    c00, c01, c02 = e * i - f * h, f * g - d * i, d * h - e * g
    det = a * c00 + b * c01 + c * c02
    x0 = (b0 * c00 + b * (f * b2 - b1 * i) + c * (b1 * h - e * b2)) / det
    x1 = (a * (b1 * i - f * b2) + b0 * c01 + c * (d * b2 - b1 * g)) / det
    x2 = (a * (e * b2 - b1 * h) + b * (b1 * g - d * b2) + b0 * c02) / det
    return x0, x1, x2


@numba.njit(cache=True, fastmath=FASTMATH)
def planar_filter_error(y, p, hg, e):  # pragma: no cover - compiled
    """Replace each ball's (r, r', theta') rows of the error estimate ``e`` by (I - hg J_I)^-1 e, J_I the
    Jacobian of the implicit part on those rows at ``y`` (Shampine's filter, as RADAU5's estimate;
    Hairer & Wanner, Solving ODEs II, sect. IV.8). Without it the estimate carries the stiff normal
    modes (C_ho / m = 1.4e6 1/s) that the L-stable implicit table damps, and the loaded balls' radial speeds
    set the step."""
    if p[B.P_F_RACE] < 0.5:
        return
    z = int(p[B.P_Z])
    m = p[B.P_M]
    ring = (y[5 * z], y[5 * z + 1], y[5 * z + 2], y[5 * z + 3])
    for j in range(z):
        c, s = math.cos(y[z + j]), math.sin(y[z + j])
        r, rd, thd = y[j], y[2 * z + j], y[3 * z + j]
        _, _, a_rd, a_th, b_rd, b_th = _forces(r, rd, thd, c, s, ring, p, 0.0)
        _, _, a_r, _, b_r, _ = _forces(r, rd, thd, c, s, ring, p, 1.0)  # d/dr + d/dr' (see _forces)
        if a_rd == 0.0 and a_th == 0.0 and b_rd == 0.0 and b_th == 0.0 and a_r == 0.0 and b_r == 0.0:
            e[j] = e[j] + hg * e[2 * z + j]  # no closed contact: only the kinematics, [[1, -hg], [0, 1]]
            continue
        gm, gr = hg / m, hg / (m * r)
        mat = (1.0, -hg, 0.0,
               -gm * (a_r - a_rd), 1.0 - gm * a_rd, -gm * a_th,
               -gr * (b_r - b_rd), -gr * b_rd, 1.0 - gr * b_th)
        e[j], e[2 * z + j], e[3 * z + j] = _solve3(mat, e[j], e[2 * z + j], e[3 * z + j])
