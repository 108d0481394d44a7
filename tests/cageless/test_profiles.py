"""Angle profiles: binning, mean and spread against values computed by hand."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cageless.errors import ParameterError
from cageless.profiles import angle_profile, peak_standard_error


def test_profile_by_hand():
    # Angles 0.5, 0.7 and 360.5 deg fall in bin 0 (values 1, 3, 5: mean 3, sample std 2); 90.2 deg in bin 90.
    a = np.radians([0.5, 0.7, 360.5, 90.2])
    p = angle_profile(a, [1.0, 3.0, 5.0, 7.0])
    assert len(p) == 360
    assert p.loc[0, "angle_deg"] == 0.5
    assert (p.loc[0, "mean"], p.loc[0, "std"], p.loc[0, "count"]) == (3.0, 2.0, 3)
    assert p.loc[90, "mean"] == 7.0 and np.isnan(p.loc[90, "std"])
    assert p["count"].sum() == 4 and np.isnan(p.loc[200, "mean"])


def test_profile_mask_nan_and_bins():
    a = np.radians([[10.0, 10.0], [20.0, 20.0]])
    v = np.array([[1.0, np.nan], [2.0, 4.0]])
    p = angle_profile(a, v, bin_deg=10.0, valid=[[True, True], [True, False]])
    assert len(p) == 36
    assert p.loc[1, "mean"] == 1.0 and p.loc[2, "mean"] == 2.0
    with pytest.raises(ParameterError, match="whole number"):
        angle_profile(a, v, bin_deg=7.0)


def test_peak_of_a_cosine_matches_the_gaussian_closed_form():
    # A periodic Gaussian of standard deviation s (rad) multiplies a first harmonic by exp(-s^2 / 2) (the
    # Gaussian's characteristic function); the peak sits between bins 89.5 and 90.5 deg, so a factor cos(0.5 deg).
    from cageless.profiles import peak_of_mean, PEAK_SMOOTHING_DEG

    amp, s = 0.08, math.radians(PEAK_SMOOTHING_DEG)
    centres = np.arange(360) + 0.5
    expected = amp * math.exp(-s * s / 2) * math.cos(math.radians(0.5))
    assert peak_of_mean(amp * np.cos(np.radians(centres - 90)), 1.0) == pytest.approx(expected, rel=2e-5)
    # the estimate does not depend on the bin width (2 deg bins: peak between 89 and 91 deg)
    centres2 = 2 * np.arange(180) + 1.0
    expected2 = amp * math.exp(-s * s / 2) * math.cos(math.radians(1.0))
    assert peak_of_mean(amp * np.cos(np.radians(centres2 - 90)), 2.0) == pytest.approx(expected2, rel=2e-5)
    assert peak_of_mean(amp * np.cos(np.radians(centres - 90)), 1.0, sigma_deg=0.0) == pytest.approx(
        amp * math.cos(math.radians(0.5)), rel=1e-12)


def test_smoothed_peak_removes_most_of_the_bin_noise_bias():
    # A flat profile with independent bin noise sigma: the raw maximum over the 180 bins of the zone is biased by
    # the expected maximum of 180 standard normals, 2.71 sigma (order statistics: E[max of n] ~ sqrt(2 ln n) less
    # a slowly varying correction; tabulated 2.51 for n = 100, 2.75 for n = 200). Smoothing over 5 deg leaves a
    # bias under a fifth of that.
    from cageless.profiles import peak_of_mean

    rng = np.random.default_rng(1)
    sigma, true = 0.01, 0.05
    raw, smooth = [], []
    for _ in range(300):
        m = true + rng.normal(0.0, sigma, 360)
        raw.append(peak_of_mean(m, 1.0, sigma_deg=0.0) - true)
        smooth.append(peak_of_mean(m, 1.0) - true)
    assert 2.55 * sigma < np.mean(raw) < 2.9 * sigma
    assert np.mean(smooth) < 0.2 * np.mean(raw)
    assert np.std(smooth) < 0.5 * np.std(raw)


def test_smoothing_skips_empty_bins_and_keeps_them_empty():
    from cageless.profiles import smooth_profile, unloaded_zone_peak

    m = np.full(36, 0.02)
    m[3] = np.nan
    out = smooth_profile(m, 10.0, sigma_deg=10.0)
    assert np.isnan(out[3]) and np.allclose(np.delete(out, 3), 0.02)
    prof = angle_profile(np.radians([200.0, 210.0]), [0.1, 0.2], bin_deg=10.0)
    assert np.isnan(unloaded_zone_peak(prof))  # no data in 0-180 deg
    with pytest.raises(ParameterError, match="sigma_deg"):
        smooth_profile(m, 10.0, sigma_deg=-1.0)


def test_peak_standard_error_of_balls_offset_by_constants_is_the_standard_error_of_their_mean():
    """Closed form: ball j's profile = base + c_j (every ball on every bin), so the peak of any draw's mean is
    peak(base) + mean(c over the draw), and the bootstrap standard error of a mean of Z values is
    std(c, ddof=0) / sqrt(Z) (Efron & Tibshirani 1993, eq. 6.8); 300 draws estimate it to about
    1 / sqrt(2 x 300) = 4 %."""
    bins = np.arange(360) + 0.5
    base = 0.05 * np.exp(-0.5 * ((bins - 90.0) / 25.0) ** 2)
    c = np.random.default_rng(3).normal(0.0, 0.01, 14)
    per_ball = base[:, None] + c[None, :]
    se = peak_standard_error(per_ball, 1.0)
    assert se == pytest.approx(c.std() / np.sqrt(14), rel=0.12)
    assert peak_standard_error(per_ball, 1.0) == se  # the fixed seed: the same trace gives the same figure
    assert peak_standard_error(np.repeat(base[:, None], 14, axis=1), 1.0) == pytest.approx(0.0, abs=1e-12)
    assert np.isnan(peak_standard_error(base[:, None], 1.0))  # one ball: no spread to draw from


def test_peak_standard_error_grows_when_each_angle_is_seen_by_few_balls():
    """A short clip: each ball covers its own 60 deg arc, so each bin holds two or three balls and the draws
    leave some bins to one ball; the same balls seen all round give a smaller error."""
    bins = np.arange(360) + 0.5
    base = 0.05 * np.exp(-0.5 * ((bins - 90.0) / 25.0) ** 2)
    c = np.random.default_rng(4).normal(0.0, 0.01, 14)
    full = base[:, None] + c[None, :]
    arcs = full.copy()
    for j in range(14):
        seen = ((bins - j * 360 / 14) % 360) < 60
        arcs[~seen, j] = np.nan
    assert peak_standard_error(arcs, 1.0) > 1.5 * peak_standard_error(full, 1.0)
