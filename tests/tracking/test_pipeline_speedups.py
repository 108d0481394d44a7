"""The pipeline's shortcuts give the very values of the plain forms they replace.

Reference: :func:`cageless.tracking.locate.background_frame` over the full frames, then cropped (the form the
pipeline used before it computed the selection's background over the crop only); a per-pixel quantile
depends on that pixel's values alone, so the two must agree bit for bit.
"""

from __future__ import annotations

import numpy as np
import pytest

from cageless.tracking.io import open_video, write_cine
from cageless.tracking.locate import background_frame
from cageless.tracking.pipeline import _CropView


@pytest.mark.parametrize("n_frames", [7, 30])
@pytest.mark.parametrize("quantile", [0.25, 0.5])
def test_background_over_the_crop_is_the_full_background_cropped(tmp_path, n_frames, quantile):
    rng = np.random.default_rng(n_frames)
    frames = rng.integers(0, 4096, (n_frames, 90, 130)).astype(np.uint16)
    frames[:, 10:20, 10:20] = 7  # ties
    clip = write_cine(tmp_path / "c.cine", frames, fps=1000.0, fmt="16", real_bpp=12)
    rows, cols = slice(13, 77), slice(29, 118)
    with open_video(clip) as video:
        full = background_frame(video, quantile=quantile)[rows, cols]
        crop = background_frame(_CropView(video, rows, cols), quantile=quantile)
    assert crop.shape == (64, 89)
    assert crop.dtype == full.dtype == np.float32
    assert crop.tobytes() == full.tobytes()
