"""The trace's self-assessed precision (tracking/precision.py) on tracks with known added noise.

Closed forms used: white noise of standard deviation sigma about a least-squares quadratic over N samples
leaves sigma sqrt(1 - h) at the centre sample, h its leverage (for N = 7, h = 7/21 = 1/3: the centre weight
of the 7-point quadratic Savitzky-Golay smoother, Savitzky & Golay 1964, table I); the slope of that fit
has standard deviation sigma sqrt(12 / (N (N^2 - 1))) per sample step; a per-frame least-squares fit of
3 parameters (radius, translation) to Z points leaves (Z - 3) / Z of their variance.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from cageless.tracking.precision import (ANGLE_GAIN, SPEED_GAIN, Precision, angle_noise, assess_precision,
                                         centre_leverage, precision_warning, radial_scatter, savgol_slope_gain)
from cageless.tracking.qc import QC_LIMITS

FPS = 10_000.0
T = 4000
Z = 12
OMEGA_C = 120.0  # rad/s, a cage at about 3000 r/min
RADIUS_PX = 150.0
CENTRE = (320.0, 240.0)


def _smooth_track(seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Times and (T, Z) angles: cage motion with a slow slip wave per ball (smooth at 10 kfps)."""
    rng = np.random.default_rng(seed)
    t = np.arange(T) / FPS
    phase = 2 * np.pi * np.arange(Z) / Z
    wobble = 0.02 * np.sin(2 * np.pi * 40 * t[:, None] + rng.uniform(0, 2 * np.pi, Z))  # 40 Hz, 20 mrad
    return t, phase + OMEGA_C * t[:, None] + wobble


def _positions(angle: np.ndarray, radial_px: np.ndarray | float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    r = RADIUS_PX + radial_px
    return CENTRE[0] + r * np.cos(angle), CENTRE[1] - r * np.sin(angle)


def test_closed_forms():
    assert centre_leverage(7) == pytest.approx(1 / 3, rel=1e-12)
    assert centre_leverage(11) == pytest.approx(89 / 429, rel=1e-12)  # Savitzky & Golay table I, 11 points
    for n in (7, 21, 31):
        assert savgol_slope_gain(n, 2) == pytest.approx(math.sqrt(12 / (n * (n * n - 1))), rel=1e-12)
        assert savgol_slope_gain(n, 1) == pytest.approx(math.sqrt(12 / (n * (n * n - 1))), rel=1e-12)


@pytest.mark.parametrize("sigma", [2e-5, 1e-4, 1e-3])
def test_white_noise_on_a_smooth_track_comes_back(sigma):
    t, a = _smooth_track()
    noisy = a + np.random.default_rng(1).normal(0, sigma, a.shape)
    got, jumps = angle_noise(t, noisy, np.ones(a.shape, bool))
    assert np.all(np.abs(got / sigma - 1) < 0.05)  # 4000 samples per ball: a 1.1 % standard error
    assert np.all(jumps < 1e-3)  # a Gaussian is beyond 5 sigma 6e-7 of the time


def test_noise_free_track_reads_far_below_any_bar():
    t, a = _smooth_track()
    got, _ = angle_noise(t, a, np.ones(a.shape, bool))
    assert np.all(got < 1e-6)  # the 40 Hz wobble's departure from a quadratic over 1.1 ms: < 1 urad


def test_interpolated_samples_do_not_count():
    t, a = _smooth_track()
    noisy = a + np.random.default_rng(2).normal(0, 1e-4, a.shape)
    valid = np.ones(a.shape, bool)
    valid[::5] = False
    noisy[::5] += 0.05  # wild values where the samples are marked interpolated
    got, _ = angle_noise(t, noisy, valid)
    assert np.all(np.abs(got / 1e-4 - 1) < 0.06)


def test_radial_scatter_is_the_noise_a_frame_fit_leaves():
    t, a = _smooth_track()
    rng = np.random.default_rng(3)
    sigma_px = 0.1
    u, v = _positions(a, rng.normal(0, sigma_px, a.shape))
    u += rng.normal(0, 2.0, (T, 1))  # each frame's own translation: removed by the frame fit
    v += rng.normal(0, 2.0, (T, 1))
    res = radial_scatter(u, v, np.ones(a.shape, bool), CENTRE, RADIUS_PX)
    rms = float(np.sqrt(np.mean(res**2)))
    assert rms == pytest.approx(sigma_px / RADIUS_PX * math.sqrt((Z - 3) / Z), rel=0.03)


def test_estimate_for_isotropic_white_noise():
    """Isotropic white noise sigma (px) on every highlight: the tangential view reads sigma / R, the radial
    view sqrt((Z - 3) / Z) of it; the trace's estimate is both in quadrature through the track fit."""
    t, a = _smooth_track()
    rng = np.random.default_rng(4)
    sigma_px = 0.05
    tangential = rng.normal(0, sigma_px, a.shape) / RADIUS_PX
    measured = a + tangential
    u, v = _positions(measured, rng.normal(0, sigma_px, a.shape))
    p = assess_precision(t, measured, np.ones(a.shape, bool), u, v, CENTRE, RADIUS_PX, OMEGA_C, 21, 2, 7)
    sigma = sigma_px / RADIUS_PX
    both = math.sqrt(1 + (Z - 3) / Z)
    assert p.noise_mrad == pytest.approx(1e3 * sigma, rel=0.03)
    assert p.angle_rms_mrad == pytest.approx(1e3 * ANGLE_GAIN * sigma * math.sqrt(1 / 3) * both, rel=0.05)
    slope = sigma * math.sqrt(12 / (21 * 440)) * FPS / OMEGA_C
    assert p.speed_rms_pct == pytest.approx(100 * SPEED_GAIN * slope * both, rel=0.05)


def test_too_short_or_no_speed_gives_no_estimate():
    t, a = _smooth_track()
    u, v = _positions(a)
    ok = np.ones(a.shape, bool)
    assert assess_precision(t[:10], a[:10], ok[:10], u[:10], v[:10], CENTRE, RADIUS_PX, OMEGA_C, 21) is None
    assert assess_precision(t, a, ok, u, v, CENTRE, RADIUS_PX, 0.0, 21) is None


def test_warning_names_the_number_the_bar_and_the_slip_uncertainty():
    quiet = Precision(0.3, 0.2, 0.3, 0.2, 0.4, 0.0)
    assert precision_warning(quiet, QC_LIMITS) is None
    loud = Precision(1.04, 0.62, 0.9, 0.8, 1.2, 0.001)
    text = precision_warning(loud, QC_LIMITS)
    assert "1.04 mrad" in text and "worse than 0.5 mrad" in text
    assert "0.62 %" in text and "worse than 0.5 %" in text and "uncertain to about 0.62 pp" in text
    speed_only = precision_warning(Precision(0.4, 0.7, 0.3, 0.2, 0.4, 0.0), QC_LIMITS)
    assert "worse than 0.5 mrad" not in speed_only and "0.70 % of the cage speed is worse than 0.5 %" in speed_only
