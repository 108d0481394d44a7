"""Dormand-Prince 5(4) with its whole loop compiled (numba).

The method of Dormand & Prince, "A family of embedded Runge-Kutta formulae",
J. Comput. Appl. Math. 6 (1980) 19-26, with the step-size control of Hairer,
Norsett & Wanner, *Solving ODEs I*, 2nd ed. (1993), sect. II.4 (PI control,
safety 0.9, factor limits 0.2..10, beta = 0.04) and FSAL: the last stage of an
accepted step is the first of the next. The error norm is the RMS of
``err_i / (atol_i + rtol max(|y_old_i|, |y_new_i|))``; ``atol`` is per component.

Samples at the requested times come from cubic Hermite interpolation between
the step ends (values and derivatives, both known), accurate to O(h^4), far
below the tolerance at the small steps contact problems take.

The right-hand side is the compiled kernel of the problem's model
(:func:`cageless.simulation.kernels.model_rhs`, writing into ``dydt``, no allocation);
:func:`~cageless.simulation.kernels.model_post` runs after every accepted step and may
update the contact log ``log`` (contact bookkeeping). The kernels are
reached by a static switch on the model id, so this loop is cached on disk.
"""

from __future__ import annotations

import numba
import numpy as np

from cageless.simulation.kernels import model_post, model_rhs, model_signature

__all__ = ["dp5_integrate", "STATUS_OK", "STATUS_MAX_STEPS", "STATUS_STEP_UNDERFLOW", "STATUS_NONFINITE", "ONSET_TOL"]

STATUS_OK = 0
STATUS_MAX_STEPS = 1
STATUS_STEP_UNDERFLOW = 2
STATUS_NONFINITE = 3

# Dormand-Prince 5(4) tableau.
C2, C3, C4, C5 = 1 / 5, 3 / 10, 4 / 5, 8 / 9
A21 = 1 / 5
A31, A32 = 3 / 40, 9 / 40
A41, A42, A43 = 44 / 45, -56 / 15, 32 / 9
A51, A52, A53, A54 = 19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729
A61, A62, A63, A64, A65 = 9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656
B1, B3, B4, B5, B6 = 35 / 384, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84
E1, E3, E4, E5, E6, E7 = 71 / 57600, -71 / 16695, 71 / 1920, -17253 / 339200, 22 / 525, -1 / 40


#: Relative tolerance of "longer than the onset step" (:func:`over_onset`): a step meant to be the onset step may
#: come out a few ulps longer (its end is a located contact change's time plus half an onset step, and t + h is
#: rounded), and must not be refused for that.
ONSET_TOL = 1e-9

# Counters of the loop, kept in one integer array so the helpers can update them; their order is ``stats``'.
_STEPS, _REJ, _RHS, _ONSET, _CHANGES, _JUMPS, _STIFF = 0, 1, 2, 4, 5, 6, 7


@numba.njit(cache=True)
def dp5_integrate(model_id, p, log, y0, t0, t_out, rtol, atol, h0, h_max, max_steps, out, stats, h_onset,
                  jump_floor, force_jump):
    """Integrate from ``t0`` and write ``y`` at each ``t_out[k]`` (increasing, >= t0) into ``out[k]``.

    A step longer than ``h_onset`` during which a contact opens or closes (the model's signature
    changes) is rejected and retried at most ``h_onset`` long, so contact onsets are never stepped over.
    A step longer than ``h_onset`` across which a force jumps is rejected and retried at half the
    length (never below ``h_onset``): for each component i with ``jump_floor[i] > 0`` (the
    accelerations), |f_i(end) - f_i(start)| > ``force_jump`` (max(|f_i(start)|, |f_i(end)|) + floor_i).
    ``stats`` receives [n_steps, n_rejected, n_rhs, last_h, n_onset_retries, n_contact_changes,
    n_force_jump_retries, n_stiff_steps] (a stiff step: see :func:`_stiff`). Returns a status code:
    0 ok, 1 too many steps, 2 step-size underflow, 3 non-finite state.
    """  # noqa: D401
    n = y0.shape[0]
    y = y0.copy()
    ks = np.empty((7, n))  # the stages k1 .. k7
    yt = np.empty(n)
    ynew = np.empty(n)
    cnt = np.zeros(8, dtype=np.int64)
    t = t0
    model_rhs(model_id, t, y, p, log, ks[0])
    cnt[_RHS] = 1
    sig = model_signature(model_id, y, p) if h_onset > 0.0 else 0.0
    h = h0
    err_old = 1e-4
    k = _samples_before(t_out, t, y, out)
    status = STATUS_OK
    t_end = t_out[t_out.shape[0] - 1]
    tiny = 1e-13 * max(abs(t_end), t_end - t0)  # round-off scale of the time axis
    while k < t_out.shape[0]:
        stop, h = _before_step(cnt, max_steps, t, t_end, h, h_max, tiny)
        if stop >= 0:
            if stop == STATUS_OK:  # only round-off left: the remaining samples are the current state
                out[k:, :] = y
            status = stop
            break
        _dp5_stages(model_id, t, h, y, p, log, ks, yt, ynew)
        cnt[_RHS] += 6
        err = _dp5_error(h, y, ynew, ks, atol, rtol)
        h_retry, refused = _error_refusal(err, h, cnt)
        if refused:
            h = h_retry
            if h < tiny and not np.isfinite(err):
                status = STATUS_NONFINITE
                break
            continue
        verdict, sig = _controls(model_id, ynew, p, sig, h, h_onset, ks[0], ks[6], jump_floor, force_jump)
        if verdict == 1 or verdict == 2:  # a contact changed in a long step, or a force jumped
            h = _retry_step(verdict, h, h_onset, cnt)
            continue
        cnt[_CHANGES] += verdict == 3
        cnt[_STIFF] += _stiff(h, ks, ynew, yt)
        fac, err_old = _pi_factor(err, err_old)
        k = _accept(model_id, t, h, y, ynew, ks[0], ks[6], p, log, t_out, out, k)
        t = t + h
        cnt[_STEPS] += 1
        h = h / fac
    _write_stats(stats, cnt, h)
    return status


@numba.njit(cache=True, inline="always")
def _before_step(cnt, max_steps, t, t_end, h, h_max, tiny):  # pragma: no cover - compiled
    """Before a step: (-1, its length) to take it, else (the status the loop stops with, h): too many steps,
    only round-off of the time axis left (``STATUS_OK``: the remaining samples are the current state), or a
    step-size underflow."""
    if cnt[_STEPS] + cnt[_REJ] >= max_steps:
        return STATUS_MAX_STEPS, h
    if t_end - t <= tiny:
        return STATUS_OK, h
    h = min(h, h_max, t_end - t)
    if h < tiny:
        return STATUS_STEP_UNDERFLOW, h
    return -1, h


@numba.njit(cache=True, inline="always")
def _error_refusal(err, h, cnt):  # pragma: no cover - compiled
    """A step refused by its error estimate: (the length to retry it at, True), counted as rejected; a quarter of
    the length when the new state is not finite, the controller's shrink err^0.17 / 0.9 (at most 5) when the
    error exceeds 1. (h, False) when the error accepts the step."""
    if not np.isfinite(err):
        cnt[_REJ] += 1
        return h * 0.25, True
    if err > 1.0:
        cnt[_REJ] += 1
        return h / min(5.0, err ** 0.17 / 0.9), True  # 0.17 = 0.2 - 0.75 beta, beta = 0.04
    return h, False


@numba.njit(cache=True, inline="always")
def _pi_factor(err, err_old):  # pragma: no cover - compiled
    """The PI controller's step-length divisor after an accepted step (within 0.1 .. 5, safety 0.9), and the
    error to remember for the next one (floored at 1e-4)."""
    fac = err ** 0.17 / err_old ** 0.04
    return max(0.1, min(5.0, fac / 0.9)), max(err, 1e-4)


@numba.njit(cache=True, inline="always")
def _samples_before(t_out, t, y, out):  # pragma: no cover - compiled
    """Write the samples at or before ``t`` (the start) as ``y``; the next sample index."""
    k = 0
    while k < t_out.shape[0] and t_out[k] <= t:
        out[k, :] = y
        k += 1
    return k


@numba.njit(cache=True, inline="always")
def _dp5_stages(model_id, t, h, y, p, log, ks, yt, ynew):  # pragma: no cover - compiled
    """The stages k2 .. k7 of one step of length h from (t, y) with ks[0] = f(y): the new state into ``ynew``,
    its derivative into ks[6] (FSAL); ``yt`` is left holding the sixth stage's state."""
    n = y.shape[0]
    for i in range(n):
        yt[i] = y[i] + h * A21 * ks[0, i]
    model_rhs(model_id, t + C2 * h, yt, p, log, ks[1])
    for i in range(n):
        yt[i] = y[i] + h * (A31 * ks[0, i] + A32 * ks[1, i])
    model_rhs(model_id, t + C3 * h, yt, p, log, ks[2])
    for i in range(n):
        yt[i] = y[i] + h * (A41 * ks[0, i] + A42 * ks[1, i] + A43 * ks[2, i])
    model_rhs(model_id, t + C4 * h, yt, p, log, ks[3])
    for i in range(n):
        yt[i] = y[i] + h * (A51 * ks[0, i] + A52 * ks[1, i] + A53 * ks[2, i] + A54 * ks[3, i])
    model_rhs(model_id, t + C5 * h, yt, p, log, ks[4])
    for i in range(n):
        yt[i] = y[i] + h * (A61 * ks[0, i] + A62 * ks[1, i] + A63 * ks[2, i] + A64 * ks[3, i] + A65 * ks[4, i])
    model_rhs(model_id, t + h, yt, p, log, ks[5])
    for i in range(n):
        ynew[i] = y[i] + h * (B1 * ks[0, i] + B3 * ks[2, i] + B4 * ks[3, i] + B5 * ks[4, i] + B6 * ks[5, i])
    model_rhs(model_id, t + h, ynew, p, log, ks[6])


@numba.njit(cache=True, inline="always")
def _dp5_error(h, y, ynew, ks, atol, rtol):  # pragma: no cover - compiled
    """The RMS of err_i / (atol_i + rtol max(|y_i|, |ynew_i|)) of the embedded 4th-order estimate; inf when the
    new state is not finite."""
    n = y.shape[0]
    err = 0.0
    finite = True
    for i in range(n):
        e = h * (E1 * ks[0, i] + E3 * ks[2, i] + E4 * ks[3, i] + E5 * ks[4, i] + E6 * ks[5, i] + E7 * ks[6, i])
        sc = atol[i] + rtol * max(abs(y[i]), abs(ynew[i]))
        err += (e / sc) ** 2
        if not np.isfinite(ynew[i]):
            finite = False
    err = np.sqrt(err / n)
    return err if finite else np.inf


@numba.njit(cache=True, inline="always")
def _stiff(h, ks, ynew, yt):  # pragma: no cover - compiled
    """Whether an accepted step sits at the edge of the method's stability region: h |lambda| > 3.25, with
    |lambda| estimated as ||f(y1) - f(y_6)|| / ||y1 - y_6|| from the last two stages (Hairer & Wanner, *Solving
    ODEs II*, sect. IV.2, the test of their DOPRI5 code)."""
    num = 0.0
    den = 0.0
    for i in range(ynew.shape[0]):
        num += (ks[6, i] - ks[5, i]) ** 2
        den += (ynew[i] - yt[i]) ** 2
    return 1 if den > 0.0 and h * h * num > 3.25 * 3.25 * den else 0


@numba.njit(cache=True, inline="always")
def _retry_step(verdict, h, h_onset, cnt):  # pragma: no cover - compiled
    """Count a step refused by :func:`_controls` and return the length to retry it at: the onset step after a
    contact change in a long step (verdict 1), half the length after a force jump (verdict 2)."""
    cnt[_REJ] += 1
    cnt[_ONSET if verdict == 1 else _JUMPS] += 1
    return h_onset if verdict == 1 else max(0.5 * h, h_onset)


@numba.njit(cache=True, inline="always")
def over_onset(h, h_onset):  # pragma: no cover - compiled
    """Whether a step of length ``h`` is longer than the onset step ``h_onset`` by more than :data:`ONSET_TOL`."""
    return h > h_onset * (1.0 + ONSET_TOL)


@numba.njit(cache=True, inline="always")
def _controls(model_id, y_new, p, sig, h, h_onset, k1, k7, jump_floor, force_jump):  # pragma: no cover
    """The contact-onset and force-jump tests of an error-accepted step: (verdict, new signature), verdict
    0 accept, 1 retry at the onset step (a contact changed in a long step), 2 retry at half the length
    (a force jumped), 3 accept with a contact change. (A contact change is accepted only at most ``h_onset``
    long, and a force jump is tested only above it, so no step is both; both to :data:`ONSET_TOL`.)"""
    verdict = 0
    sig_new = sig
    if h_onset > 0.0:
        sig_new = model_signature(model_id, y_new, p)
        if sig_new != sig:
            if over_onset(h, h_onset):
                return 1, sig
            verdict = 3
    if force_jump > 0.0 and over_onset(h, h_onset) and _force_jumped(k1, k7, jump_floor, force_jump):
        return 2, sig
    return verdict, sig_new


@numba.njit(cache=True, inline="always")
def _accept(model_id, t, h, y, ynew, k1, k7, p, log, t_out, out, k):  # pragma: no cover - compiled
    """Write the samples inside (t, t + h], move to the step's end, run the bookkeeping; next sample index."""
    t_new = t + h
    while k < t_out.shape[0] and t_out[k] <= t_new:
        _hermite(t, h, y, ynew, k1, k7, t_out[k], out[k])
        k += 1
    for i in range(y.shape[0]):
        y[i] = ynew[i]
        k1[i] = k7[i]
    model_post(model_id, t_new, y, p, log)
    return k


@numba.njit(cache=True, inline="always")
def _write_stats(stats, cnt, h):  # pragma: no cover - compiled
    for i in range(cnt.shape[0]):
        stats[i] = cnt[i]
    stats[3] = h


@numba.njit(cache=True, inline="always")
def _force_jumped(f0, f1, floor, fraction):  # pragma: no cover - compiled
    for i in range(f0.shape[0]):
        if floor[i] > 0.0:
            a, b = f0[i], f1[i]
            if abs(b - a) > fraction * (max(abs(a), abs(b)) + floor[i]):
                return True
    return False


@numba.njit(cache=True, inline="always")
def _hermite(t, h, y0, y1, f0, f1, ts, dest):  # pragma: no cover - compiled
    s = (ts - t) / h
    h00 = (1 + 2 * s) * (1 - s) ** 2
    h10 = s * (1 - s) ** 2
    h01 = s * s * (3 - 2 * s)
    h11 = s * s * (s - 1)
    for i in range(y0.shape[0]):
        dest[i] = h00 * y0[i] + h10 * h * f0[i] + h01 * y1[i] + h11 * h * f1[i]
