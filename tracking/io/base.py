"""The frame-source interface every video reader implements.

A frame source is lazy and random-access, PIMS style: ``len(src)``,
``src[i]`` (one frame as a 2-D array, rows top to bottom as displayed),
``src[a:b]`` (a stacked copy), ``src.iter_chunks(n)``, ``src.times`` (s, one per
frame, from the first frame) and ``src.metadata``. No reader loads a whole
video into memory.
"""

from __future__ import annotations

import abc
import logging
from collections.abc import Iterable, Iterator
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from cageless.errors import VideoError

__all__ = ["VideoMetadata", "FrameSource", "times_from_timestamps"]

log = logging.getLogger(__name__)

#: Relative difference between header and time-stamp frame rates above which we say so.
FPS_MISMATCH = 1e-3


@dataclass
class VideoMetadata:
    """What a reader knows about a video.

    Attributes
    ----------
    path
        The file or folder.
    format
        ``"cine"``, ``"opencv"`` or ``"image-sequence"``.
    n_frames, width, height
        Frame count and size in pixels.
    dtype
        NumPy dtype of the frames returned (``uint8`` or ``uint16``).
    bit_depth
        Significant bits per pixel (e.g. 12 for 12-bit data in 16-bit words).
    storage
        How pixels are stored, e.g. ``"16-bit words"`` or ``"packed 12-bit (P12L)"``.
    header_fps
        Frame rate written in the header, or ``None``.
    timestamp_fps
        Mean frame rate implied by per-frame time stamps, or ``None``.
    time_source
        Where ``times`` come from: ``"timestamps"``, ``"header frame rate"``,
        ``"fps override"`` or ``"container frame rate"``.
    exposure_s
        Exposure time (s), or ``None``.
    camera
        Camera description (model, serial), or ``""``.
    notes
        Human-readable remarks, e.g. that the header frame rate disagrees with the time stamps.
    extra
        Format-specific fields.
    """

    path: str
    format: str
    n_frames: int
    width: int
    height: int
    dtype: str
    bit_depth: int
    storage: str
    header_fps: float | None = None
    timestamp_fps: float | None = None
    time_source: str = ""
    exposure_s: float | None = None
    camera: str = ""
    notes: list[str] = field(default_factory=list)
    extra: dict[str, Any] = field(default_factory=dict)

    @property
    def duration_s(self) -> float | None:
        """Nominal duration n_frames / fps from the frame rate in use, or ``None``."""
        fps = self.timestamp_fps if self.time_source == "timestamps" else self.header_fps
        return None if not fps else self.n_frames / fps

    def to_dict(self) -> dict[str, Any]:
        """Return a JSON-ready dict (with ``duration_s``)."""
        return {**asdict(self), "duration_s": self.duration_s}


def times_from_timestamps(stamps: npt.NDArray[np.float64]) -> tuple[npt.NDArray[np.float64], float | None]:
    """Times from the first frame and the mean frame rate implied by absolute time stamps.

    The mean rate is (n - 1) / (t_last - t_first); ``None`` for fewer than 2 frames.
    """
    t = np.asarray(stamps, dtype=np.float64) - float(stamps[0])
    fps = None if len(t) < 2 or t[-1] <= 0 else (len(t) - 1) / t[-1]
    return t, fps


class FrameSource(abc.ABC):
    """Abstract lazy, random-access frame source.

    Subclasses implement :meth:`_read` (one frame by non-negative index) and set
    ``metadata`` and ``_times`` in ``__init__``.
    """

    metadata: VideoMetadata
    _times: npt.NDArray[np.float64] | None
    #: Whether reading frame ``i`` costs about the same wherever the last read ended. False where going back
    #: means decoding again from the start (MKV/MP4 through OpenCV): readers then go through it in order.
    seekable: bool = True

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)

    # -- the interface -------------------------------------------------------------------------
    def __len__(self) -> int:
        return self.metadata.n_frames

    @property
    def shape(self) -> tuple[int, int, int]:
        """(n_frames, height, width)."""
        return (len(self), self.metadata.height, self.metadata.width)

    @property
    def frame_shape(self) -> tuple[int, int]:
        """(height, width)."""
        return (self.metadata.height, self.metadata.width)

    @property
    def dtype(self) -> np.dtype:
        """Dtype of the frames."""
        return np.dtype(self.metadata.dtype)

    @property
    def times(self) -> npt.NDArray[np.float64]:
        """Frame times (s) from the first frame, one per frame.

        Raises
        ------
        VideoError
            When the source carries no timing and no ``fps`` was given.
        """
        if self._times is None:
            raise VideoError(self.path, "has no frame timing.", hint="Give --fps (or fps in the conditions).")
        return self._times

    def __getitem__(self, key: int | slice) -> np.ndarray:
        if isinstance(key, slice):
            start, stop, step = key.indices(len(self))
            if step == 1:
                return self._read_range(start, max(start, stop))
            idx = range(start, stop, step)
            out = np.empty((len(idx), *self.frame_shape), dtype=self.dtype)
            for k, i in enumerate(idx):
                out[k] = self._read(i)
            return out
        i = int(key)
        n = len(self)
        if i < -n or i >= n:
            raise IndexError(f"frame {key} out of range for {n} frames of {self.path}")
        return self._read(i % n)

    def __iter__(self) -> Iterator[np.ndarray]:
        for i in range(len(self)):
            yield self._read(i)

    def iter_chunks(self, chunk_size: int = 256, start: int = 0, stop: int | None = None) -> Iterator[tuple[int, np.ndarray]]:
        """Yield ``(first_index, frames)`` with ``frames`` of shape (k, H, W), k <= chunk_size."""
        if chunk_size < 1:
            raise ValueError(f"chunk_size = {chunk_size}: must be >= 1")
        stop = len(self) if stop is None else min(stop, len(self))
        for a in range(start, stop, chunk_size):
            yield a, self[a:min(a + chunk_size, stop)]

    def frame_view(self, index: int) -> np.ndarray:
        """Frame ``index`` without copying where the format allows (memory-mapped cine); else a copy.

        A view is read-only and valid while the source is open.
        """
        return self[index]

    def prefetch(self, indices: Iterable[int]) -> None:  # noqa: B027 - optional hook
        """Hint that frames ``indices`` will be read soon, in any order. A reader that is not
        :attr:`seekable` decodes them in one pass and keeps them; the others read them when asked."""

    def close(self) -> None:  # noqa: B027 - optional hook
        """Release the file handle (readers that hold one override this)."""

    def __enter__(self) -> FrameSource:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def __repr__(self) -> str:
        m = self.metadata
        return (f"<{type(self).__name__} {self.path.name}: {m.n_frames} frames {m.width}x{m.height} "
                f"{m.dtype} ({m.bit_depth}-bit), time from {m.time_source or 'nothing'}>")

    @abc.abstractmethod
    def _read(self, index: int) -> np.ndarray:
        """Return frame ``index`` (0 <= index < len) as a new 2-D array."""

    def _read_range(self, start: int, stop: int) -> np.ndarray:
        """Return frames ``start:stop`` as an array of shape (k, H, W); readers may override for speed.

        The result may be a view with unusual strides (e.g. rows reversed); it is never shared.
        """
        out = np.empty((stop - start, *self.frame_shape), dtype=self.dtype)
        for k, i in enumerate(range(start, stop)):
            out[k] = self._read(i)
        return out

    # -- shared helpers -------------------------------------------------------------------------
    def _apply_timing(self, fps_override: float | None, stamps: npt.NDArray[np.float64] | None) -> None:
        """Set ``_times`` from an override, time stamps or the header rate, and record which."""
        m = self.metadata
        if fps_override is not None:
            if not np.isfinite(fps_override) or fps_override <= 0:
                raise VideoError(self.path, f"fps override {fps_override!r} must be a finite number > 0.")
            self._times = np.arange(m.n_frames) / float(fps_override)
            m.time_source = "fps override"
            m.extra["fps_override"] = float(fps_override)
            return
        if stamps is not None and len(stamps) == m.n_frames and np.all(np.diff(stamps) > 0):
            self._times, m.timestamp_fps = times_from_timestamps(stamps)
            m.time_source = "timestamps"
            if m.header_fps and m.timestamp_fps and abs(m.timestamp_fps / m.header_fps - 1) > FPS_MISMATCH:
                note = (f"header frame rate {m.header_fps:g} fps differs from the time stamps "
                        f"({m.timestamp_fps:.1f} fps, e.g. a decimated recording); times use the time stamps")
                m.notes.append(note)
                log.info("%s: %s", self.path, note)
            return
        if stamps is not None:
            m.notes.append("time stamps are not increasing; times use the header frame rate")
        if m.header_fps:
            self._times = np.arange(m.n_frames) / m.header_fps
            m.time_source = "header frame rate"
        else:
            self._times = None
