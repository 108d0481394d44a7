"""Lint in front of the balls, subtracted from the centroid (tracking/static.py: static_pattern)."""

from __future__ import annotations

import numpy as np

from cageless.tracking.detect import centroid_windows
from cageless.tracking.static import static_defects, static_pattern


def _spot(shape: tuple[int, int], u: float, v: float, sigma: float, peak: float) -> np.ndarray:
    vv, uu = np.mgrid[0:shape[0], 0:shape[1]]
    return peak * np.exp(-0.5 * ((uu - u) ** 2 + (vv - v) ** 2) / sigma**2)


def _frames(n: int = 16, noise: float = 2.0, seed: int = 0):
    """Dark balls (level 100) under a faint speck (60 DN, sigma 0.8 px) at (40, 30); a 400 DN highlight passes."""
    rng = np.random.default_rng(seed)
    shape = (60, 80)
    speck = _spot(shape, 40.0, 30.0, 0.8, 60.0)
    frames = np.stack([100.0 + speck + rng.normal(0, noise, shape) for _ in range(n)]).astype(np.float32)
    return shape, speck, frames


def test_a_faint_speck_is_found_and_subtracted():
    """The speck, 30 noise sigmas of the frames but under 8 of the band's much larger spread (50), is found
    and its excess recovered to a few DN; the old test leaves it."""
    shape, speck, frames = _frames()
    background = np.median(frames, axis=0)
    region = np.ones(shape, bool)
    assert not static_defects(background, 50.0, frames=frames).any()
    pattern = static_pattern(background, frames, region, np.zeros(shape, bool))
    assert abs(pattern[30, 40] - speck[30, 40]) < 5.0
    assert np.count_nonzero(pattern) < 30


def test_the_centroid_of_a_highlight_under_the_speck_is_unbiased():
    """A highlight 4 px from the speck is pulled 0.07 px towards it; with the pattern subtracted, under 0.01 px."""
    shape, speck, frames = _frames()
    background = np.median(frames, axis=0)
    pattern = static_pattern(background, frames, np.ones(shape, bool), np.zeros(shape, bool))
    frame = (100.0 + speck + _spot(shape, 36.0, 30.0, 2.5, 400.0)).astype(np.float32)
    mask = np.ones(shape, bool)
    raw = centroid_windows(frame, background, mask, [36.0], [30.0], 9.0, 4.0, 20)
    fixed = centroid_windows(frame, background, mask, [36.0], [30.0], 9.0, 4.0, 20,
                             static=(pattern, float(frame.max()) + 1.0))
    assert raw[0][0] - 36.0 > 0.05
    assert abs(fixed[0][0] - 36.0) < 0.01


def test_a_window_without_pattern_pixels_skips_the_pattern_exactly():
    """The per-window test (summed-area table) must not change any result: a window that holds none of the
    pattern gives bit for bit the centroid without a pattern, and one whose ring of background pixels
    (radius + 2) reaches a single pattern pixel still reads it."""
    shape = (60, 80)
    rng = np.random.default_rng(3)
    background = np.full(shape, 100.0, np.float32)
    frame = (100.0 + rng.normal(0, 2.0, shape) + _spot(shape, 36.0, 30.0, 2.5, 400.0)).astype(np.float32)
    mask = np.ones(shape, bool)
    far = np.zeros(shape, np.float32)
    far[5, 75] = 50.0  # far from the window
    clip = float(frame.max()) + 1.0
    plain = centroid_windows(frame, background, mask, [36.0], [30.0], 9.0, 4.0, 20)
    skipped = centroid_windows(frame, background, mask, [36.0], [30.0], 9.0, 4.0, 20, static=(far, clip))
    assert np.array_equal(np.array(plain), np.array(skipped))
    near = np.zeros(shape, np.float32)
    near[30, 36 + 10] = 50.0  # in the local-background ring (9 < 10 <= 11 px), outside the window itself
    read = centroid_windows(frame, background, mask, [36.0], [30.0], 9.0, 4.0, 20, static=(near, clip))
    assert not np.array_equal(np.array(plain), np.array(read))
