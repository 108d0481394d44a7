"""Faster forms of the selection's arithmetic give the very values of the plain numpy/OpenCV forms they replace.

References: numpy's own ``polyfit``, ``unwrap`` and ``median``, and the Hessian eigenvalue written out as
before (``Sobel(...) * 0.25``, then the closed-form smaller eigenvalue of a symmetric 2 x 2 matrix).
"""

from __future__ import annotations

import cv2
import numpy as np
import pytest

from cageless.tracking.candidates import _hessian_min
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
