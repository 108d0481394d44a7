"""The track fit's window chosen by cross-validation (tracking/track_window.py)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from cageless.bearing import default_bearing
from cageless.errors import TrackingError
from cageless.tracking.kinematics import DEFAULT_TRACK_FIT, robust_track_fit
from cageless.tracking.pipeline import TrackOptions, _track_fit_frames
from cageless.tracking.synthetic.motion import KinematicLaw
from cageless.tracking.track_window import LADDER, _leverage, choose_track_fit

FPS = 10_000.0  # the paper's camera (Wang et al. 2026, sec. 4: 10,000 frames/s)


@pytest.mark.parametrize("frames", [7, 21, 41])
def test_leverage_is_the_savitzky_golay_centre_weight(frames):
    """With no sample dropped, a sample's leverage is the centre coefficient of the quadratic smoothing filter,
    3 (3 n^2 - 7) / (4 n (n^2 - 4)) (Savitzky & Golay 1964, Anal. Chem. 36, 1627: 7/21 = 1/3 for 7 points);
    a dropped neighbour raises it, a dropped sample has none."""
    keep = np.ones((100, 2), bool)
    n = float(frames)
    assert _leverage(keep, frames)[50, 0] == pytest.approx(3 * (3 * n * n - 7) / (4 * n * (n * n - 4)), rel=1e-12)
    keep[50, 0] = False
    h = _leverage(keep, frames)
    assert h[50, 0] == 0.0 and h[51, 0] > h[51, 1]


def test_white_noise_on_a_smooth_track_takes_the_longest_window():
    """Nothing but white noise to remove: the longest window wins, and its error is the noise times the square
    root of its leverage (0.0549 for 41 points; the biweight costs a few per cent)."""
    t = np.arange(4000) / FPS
    truth = np.stack([200.0 * t + 0.002 * np.sin(2 * np.pi * t / 0.05 + k) for k in range(4)], axis=1)
    noisy = truth + np.random.default_rng(1).normal(0, 1e-3, truth.shape)
    choice = choose_track_fit(t, noisy, np.ones_like(noisy, bool))
    assert choice.frames == max(LADDER) == 41
    fit, _ = robust_track_fit(t, noisy, np.ones_like(noisy, bool), choice.frames)
    ratio = np.var((fit - truth)[30:-30]) / 1e-6
    assert 0.0549 <= ratio <= 0.065


def _law(speed_rpm: float, noise_rad: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Three tenths of a second of the renderer's ball-motion law (14 balls, impacts between neighbours with
    restitution 0.6: speed jumps) at 10,000 frames/s, with white localisation noise."""
    t = np.arange(3000) / FPS
    truth = KinematicLaw(default_bearing().geometry, speed_rpm, seed=1).sample(t).angle
    return t, truth, truth + np.random.default_rng(0).normal(0, noise_rad, truth.shape)


def _rms_mrad(t: np.ndarray, noisy: np.ndarray, truth: np.ndarray, frames: int) -> float:
    fit, _ = robust_track_fit(t, noisy, np.ones_like(noisy, bool), frames)
    return float(1e3 * np.sqrt(np.mean((fit - truth)[30:-30] ** 2)))


@pytest.mark.parametrize(("speed_rpm", "noise_mrad", "frames", "gain"),
                         [(1800, 0.02, 7, 1.0), (3000, 0.02, 11, 1.05), (1800, 0.3, 21, 0.63), (6000, 0.3, 41, 0.43)])
def test_impacts_keep_the_window_short_and_noise_makes_it_long(speed_rpm, noise_mrad, frames, gain):
    """On the kinematic law's impacts (1800 r/min: 22.8 % peak slip, bunching balls) with little noise the
    choice stays at or near 7 frames; with 0.3 mrad of noise it grows, and the angle error falls to ``gain``
    times the fixed 7-frame fit's (measured: 0.0152 / 0.0152, 0.0133 / 0.0127, 0.111 / 0.178, 0.0752 / 0.177
    mrad RMS)."""
    t, truth, noisy = _law(speed_rpm, noise_mrad * 1e-3)
    choice = choose_track_fit(t, noisy, np.ones_like(noisy, bool))
    assert choice.frames == frames
    assert _rms_mrad(t, noisy, truth, frames) <= gain * _rms_mrad(t, noisy, truth, 7) + 1e-9


def test_a_short_clip_keeps_the_default_and_the_choice_is_deterministic():
    t = np.arange(30) / FPS
    a = np.outer(t, np.full(3, 200.0))
    choice = choose_track_fit(t, a, np.ones_like(a, bool))
    assert choice.frames == DEFAULT_TRACK_FIT and choice.cv_mrad == ()
    t, _, noisy = _law(3000, 1e-4)
    assert choose_track_fit(t, noisy, np.ones_like(noisy, bool)) == choose_track_fit(t, noisy,
                                                                                     np.ones_like(noisy, bool))


def test_the_option_takes_auto_or_a_fixed_window():
    """``TrackOptions.track_fit`` is ``"auto"`` by default; a number keeps that window (7: the old default);
    any other text is refused with the parameter's name and what to give."""
    assert TrackOptions().track_fit == "auto"
    t, _, noisy = _law(3000, 3e-4)
    ok = np.ones_like(noisy, bool)
    assert _track_fit_frames(Path("clip.cine"), t, noisy, ok, 7) == (7, None)
    frames, record = _track_fit_frames(Path("clip.cine"), t, noisy, ok, "auto")
    assert record is not None and frames == record["frames"] == 31
    with pytest.raises(TrackingError, match="track_fit = 'long' is not a window"):
        _track_fit_frames(Path("clip.cine"), t, noisy, ok, "long")
    with pytest.raises(TrackingError, match="track_fit = 4 is not a window"):
        _track_fit_frames(Path("clip.cine"), t, noisy, ok, 4)
    assert _track_fit_frames(Path("clip.cine"), t, noisy, ok, 1) == (1, None)
