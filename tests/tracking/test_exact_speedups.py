"""Faster forms of the selection's arithmetic give the very values of the plain numpy/OpenCV forms they replace.

References: numpy's own ``polyfit``, ``unwrap`` and ``median``, the Hessian eigenvalue written out as
before (``Sobel(...) * 0.25``, then the closed-form smaller eigenvalue of a symmetric 2 x 2 matrix), and the
centroid's local background as commit 5920b3c computed it.
"""

from __future__ import annotations

import cv2
import numba
import numpy as np
import pytest

from cageless.tracking.candidates import _hessian_min
from cageless.tracking.detect import (NO_STATIC, _local_background, _span, _static_at, _window_has_static,
                                      compiled_static)
from cageless.tracking.select import _median, _slope, _unwrap


def _hessian_min_plain(img: np.ndarray, sigma: float) -> np.ndarray:
    g = cv2.GaussianBlur(img, (0, 0), sigma, borderType=cv2.BORDER_REPLICATE)
    dxx = cv2.Sobel(g, cv2.CV_32F, 2, 0, ksize=3, borderType=cv2.BORDER_REPLICATE) * 0.25
    dyy = cv2.Sobel(g, cv2.CV_32F, 0, 2, ksize=3, borderType=cv2.BORDER_REPLICATE) * 0.25
    dxy = cv2.Sobel(g, cv2.CV_32F, 1, 1, ksize=3, borderType=cv2.BORDER_REPLICATE) * 0.25
    a, c = -dxx, -dyy
    half = 0.5 * (a - c)
    return (sigma * sigma) * (0.5 * (a + c) - np.sqrt(half * half + dxy * dxy))


@pytest.mark.parametrize("sigma", [0.8, 1.5, 3.1, 6.0])
def test_hessian_min_is_bit_identical_to_the_plain_formula(sigma):
    rng = np.random.default_rng(7)
    img = rng.normal(0.0, 40.0, (121, 157)).astype(np.float32)
    yy, xx = np.mgrid[0:121, 0:157]
    img += (900.0 * np.exp(-((xx - 60.3) ** 2 + (yy - 50.7) ** 2) / (2 * 3.0**2))).astype(np.float32)
    assert _hessian_min(img, sigma).tobytes() == _hessian_min_plain(img, sigma).tobytes()


def test_tracklet_fits_are_bit_identical_to_numpy():
    rng = np.random.default_rng(3)
    for k in range(2000):
        n = int(rng.integers(3, 70))
        x = np.cumsum(rng.uniform(0.5e-4, 2e-4, n))
        x = x - x.mean()
        # angles near +-pi (wrapped by arctan2), some jumpy, some smooth
        th = np.arctan2(np.sin(3.0 + rng.normal(0, 0.05 if k % 2 else 1.5, n).cumsum()),
                        np.cos(3.0 + rng.normal(0, 0.05 if k % 2 else 1.5, n).cumsum()))
        assert _unwrap(th).tobytes() == np.unwrap(th).tobytes()
        y = np.unwrap(th)
        assert np.float64(_slope(x, y)).tobytes() == np.float64(np.polyfit(x, y, 1)[0]).tobytes()
        vals = list(rng.exponential(4.0, n))
        assert np.float64(_median(vals)).tobytes() == np.float64(np.median(vals)).tobytes()


def _prefix_argmax_loop(x: np.ndarray) -> np.ndarray:
    out = np.zeros(x.size, dtype=np.int64)
    best = 0
    for i in range(x.size):
        if x[i] > x[best]:
            best = i
        out[i] = best
    return out


def test_prefix_argmax_matches_the_loop_with_ties_and_minus_infinity():
    from cageless.tracking.cyclic import _prefix_argmax

    rng = np.random.default_rng(5)
    for _ in range(3000):
        n = int(rng.integers(0, 40))
        x = rng.integers(-3, 4, n).astype(np.float64)  # many ties
        x[rng.random(n) < 0.3] = -np.inf
        assert np.array_equal(_prefix_argmax(x), _prefix_argmax_loop(x))


@pytest.mark.parametrize("frames", [5, 7, 11])
def test_track_fit_normal_equations_are_bit_identical_to_einsum(frames):
    """The compiled normal equations of the robust track fit (tracking.kinematics._normal_equations) give the very
    values of the two ``np.einsum`` calls they replace, zero weights, large and tiny values included."""
    from cageless.tracking.kinematics import _normal_equations

    rng = np.random.default_rng(frames)
    t = 3000
    x = np.arange(frames) - frames // 2 + rng.normal(0.0, 1e-3, (t, frames))
    design = np.stack([np.ones_like(x), x, x * x], axis=-1)
    w = rng.random((t, frames)) * np.exp(rng.normal(0.0, 3.0, (t, frames)))
    w[rng.random((t, frames)) < 0.2] = 0.0
    y = rng.normal(0.0, 1.0, (t, frames)) * 10.0 ** rng.integers(-6, 4, (t, 1)) + rng.uniform(-50, 50, (t, 1))
    dw = design * w[..., None]
    lhs, rhs = _normal_equations(design, w, y)
    assert lhs.tobytes() == np.einsum("tkp,tkq->tpq", dw, design).tobytes()
    assert rhs.tobytes() == np.einsum("tkp,tk->tp", dw, y).tobytes()


@numba.njit(cache=False)
def _local_background_whole_disc(frame, mask, u, v, r, ring, static):  # pragma: no cover - compiled
    """The local background as it was written before it skipped the window's own pixels (commit 5920b3c): every
    pixel of the outer disc visited, those inside the window left out one by one."""
    h, w = frame.shape
    ro = r + 2.0
    use = _window_has_static(static, u, v, ro)
    cnt = 0
    for y in range(max(int(np.floor(v - ro)), 0), min(int(np.ceil(v + ro)) + 1, h)):
        dy2 = (y - v) * (y - v)
        x0, x1 = _span(u, ro * ro, dy2, 0, w)
        i0, i1 = _span(u, r * r, dy2, 0, w)
        for x in range(x0, x1 + 1):
            if (i0 <= x <= i1 and (x - u) * (x - u) + dy2 <= r * r) or not mask[y, x]:
                continue
            ring[cnt] = frame[y, x] - _static_at(frame, static, y, x) if use else frame[y, x]
            cnt += 1
    return np.median(ring[:cnt]) if cnt >= 8 else np.nan


def test_local_background_skipping_the_window_is_bit_identical_to_the_whole_disc():
    rng = np.random.default_rng(11)
    h, w = 61, 67
    frame = rng.integers(0, 4096, (h, w)).astype(np.uint16)
    mask = rng.random((h, w)) > 0.15  # holes everywhere, as static defects leave them
    pattern = np.zeros((h, w), np.float32)
    pattern[40:44, 5:12] = 37.5  # lint in one corner: windows there subtract it
    static = compiled_static((pattern, 3000.0))
    ring = np.empty(4096)
    checked = 0
    # Centres on and off the pixel grid, windows cut by the image edge, radii from a pixel to most of the image.
    for _ in range(4000):
        u, v = rng.uniform(-3.0, w + 3.0), rng.uniform(-3.0, h + 3.0)
        if rng.random() < 0.2:
            u, v = float(round(u)), float(round(v))
        r = float(rng.choice([0.5, 1.0, 2.0, 3.7, 7.0, 22.257856953523373, 30.0]))
        for st in (NO_STATIC, static):
            new = _local_background(frame, mask, u, v, r, ring, st)
            old = _local_background_whole_disc(frame, mask, u, v, r, ring, st)
            assert np.float64(new).tobytes() == np.float64(old).tobytes(), (u, v, r)
            checked += np.isfinite(old)
    assert checked > 4000  # most windows had their 8 ring pixels: the medians compared are real ones


def _window_case(rng: np.random.Generator, holes: bool) -> tuple:
    """A 16-bit frame with a noisy Gaussian highlight, its background, a mask, and a window about the spot."""
    h, w = 90, 110
    yy, xx = np.mgrid[0:h, 0:w]
    u, v = float(rng.uniform(40, 70)), float(rng.uniform(35, 55))
    spot = 3000.0 * np.exp(-((xx - u - 0.4) ** 2 + (yy - v + 0.3) ** 2) / (2 * 4.0**2))
    frame = np.clip(800 + spot + rng.normal(0, 30, (h, w)), 0, 65535).astype(np.uint16)
    background = np.full((h, w), 800.0, np.float32) + rng.normal(0, 3, (h, w)).astype(np.float32)
    mask = np.ones((h, w), bool)
    if holes:
        mask[rng.random((h, w)) < 0.02] = False
    return frame, background, mask, u, v, float(rng.uniform(12, 24))


@numba.njit
def _pass_skipping(frame, background, mask, u, v, r, local, threshold):  # pragma: no cover - compiled
    """detect._pass without ``mirror`` and ``static`` as commit 6ed1501 wrote it: pixels at or below the threshold
    skipped."""
    h, w = frame.shape
    su = 0.0
    sv = 0.0
    m = 0.0
    holes = False
    for y in range(max(int(np.floor(v - r)), 0), min(int(np.ceil(v + r)) + 1, h)):
        dy2 = (y - v) * (y - v)
        x0, x1 = _span(u, r * r, dy2, 0, w)
        for x in range(x0, x1 + 1):
            if not mask[y, x]:
                holes = True
                continue
            base = local if np.isfinite(local) else background[y, x]
            wgt = np.float64(frame[y, x]) - base - threshold
            if wgt > 0.0:
                taper = 1.0 - ((x - u) * (x - u) + dy2) / (r * r)
                wgt *= taper * taper
                su += wgt * x
                sv += wgt * y
                m += wgt
    return su, sv, m, holes


def test_plain_centroid_pass_is_bit_identical_to_the_skipping_form():
    """detect._pass_plain adds +0.0 for a pixel at or below the threshold instead of skipping it: the same sums
    bit for bit as the skipping loop of commit 6ed1501 (written out above)."""
    from cageless.tracking.detect import _pass_plain

    rng = np.random.default_rng(11)
    for k in range(300):
        frame, background, mask, u, v, r = _window_case(rng, holes=k % 2 == 1)
        for local in (float(rng.uniform(780, 820)), np.nan):
            got = _pass_plain(frame, background, mask, u, v, r, local, 60.0, NO_STATIC, False)
            want = _pass_skipping(frame, background, mask, u, v, r, local, 60.0)
            assert np.array(got[:3]).tobytes() == np.array(want[:3]).tobytes() and got[3] == want[3]


def test_vectorised_centroid_pass_equals_the_plain_one_to_rounding():
    """detect._pass_fast reassociates the sums (fastmath): the same sums to rounding (relative 1e-12 here; the
    centroids move by up to 4e-12 px on the benchmark clip, benchmarks/centroid_replay.py) and the same holes."""
    from cageless.tracking.detect import _pass_fast, _pass_plain

    rng = np.random.default_rng(12)
    for k in range(300):
        frame, background, mask, u, v, r = _window_case(rng, holes=k % 2 == 1)
        local = float(rng.uniform(780, 820))
        fast = _pass_fast(frame, mask, u, v, r, local + 60.0)
        plain = _pass_plain(frame, background, mask, u, v, r, local, 60.0, NO_STATIC, False)
        assert np.allclose(fast[:3], plain[:3], rtol=1e-12, atol=0.0) and fast[3] == plain[3]


def test_track_fit_solve_matches_lapack():
    """kinematics._solve3 (Gaussian elimination with partial pivoting) against numpy.linalg.solve (LAPACK dgesv),
    on random systems and on ones that need a row swap (a zero leading pivot)."""
    from cageless.tracking.kinematics import _solve3

    rng = np.random.default_rng(13)
    for k in range(2000):
        m = rng.normal(size=(3, 3))
        if k % 4 == 0:
            m[0, 0] = 0.0
        b = rng.normal(size=3)
        want = np.linalg.solve(m, b)
        got = _solve3(m.copy(), b.copy())
        scale = np.linalg.cond(m) * np.abs(want).max()
        assert np.max(np.abs(got - want)) <= 1e-13 * scale
