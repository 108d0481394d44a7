"""Locating the ball band on footage with lighting dropouts and lands over the balls (issue 14).

Reference values are closed forms: the per-pixel population standard deviation of the steady frames
(:func:`numpy.std`), and the band geometry (a ball of diameter D centred on the pitch circle spans
d_m / 2 +- D / 2).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from cageless.tracking.static import static_defects
from cageless.tracking.locate import BALL_BAND, BearingLocation
from cageless.tracking.locate_motion import DROPOUT_GAIN, frame_gains, motion_map

sys.path.insert(0, str(Path(__file__).parent))
from frame_stubs import ArrayFrames  # noqa: E402


def _clip(n: int = 25, dark: tuple[int, ...] = ()) -> np.ndarray:
    """A lit background (a gradient, 100-160 DN) with a bright spot moving along a row; ``dark`` frames at a
    fifth of the light (a dropout)."""
    h, w = 40, 60
    base = np.tile(np.linspace(100.0, 160.0, w), (h, 1))
    out = np.empty((n, h, w), np.uint16)
    for k in range(n):
        f = base.copy()
        f[18:22, 2 + 2 * k: 6 + 2 * k] += 800.0
        out[k] = np.round(f * (0.2 if k in dark else 1.0))
    return out


def test_a_dropout_is_not_motion():
    frames = _clip(dark=(7, 16))
    steady = np.delete(frames, [7, 16], axis=0).astype(np.float64)
    spread = motion_map(ArrayFrames(frames))
    np.testing.assert_allclose(spread, steady.std(axis=0), atol=1e-3)
    assert spread[:10].max() == 0.0  # the background far from the spot's row does not move
    with_dropouts = frames.astype(np.float64).std(axis=0)
    assert with_dropouts[:10].min() > 20.0  # what the dark frames alone made of it before (sqrt(p (1 - p)) x 80 DN = 21.7 DN, p = 2/25)


def test_frame_gains_flag_the_dropouts_only():
    gains = frame_gains(list(_clip(dark=(3,))))
    assert np.flatnonzero(gains < DROPOUT_GAIN).tolist() == [3]
    assert gains[3] == pytest.approx(0.2, abs=0.01)


def test_a_band_narrower_than_a_ball_is_widened_to_whole_balls():
    ratio = 0.33  # D / (d_m / 2)
    narrow = BearingLocation(centre=(50.0, 50.0), outer_radius=300.0, band_inner=205.0, band_outer=226.0,
                             contour_residual=0.3)
    wide = narrow.holding_balls(ratio)
    mid, ball = 215.5, ratio * 215.5
    assert wide.band_inner == pytest.approx(mid - 0.5 * BALL_BAND * ball)
    assert wide.band_outer == pytest.approx(mid + 0.5 * BALL_BAND * ball)
    assert wide.centre == narrow.centre and wide.source == narrow.source
    already = BearingLocation(centre=(50.0, 50.0), outer_radius=300.0, band_inner=160.0, band_outer=270.0,
                              contour_residual=0.3)
    assert already.holding_balls(ratio) is already


def test_a_compact_static_glint_is_a_defect():
    """A saturated 3 x 3 glint on a flat face, bright in every frame: all 9 of its pixels are static defects (the
    5 x 5 median is the face's level there; a 3 x 3 median would be the glint's own); a highlight seen in one
    frame of 8 is not."""
    rng = np.random.default_rng(3)
    frames = rng.normal(40.0, 2.0, (8, 30, 30))
    frames[:, 10:13, 10:13] = 255.0
    frames[2, 18:21, 18:21] += 150.0
    background = np.median(frames, axis=0)
    out = static_defects(background.astype(np.float32), 2.0, frames=frames.astype(np.float32))
    expected = np.zeros((30, 30), bool)
    expected[10:13, 10:13] = True
    np.testing.assert_array_equal(out, expected)
    old = static_defects(background.astype(np.float32), 2.0, frames=frames.astype(np.float32), size=3)
    # What the 3 x 3 median found: the glint's 4 corners only (4 of 9 bright there), its centre and edges left in.
    assert sorted(map(tuple, np.argwhere(old).tolist())) == [(10, 10), (10, 12), (12, 10), (12, 12)]


def test_a_static_defect_stands_out_by_k_sigma_in_the_frames_too():
    """Both conditions use the same k sigma (8 by default): a spot 6 sigma above the face in the background and in
    every frame is not a defect, one 10 sigma above is. (The frames' test once used the quartile index, 4 for
    16 frames, as its threshold: the 6 sigma spot passed it.)"""
    rng = np.random.default_rng(5)
    frames = rng.normal(40.0, 0.2, (16, 30, 30))
    frames[:, 8:10, 8:10] += 12.0  # 6 sigma of sigma_noise = 2
    frames[:, 20:22, 20:22] += 20.0  # 10 sigma
    background = np.median(frames, axis=0).astype(np.float32)
    loose = np.zeros((30, 30), np.float32) + background
    loose[8:10, 8:10] += 30.0  # the background alone would call both spots defects
    out = static_defects(loose, 2.0, frames=frames.astype(np.float32))
    assert not out[8:10, 8:10].any() and out[20:22, 20:22].all()
