"""The per-frame step of :mod:`cageless.tracking.link`, compiled and run over blocks of frames.

:func:`run_block` tracks the frames of one ``(frames, rows, cols)`` block in one call: predict each
ball's angle (constant angular velocity), measure it with the weighted-centroid windows of
:func:`cageless.tracking.detect.centroid_windows` (the same compiled kernel), and update the state,
exactly as :func:`cageless.tracking.link._step` does with the ``"window"`` detector. It releases the
GIL, so segments tracked in threads run on both cores.

The rare frames that need more than the window (a ball lost for a few frames, looked for among the
blob candidates on the ball circle, or a full re-detection) are not handled here: the kernel stops
*before* such a frame, without changing the state, and returns its index; the caller runs the Python
step on it and resumes the kernel on the next frame.
"""

from __future__ import annotations

import numba
import numpy as np

from cageless.tracking.detect import _centroids

__all__ = ["run_block", "WIDEN_AFTER", "REDETECT_AFTER", "MAX_MASS_RATIO"]

#: The limits of :mod:`cageless.tracking.link` (defined here so that the compiled kernel sees constants).
WIDEN_AFTER = 3
REDETECT_AFTER = 12
MAX_MASS_RATIO = 4.0


@numba.njit(cache=True, nogil=True)
def _predict(theta, radius, omega, dt, cx, cy):  # pragma: no cover - compiled
    pred = theta + omega * dt
    return pred, cx + radius * np.cos(pred), cy - radius * np.sin(pred)


@numba.njit(cache=True, nogil=True)
def _measure(frame, bg, mask, pu, pv, omega, misses, ref_mass, half, thr, iters, lost_fraction,
             has_ring, static):  # pragma: no cover - compiled
    """Centroids at the predictions (re-centred first in a doubled window where the speed is not yet known,
    or, without a ball circle, after a few misses); return ``(mu, mv, mm, ok, needs_python)``."""
    z = pu.size
    hh = np.empty(z)
    grow = False
    for j in range(z):
        wide = omega[j] == 0.0 or (misses[j] >= WIDEN_AFTER and not has_ring)
        hh[j] = half * (2.0 if wide else 1.0)
        grow = grow or wide
    if grow:
        fu, fv, _ = _centroids(frame, bg, mask, pu, pv, hh, thr, 1, static)
        for j in range(z):
            if np.isfinite(fu[j]):
                pu[j] = fu[j]
            if np.isfinite(fv[j]):
                pv[j] = fv[j]
    mu, mv, mm = _centroids(frame, bg, mask, pu, pv, np.full(z, half), thr, iters, static)
    ok = np.empty(z, dtype=np.bool_)
    needs_python = False
    for j in range(z):
        ok[j] = mm[j] >= lost_fraction * ref_mass[j] and np.hypot(mu[j] - pu[j], mv[j] - pv[j]) <= half
        if has_ring:
            ok[j] = ok[j] and mm[j] <= MAX_MASS_RATIO * ref_mass[j]
            needs_python = needs_python or (not ok[j] and misses[j] + 1 >= WIDEN_AFTER)
        else:
            needs_python = needs_python or (not ok[j] and misses[j] + 1 >= REDETECT_AFTER)
    return mu, mv, mm, ok, needs_python


@numba.njit(cache=True, nogil=True)
def _update(i, t, dt, pred, mu, mv, mm, ok, cx, cy, theta, radius, omega, misses, ref_mass, out_u, out_v,
            out_m):  # pragma: no cover - compiled
    """Commit one frame's measurement to the state (in place) and to row ``i`` of the outputs."""
    for j in range(pred.size):
        if ok[j]:
            d = np.arctan2(-(mv[j] - cy), mu[j] - cx) - pred[j]
            new = pred[j] + np.arctan2(np.sin(d), np.cos(d))  # the angle of exp(1j d): d wrapped to (-pi, pi]
        else:
            new = pred[j]
        if dt != 0.0 and ok[j]:
            rate = (new - theta[j]) / dt
            omega[j] = rate if omega[j] == 0.0 else 0.5 * omega[j] + 0.5 * rate
        theta[j] = new
        if ok[j]:
            radius[j] = np.hypot(mu[j] - cx, mv[j] - cy)
            misses[j] = 0
            ref_mass[j] = 0.9 * ref_mass[j] + 0.1 * mm[j]
            out_u[i, j], out_v[i, j], out_m[i, j] = mu[j], mv[j], mm[j]
        else:
            misses[j] += 1
            out_u[i, j], out_v[i, j], out_m[i, j] = np.nan, np.nan, 0.0


@numba.njit(cache=True, nogil=True)
def run_block(stack, k0, k1, step, frame0, times, bg, mask, cx, cy, half, thr, iters, lost_fraction, has_ring,
              theta, radius, omega, misses, ref_mass, t_state, out_u, out_v, out_m, static):  # pragma: no cover
    """Track ``stack[k]`` for ``k = k0, k0 + step, ...`` up to (not including) ``k1``; frame ``k`` is row
    ``frame0 + k`` of ``times`` and the outputs; ``static``, ``(pattern, clip)``, is subtracted from every pixel
    read below ``clip`` (:data:`~cageless.tracking.detect.NO_STATIC`: none).

    The state arrays (``theta``, ``radius``, ``omega``, ``misses``, ``ref_mass`` and the one-element
    ``t_state``) are updated in place. Returns ``k1`` when done, or the first ``k`` that needs the Python
    step (its state untouched).
    """
    for k in range(k0, k1, step):
        i = frame0 + k
        t = times[i]
        dt = t - t_state[0]
        pred, pu, pv = _predict(theta, radius, omega, dt, cx, cy)
        mu, mv, mm, ok, needs_python = _measure(stack[k], bg, mask, pu, pv, omega, misses, ref_mass, half, thr,
                                                iters, lost_fraction, has_ring, static)
        if needs_python:
            return k
        _update(i, t, dt, pred, mu, mv, mm, ok, cx, cy, theta, radius, omega, misses, ref_mass, out_u, out_v, out_m)
        t_state[0] = t
    return k1
