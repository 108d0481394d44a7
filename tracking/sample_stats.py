"""The set-up's per-pixel statistics of the sample frames, from one pass over them.

Three set-up stages read the same frames spread over the video (up to 25, at the same indices): the median
background (:func:`cageless.tracking.locate.background_frame`), the selection's low-quantile background (the
same with ``quantile=0.25``, over the crop) and the motion map of the localisation
(:func:`cageless.tracking.locate_motion.motion_map`). :func:`sample_statistics` reads each frame once and
computes all three in one compiled pass over bands of rows, with the very values of those functions (tested
bit for bit): the order statistics are picked from a sorting network run across a tile of pixels at once
(vectorised min/max), and the motion map's sums add the same float64 values in the same order.
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numba
import numpy as np
import numpy.typing as npt

from cageless.tracking.io.base import FrameSource
from cageless.tracking.locate import background_frame
from cageless.tracking.locate_motion import dropout_frames, frame_level, motion_map

__all__ = ["SampleStats", "kth_smallest", "sample_statistics", "sorting_network"]

#: Rows per band (25 frames x 32 rows x 1280 px x 2 B = 2 MB), as :func:`~cageless.tracking.locate.background_frame`.
_BAND_ROWS = 32
#: Pixels sorted together: the comparators run over this many lanes (the tile stays in the L1 cache).
_TILE = 256


@dataclass(frozen=True)
class SampleStats:
    """Per-pixel statistics of the sample frames (full frame, float32).

    Attributes
    ----------
    median
        The median background (``background_frame(video)``).
    low
        The ``quantile`` background (``background_frame(video, quantile=quantile)``).
    spread
        The motion map (``motion_map(video)``), lighting dropouts left out.
    """

    median: npt.NDArray[np.float32]
    low: npt.NDArray[np.float32]
    spread: npt.NDArray[np.float32]


def sorting_network(n: int) -> npt.NDArray[np.intp]:
    """Comparators ``(i, j)``, ``i < j``, of Batcher's odd-even merge sort of ``m`` inputs, ``m`` the least power
    of two ``>= n`` (Knuth, TAOCP vol. 3, 5.3.4, algorithm M): applied in order, they sort any ``m`` values."""
    m = 1 << max(0, (n - 1).bit_length())
    pairs: list[tuple[int, int]] = []

    def merge(lo: int, hi: int, r: int) -> None:
        step = 2 * r
        if step < hi - lo:
            merge(lo, hi, step)
            merge(lo + r, hi, step)
            pairs.extend((i, i + r) for i in range(lo + r, hi - r, step))
        else:
            pairs.append((lo, lo + r))

    def sort(lo: int, hi: int) -> None:
        if hi - lo >= 1:
            mid = lo + (hi - lo) // 2
            sort(lo, mid)
            sort(mid + 1, hi)
            merge(lo, hi, 1)

    sort(0, m - 1)
    return np.array(pairs, dtype=np.intp).reshape(-1, 2)


@numba.njit(cache=True, nogil=True)
def _tile_buffer(band):  # pragma: no cover - compiled
    """A tile of ``m`` rows (the least power of two >= the frames of ``band``) by :data:`_TILE` lanes."""
    m = 1
    while m < band.shape[0]:
        m *= 2
    return np.empty((m, _TILE), dtype=band.dtype)


@numba.njit(cache=True, nogil=True)
def _load_tile(band, r, c0, tn, pad, buf):  # pragma: no cover - compiled
    """Row ``r``, columns ``c0..c0+tn-1`` of every frame of ``band`` into ``buf``, ``pad`` in the rows above."""
    for k in range(band.shape[0]):
        for t in range(tn):
            buf[k, t] = band[k, r, c0 + t]
    for k in range(band.shape[0], buf.shape[0]):
        for t in range(tn):
            buf[k, t] = pad


@numba.njit(cache=True, nogil=True)
def _sort_tile(buf, tn, pairs):  # pragma: no cover - compiled
    """Sort each of the first ``tn`` lanes of ``buf`` (its rows) by the comparators ``pairs``."""
    for p in range(pairs.shape[0]):
        i, j = pairs[p, 0], pairs[p, 1]
        for t in range(tn):
            a, b = buf[i, t], buf[j, t]
            buf[i, t] = min(a, b)
            buf[j, t] = max(a, b)


@numba.njit(cache=True, nogil=True)
def _kth(stack, pad, pairs, k, out):  # pragma: no cover - compiled
    """``out[r, c]``: the ``k``-th smallest (from 0) of ``stack[:, r, c]``."""
    buf = _tile_buffer(stack)
    for r in range(stack.shape[1]):
        for c0 in range(0, stack.shape[2], _TILE):
            tn = min(_TILE, stack.shape[2] - c0)
            _load_tile(stack, r, c0, tn, pad, buf)
            _sort_tile(buf, tn, pairs)
            for t in range(tn):
                out[r, c0 + t] = buf[k, t]


def kth_smallest(frames: np.ndarray, k: int) -> np.ndarray:
    """``np.partition(frames, k, axis=0)[k]`` (the same values) for a stack of 8- or 16-bit frames, by the sorting
    network across tiles of pixels; other stacks by :func:`numpy.partition`."""
    n = frames.shape[0]
    if frames.dtype not in (np.uint8, np.uint16) or frames.ndim != 3 or not 0 < n <= 32:
        return np.partition(frames, k, axis=0)[k]
    out = np.empty(frames.shape[1:], frames.dtype)
    _kth(frames, np.iinfo(frames.dtype).max, sorting_network(n), int(k) % n, out)
    return out


@numba.njit(cache=True, nogil=True)
def _band_stats(band, pad, pairs, drop, k_mid, k_low, even, med, low, s1, s2):  # pragma: no cover - compiled
    """One band of rows: ``band`` is (n, rows, W); the sorted tile has ``pad`` above the ``n`` values."""
    n, rows, w = band.shape
    buf = _tile_buffer(band)
    for r in range(rows):
        for c0 in range(0, w, _TILE):
            tn = min(_TILE, w - c0)
            _load_tile(band, r, c0, tn, pad, buf)
            for t in range(tn):  # the motion map's sums: the same float64 additions in frame order
                s1[r, c0 + t] = 0.0
                s2[r, c0 + t] = 0.0
            for k in range(n):
                for t in range(tn):
                    x = np.float64(buf[k, t])
                    s1[r, c0 + t] += x
                    s2[r, c0 + t] += x * x
            for k in range(n):  # then the dropouts taken out again, in frame order
                if drop[k]:
                    for t in range(tn):
                        x = np.float64(buf[k, t])
                        s1[r, c0 + t] -= x
                        s2[r, c0 + t] -= x * x
            _sort_tile(buf, tn, pairs)
            for t in range(tn):
                if even:
                    med[r, c0 + t] = np.float32((np.float64(buf[k_mid - 1, t]) + np.float64(buf[k_mid, t])) / 2.0)
                else:
                    med[r, c0 + t] = np.float32(buf[k_mid, t])
                low[r, c0 + t] = np.float32(buf[k_low, t])


def _dropouts(frames: list[np.ndarray]) -> np.ndarray:
    """Which sample frames :func:`~cageless.tracking.locate_motion.motion_map` leaves out (lighting dropouts).
    Each frame's level is taken as that function takes it, of the frame converted to float64 (the same strided
    view, so the same sum), converting only the pixels the level reads."""
    scratch = np.empty(frames[0].shape, np.float64)
    levels = np.empty(len(frames))
    for k, f in enumerate(frames):
        scratch[::4, ::4] = f[::4, ::4]
        levels[k] = frame_level(scratch)
    return dropout_frames(levels)


def sample_statistics(video: FrameSource, n_sample: int = 25, quantile: float = 0.25,
                      workers: int = 1) -> SampleStats:
    """The median and ``quantile`` backgrounds and the motion map of up to ``n_sample`` frames spread over the
    video, each frame read once, in bands of rows on ``workers`` threads (the same values with any number).

    Frames of other than 8- or 16-bit integer pixels, or more than 32 sample frames, take the three functions
    it replaces.
    """
    n = len(video)
    idx = np.unique(np.linspace(0, n - 1, min(n, n_sample)).round().astype(int))
    frames = [video.frame_view(int(i)) for i in idx]
    if frames[0].dtype not in (np.uint8, np.uint16) or frames[0].ndim != 2 or idx.size > 32:
        return SampleStats(background_frame(video, n_sample, workers=workers),
                           background_frame(video, n_sample, quantile, workers), motion_map(video, n_sample))
    drop = _dropouts(frames)
    positions = np.arange(idx.size, dtype=np.float64)
    mid = float(np.median(positions))  # k, or k - 0.5 for an even count (the mean of the two middle values)
    k_low = int(np.quantile(positions, quantile, method="inverted_cdf"))
    even = mid != int(mid)
    k_mid = int(np.ceil(mid))
    pairs = sorting_network(idx.size)
    pad = np.iinfo(frames[0].dtype).max
    h, w = video.frame_shape
    med, low = np.empty((h, w), np.float32), np.empty((h, w), np.float32)
    s1, s2 = np.empty((h, w), np.float64), np.empty((h, w), np.float64)

    def one(r0: int) -> None:
        r1 = min(r0 + _BAND_ROWS, h)
        band = np.stack([f[r0:r1] for f in frames])
        _band_stats(band, pad, pairs, drop, k_mid, k_low, even, med[r0:r1], low[r0:r1], s1[r0:r1], s2[r0:r1])

    with ThreadPoolExecutor(max_workers=max(1, workers)) as pool:
        list(pool.map(one, range(0, h, _BAND_ROWS)))
    used = idx.size - int(drop.sum())
    mean = s1 / used
    spread = np.sqrt(np.maximum(s2 / used - mean * mean, 0.0)).astype(np.float32)
    return SampleStats(median=med, low=low, spread=spread)
