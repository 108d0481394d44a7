"""An additive Runge-Kutta IMEX method, ARK4(3)6L[2]SA, with its whole loop compiled (numba).

Why: the explicit DP5's step is held at about 1.1 us by the race lubricant damping (2 C_ho / m = 2.8e6 1/s),
a stability limit, and behind it the Hertz oscillations of the loaded balls (|lambda| = 2.1e5 1/s) set the
next one. Both are local to a ball: the implicit part is each ball's race normal forces (Hertz spring and
damping, clamped as the models clamp them) and its radial (and axial) kinematics, solved per ball by a
few Newton iterations on a 2 x 2 (planar) or 3 x 3 (spatial) system
(:mod:`cageless.simulation.models.implicit_normal`, :mod:`cageless.simulation.models.implicit_normal_spatial`).
What is left explicit (traction, spin, the ring, the ball-ball contacts) has its fastest modes near
|lambda| = 2e4 1/s at 3000 rpm, 500 N (planar, settled; benchmarks/ark_speed.py prints them).

The method is Kennedy & Carpenter, "Additive Runge-Kutta schemes for convection-diffusion-reaction
equations", Appl. Numer. Math. 44 (2003) 139-181, ARK4(3)6L[2]SA: six stages, order 4 with an embedded
order 3, an explicit table (ERK) for f_E and an L-stable, stiffly accurate ESDIRK (diagonal 1/4) for f_I,
sharing the stage times and weights. The coefficients are the paper's, as SUNDIALS ARKODE ships them
(``ARKODE_ARK436L2SA_ERK_6_3_4`` and ``ARKODE_ARK436L2SA_DIRK_6_3_4``). Because the weights are shared, a
step is y + h sum_i b_i f(Y_i) with the full right-hand side of each stage, and its error estimate is
h sum_i (b_i - b_hat_i) f(Y_i), filtered through (I - h gamma J_I)^-1 per ball (Shampine's filter, as in
RADAU5; ``model_filter_error``): unfiltered, the stiff normal modes that the L-stable table damps dominate
the estimate (a loaded ball's radial speed in every accepted step) and hold the step near 9 us.

A stage is Y_i = Z_i + h/4 f_I(Y_i) with the explicit predictor
Z_i = y + h sum_{j<i} (aE_ij f_E(Y_j) + aI_ij f_I(Y_j)); the model solves it and evaluates f there in one call
(``model_stage``: ``model_implicit``, then ``model_rhs``, the planar model's angles' cos and sin computed once for
both), and f_E(Y_i) = f(Y_i) - f_I(Y_i). So a step costs five right-hand sides and five per-ball solves, plus the
right-hand side at its end (the next step's first stage, the dense output and the force-jump test).

Around the step everything is DP5's (:mod:`cageless.simulation.integrators.dp5`, reused, not changed): the
contact-onset and force-jump retries, cubic Hermite samples between step ends, the model's bookkeeping
after every accepted step (the contact log), the step-size bounds and the statistics layout, with one
addition: a step refused because a contact opened or closed in it is retried up to the change, located on
the straight line between the contact gaps at its ends, and the next step crosses it at the onset length
(:func:`_onset_retry`, :func:`_toward_change`), where DP5 retries at the onset length and then steps up to the change by
onset-length retries (3-5 refused steps per change at 3000 rpm, 500 N). The step controller is Hairer's PI
controller (Solving ODEs I, sect. II.4) with the exponents of an order-3 error estimate: 1/4 - 0.75 beta
and beta = 0.04, with no growth right after a rejected step (Hairer & Wanner's facmax = 1). The step after
the end of a span starts from the controller's proposal, not from the step the span's end clipped. Three controls
keep the refusals down (over 100 ms settled at 3000 rpm, 500 N, planar, 889 of 4049 steps were refused: 349 by the
error test, 221 at contact changes, 319 by the force-jump test): a contact change predicted within 2.5 onset steps
is crossed by an onset step instead of being stepped into (:func:`_onset_ahead`), a step the error test refuses
across a contact change is retried as the onset control retries (:func:`_refused_across`), and the step after an
accepted one is bounded where the force-jump test is expected to pass (:func:`_jump_bound`); 596 of 4108 refused
then. A located change stays located until it is crossed (through error refusals and retries that locate none), the
crossing step is the onset step itself (it was a few ulps longer, and refused), "longer than the onset step" is
tested to :data:`cageless.simulation.integrators.dp5.ONSET_TOL` throughout, and predictions that keep being passed
without a change stop (:data:`AHEAD_MISSES`); 584 of 4118 refused (docs/imex.md). A run in chunks keeps the integrator in a session (``state`` and ``rows``, :class:`cageless.simulation.solve.ArkSession`):
a call returns after the step that crosses its last sample, and the next call resumes there, writing its first
samples from that step's interpolant, so that the chunks take the same steps as one call.
"""

from __future__ import annotations

import numba
import numpy as np

from cageless.simulation.integrators.dp5 import (STATUS_NONFINITE, STATUS_OK, _accept, _before_step, _controls,
                                                 _hermite, _retry_step, _samples_before, _write_stats, over_onset)
from cageless.simulation.kernels import (model_filter_error, model_gaps, model_implicit, model_rhs, model_signature,
                                        model_stage)

__all__ = ["ark_integrate", "SESSION_SLOTS", "SESSION_ROWS", "AE", "AI", "B", "B_HAT", "C", "GAMMA"]

# Kennedy & Carpenter (2003), ARK4(3)6L[2]SA, tables as in SUNDIALS ARKODE (see the module docstring).
GAMMA = 0.25
C = np.array([0.0, 0.5, 83 / 250, 31 / 50, 17 / 20, 1.0])
AE = np.zeros((6, 6))
AE[1, 0] = 0.5
AE[2, :2] = [13861 / 62500, 6889 / 62500]
AE[3, :3] = [-116923316275 / 2393684061468, -2731218467317 / 15368042101831, 9408046702089 / 11113171139209]
AE[4, :4] = [-451086348788 / 2902428689909, -2682348792572 / 7519795681897, 12662868775082 / 11960479115383,
             3355817975965 / 11060851509271]
AE[5, :5] = [647845179188 / 3216320057751, 73281519250 / 8382639484533, 552539513391 / 3454668386233,
             3354512671639 / 8306763924573, 4040 / 17871]
AI = np.zeros((6, 6))
AI[1, :2] = [0.25, 0.25]
AI[2, :3] = [8611 / 62500, -1743 / 31250, 0.25]
AI[3, :4] = [5012029 / 34652500, -654441 / 2922500, 174375 / 388108, 0.25]
AI[4, :5] = [15267082809 / 155376265600, -71443401 / 120774400, 730878875 / 902184768, 2285395 / 8070912, 0.25]
B = np.array([82889 / 524892, 0.0, 15625 / 83664, 69875 / 102672, -2260 / 8211, 0.25])
AI[5, :] = B
B_HAT = np.array([4586570599 / 29645900160, 0.0, 178811875 / 945068544, 814220225 / 1159782912,
                  -3700637 / 11593932, 61727 / 225920])
_E = B - B_HAT

# the statistics counters (dp5's layout)
_STEPS, _REJ, _RHS = 0, 1, 2


@numba.njit(cache=True)
def ark_integrate(model_id, p, log, y0, t0, t_out, rtol, atol, h0, h_max, max_steps, out, stats, h_onset,
                  jump_floor, force_jump, t_stop, state, rows):
    """Integrate from ``t0`` and write ``y`` at each ``t_out[k]`` into ``out[k]``: the signature, controls,
    statistics and status codes of :func:`cageless.simulation.integrators.dp5.dp5_integrate` (no stiffness
    counter: ``stats[7]`` stays 0), with a session kept across calls.

    Steps are bounded by ``t_stop`` (>= ``t_out[-1]``), not by the last sample: the call returns once every
    sample is written, after the step that crosses the last one, and leaves the integrator where it is in
    ``state`` (:data:`SESSION_SLOTS`) and ``rows`` ((5, n): y, f(y), f_I(y), and the last step's start and
    its f, from which the next call's samples behind the integrator are interpolated). A call with
    ``state[0] > 0`` resumes there (``y0``, ``t0`` and ``h0`` are then not used), so a run in many calls takes
    the same steps as one call. With ``t_stop = t_out[-1]`` and a fresh ``state`` it is one solve."""  # noqa: D401
    f, ki, yt, ynew, f_end, e, g0, g1, work, cnt = _buffers(y0.shape[0])
    y = rows[0]  # the integrator's state lives in the session's rows
    t, h, err_old, held, t_cross, sig, misses, k = _start(model_id, p, log, y0, t0, h0, h_onset, t_out, out, state,
                                                          rows, f, ki, work, cnt)
    status = STATUS_OK
    tiny = 1e-13 * max(abs(t_stop), t_stop - state[_S_T0])
    h_want = h  # the controller's proposal before the end of the span clipped it: where the next span starts
    while k < t_out.shape[0]:
        h_want = h
        status, h = _before_step(cnt, max_steps, t, t_stop, _toward_change(t, h, t_cross, h_onset), h_max, tiny)
        if status >= 0:
            break
        h, t_cross, misses = _onset_ahead(model_id, p, t, h, y, f[0], h_onset, t_cross, misses, g0, g1, yt)
        err = _ark_trial(model_id, t, h, y, p, log, f, ki, yt, ynew, f_end, work, atol, rtol, e, cnt)
        if not np.isfinite(err) or err > 1.0:
            held = True
            status, h, t_cross = _refused(model_id, p, t, h, y, ynew, f[0], f_end, err, h_onset, sig, t_cross, tiny,
                                          g0, g1, yt, cnt)
            if status >= 0:
                break
            continue
        verdict, sig = _controls(model_id, ynew, p, sig, h, h_onset, f[0], f_end, jump_floor, force_jump)
        if verdict == 1 or verdict == 2:
            h, t_cross = _control_retry(model_id, p, verdict, t, h, y, ynew, f[0], f_end, h_onset, t_cross, g0, g1,
                                        yt, cnt)
            continue
        misses = _passed(misses, verdict, t, h, t_cross, cnt)
        h_next, err_old = _next_step(err, err_old, held, h, h_onset, f[0], f_end, jump_floor, force_jump)
        held = False
        if t + h > t_out[t_out.shape[0] - 1]:  # the step that crosses the last sample: keep its start (next call)
            _hold_step(t, h, y, f[0], state, rows)
        k = _ark_accept(model_id, t, h, y, ynew, f, f_end, ki, work, p, log, t_out, out, k, cnt)
        t, h = t + h, h_next
    if status == STATUS_OK:
        out[k:, :] = y  # stopped with only round-off of the time axis left (none when every sample is written)
    _write_stats(stats, cnt, max(h, h_want) if status <= STATUS_OK else h)
    _keep(state, rows, f, ki, t, h, err_old, held, t_cross, sig, misses)
    return max(status, STATUS_OK)


# The session's scalar slots (``state`` of ark_integrate): whether it holds an integrator, its time, the next trial
# step, the controller's last error, whether the last trial was refused, a contact change located ahead, the contact
# signature, the start and length of the last step that crossed a call's last sample, the first call's start, and
# the predicted contact changes passed without one (:func:`_onset_ahead`).
_S_ACTIVE, _S_T, _S_H, _S_ERR_OLD, _S_HELD, _S_T_CROSS, _S_SIG, _S_T_PREV, _S_H_PREV, _S_T0, _S_MISSES = range(11)
#: Length of the session's ``state`` array.
SESSION_SLOTS = 11
#: Rows of the session's ``rows`` array: y, f(y), f_I(y) at the integrator's time, the held step's start and its f.
SESSION_ROWS = 5


@numba.njit(cache=True, inline="always")
def _start(model_id, p, log, y0, t0, h0, h_onset, t_out, out, state, rows, f, ki, work, cnt):  # pragma: no cover
    """The loop's variables at the start of a call, with f(y) and f_I(y) in f[0] and ki[0] and the samples at or
    before its time written: (t, h, the controller's last error, whether the last trial step was refused, so that
    the next accepted one may not grow (Hairer & Wanner, II.4), a contact change located ahead (see
    :func:`_onset_retry`; the step that crosses it is short), the contact signature, the predicted changes passed
    without one (:func:`_onset_ahead`), the next sample's index). Resumed from the session when it holds one
    (``state[0] > 0``), else from ``(t0, y0)`` and ``h0``."""
    if state[_S_ACTIVE] > 0.0:
        f[0, :] = rows[1]
        ki[0, :] = rows[2]
        return (state[_S_T], state[_S_H], state[_S_ERR_OLD], state[_S_HELD] > 0.0, state[_S_T_CROSS],
                state[_S_SIG], int(state[_S_MISSES]), _samples_held(t_out, out, state, rows))
    y = rows[0]
    y[:] = y0
    state[_S_T0] = t0
    model_rhs(model_id, t0, y, p, log, f[0])
    model_implicit(model_id, t0, y, p, 0.0, ki[0], work)
    cnt[_RHS] = 1
    sig = model_signature(model_id, y, p) if h_onset > 0.0 else 0.0
    return t0, h0, 1e-4, False, -np.inf, sig, 0, _samples_before(t_out, t0, y, out)


@numba.njit(cache=True, inline="always")
def _keep(state, rows, f, ki, t, h, err_old, held, t_cross, sig, misses):  # pragma: no cover - compiled
    """Store the loop's variables in the session (y is already in rows[0])."""
    rows[1, :] = f[0]
    rows[2, :] = ki[0]
    state[_S_ACTIVE] = 1.0
    state[_S_T], state[_S_H], state[_S_ERR_OLD] = t, h, err_old
    state[_S_HELD] = 1.0 if held else 0.0
    state[_S_T_CROSS], state[_S_SIG], state[_S_MISSES] = t_cross, sig, misses


@numba.njit(cache=True, inline="always")
def _hold_step(t, h, y, f0, state, rows):  # pragma: no cover - compiled
    """Keep the start (t, y, f(y)) and length of the step about to be accepted, for :func:`_samples_held`."""
    rows[3, :] = y
    rows[4, :] = f0
    state[_S_T_PREV], state[_S_H_PREV] = t, h


@numba.njit(cache=True, inline="always")
def _samples_held(t_out, out, state, rows):  # pragma: no cover - compiled
    """Write the samples at or before the session's time from the held step's cubic Hermite interpolant (the
    values the one-call run writes when it accepts that step); the next sample index."""
    k = 0
    t, t_prev, h_prev = state[_S_T], state[_S_T_PREV], state[_S_H_PREV]
    while k < t_out.shape[0] and t_out[k] <= t:
        if h_prev > 0.0 and t_out[k] > t_prev:
            _hermite(t_prev, h_prev, rows[3], rows[0], rows[4], rows[1], t_out[k], out[k])
        else:
            out[k, :] = rows[0]
        k += 1
    return k


@numba.njit(cache=True, inline="always")
def _buffers(n):  # pragma: no cover - compiled
    """The work arrays of :func:`ark_integrate`: f(Y_i) and f_I(Y_i) of the six stages, a stage's state, the
    step's end state and right-hand side, the error vector, the contact gaps at the step's start and end (3 Z
    of them in the bearing models, n >= 3 Z), the implicit solves' scratch and the counters."""
    return (np.empty((6, n)), np.empty((6, n)), np.empty(n), np.empty(n), np.empty(n), np.empty(n), np.zeros(n),
            np.zeros(n), np.empty(12), np.zeros(8, dtype=np.int64))


@numba.njit(cache=True, inline="always")
def _ark_trial(model_id, t, h, y, p, log, f, ki, yt, ynew, f_end, work, atol, rtol, e, cnt):  # pragma: no cover
    """One trial step of length ``h`` from (t, y): the stages (:func:`_ark_stages`), the right-hand side at its
    end into ``f_end`` (six counted in ``cnt``) and the error norm of :func:`_ark_error`, returned."""
    _ark_stages(model_id, t, h, y, p, log, f, ki, yt, ynew, work)
    model_rhs(model_id, t + h, ynew, p, log, f_end)
    cnt[_RHS] += 6
    return _ark_error(model_id, p, h, y, ynew, f, atol, rtol, e)


@numba.njit(cache=True, inline="always")
def _ark_accept(model_id, t, h, y, ynew, f, f_end, ki, work, p, log, t_out, out, k, cnt):  # pragma: no cover
    """Accept the step from t to t + h: DP5's samples and bookkeeping (y, f[0] <- ynew, f_end), the implicit
    part at the new state into ki[0], the step counted; the next sample index."""
    k = _accept(model_id, t, h, y, ynew, f[0], f_end, p, log, t_out, out, k)
    model_implicit(model_id, t + h, y, p, 0.0, ki[0], work)
    cnt[_STEPS] += 1
    return k


@numba.njit(cache=True, inline="always")
def _rejected(err, h, cnt):  # pragma: no cover - compiled
    """The next trial step after the error test refused one of length ``h`` (counted in ``cnt``)."""
    cnt[_REJ] += 1
    return h * 0.25 if not np.isfinite(err) else h / min(5.0, err ** 0.25 / 0.9)


#: The share of the force-jump test's limit (:func:`cageless.simulation.integrators.dp5._controls`) that the step after
#: an accepted one aims at, extrapolating the jump linearly in the step length (see :func:`_jump_bound`).
JUMP_AIM = 0.8


@numba.njit(cache=True, inline="always")
def _jump_bound(h, h_onset, f0, f1, floor, fraction):  # pragma: no cover - compiled
    """The longest next step the force-jump test is expected to pass after an accepted step of length ``h`` whose
    accelerations went from ``f0`` to ``f1``: the test's largest share q = |f1_i - f0_i| / (fraction
    (max(|f0_i|, |f1_i|) + floor_i)) (<= 1, the step passed), extrapolated linearly, h JUMP_AIM / q, never below
    ``h_onset`` (where the test stops); inf when the test is off or did not run (steps up to ``h_onset``).
    Without it the PI controller grew the step through the impacts' rising forces into the test: 319 of 889
    refusals over 100 ms settled at 3000 rpm, 500 N (planar), at a median 1.45 times the step before, whose share
    was 0.76."""
    if fraction <= 0.0 or not over_onset(h, h_onset):
        return np.inf
    q = 0.0
    for i in range(f0.shape[0]):
        if floor[i] > 0.0:
            a, b = f0[i], f1[i]
            q = max(q, abs(b - a) / (fraction * (max(abs(a), abs(b)) + floor[i])))
    if q > 0.0 and np.isfinite(q):
        return max(h_onset, h * JUMP_AIM / q)
    return np.inf


@numba.njit(cache=True, inline="always")
def _refused(model_id, p, t, h, y, ynew, f0, f1, err, h_onset, sig, t_cross, tiny, g0, g1, yt,
             cnt):  # pragma: no cover - compiled
    """After the error test refused a step of length ``h`` (counted): (-1, the retry, the contact change located
    ahead; :func:`_refused_across`), or (``STATUS_NONFINITE``, ...) when the state is not finite even at a
    step below ``tiny``."""
    h_err = _rejected(err, h, cnt)
    if h_err < tiny and not np.isfinite(err):
        return STATUS_NONFINITE, h_err, t_cross
    h, t_cross = _refused_across(model_id, p, t, h, y, ynew, f0, f1, h_err, h_onset, sig, t_cross, g0, g1, yt, err,
                                 cnt)
    return -1, h, t_cross


@numba.njit(cache=True, inline="always")
def _refused_across(model_id, p, t, h, y, ynew, f0, f1, h_err, h_onset, sig, t_cross, g0, g1, yt, err,
                    cnt):  # pragma: no cover - compiled
    """The retry after the error test refused a step of length ``h`` (``h_err``: the controller's shrink), and a
    contact change located ahead (the loop's ``t_cross``, -inf for none). When a contact opened or closed in the
    step (its end's signature differs from ``sig``) and the step is longer than an onset step, the retry is placed
    as the onset control places it (:func:`_onset_retry`: up to half an onset step before the change, located on
    the step's interpolant, and the next step crossing it short; the onset step itself where the change lies
    within 1.5 onset steps of the start; counted as an onset retry too). The error of a step across a contact
    change says nothing of the length that passes: the controller's shrink (err^(1/4) / 0.9, 1.1-1.3 times at the
    errors of 1-2 these steps have) was refused again and again until the onset control ran, on an error that
    passed. 135 of the 349 error refusals over 100 ms settled at 3000 rpm, 500 N (planar) had a contact change in
    the step, a few onset steps long, the change mostly within two onset steps of the start (which
    :func:`_onset_ahead` left to the onset control). Otherwise ``(h_err, t_cross)``: a change located before
    (most often by :func:`_onset_ahead`, whose shortened step the error test refused: 131 of 291 error refusals
    over the same 100 ms) stays located, instead of being predicted again from the retry."""
    if h_onset <= 0.0 or not over_onset(h, h_onset) or not np.isfinite(err) or model_signature(model_id, ynew,
                                                                                               p) == sig:
        return h_err, t_cross
    cnt[4] += 1  # dp5's onset-retry counter
    return _onset_retry(model_id, p, t, h, y, ynew, f0, f1, h_onset, t_cross, g0, g1, yt)


@numba.njit(cache=True, inline="always")
def _control_retry(model_id, p, verdict, t, h, y, ynew, f0, f1, h_onset, t_cross, g0, g1, yt,
                   cnt):  # pragma: no cover - compiled
    """After the onset (``verdict`` 1) or force-jump (2) control refused an error-accepted step (counted): the
    retry and the contact change located ahead (:func:`_onset_retry` after a contact change, dp5's half step
    after a force jump)."""
    h_retry = _retry_step(verdict, h, h_onset, cnt)
    if verdict == 2:
        return h_retry, t_cross
    return _onset_retry(model_id, p, t, h, y, ynew, f0, f1, h_retry, t_cross, g0, g1, yt)


@numba.njit(cache=True, inline="always")
def _toward_change(t, h, t_cross, h_onset):  # pragma: no cover - compiled
    """The trial step from ``t`` given the proposal ``h`` and a contact change located at ``t_cross``: the onset
    step (it may cross the change) when the change lies within one, else a step ending half an onset step before
    it, never below the onset step; ``h`` when none lies ahead. The retry after a located change ends half an
    onset step before it, so the step that crosses it is the onset step itself (it was the change's time plus half
    an onset step, minus t, a few ulps off the onset step, and 34 % of those crossings were refused as longer than
    it)."""
    d = t_cross - t
    if d <= 0.0:
        return h
    if not over_onset(d, h_onset):
        return min(h, h_onset)
    return min(h, max(h_onset, d - 0.5 * h_onset))


@numba.njit(cache=True, inline="always")
def _passed(misses, verdict, t, h, t_cross, cnt):  # pragma: no cover - compiled
    """The predicted contact changes passed without one, after the accepted step of length ``h`` from ``t``
    (``verdict`` 3: a contact changed in it, counted, and the count restarts; a step across ``t_cross`` without a
    change adds one; :func:`_onset_ahead` stops predicting at :data:`AHEAD_MISSES`)."""
    if verdict == 3:
        cnt[5] += 1  # contact changes (dp5's counter)
        return 0
    if t < t_cross <= t + h:
        return misses + 1
    return misses


@numba.njit(cache=True, inline="always")
def _next_step(err, err_old, held, h, h_onset, f0, f1, floor, force_jump):  # pragma: no cover - compiled
    """The trial step after an accepted one of length ``h`` with error ``err``, and the controller's error to keep:
    Hairer's PI controller (no growth after a refusal, ``held``) bounded by :func:`_jump_bound`."""
    fac = max(1.0 if held else 0.1, min(5.0, err ** 0.22 / err_old ** 0.04 / 0.9))
    return min(h / fac, _jump_bound(h, h_onset, f0, f1, floor, force_jump)), max(err, 1e-4)


@numba.njit(cache=True, inline="always")
def _ark_stages(model_id, t, h, y, p, log, f, ki, yt, ynew, work):  # pragma: no cover - compiled
    """Stages 2 .. 6 of one step of length h from (t, y), with f[0] = f(y) and ki[0] = f_I(y): f(Y_i) into f[i],
    f_I(Y_i) into ki[i], the new state y + h sum b_i f(Y_i) into ``ynew``."""
    n = y.shape[0]
    for i in range(1, 6):
        for q in range(n):
            acc = 0.0
            for j in range(i):
                acc += AE[i, j] * (f[j, q] - ki[j, q]) + AI[i, j] * ki[j, q]
            yt[q] = y[q] + h * acc
        model_stage(model_id, t + C[i] * h, yt, p, log, h * GAMMA, ki[i], f[i], work)
    for q in range(n):
        acc = 0.0
        for j in range(6):
            acc += B[j] * f[j, q]
        ynew[q] = y[q] + h * acc


#: Regula falsi iterations that refine a located contact change on the step's cubic Hermite interpolant.
ONSET_ITERATIONS = 3


@numba.njit(cache=True, inline="always")
def _onset_retry(model_id, p, t, h, y, ynew, f0, f1, h_onset, t_cross, g0, g1, yt):  # pragma: no cover - compiled
    """Where to retry a step refused because a contact opened or closed in it (longer than ``h_onset``):
    (the retry's length, the estimated time of the change). The change is located on the contact gaps at the
    step's two ends (the earliest sign change of the straight line between them), then refined by
    :data:`ONSET_ITERATIONS` steps of the Illinois regula falsi on that gap along the step's cubic Hermite
    interpolant (y, ynew and their derivatives ``f0``, ``f1``; ``yt`` is scratch): the gaps are not linear
    in time across a 20 us step, and a change located past its time made the retry cross it and be refused
    again. The retry ends half an onset step before the change, and the step after it is held to end half an
    onset step past it (the loop's ``t_cross``), so that the change is crossed by one short step instead of
    by a run of onset steps. Where the change lies within 1.5 onset steps of the start the retry is the onset
    step itself, as DP5's, and the change stays located (:func:`_toward_change` crosses it at the onset step);
    without one located, the onset step, and ``t_cross`` as it was."""
    model_gaps(model_id, y, p, g0)
    model_gaps(model_id, ynew, p, g1)
    frac = 1.0
    found = -1
    for i in range(g0.shape[0]):
        if (g0[i] > 0.0) != (g1[i] > 0.0):
            f_i = g0[i] / (g0[i] - g1[i])
            if f_i < frac or found < 0:
                found, frac = i, f_i
    if found < 0:
        return h_onset, t_cross
    lo, hi, g_lo, g_hi = 0.0, 1.0, g0[found], g1[found]
    side = 0
    for _ in range(ONSET_ITERATIONS):
        _hermite(t, h, y, ynew, f0, f1, t + frac * h, yt)
        model_gaps(model_id, yt, p, g1)
        g = g1[found]
        if (g > 0.0) == (g_lo > 0.0):
            lo, g_lo = frac, g
            if side == -1:
                g_hi *= 0.5  # Illinois: halve the end that stayed, so that both ends move
            side = -1
        else:
            hi, g_hi = frac, g
            if side == 1:
                g_lo *= 0.5
            side = 1
        frac = lo + g_lo / (g_lo - g_hi) * (hi - lo)
    if frac * h - 0.5 * h_onset <= h_onset:
        return h_onset, t + frac * h
    return frac * h - 0.5 * h_onset, t + frac * h


#: Predicted contact changes in a row that :func:`_onset_ahead` may see passed without one before it stops
#: predicting (until a change is accepted or none is predicted).
AHEAD_MISSES = 2


@numba.njit(cache=True, inline="always")
def _onset_ahead(model_id, p, t, h, y, f0, h_onset, t_cross, misses, g0, g1, yt):  # pragma: no cover - compiled
    """A step of length ``h`` shortened to end half an onset step before a contact change predicted inside it
    (the gaps at y and at the Euler predictor y + h f0, the earliest sign change of the straight line between
    them), with the change's time for the loop's ``t_cross``, and the loop's ``misses`` (predicted changes passed
    without one, :func:`_passed`): ``(h, t_cross, misses)`` unchanged when a change is already located ahead or
    the step is an onset step at most, ``(h, -inf, 0)`` when none is predicted, and ``(h_onset, the change's time,
    misses)`` when one is predicted within 2.5 onset steps of the start: the onset step, which may cross it.
    Without it every contact change cost a refused step first; before the last case (the step was taken whole, and
    refused by the onset control or, first, by the error test) 221 onset and 135 error refusals per 293 contact
    changes over 100 ms settled at 3000 rpm, 500 N (planar), after it 70 onset refusals. After
    :data:`AHEAD_MISSES` predictions in a row passed without a change it predicts nothing (``(h, -inf,
    misses)``) until none is predicted: a gap that closes towards zero without crossing it (a grazing contact)
    would otherwise keep predicting a change within 2.5 onset steps, and hold the loop at onset steps."""
    if h_onset <= 0.0 or t_cross > t or not over_onset(h, h_onset):
        return h, t_cross, misses
    for i in range(y.shape[0]):
        yt[i] = y[i] + h * f0[i]
    model_gaps(model_id, y, p, g0)
    model_gaps(model_id, yt, p, g1)
    frac = 2.0
    for i in range(g0.shape[0]):
        if (g0[i] > 0.0) != (g1[i] > 0.0):
            frac = min(frac, g0[i] / (g0[i] - g1[i]))
    if frac > 1.0:
        return h, -np.inf, 0
    if misses >= AHEAD_MISSES:
        return h, -np.inf, misses
    if frac * h - 0.5 * h_onset <= 2.0 * h_onset:  # too close to split: the onset step, which may cross it
        return h_onset, t + frac * h, misses
    return frac * h - 0.5 * h_onset, t + frac * h, misses


@numba.njit(cache=True, inline="always")
def _ark_error(model_id, p, h, y, ynew, f, atol, rtol, e):  # pragma: no cover - compiled
    """The RMS of err_i / (atol_i + rtol max(|y_i|, |ynew_i|)) of the embedded order-3 estimate
    h sum_j (b_j - b_hat_j) f(Y_j), filtered through the implicit part's stiffness at y
    (:func:`cageless.simulation.kernels.model_filter_error`); inf when the new state is not finite.
    ``e`` (n) is scratch."""
    n = y.shape[0]
    for q in range(n):
        if not np.isfinite(ynew[q]):
            return np.inf
        acc = 0.0
        for j in range(6):
            acc += _E[j] * f[j, q]
        e[q] = h * acc
    model_filter_error(model_id, y, p, h * GAMMA, e)
    err = 0.0
    for q in range(n):
        sc = atol[q] + rtol * max(abs(y[q]), abs(ynew[q]))
        err += (e[q] / sc) ** 2
    return np.sqrt(err / n)
