"""A Rosenbrock-W method (ROS34PW2) with its whole loop compiled, linearly implicit per ball.

Why: the explicit DP5's step is held at about 1.1 us by the race lubricant damping (2 C_ho / m =
2.8e6 1/s), a stability limit, while the contact dynamics themselves (the Hertz period of a loaded ball is
about 50 us) allow much longer steps. The damping, the race Hertz stiffness and the traction's slope act
within one ball: they sit in the diagonal blocks of the Jacobian. A linearly implicit method that treats
only those blocks implicitly has its step set by accuracy again, at the cost of a few small solves a stage.

The method is ROS34PW2 of Rang & Angermann, "New Rosenbrock W-methods of order 3 for partial differential
algebraic equations of index 1", BIT Numer. Math. 45 (2005) 761-787: four stages, order 3 (embedded
order 2), L-stable, stiffly accurate. It is a *W*-method: its order conditions hold for any matrix in
place of the Jacobian, so a Jacobian that keeps only the per-ball blocks (and the ring's own block),
evaluated now and then, and without the time derivative of the ring's speed ramp, still gives order 3;
only the stability of what is left out (ball-ball coupling, the ring's coupling to the balls) is an
explicit method's, and those modes are slow (periods of tens of microseconds). The stages are written in
the transformed variables u_i = sum_j gamma_ij k_j of Hairer & Wanner, *Solving ODEs II*, 2nd ed.
(1996), sect. IV.7, eq. (7.25), so no Jacobian-vector product is needed:

    (I / (h gamma) - W) u_i = f(t + alpha_i h, y + sum_j a_ij u_j) + sum_j (c_ij / h) u_j.

W is block diagonal: ball j's states (the problem's Jacobian structure names them; the solver never
indexes the model's parameters) form one block, estimated by grouped difference quotients (balls of one
colour are perturbed together, :func:`cageless.simulation.jacobian.ball_colours`); the ring's states form
another, estimated one column at a time; every other state (the energy counters) is explicit. Each
block is LU-factorised once per step; the coupling blocks of balls apart are exact zeros, and the block
elimination skips them (the same numbers; 3000 rpm, 500 N, planar, settled: the balls' block LU costs about
one right-hand side instead of four, and the whole run 15 % less CPU time; benchmarks/rosw_diagnostics.py). A model without a Jacobian structure (the textbook test models)
is one dense block.

W is re-evaluated when a step is rejected (if it is not fresh), when a contact opened or closed in the
last accepted step (a damping term switched on or off), and at least every :data:`JAC_EVERY` accepted
steps. The first stage is the end derivative of the last step (f(y) is needed for the dense output
anyway), so a step costs three new right-hand sides plus one at its end.

The controls of the compiled DP5 loop (:mod:`cageless.simulation.integrators.dp5`) are kept: a step longer than
``h_onset`` in which a contact opens or closes is retried at ``h_onset``; one across which a force jumps
is retried at half the length; samples come from cubic Hermite interpolation between step ends; the
model's bookkeeping (the contact log) runs after every accepted step.
"""

from __future__ import annotations

import numba
import numpy as np

from cageless.simulation.integrators.dp5 import (STATUS_MAX_STEPS, STATUS_NONFINITE, STATUS_OK,
                                                 STATUS_STEP_UNDERFLOW, _accept, _controls, _retry_step)
from cageless.simulation.jacobian import grouped_fd
from cageless.simulation.kernels import model_rhs, model_signature

__all__ = ["rosw_integrate", "JAC_EVERY", "LU_RATIO", "GAMMA", "transformed_tableau"]

#: Accepted steps after which W is re-evaluated even if no contact changed. Measured at 3000 rpm, 500 N,
#: planar, 5 ms from a settled state (benchmarks/rosw_diagnostics.py --jac-every): every step costs 1.8 times
#: the wall time of every 20 steps, with the same slip error.
JAC_EVERY = 20

#: Largest relative change of the step length for which the factors of the last step are kept (see
#: :func:`rosw_integrate`); 0 factorises every step. Kept at 0: measured at 3000 rpm, 500 N, planar, 5 ms from a
#: settled state, rtol 1e-7 (benchmarks/rosw_diagnostics.py, interleaved, loaded machine), 0.2 and 0.5 took
#: 1.5 and 1.7 times the wall time of 0: the shifted W rejected 4 to 5 times as many steps (1581 and 1929
#: against 397), which cost more than the 18 % of factorisations saved.
LU_RATIO = 0.0

#: Pass the error estimate through (I - h gamma W)^-1 before its norm (Shampine's filter, Hairer & Wanner II,
#: sect. IV.8, eq. (8.20)), so the fast-decaying components that the method damps do not reject steps. Off:
#: the filter costs a fifth block solve per step and, by letting the estimate of the slow components through
#: damped too, admits more slip error per step. Measured at 3000 rpm, 500 N, planar, 5 ms settled, CPU time,
#: interleaved best of 3 against ``auto`` in the same run: filter on, rtol 1e-6 / 3e-7 / 1e-7: 0.78 / 0.67 /
#: 0.58 times auto's speed at 0.011 / 0.0026 / 0.0010 pp of slip error, 611 / 564 / 397 rejections; off:
#: 0.83 / 0.66 / 0.53 at 0.0023 / 0.00096 / 0.00045 pp, 400 / 423 / 409 rejections: at equal error
#: about a fifth faster.
FILTER_ERROR = False

# ROS34PW2 (Rang & Angermann 2005, Table 4.2): alpha (the propagation table), gamma (the stage table,
# diagonal GAMMA), b (order 3) and b_hat (the embedded order 2).
GAMMA = 4.3586652150845900e-01
_ALPHA = np.array([[0.0, 0.0, 0.0, 0.0],
                   [8.7173304301691801e-01, 0.0, 0.0, 0.0],
                   [8.4457060015369423e-01, -1.1299064236484185e-01, 0.0, 0.0],
                   [0.0, 0.0, 1.0, 0.0]])
_GAMMA_TABLE = np.array([[GAMMA, 0.0, 0.0, 0.0],
                         [-8.7173304301691801e-01, GAMMA, 0.0, 0.0],
                         [-9.0338057013044082e-01, 5.4180672388095326e-02, GAMMA, 0.0],
                         [2.4212380706095346e-01, -1.2232505839045147e+00, 5.4526025533510214e-01, GAMMA]])
_B = np.array([2.4212380706095346e-01, -1.2232505839045147e+00, 1.5452602553351020e+00, 4.3586652150845900e-01])
_B_HAT = np.array([3.7810903145819369e-01, -9.6042292212423178e-02, 0.5, 2.1793326075422950e-01])


def transformed_tableau() -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The coefficients in the variables u = Gamma k (Hairer & Wanner II, (7.25)): a = alpha Gamma^-1,
    c = diag(1/gamma) - Gamma^-1 (strictly lower), m = b Gamma^-1, the error weights (b - b_hat) Gamma^-1,
    and the stage times alpha_i = sum_j alpha_ij."""
    inv = np.linalg.inv(_GAMMA_TABLE)
    a = _ALPHA @ inv
    c = np.diag(1.0 / np.diag(_GAMMA_TABLE)) - inv
    return a, np.tril(c, -1), _B @ inv, (_B - _B_HAT) @ inv, _ALPHA.sum(axis=1)


_A, _C, _M, _E, _ALPHA_T = transformed_tableau()


@numba.njit(cache=True)
def _lu(a, piv, b):  # pragma: no cover - compiled
    """In-place LU with partial pivoting of the small matrix a[b] (Golub & Van Loan, alg. 3.4.1; whole rows
    exchanged). Indexed in place, not through a view: views cost reference counting in the inner loop."""
    k = a.shape[1]
    for c in range(k):
        best, ip = abs(a[b, c, c]), c
        for r in range(c + 1, k):
            if abs(a[b, r, c]) > best:
                best, ip = abs(a[b, r, c]), r
        piv[b, c] = ip
        if ip != c:
            for q in range(k):
                a[b, c, q], a[b, ip, q] = a[b, ip, q], a[b, c, q]
        d = a[b, c, c]
        for r in range(c + 1, k):
            a[b, r, c] /= d
            for q in range(c + 1, k):
                a[b, r, q] -= a[b, r, c] * a[b, c, q]


@numba.njit(cache=True)
def _lu_solve(a, piv, b, x):  # pragma: no cover - compiled
    """x = a[b]^-1 x in place, a[b] factorised by :func:`_lu`: the row exchanges first, then the two triangles."""
    k = a.shape[1]
    for c in range(k):
        ip = piv[b, c]
        if ip != c:
            x[c], x[ip] = x[ip], x[c]
    for c in range(k):
        for r in range(c + 1, k):
            x[r] -= a[b, r, c] * x[c]
    for r in range(k - 1, -1, -1):
        s = x[r]
        for q in range(r + 1, k):
            s -= a[b, r, q] * x[q]
        x[r] = s / a[b, r, r]


@numba.njit(cache=True)
def _factor(jb, inv_hg, lu, piv):  # pragma: no cover - compiled
    """LU of I / (h gamma) - jb[b] for every block b (no coupling between blocks)."""
    for b in range(jb.shape[0]):
        for r in range(jb.shape[1]):
            for c in range(jb.shape[2]):
                lu[b, r, c] = -jb[b, r, c]
            lu[b, r, r] += inv_hg
        _lu(lu, piv, b)


@numba.njit(cache=True)
def _ball_factor(jb, inv_hg, lu, piv, pm, order, x, nz):  # pragma: no cover - compiled
    """Block LU of the balls' part of I / (h gamma) - W, block tridiagonal in the ring order ``order`` (the ring
    cut where its neighbours' coupling is weakest, :func:`_cut`): D'_i = D_i - L_i P_i, P_{i+1} = D'_i^-1 U_i,
    with D, L, U the diagonal, lower and upper blocks (block Thomas algorithm). ``pm[order[i]]`` holds P_i.
    Products with a coupling block that is zero (balls apart, ``nz`` from :func:`_cut`) are skipped, and so
    is P_{i+1} when U_i is zero (it is then never read): the same factors, at a fraction of the work."""
    nb, k = jb.shape[0], jb.shape[2]
    for i in range(nb):
        b = order[i]
        couple = i > 0 and nz[b, 0] != 0 and nz[order[i - 1], 1] != 0
        for r in range(k):
            for c in range(k):
                acc = -jb[b, 0, r, c]
                if couple:
                    for q in range(k):
                        acc += jb[b, 1, r, q] * pm[b, q, c]  # L = -W_lower
                lu[b, r, c] = acc
            lu[b, r, r] += inv_hg
        _lu(lu, piv, b)
        if i + 1 < nb and nz[b, 1] != 0:
            nxt = order[i + 1]
            for c in range(k):
                for r in range(k):
                    x[r] = -jb[b, 2, r, c]  # U = -W_upper
                _lu_solve(lu, piv, b, x)
                for r in range(k):
                    pm[nxt, r, c] = x[r]


@numba.njit(cache=True)
def _ball_solve(lu, piv, pm, jb, order, cols, rhs, out, x, nz):  # pragma: no cover - compiled
    """out[balls] = (balls' part of I / (h gamma) - W)^-1 rhs[balls], by :func:`_ball_factor`'s factors (zero
    coupling blocks skipped)."""
    nb, k = lu.shape[0], lu.shape[1]
    for i in range(nb):
        b = order[i]
        for r in range(k):
            acc = rhs[cols[r, b]]
            if i > 0 and nz[b, 0] != 0:
                prev = order[i - 1]
                for q in range(k):
                    acc += jb[b, 1, r, q] * out[cols[q, prev]]
            x[r] = acc
        _lu_solve(lu, piv, b, x)
        for r in range(k):
            out[cols[r, b]] = x[r]
    for i in range(nb - 2, -1, -1):
        b, nxt = order[i], order[i + 1]
        if nz[b, 1] == 0:
            continue
        for r in range(k):
            acc = 0.0
            for q in range(k):
                acc += pm[nxt, r, q] * out[cols[q, nxt]]
            x[r] = acc
        for r in range(k):
            out[cols[r, b]] -= x[r]


@numba.njit(cache=True)
def _cut(jb, order, nz):  # pragma: no cover - compiled
    """Order the ring of blocks from just after the pair with the weakest coupling (zero for balls apart), so
    that dropping that pair's coupling (W may be any matrix) leaves a block tridiagonal system; ``nz[b]``:
    whether block b's coupling to b - 1 and to b + 1 is nonzero (balls apart give exact zeros)."""
    nb = jb.shape[0]
    best, cut = np.inf, nb - 1
    if nb >= 3:
        for b in range(nb):
            up = (b + 1) % nb
            w = 0.0
            for r in range(jb.shape[2]):
                for c in range(jb.shape[3]):
                    w += abs(jb[b, 2, r, c]) + abs(jb[up, 1, r, c])
            if w < best:
                best, cut = w, b
    for i in range(nb):
        order[i] = (cut + 1 + i) % nb
        for side in range(2):
            nz[i, side] = 0
            for r in range(jb.shape[2]):
                for c in range(jb.shape[3]):
                    if jb[i, 1 + side, r, c] != 0.0:
                        nz[i, side] = 1


@numba.njit(cache=True)
def _block_solve(lu, piv, cols, rhs, out, x):  # pragma: no cover - compiled
    """out[cols[:, b]] = (I / (h gamma) - W_b)^-1 rhs[cols[:, b]] for every uncoupled block b (by _factor)."""
    nb, k = lu.shape[0], lu.shape[1]
    for b in range(nb):
        for r in range(k):
            x[r] = rhs[cols[r, b]]
        _lu_solve(lu, piv, b, x)
        for r in range(k):
            out[cols[r, b]] = x[r]


@numba.njit(cache=True)
def _prepare(st, wk, inv_hg):  # pragma: no cover - compiled
    """Factorise I / (h gamma) - W for a step: the ball blocks, then the Schur complement on the ring's states,
    S = I / (h gamma) - R - F Y with Y = (I / (h gamma) - B)^-1 E (E: the balls' rows in the ring's columns,
    F: the ring's rows in the balls' columns). Without shared rows (``ring_rows`` empty: W without the
    coupling of balls and ring, see :func:`cageless.simulation.solve._rosw_blocks`) E is left out too: Y = 0,
    S = I / (h gamma) - R."""
    cols, groups, ring_cols, explicit, ring_rows = st
    jb, lu, piv, jr, lur, pivr, js, share0, share1, x, g, yy, fy, fz, pm, order, nz = wk
    _ball_factor(jb, inv_hg, lu, piv, pm, order, x, nz)
    nr = ring_cols.shape[0]
    for c in range(nr):
        yy[c, :] = 0.0
        if ring_rows.shape[0] > 0:
            _ball_solve(lu, piv, pm, jb, order, cols, g[c], yy[c], x, nz)
        fy[c, :] = 0.0
        for q in range(ring_rows.shape[0]):
            acc = 0.0
            for b in range(cols.shape[1]):
                for f in range(cols.shape[0]):
                    acc += js[b, q, f] * yy[c, cols[f, b]]
            fy[c, ring_rows[q]] = acc
    for r in range(nr):
        for c in range(nr):
            jr[0, r, c] = g[c, ring_cols[r, 0]] + fy[c, ring_cols[r, 0]]
    _factor(jr, inv_hg, lur, pivr)


@numba.njit(cache=True)
def _solve(st, wk, hg, rhs, out):  # pragma: no cover - compiled
    """out = (I / (h gamma) - W)^-1 rhs by block elimination (``rhs`` is overwritten): the ball blocks, the
    Schur complement on the ring's states (:func:`_prepare`), the balls' back-substitution, then the explicit
    states (the energy counters), h gamma times their right-hand side plus their coupling to the balls and
    the ring. O(Z) work: nothing dense of the full size is formed."""
    cols, groups, ring_cols, explicit, ring_rows = st
    jb, lu, piv, jr, lur, pivr, js, share0, share1, x, g, yy, fy, fz, pm, order, nz = wk
    _ball_solve(lu, piv, pm, jb, order, cols, rhs, out, x, nz)
    fz[:] = 0.0
    for q in range(ring_rows.shape[0]):
        acc = 0.0
        for b in range(cols.shape[1]):
            for f in range(cols.shape[0]):
                acc += js[b, q, f] * out[cols[f, b]]
        fz[ring_rows[q]] = acc
    nr = ring_cols.shape[0]
    if nr > 0:
        for r in range(nr):
            rhs[ring_cols[r, 0]] += fz[ring_cols[r, 0]]
        _block_solve(lur, pivr, ring_cols, rhs, out, x)
        for c in range(nr if ring_rows.shape[0] > 0 else 0):  # Y = 0 without shared rows
            ur = out[ring_cols[c, 0]]
            for b in range(cols.shape[1]):
                for f in range(cols.shape[0]):
                    out[cols[f, b]] += yy[c, cols[f, b]] * ur
    for i in range(explicit.shape[0]):
        e = explicit[i]
        acc = rhs[e] + fz[e]
        for c in range(nr):
            acc += (fy[c, e] + g[c, e]) * out[ring_cols[c, 0]]
        out[e] = hg * acc


@numba.njit(cache=True)
def _jacobian(model_id, t, y, p, log, f0, st, wk, y_work, f1, floor):  # pragma: no cover - compiled
    """Evaluate W by the grouped difference quotients of :func:`cageless.simulation.jacobian.grouped_fd` in the
    block layout: the ball blocks with their coupling to the shared rows, and the ring's columns (every row:
    the ring's own block, the balls' rows E and the counters' rows); returns the right-hand sides used."""
    cols, groups, ring_cols, explicit, ring_rows = st
    jb, lu, piv, jr, lur, pivr, js, share0, share1, x, g, yy, fy, fz, pm, order, nz = wk
    n_rhs = grouped_fd(model_id, t, y, p, log, f0, cols, groups, ring_rows, ring_cols, floor, y_work, f1, share0,
                       share1, False, jr[0], jb, js, g)
    _cut(jb, order, nz)
    return n_rhs


@numba.njit(cache=True)
def _stages(model_id, t, h, p, log, vec, u, st, wk):  # pragma: no cover - compiled
    """The four stages of one step from (t, y = vec[0]) with f(y) = vec[1]: the new state into vec[5] and the
    error vector into vec[6]."""
    y, k1, yt, fs, ynew, err_w = vec[0], vec[1], vec[3], vec[4], vec[5], vec[6]
    n = y.shape[0]
    for s in range(4):
        if s == 0:
            for i in range(n):
                fs[i] = k1[i]
        else:
            for i in range(n):
                acc = y[i]
                for j in range(s):
                    acc += _A[s, j] * u[j, i]
                yt[i] = acc
            model_rhs(model_id, t + _ALPHA_T[s] * h, yt, p, log, fs)
            for i in range(n):
                acc = 0.0
                for j in range(s):
                    acc += _C[s, j] * u[j, i]
                fs[i] += acc / h
        _solve(st, wk, h * GAMMA, fs, u[s])
    for i in range(n):
        ynew[i] = y[i] + _M[0] * u[0, i] + _M[1] * u[1, i] + _M[2] * u[2, i] + _M[3] * u[3, i]
        err_w[i] = _E[0] * u[0, i] + _E[1] * u[1, i] + _E[2] * u[2, i] + _E[3] * u[3, i]


@numba.njit(cache=True)
def _error_norm(y, ynew, err_w, atol, rtol):  # pragma: no cover - compiled
    """The RMS of err_i / (atol_i + rtol max(|y_i|, |ynew_i|)), inf when the new state is not finite."""
    n = y.shape[0]
    err = 0.0
    for i in range(n):
        if not np.isfinite(ynew[i]):
            return np.inf
        sc = atol[i] + rtol * max(abs(y[i]), abs(ynew[i]))
        err += (err_w[i] / sc) ** 2
    return np.sqrt(err / n)


# Counters of the loop, kept in one integer array so the helpers can update them.
_STEPS, _REJ, _RHS, _ONSET, _CHANGES, _JUMPS, _JACS, _LUS = 0, 1, 2, 3, 4, 5, 6, 7


@numba.njit(cache=True)
def _workspace(n, cols, ring_cols, ring_rows):  # pragma: no cover - compiled
    """Vectors (10 x n: y, k1, k7, yt, fs, ynew, err_w, y_work, f1, difference-quotient floor), the stage
    increments (4 x n), and the blocks: (jb, lu, piv, jr, lur, pivr, js, share0, share1, x, g, yy, fy, fz): the
    ball blocks, their factors and pivots, the ring's Schur complement, its factors and pivots, the shared
    rows' coupling to the balls, two shares, a scratch vector, the ring's Jacobian columns (by column), Y, F Y, F u, the
    block Thomas factors P, the balls' order and which coupling blocks are nonzero."""
    nb, kf, nr, nq = cols.shape[1], cols.shape[0], ring_cols.shape[0], ring_rows.shape[0]
    vec = np.zeros((10, n))
    u = np.zeros((4, n))
    wk = (np.zeros((nb, 3, kf, kf)), np.zeros((nb, kf, kf)), np.zeros((nb, kf), dtype=np.int64),
          np.zeros((1, nr, nr)), np.zeros((1, nr, nr)), np.zeros((1, nr), dtype=np.int64),
          np.zeros((nb, nq, kf)), np.zeros((nb, max(nq, 1))), np.zeros(max(nq, 1)), np.zeros(max(kf, nr, 1)),
          np.zeros((nr, n)), np.zeros((nr, n)), np.zeros((nr, n)), np.zeros(n), np.zeros((nb, kf, kf)),
          np.arange(nb), np.ones((nb, 2), dtype=np.int64))
    return vec, u, wk


@numba.njit(cache=True)
def _write_stats(stats, cnt, h):  # pragma: no cover - compiled
    stats[0], stats[1], stats[2], stats[3] = cnt[_STEPS], cnt[_REJ], cnt[_RHS], h
    stats[4], stats[5], stats[6], stats[7], stats[8] = cnt[_ONSET], cnt[_CHANGES], cnt[_JUMPS], 0, cnt[_JACS]
    stats[9] = cnt[_LUS]


@numba.njit(cache=True)
def _start(model_id, t0, y0, p, log, t_out, out, atol, rtol, vec):  # pragma: no cover - compiled
    """Set up the loop's vectors at the start; write the samples at or before it; next sample index."""
    n = y0.shape[0]
    for i in range(n):
        vec[0, i] = y0[i]
        vec[9, i] = atol[i] / rtol  # the smallest perturbation scale of the difference quotients
    model_rhs(model_id, t0, vec[0], p, log, vec[1])
    k = 0
    while k < t_out.shape[0] and t_out[k] <= t0:
        out[k, :] = vec[0]
        k += 1
    return k


@numba.njit(cache=True)
def _step(model_id, t, h, p, log, atol, rtol, vec, u, st, wk, fresh_w, cnt, lu_at, lu_ratio):  # pragma: no cover
    """One attempted step of length h from (t, vec[0]): W evaluated if ``fresh_w``, factorised unless the
    factors of I / (h' gamma) - W at ``lu_at[0]`` = 1 / (h' gamma) serve (see :func:`rosw_integrate`), the stages;
    returns the error norm (inf if the state became non-finite)."""
    if fresh_w:
        cnt[_RHS] += _jacobian(model_id, t, vec[0], p, log, vec[1], st, wk, vec[7], vec[8], vec[9])
        cnt[_JACS] += 1
    inv_hg = 1.0 / (h * GAMMA)
    if fresh_w or lu_at[0] == 0.0 or not abs(inv_hg / lu_at[0] - 1.0) <= lu_ratio:
        _prepare(st, wk, inv_hg)
        lu_at[0] = inv_hg
        cnt[_LUS] += 1
    _stages(model_id, t, h, p, log, vec, u, st, wk)
    cnt[_RHS] += 3
    if FILTER_ERROR:  # (I - h gamma W)^-1 err: the stiff components' part of the estimate damped
        hg = h * GAMMA
        vec[4, :] = vec[6]
        _solve(st, wk, hg, vec[4], vec[6])
        for i in range(vec.shape[1]):
            vec[6, i] /= hg
    return _error_norm(vec[0], vec[5], vec[6], atol, rtol)


@numba.njit(cache=True, inline="always")
def _counters():  # pragma: no cover - compiled
    """:func:`rosw_integrate`'s step counters (the first right-hand side counted) and 1 / (h gamma) of the
    current factors (0: none yet)."""
    cnt = np.zeros(8, dtype=np.int64)
    cnt[_RHS] = 1
    return cnt, np.zeros(1)


@numba.njit(cache=True, inline="always")
def _reject(err, h, tiny, age, jac_every, rejected, cnt):  # pragma: no cover - compiled
    """A rejected (or non-finite) step of :func:`rosw_integrate`: count it, mark W stale after a second rejection
    in a row and shrink the step; returns (h, age, failed), failed when a non-finite step fell below ``tiny``."""
    cnt[_REJ] += 1
    if rejected and age > 0:  # a second rejection in a row: a stale W may be why, evaluate it afresh
        age = jac_every
    h *= max(0.2, 0.9 * err ** (-1.0 / 3.0)) if np.isfinite(err) else 0.25
    return h, age, not np.isfinite(err) and h < tiny


@numba.njit(cache=True, inline="always")
def _accept_sampled(model_id, t, h, y, ynew, k1, k7, p, log, t_out, out, k, t_end,
                    tiny):  # pragma: no cover - compiled
    """Accept the step from t to t + h and write the samples it passes; returns the next sample's index."""
    k = _accept(model_id, t, h, y, ynew, k1, k7, p, log, t_out, out, k)
    if t_end - (t + h) <= tiny:  # only round-off left: the remaining samples are this state
        out[k:, :] = ynew
        k = t_out.shape[0]
    return k


@numba.njit(cache=True)
def rosw_integrate(model_id, p, log, y0, t0, t_out, rtol, atol, h0, h_max, max_steps, out, stats, h_onset,
                   jump_floor, force_jump, st, jac_every, lu_ratio):  # pragma: no cover - compiled
    """Integrate from ``t0`` and write ``y`` at each ``t_out[k]`` into ``out[k]`` (as
    :func:`cageless.simulation.integrators.dp5.dp5_integrate`, the same controls and status codes).

    ``st`` = (cols, groups, ring_cols, explicit, ring_rows): ``cols[f, b]`` is the state of field f of block
    b (the balls), ``groups`` the blocks perturbed together (padded with -1), ``ring_cols`` the ring's block
    (may be empty), ``explicit`` every other state, ``ring_rows`` the rows every ball reaches (may be empty).
    ``jac_every`` <= 0 keeps W = 0 (an explicit method of order 3, for the tests of the W-property).
    ``lu_ratio``: the factors of I / (h' gamma) - W are kept for a step of length h while W is not re-evaluated
    and |h' / h - 1| <= ``lu_ratio`` (0: factorised every step). The step then uses W + (1 / (h gamma) -
    1 / (h' gamma)) I in place of W (the explicit states' rows keep theirs); a W-method's order holds for any
    W (Rang & Angermann 2005), so only its stability moves, as CVODE keeps its Newton matrix while its
    gamma changes by less than 30 % (Hindmarsh et al., ACM TOMS 31 (2005) 363, sect. 2.1).
    ``stats`` (10) receives [n_steps, n_rejected, n_rhs, last_h, n_onset_retries, n_contact_changes,
    n_force_jump_retries, 0, n_jacobians, n_factorisations].
    """
    vec, u, wk = _workspace(y0.shape[0], st[0], st[2], st[4])
    y, k1, k7, ynew = vec[0], vec[1], vec[2], vec[5]
    cnt, lu_at = _counters()
    k = _start(model_id, t0, y0, p, log, t_out, out, atol, rtol, vec)
    # age >= jac_every: evaluate W before the next step
    t, h, age, status, rejected = t0, h0, jac_every, STATUS_OK, False
    sig = model_signature(model_id, y, p) if h_onset > 0.0 else 0.0
    t_end = t_out[t_out.shape[0] - 1]
    tiny = 1e-13 * max(abs(t_end), t_end - t0)  # round-off scale of the time axis
    while k < t_out.shape[0]:
        h = min(h, h_max, t_end - t)
        if cnt[_STEPS] + cnt[_REJ] >= max_steps or h < tiny:
            status = STATUS_MAX_STEPS if h >= tiny else STATUS_STEP_UNDERFLOW
            break
        err = _step(model_id, t, h, p, log, atol, rtol, vec, u, st, wk, 0 < jac_every <= age, cnt, lu_at, lu_ratio)
        age = 0 if 0 < jac_every <= age else age
        if not err <= 1.0:  # rejected, or not finite
            h, age, failed = _reject(err, h, tiny, age, jac_every, rejected, cnt)
            rejected = True
            if failed:
                status = STATUS_NONFINITE
                break
            continue
        model_rhs(model_id, t + h, ynew, p, log, k7)
        cnt[_RHS] += 1
        grow = 1.0 if rejected else 5.0  # no growth right after a rejection
        rejected = False
        verdict, sig = _controls(model_id, ynew, p, sig, h, h_onset, k1, k7, jump_floor, force_jump)
        if verdict == 1 or verdict == 2:  # a contact changed in a long step, or a force jumped
            h = _retry_step(verdict, h, h_onset, cnt)
            continue
        cnt[_CHANGES] += verdict == 3
        age = jac_every if verdict == 3 else age + 1  # a contact opened or closed: a damping term switched
        k = _accept_sampled(model_id, t, h, y, ynew, k1, k7, p, log, t_out, out, k, t_end, tiny)
        t += h
        cnt[_STEPS] += 1
        h *= min(grow, max(0.2, 0.9 * max(err, 1e-10) ** (-1.0 / 3.0)))
    _write_stats(stats, cnt, h)
    return status
