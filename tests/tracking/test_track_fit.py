"""The robust local quadratic along each ball's track (tracking/kinematics.py: robust_track_fit)."""

from __future__ import annotations

import numpy as np
import pytest

from cageless.errors import ParameterError
from cageless.tracking.kinematics import robust_track_fit


def _clip(n: int = 2000, z: int = 3, seed: int = 0):
    t = np.arange(n) / 10_000.0
    # Cage-like motion with a real speed variation: 200 rad/s +- 10 % over a 100-frame period.
    omega, period = 200.0, 100 / 10_000.0
    truth = np.stack([omega * t + 0.1 * omega * period / (2 * np.pi) * np.sin(2 * np.pi * t / period + k)
                      for k in range(z)], axis=1)
    return t, truth, np.random.default_rng(seed)


def test_a_real_speed_variation_passes_unchanged():
    """Noise-free angles come back to far below the 0.5 mrad bar (a 7-frame quadratic cannot follow a
    100-frame period exactly: its error is third order in the window)."""
    t, truth, _ = _clip()
    fit, valid = robust_track_fit(t, truth, np.ones_like(truth, bool))
    assert np.max(np.abs(fit - truth)) < 2e-5
    assert valid.all()


def test_white_noise_falls_to_the_savitzky_golay_factor():
    """With white noise the centre estimate of a 7-point least-squares quadratic has variance 1/3 of the
    noise (Savitzky & Golay 1964, Anal. Chem. 36, 1627, table I: weights (-2, 3, 6, 7, 6, 3, -2) / 21, whose
    squares sum to 147 / 441). The biweight costs a few per cent of that on Gaussian noise."""
    t, truth, rng = _clip(20_000)
    noisy = truth + rng.normal(0, 1e-3, truth.shape)
    fit, _ = robust_track_fit(t, noisy, np.ones_like(truth, bool))
    ratio = np.var((fit - truth)[10:-10]) / 1e-6
    assert 1 / 3 <= ratio <= 0.40


def test_a_sample_off_the_path_is_dropped():
    """A glint crossing the highlight for one frame moves it 20 noise sigmas: no weight, not valid, and the
    fitted angle there is the path's."""
    t, truth, rng = _clip(400)
    noisy = truth + rng.normal(0, 1e-4, truth.shape)
    noisy[200, 1] += 2e-3
    fit, valid = robust_track_fit(t, noisy, np.ones_like(truth, bool))
    assert not valid[200, 1] and valid.sum() >= truth.size - 3
    assert abs(fit[200, 1] - truth[200, 1]) < 2e-4


def test_window_must_be_odd_and_at_least_five():
    t, truth, _ = _clip(100)
    with pytest.raises(ParameterError, match="track_fit"):
        robust_track_fit(t, truth, np.ones_like(truth, bool), frames=4)
    same, _ = robust_track_fit(t, truth, np.ones_like(truth, bool), frames=1)
    assert np.array_equal(same, truth)


@pytest.mark.parametrize("frames", [7, 11, 21])
def test_matrix_product_form_equals_the_exact_one_to_rounding(frames):
    """``exact=False`` (matmul instead of einsum, for QC estimates) sums in another order: the same fit to
    rounding of the angles' size (here up to 40 rad: 1e-13 rad), the same samples dropped."""
    t, truth, rng = _clip(2000, z=4)
    noisy = truth + rng.normal(0, 1e-4, truth.shape)
    noisy[500, 2] += 5e-3
    valid = np.ones_like(truth, bool)
    valid[::37, 1] = False
    exact, keep = robust_track_fit(t, noisy, valid, frames)
    fast, keep_fast = robust_track_fit(t, noisy, valid, frames, exact=False)
    assert np.max(np.abs(fast - exact)) < 1e-11
    assert np.array_equal(keep, keep_fast) and not keep[500, 2]


@pytest.mark.parametrize("layout", ["C", "F"])
def test_columns_shared_among_threads_give_the_same_bits(layout):
    """Each ball's fit is independent of the others', so sharing the columns among threads (from
    ``_SPLIT_SAMPLES`` samples on) changes no bit of the angles or of the samples kept."""
    rng = np.random.default_rng(5)
    t = np.arange(5000) * 1e-4  # 70,000 samples: up to 3 threads
    angle = 95.0 * t[:, None] + rng.normal(0.0, 2e-4, (5000, 14)) + np.arange(14)[None, :]
    angle[rng.random(angle.shape) < 0.003] += 0.05  # samples off the path, which the fit drops
    valid = rng.random(angle.shape) > 0.02
    angle, valid = np.asarray(angle, order=layout), np.asarray(valid, order=layout)
    one = robust_track_fit(t, angle, valid, 7, workers=1)
    for workers in (2, 3, 14):
        many = robust_track_fit(t, angle, valid, 7, workers=workers)
        assert np.array_equal(many[0], one[0]) and np.array_equal(many[1], one[1])
    assert (~one[1] & valid).sum() > 0  # the dropping was exercised
