"""Stage 5: revolution speed and slip from the unwrapped orbital angles.

The revolution speed is a Savitzky-Golay derivative of the unwrapped angle:
a polynomial of order ``polyorder`` fitted by least squares over ``window``
frames centred on each sample. The window is the accuracy-versus-noise knob
(benchmarked by ``cageless bench tracking``). Time comes from the reader's time
vector: when frames were dropped the angle is resampled onto a uniform grid at
the median frame period, differentiated there and sampled back.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
from typing import Any

import numba
import numpy as np
import numpy.typing as npt

from cageless.errors import ParameterError

__all__ = ["DEFAULT_WINDOW", "DEFAULT_TRACK_FIT", "revolution_speed", "robust_track_fit"]

#: Default Savitzky-Golay window (frames): 2.1 ms at 10 kfps.
DEFAULT_WINDOW = 21
#: Default window of :func:`robust_track_fit` (frames).
DEFAULT_TRACK_FIT = 7
#: Biweight cut-off of :func:`robust_track_fit` in robust standard deviations (6: a Gaussian sample is cut
#: about once in 10^5; 4.685, the 95 %-efficiency value, cut a few in 10^3 of a 7-point window's samples),
#: and the smallest scale it uses (rad; far below any localisation noise, above a quadratic's model error).
_BIWEIGHT_C = 6.0
_SCALE_FLOOR_RAD = 1e-5

_UNIFORM_TOL = 1e-3


def _savgol_filter(*args: Any, **kwargs: Any) -> npt.NDArray[np.float64]:
    """:func:`scipy.signal.savgol_filter`, imported on first use: ``scipy.signal`` takes 1.4-1.6 s of CPU to
    import (it imports ``scipy.stats``), which a cold ``cageless track`` would otherwise spend before its first
    frame; :func:`cageless.tracking.pipeline.track_video` imports it in a thread while the frames are tracked."""
    from scipy.signal import savgol_filter

    return savgol_filter(*args, **kwargs)  # type: ignore[no-any-return]


def revolution_speed(time_s: npt.ArrayLike, angle: npt.ArrayLike, window: int = DEFAULT_WINDOW,
                     polyorder: int = 2) -> npt.NDArray[np.float64]:
    """Savitzky-Golay derivative d(angle)/dt along axis 0 (rad/s).

    Parameters
    ----------
    time_s
        Sample times (s), increasing, shape (T,).
    angle
        Unwrapped angles (rad), shape (T,) or (T, Z).
    window
        Odd window length in frames, > polyorder.
    polyorder
        Polynomial order.
    """
    t = np.asarray(time_s, dtype=np.float64)
    a = np.asarray(angle, dtype=np.float64)
    if window % 2 == 0 or window <= polyorder:
        raise ParameterError("window", f"must be odd and larger than polyorder = {polyorder}", window)
    if len(t) < window:
        raise ParameterError("window", f"needs at least {window} frames; the video has {len(t)}", window)
    dt = np.diff(t)
    step = float(np.median(dt))
    if np.all(np.abs(dt - step) <= _UNIFORM_TOL * step):
        return _savgol_filter(a, window, polyorder, deriv=1, delta=step, axis=0, mode="interp")
    grid = np.arange(t[0], t[-1] + 0.5 * step, step)
    flat = a.reshape(len(t), -1)
    resampled = np.column_stack([np.interp(grid, t, flat[:, j]) for j in range(flat.shape[1])])
    d = _savgol_filter(resampled, window, polyorder, deriv=1, delta=step, axis=0, mode="interp")
    back = np.column_stack([np.interp(t, grid, d[:, j]) for j in range(d.shape[1])])
    return back.reshape(a.shape)


def robust_track_fit(time_s: npt.ArrayLike, angle: npt.ArrayLike, valid: npt.ArrayLike, frames: int = 7,
                     passes: int = 3, exact: bool = True, workers: int = 2
                     ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.bool_]]:
    """Each ball's angle from a robust local quadratic over ``frames`` frames around each sample.

    Over a few frames a ball moves along its circle at nearly constant speed, so its angle is a
    quadratic in time to far better than the localisation noise. Each sample's angle becomes the value
    at its time of the quadratic fitted to the ``frames`` nearest samples (a window cut short at the
    clip's ends slides inwards), with Tukey biweight weights (c = 6 robust standard deviations of
    the ball's residuals, re-weighted ``passes`` times; Holland & Welsch 1977): a sample that leaves its
    ball's path (a glint or a speck crossing the highlight) gets no weight and is reported not valid;
    samples already not valid (interpolated) get no weight from the start. ``frames = 1`` returns the
    input.

    Parameters
    ----------
    time_s
        Sample times (s), shape (T,).
    angle
        Unwrapped angles (rad), shape (T, Z).
    valid
        Measured (True) or interpolated (False) samples, shape (T, Z).
    frames
        Odd window length (frames), at least 5 (3 points fit a quadratic exactly).
    passes
        Biweight re-weightings.
    exact
        True: compiled (:func:`_robust_columns`, each row's 3 x 3 normal equations solved by hand); False: the
        same fit by numpy's matrix products and LAPACK's solve, column by column (kept as the reference the
        compiled form is tested against: the same fit to rounding, the same samples dropped).
    workers
        Threads the compiled fits of the columns are shared among (each column's fit is independent: the same
        values with any number); used from :data:`_SPLIT_SAMPLES` samples on.

    Returns
    -------
    angle, valid
        The fitted angles and the validity with the rejected samples cleared.
    """
    t = np.asarray(time_s, dtype=np.float64)
    a = np.asarray(angle, dtype=np.float64)
    ok = np.asarray(valid, dtype=bool)
    if frames == 1:
        return a.copy(), ok.copy()
    if frames % 2 == 0 or frames < 5:
        raise ParameterError("track_fit", "must be 1 (off) or odd and at least 5", frames)
    n = len(t)
    if n < frames:
        return a.copy(), ok.copy()
    start = np.clip(np.arange(n) - frames // 2, 0, n - frames)
    idx = start[:, None] + np.arange(frames)[None, :]  # (T, frames)
    step = float(np.median(np.diff(t))) if n > 1 else 1.0
    x = (t[idx] - t[:, None]) / step  # frames from each sample, (T, frames)
    design = np.stack([np.ones_like(x), x, x * x], axis=-1)  # (T, frames, 3)
    out = a.copy()
    keep = ok.copy()
    if exact:
        _robust_columns_split(design, a, ok, start, idx, passes, out, keep, workers)
    else:
        _robust_columns_numpy(design, a, ok, start, idx, passes, out, keep)
    return out, keep


#: Samples (rows x columns) from which :func:`robust_track_fit` shares its columns among threads (a thread's
#: start costs about 0.1 ms; the fits about 0.4 us a sample).
_SPLIT_SAMPLES = 20_000


def _robust_columns_split(design: np.ndarray, a: np.ndarray, ok: np.ndarray, start: np.ndarray, idx: np.ndarray,
                          passes: int, out: np.ndarray, keep: np.ndarray, workers: int) -> None:
    """:func:`_robust_columns` on ``workers`` threads, each on a contiguous copy of its share of the columns (the
    compiled kernel releases the GIL; the copies keep its one compiled signature), written back in place."""
    k = max(1, min(workers, a.shape[1], a.size // _SPLIT_SAMPLES))
    if k == 1:
        _robust_columns(design, a, ok, start, idx, passes, out, keep)
        return
    bounds = np.linspace(0, a.shape[1], k + 1).astype(int)

    def part(span: tuple[int, int]) -> tuple[np.ndarray, np.ndarray]:
        cols = slice(*span)
        o, kp = np.ascontiguousarray(out[:, cols]), np.ascontiguousarray(keep[:, cols])
        _robust_columns(design, np.ascontiguousarray(a[:, cols]), np.ascontiguousarray(ok[:, cols]), start, idx,
                        passes, o, kp)
        return o, kp

    spans = list(zip(bounds[:-1].tolist(), bounds[1:].tolist(), strict=True))
    with ThreadPoolExecutor(max_workers=k) as pool:
        for (j0, j1), (o, kp) in zip(spans, pool.map(part, spans), strict=True):
            out[:, j0:j1] = o
            keep[:, j0:j1] = kp


def _robust_columns_numpy(design: np.ndarray, a: np.ndarray, ok: np.ndarray, start: np.ndarray, idx: np.ndarray,
                          passes: int, out: np.ndarray, keep: np.ndarray) -> None:
    """:func:`_robust_columns` by numpy's matrix products and LAPACK's solve (``exact=False`` of
    :func:`robust_track_fit`, the reference the compiled form is tested against), into ``out`` and ``keep``."""
    n = len(start)
    for j in range(a.shape[1]):
        y = a[idx, j]
        base = ok[idx, j].astype(np.float64)
        w = base.copy()
        for _ in range(passes):
            fit = _weighted_quadratic(design, y, w)
            res = y - (design @ fit[..., None])[..., 0]
            centre_res = res[np.arange(n), np.arange(n) - start]
            scale = 1.4826 * float(np.median(np.abs(centre_res[ok[:, j]]))) if ok[:, j].any() else 0.0
            scale = max(scale, _SCALE_FLOOR_RAD)
            u = res / (_BIWEIGHT_C * scale)
            w = base * np.where(np.abs(u) < 1.0, (1.0 - u * u) ** 2, 0.0)
        fit = _weighted_quadratic(design, y, w)
        good = (w > 0).sum(axis=1) >= 3
        out[good, j] = fit[good, 0]
        own = w[np.arange(n), np.arange(n) - start]
        keep[:, j] = ok[:, j] & (own > 0)


def _weighted_quadratic(design: np.ndarray, y: np.ndarray, w: np.ndarray) -> np.ndarray:
    """Weighted least-squares quadratic coefficients for each row (a tiny ridge keeps a starved row solvable), by
    matrix products and LAPACK (``exact=False`` of :func:`robust_track_fit`)."""
    dwt = (design * w[..., None]).transpose(0, 2, 1)
    lhs = dwt @ design + 1e-9 * np.eye(3)
    rhs = (dwt @ y[..., None])[..., 0]
    return np.linalg.solve(lhs, rhs[..., None])[..., 0]


@numba.njit(cache=True, nogil=True)
def _solve3(m, b):  # pragma: no cover - compiled
    """``m x = b`` for one 3 x 3 system (``m`` and ``b`` are overwritten): Gaussian elimination with partial
    pivoting, as LAPACK's ``dgesv`` does it, though not in its exact order of operations."""
    for k in range(3):
        p = k
        for i in range(k + 1, 3):
            if abs(m[i, k]) > abs(m[p, k]):
                p = i
        if p != k:
            for c in range(3):
                m[k, c], m[p, c] = m[p, c], m[k, c]
            b[k], b[p] = b[p], b[k]
        for i in range(k + 1, 3):
            f = m[i, k] / m[k, k]
            for c in range(k + 1, 3):
                m[i, c] -= f * m[k, c]
            b[i] -= f * b[k]
    x = np.empty(3)
    for k in range(2, -1, -1):
        acc = b[k]
        for c in range(k + 1, 3):
            acc -= m[k, c] * x[c]
        x[k] = acc / m[k, k]
    return x


@numba.njit(cache=True, nogil=True)
def _quadratic_fits(design, y, w, fit):  # pragma: no cover - compiled
    """Each row's weighted least-squares quadratic into ``fit`` (T, 3): :func:`_weighted_quadratic`'s normal
    equations and ridge, solved by :func:`_solve3`."""
    lhs, rhs = _normal_equations(design, w, y)
    for t in range(w.shape[0]):
        for a in range(3):
            lhs[t, a, a] += 1e-9
        fit[t] = _solve3(lhs[t], rhs[t])


@numba.njit(cache=True, nogil=True)
def _robust_columns(design, a, ok, start, idx, passes, out, keep):  # pragma: no cover - compiled
    """:func:`robust_track_fit`'s passes for every column of ``a`` (T, Z), into ``out`` and ``keep`` (in place):
    the numpy form's arithmetic, its residuals summed over the three coefficients in order, but its solves
    those of :func:`_solve3` (the fitted angles differ from LAPACK's in the last bits; 5x less CPU)."""
    n, m = idx.shape
    y = np.empty((n, m))
    base = np.empty((n, m))
    w = np.empty((n, m))
    fit = np.empty((n, 3))
    centre = np.empty(n)
    for j in range(a.shape[1]):
        for t in range(n):
            for k in range(m):
                y[t, k] = a[idx[t, k], j]
                base[t, k] = 1.0 if ok[idx[t, k], j] else 0.0
                w[t, k] = base[t, k]
        for _ in range(passes):
            _quadratic_fits(design, y, w, fit)
            cnt = 0
            for t in range(n):
                if ok[t, j]:
                    kk = t - start[t]
                    r = y[t, kk] - (design[t, kk, 0] * fit[t, 0] + design[t, kk, 1] * fit[t, 1]
                                    + design[t, kk, 2] * fit[t, 2])
                    centre[cnt] = abs(r)
                    cnt += 1
            scale = 1.4826 * np.median(centre[:cnt]) if cnt > 0 else 0.0
            scale = max(scale, _SCALE_FLOOR_RAD)
            for t in range(n):
                for k in range(m):
                    r = y[t, k] - (design[t, k, 0] * fit[t, 0] + design[t, k, 1] * fit[t, 1]
                                   + design[t, k, 2] * fit[t, 2])
                    u = r / (_BIWEIGHT_C * scale)
                    w[t, k] = base[t, k] * ((1.0 - u * u) ** 2 if abs(u) < 1.0 else 0.0)
        _quadratic_fits(design, y, w, fit)
        for t in range(n):
            used = 0
            for k in range(m):
                if w[t, k] > 0:
                    used += 1
            if used >= 3:
                out[t, j] = fit[t, 0]
            keep[t, j] = ok[t, j] and w[t, t - start[t]] > 0


@numba.njit(cache=True, nogil=True)
def _normal_equations(design, w, y):  # pragma: no cover - compiled
    """``lhs[t] = sum_k w[t, k] d d^T`` and ``rhs[t] = sum_k w[t, k] d y[t, k]`` with ``d = design[t, k]``: the
    values of ``np.einsum("tkp,tkq->tpq", design * w[..., None], design)`` and ``np.einsum("tkp,tk->tp", ...)``
    bit for bit (the same products, summed over ``k`` in order from 0; tested), without their cost: the two
    einsums were 2.1 of the 3.9 s that fitting and writing took in a cold run on 4,000 full-size frames
    (the three robust fits of the orbit, the place bias and the angles)."""
    n, m, p = design.shape
    lhs = np.zeros((n, p, p))
    rhs = np.zeros((n, p))
    for t in range(n):
        for k in range(m):
            for a in range(p):
                da = design[t, k, a] * w[t, k]
                for b in range(p):
                    lhs[t, a, b] += da * design[t, k, b]
                rhs[t, a] += da * y[t, k]
    return lhs, rhs
