"""The set-up's one pass over its sample frames gives the very values of the three functions it replaces.

References: :func:`cageless.tracking.locate.background_frame` (the median, and the 0.25 quantile, numpy's
``inverted_cdf``) and :func:`cageless.tracking.locate_motion.motion_map` (the per-pixel spread without the lighting
dropouts), compared bit for bit; the sorting network against the 0-1 principle (Knuth, TAOCP vol. 3, 5.3.4,
theorem Z: a comparator network that sorts every sequence of 0s and 1s sorts every sequence).
"""

from __future__ import annotations

import itertools
import sys
from pathlib import Path

import numpy as np
import pytest

from cageless.tracking.io import open_video, write_cine
from cageless.tracking.locate import background_frame
from cageless.tracking.locate_motion import motion_map
from cageless.tracking.sample_stats import kth_smallest, sample_statistics, sorting_network

sys.path.insert(0, str(Path(__file__).parent))
from frame_stubs import ArrayFrames  # noqa: E402


@pytest.mark.parametrize("n", [1, 2, 3, 5, 7, 8, 12, 16])
def test_the_network_sorts_every_zero_one_sequence(n):
    pairs = sorting_network(n)
    m = 1 << max(0, (n - 1).bit_length())
    for bits in itertools.product((0, 1), repeat=m):
        v = list(bits)
        for i, j in pairs:
            if v[i] > v[j]:
                v[i], v[j] = v[j], v[i]
        assert v == sorted(v)


def test_the_network_of_32_sorts_random_sequences():
    pairs = sorting_network(25)
    assert len(pairs) == 191  # Batcher's odd-even merge sort of 32 inputs (Knuth 5.3.4, table 1)
    rng = np.random.default_rng(3)
    for _ in range(3000):
        v = list(rng.integers(0, 6, 32))
        for i, j in pairs:
            if v[i] > v[j]:
                v[i], v[j] = v[j], v[i]
        assert v == sorted(v)


def _frames(n: int, dtype: type, seed: int) -> np.ndarray:
    """Noise with ties, a bright spot moving along a row and two lighting dropouts (frames at a fifth)."""
    rng = np.random.default_rng(seed)
    top = 200 if dtype == np.uint8 else 4000
    frames = rng.integers(0, top, (n, 70, 300)).astype(dtype)
    frames[:, 5:9, :] = 11  # ties
    for k in range(n):
        frames[k, 30:34, 4 * k:4 * k + 6] = top
    for k in (1, n - 2):
        frames[k] = (frames[k] // 5).astype(dtype)
    return frames


@pytest.mark.parametrize("n_frames", [4, 7, 25, 30])
@pytest.mark.parametrize("fmt, dtype", [("16", np.uint16), ("8", np.uint8)])
def test_one_pass_gives_the_backgrounds_and_the_motion_map(tmp_path, n_frames, fmt, dtype):
    frames = _frames(n_frames, dtype, n_frames)
    clip = write_cine(tmp_path / "c.cine", frames, fps=1000.0, fmt=fmt)
    with open_video(clip) as video:
        refs = (background_frame(video), background_frame(video, quantile=0.25), motion_map(video))
        for workers in (1, 2):
            got = sample_statistics(video, quantile=0.25, workers=workers)
            for a, b in zip((got.median, got.low, got.spread), refs, strict=True):
                assert a.dtype == b.dtype == np.float32
                assert a.tobytes() == b.tobytes()


def test_other_pixel_types_take_the_plain_functions():
    video = ArrayFrames(_frames(9, np.uint16, 1).astype(np.float32) / 7)
    got = sample_statistics(video)
    assert got.median.tobytes() == background_frame(video).tobytes()
    assert got.low.tobytes() == background_frame(video, quantile=0.25).tobytes()
    assert got.spread.tobytes() == motion_map(video).tobytes()


@pytest.mark.parametrize("n", [1, 4, 16, 25, 32])
@pytest.mark.parametrize("dtype", [np.uint8, np.uint16])
def test_kth_smallest_is_numpys_partition(n, dtype):
    frames = _frames(max(n, 4), dtype, 40 + n)[:n]
    frames = np.ascontiguousarray(frames[:, :, :290])  # a width that is not a multiple of the tile
    for k in sorted({0, n // 4, n // 2, n - 1}):
        assert kth_smallest(frames, k).tobytes() == np.partition(frames, k, axis=0)[k].tobytes()
