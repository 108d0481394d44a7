"""Cropped frames for the tracking pipeline (:mod:`cageless.tracking.pipeline`): zero-copy views of a memory-mapped
cine whose pages are dropped behind the reader, or chunks read and cached from any other frame source.
"""

from __future__ import annotations

from collections import OrderedDict

import numpy as np

from cageless.tracking.io import CineReader, FrameSource

__all__ = ["_CroppedFrames", "_CropView"]

#: Frames served from a memory map between drops of their pages (fault-around maps whole frames:
#: 8 full-size 16-bit frames are 16 MB).
_DROP_EVERY = 8
#: Single frames kept by a non-memory-mapped frame source between chunk reads (:class:`_CroppedFrames`).
_SINGLE_FRAMES = 16


class _CroppedFrames:
    """Random access to cropped frames ``offset + i``: zero-copy views of a memory-mapped cine; otherwise
    :meth:`block` reads whole chunks and keeps the last two, and a single frame outside them is read alone
    (the last :data:`_SINGLE_FRAMES` kept): the set-up's spread sample frames each cost a 64-frame chunk before."""

    def __init__(self, video: FrameSource, rows: slice, cols: slice, chunk: int, offset: int = 0,
                 stop: int | None = None) -> None:
        self.video, self.rows, self.cols, self.chunk, self.offset = video, rows, cols, chunk, offset
        self.stop = len(video) if stop is None else stop
        self._cache: OrderedDict[int, np.ndarray] = OrderedDict()
        self._single: OrderedDict[int, np.ndarray] = OrderedDict()
        # Memory-mapped 8/16-bit cine: hand out views; the window kernel touches only the pages it needs.
        self.zero_copy = isinstance(video, CineReader) and not video._packed_bits
        self._stack = video.frame_stack() if self.zero_copy else None  # type: ignore[attr-defined]
        self._span = (offset, offset)

    def __call__(self, i: int) -> np.ndarray:
        if self.zero_copy:
            j = self.offset + i
            self._span = (min(self._span[0], j), max(self._span[1], j))
            if self._span[1] - self._span[0] >= _DROP_EVERY:
                self.video.drop_pages(*self._span)  # type: ignore[attr-defined]
                self._span = (j, j)
            if self._stack is not None:  # one ndarray slice, no per-frame objects
                return self._stack[j, self.rows, self.cols]
            return self.video.frame_view(j)[self.rows, self.cols]
        k = i // self.chunk
        block = self._cache.get(k)
        if block is not None:
            return block[i - k * self.chunk]
        frame = self._single.get(i)
        if frame is None:
            frame = self.video[self.offset + i][self.rows, self.cols]
            self._single[i] = frame
            if len(self._single) > _SINGLE_FRAMES:
                self._single.popitem(last=False)
        return frame

    @property
    def block_size(self) -> int:
        """Frames per :meth:`block` (a memory-mapped block's pages are dropped after the next is asked for)."""
        return _DROP_EVERY if self.zero_copy else self.chunk

    def block(self, a: int, b: int) -> np.ndarray:
        """Frames ``a..b-1`` as one ``(frames, rows, cols)`` array (a view where possible), ``a`` a multiple of
        :attr:`block_size` and ``b - a`` at most that."""
        if not self.zero_copy:
            k = a // self.chunk
            return self._chunk(k)[a - k * self.chunk:b - k * self.chunk]
        j, last = self.offset + a, self.offset + b - 1
        if self._span != (j, j):  # the previous block is done: unmap its pages
            self.video.drop_pages(*self._span)  # type: ignore[attr-defined]
        self._span = (min(j, last), max(j, last))
        if self._stack is not None:
            return self._stack[j:last + 1, self.rows, self.cols]
        return np.stack([self.video.frame_view(x)[self.rows, self.cols] for x in range(j, last + 1)])

    def _chunk(self, k: int) -> np.ndarray:
        block = self._cache.get(k)
        if block is None:
            a = self.offset + k * self.chunk
            raw = self.video[a:min(a + self.chunk, self.stop)]
            block = raw[:, self.rows, self.cols]  # a view: the window kernel reads any strides
            self._cache[k] = block
            if len(self._cache) > 2:
                self._cache.popitem(last=False)
        return block


class _CropView:
    """The rows and columns of a video that :func:`~cageless.tracking.locate.background_frame` needs, cropped:
    per-pixel statistics over the crop are those of the full frames cropped, for less work."""

    def __init__(self, video: FrameSource, rows: slice, cols: slice) -> None:
        self.video, self.rows, self.cols = video, rows, cols
        self.frame_shape = (len(range(*rows.indices(video.frame_shape[0]))),
                            len(range(*cols.indices(video.frame_shape[1]))))

    def __len__(self) -> int:
        return len(self.video)

    def frame_view(self, i: int) -> np.ndarray:
        return self.video.frame_view(i)[self.rows, self.cols]
