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

__all__ = ["dp5_integrate", "STATUS_OK", "STATUS_MAX_STEPS", "STATUS_STEP_UNDERFLOW", "STATUS_NONFINITE"]

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
    n_force_jump_retries, n_stiff_steps]. A stiff step is an accepted step at the edge of the method's
    stability region: h |lambda| > 3.25, with |lambda| estimated as ||f(y1) - f(y_6)|| / ||y1 - y_6|| from
    the last two stages (Hairer & Wanner, *Solving ODEs II*, sect. IV.2, the test of their DOPRI5 code).
    Returns a status code:
    0 ok, 1 too many steps, 2 step-size underflow, 3 non-finite state.
    """  # noqa: D401
    n = y0.shape[0]
    y = y0.copy()
    k1 = np.empty(n)
    k2 = np.empty(n)
    k3 = np.empty(n)
    k4 = np.empty(n)
    k5 = np.empty(n)
    k6 = np.empty(n)
    k7 = np.empty(n)
    yt = np.empty(n)
    ynew = np.empty(n)
    t = t0
    model_rhs(model_id, t, y, p, log, k1)
    sig = model_signature(model_id, y, p) if h_onset > 0.0 else 0.0
    n_onset = 0
    n_jumps = 0
    n_stiff = 0
    n_changes = 0
    n_rhs = 1
    n_steps = 0
    n_rej = 0
    h = h0
    err_old = 1e-4
    k = 0
    while k < t_out.shape[0] and t_out[k] <= t:
        out[k, :] = y
        k += 1
    status = STATUS_OK
    t_end = t_out[t_out.shape[0] - 1]
    tiny = 1e-13 * max(abs(t_end), t_end - t0)  # round-off scale of the time axis
    while k < t_out.shape[0]:
        if n_steps + n_rej >= max_steps:
            status = STATUS_MAX_STEPS
            break
        if t_end - t <= tiny:  # only round-off left: the remaining samples are the current state
            while k < t_out.shape[0]:
                out[k, :] = y
                k += 1
            break
        h = min(h, h_max, t_end - t)
        if h < tiny:
            status = STATUS_STEP_UNDERFLOW
            break
        for i in range(n):
            yt[i] = y[i] + h * A21 * k1[i]
        model_rhs(model_id, t + C2 * h, yt, p, log, k2)
        for i in range(n):
            yt[i] = y[i] + h * (A31 * k1[i] + A32 * k2[i])
        model_rhs(model_id, t + C3 * h, yt, p, log, k3)
        for i in range(n):
            yt[i] = y[i] + h * (A41 * k1[i] + A42 * k2[i] + A43 * k3[i])
        model_rhs(model_id, t + C4 * h, yt, p, log, k4)
        for i in range(n):
            yt[i] = y[i] + h * (A51 * k1[i] + A52 * k2[i] + A53 * k3[i] + A54 * k4[i])
        model_rhs(model_id, t + C5 * h, yt, p, log, k5)
        for i in range(n):
            yt[i] = y[i] + h * (A61 * k1[i] + A62 * k2[i] + A63 * k3[i] + A64 * k4[i] + A65 * k5[i])
        model_rhs(model_id, t + h, yt, p, log, k6)
        for i in range(n):
            ynew[i] = y[i] + h * (B1 * k1[i] + B3 * k3[i] + B4 * k4[i] + B5 * k5[i] + B6 * k6[i])
        model_rhs(model_id, t + h, ynew, p, log, k7)
        n_rhs += 6
        err = 0.0
        finite = True
        for i in range(n):
            e = h * (E1 * k1[i] + E3 * k3[i] + E4 * k4[i] + E5 * k5[i] + E6 * k6[i] + E7 * k7[i])
            sc = atol[i] + rtol * max(abs(y[i]), abs(ynew[i]))
            err += (e / sc) ** 2
            if not np.isfinite(ynew[i]):
                finite = False
        err = np.sqrt(err / n)
        if not finite or not np.isfinite(err):
            h *= 0.25
            n_rej += 1
            if h < tiny:
                status = STATUS_NONFINITE
                break
            continue
        fac11 = err ** 0.17  # 0.2 - 0.75 beta, beta = 0.04
        if err <= 1.0 and h_onset > 0.0:
            sig_new = model_signature(model_id, ynew, p)
            if sig_new != sig:
                if h > h_onset:
                    n_onset += 1
                    n_rej += 1
                    h = h_onset
                    continue
                n_changes += 1
                sig = sig_new
        if err <= 1.0 and force_jump > 0.0 and h > h_onset:
            if _force_jumped(k1, k7, jump_floor, force_jump):
                n_jumps += 1
                n_rej += 1
                h = max(0.5 * h, h_onset)
                continue
        if err <= 1.0:
            num = 0.0
            den = 0.0
            for i in range(n):
                num += (k7[i] - k6[i]) ** 2
                den += (ynew[i] - yt[i]) ** 2
            if den > 0.0 and h * h * num > 3.25 * 3.25 * den:
                n_stiff += 1
            fac = fac11 / err_old ** 0.04
            fac = max(0.1, min(5.0, fac / 0.9))
            t_new = t + h
            while k < t_out.shape[0] and t_out[k] <= t_new:
                _hermite(t, h, y, ynew, k1, k7, t_out[k], out[k])
                k += 1
            err_old = max(err, 1e-4)
            t = t_new
            for i in range(n):
                y[i] = ynew[i]
                k1[i] = k7[i]
            n_steps += 1
            model_post(model_id, t, y, p, log)
            h = h / fac
        else:
            n_rej += 1
            h = h / min(5.0, fac11 / 0.9)
    stats[0] = n_steps
    stats[1] = n_rej
    stats[2] = n_rhs
    stats[3] = h
    stats[4] = n_onset
    stats[5] = n_changes
    stats[6] = n_jumps
    stats[7] = n_stiff
    return status


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
