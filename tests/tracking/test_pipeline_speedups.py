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


def _background_plain(video, n_sample: int = 25, quantile: float = 0.5) -> np.ndarray:
    """The background as first written: numpy's median (or inverted_cdf quantile) over the stacked frames' first axis."""
    idx = np.unique(np.linspace(0, len(video) - 1, min(len(video), n_sample)).round().astype(int))
    stack = np.stack([video.frame_view(int(i)) for i in idx])
    out = np.median(stack, axis=0) if quantile == 0.5 else np.quantile(stack, quantile, axis=0, method="inverted_cdf")
    return out.astype(np.float32)


@pytest.mark.parametrize("n_frames", [4, 7, 30])
@pytest.mark.parametrize("quantile", [0.25, 0.5])
def test_background_frame_is_numpys_median_over_the_first_axis(tmp_path, n_frames, quantile):
    rng = np.random.default_rng(10 + n_frames)
    frames = rng.integers(0, 4096, (n_frames, 70, 150)).astype(np.uint16)
    frames[:, 5:9, :] = 11  # ties
    clip = write_cine(tmp_path / "c.cine", frames, fps=1000.0, fmt="16", real_bpp=12)
    with open_video(clip) as video:
        got = background_frame(video, quantile=quantile)
        ref = _background_plain(video, quantile=quantile)
        threaded = background_frame(video, quantile=quantile, workers=2)  # bands of 32 rows on two threads
    assert got.tobytes() == ref.tobytes()
    assert threaded.tobytes() == ref.tobytes()


def test_a_single_frame_of_a_decoded_video_is_read_alone(tmp_path, monkeypatch):
    """A frame asked for outside the chunks kept is read alone, not with its whole chunk (the set-up's spread
    sample frames each cost a 64-frame chunk before), and cropped like the chunks."""
    from cageless.tracking.io import write_ffv1
    from cageless.tracking.pipeline import _CroppedFrames

    rng = np.random.default_rng(3)
    data = rng.integers(0, 256, size=(150, 20, 30), dtype=np.int64).astype(np.uint8)
    path = write_ffv1(tmp_path / "x.avi", data, fps=1000)
    with open_video(path) as video:
        reads = []
        inner = video._read
        monkeypatch.setattr(video, "_read", lambda i: reads.append(i) or inner(i))
        frames = _CroppedFrames(video, slice(2, 18), slice(3, 25), chunk=64)
        for i in (10, 100, 149, 10):
            np.testing.assert_array_equal(frames(i), data[i, 2:18, 3:25])
        assert reads == [10, 100, 149]
        np.testing.assert_array_equal(frames.block(64, 128), data[64:128, 2:18, 3:25])
        reads.clear()
        np.testing.assert_array_equal(frames(100), data[100, 2:18, 3:25])  # now from the chunk read for block
        assert reads == []
