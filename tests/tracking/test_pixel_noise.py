"""The pixel-noise estimate of the detector's thresholds (tracking/detect.py: pixel_noise)."""

from __future__ import annotations

import numpy as np
import pytest

from cageless.tracking.detect import noise_sigma, pixel_noise


def _scene(shape: tuple[int, int] = (120, 160)) -> np.ndarray:
    """Shaded dark balls (a gradient of 2 DN/px) with bright 40-px discs and 3-px highlights: structure that a
    frame's spread about a median background takes for noise."""
    vv, uu = np.mgrid[0:shape[0], 0:shape[1]].astype(np.float64)
    img = 100.0 + 2.0 * uu
    for k in range(4):
        cu, cv = 20.0 + 40.0 * k, 60.0
        r2 = (uu - cu) ** 2 + (vv - cv) ** 2
        img = np.where(r2 < 18.0**2, img + 300.0, img)
        img += 1500.0 * np.exp(-0.5 * r2 / 3.0**2)
    return img


@pytest.mark.parametrize("sigma", [0.5, 2.0, 8.0])
def test_the_estimate_is_the_noise_not_the_structure(sigma: float):
    """White Gaussian noise on a scene with edges, a gradient and highlights, stored as integers: the estimate is
    within 12 % of sqrt(sigma^2 + 1/12) (the noise with the quantisation; measured with seed 3: 0.577 -> 0.571,
    2.021 -> 2.144, 8.005 -> 8.457 DN)."""
    rng = np.random.default_rng(3)
    frames = np.stack([np.rint(_scene() + rng.normal(0.0, sigma, _scene().shape)) for _ in range(4)])
    true = np.sqrt(sigma**2 + 1 / 12)
    assert pixel_noise(frames.astype(np.float32), np.ones(frames.shape[1:], bool)) == pytest.approx(true, rel=0.12)


def test_the_old_estimate_measured_the_scene():
    """The same frames with the balls moved between them: the spread about their median reads the scene's contrast,
    over 10 times the 2 DN noise (40.0 DN measured); the pixel noise stays within 12 % of it (2.07 DN measured)."""
    rng = np.random.default_rng(4)
    base = _scene((120, 200))
    frames = np.stack([np.roll(base, 10 * k, axis=1) + rng.normal(0.0, 2.0, base.shape) for k in range(4)])
    frames = frames.astype(np.float32)
    mask = np.ones(base.shape, bool)
    mask[:, :40] = False  # the rolled-in columns
    assert noise_sigma(frames, np.median(frames, axis=0), mask) > 20.0
    assert pixel_noise(frames, mask) == pytest.approx(2.0, rel=0.12)


def test_a_single_frame_and_an_empty_mask():
    """One 2-d frame is accepted; a mask without a 3 x 3 interior gives the floor, the rounding error
    1 / sqrt(12) DN, rather than failing."""
    rng = np.random.default_rng(5)
    frame = rng.normal(50.0, 3.0, (40, 40)).astype(np.float32)
    assert pixel_noise(frame, np.ones((40, 40), bool)) == pytest.approx(3.0, rel=0.12)
    thin = np.zeros((40, 40), bool)
    thin[10, :] = True
    assert pixel_noise(frame, thin) == pytest.approx(12 ** -0.5)


def test_smooth_compressed_data_read_the_rounding_floor():
    """Integer frames without any pixel-to-pixel noise (JPEG's smooth blocks: TUNING seeds 1004 and 1018 gave a
    residual of 0.000 DN) read 1 / sqrt(12) DN, not 0: the thresholds do not collapse to zero."""
    frames = np.rint(np.stack([_scene() for _ in range(3)])).astype(np.float32)
    frames[:, 60:, :] = 100.0  # half the image flat
    assert pixel_noise(frames, np.ones(frames.shape[1:], bool)) == pytest.approx(12 ** -0.5)
