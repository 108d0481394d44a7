"""Write Phantom ``.cine`` files: 8-bit, 16-bit, packed 10-bit and packed 12-bit.

Files are laid out as :mod:`cageless.tracking.io.cine_layout` describes, with a
time-stamp block (so dropped frames show as gaps) and an exposure block, and
are written atomically. :class:`~cageless.tracking.io.cine.CineReader` reads back
exactly what this writer wrote.
"""

from __future__ import annotations

import struct
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import BinaryIO

import numpy as np
import numpy.typing as npt

from cageless._version import __version__
from cageless.atomic import atomic_path
from cageless.errors import ParameterError
from cageless.tracking.io.cine_layout import (
    BITMAPINFO,
    BLOCK_HEADER,
    HEADER,
    MAGIC,
    SETUP_FIELDS,
    SETUP_SIZE,
    TAG_EXPOSURE_ONLY,
    TAG_TIME_ONLY,
    TIME64_FRACTION,
)
from cageless.tracking.io.packing import pack10, pack12

__all__ = ["CineFormat", "write_cine", "CINE_FORMATS"]

#: A fixed trigger time (2026-01-01T00:00:00Z) so the same input gives the same bytes.
DEFAULT_TRIGGER_S = 1_767_225_600


@dataclass(frozen=True)
class CineFormat:
    """A pixel storage format: bits per pixel, container and packing code."""

    name: str
    bits: int
    bi_bit_count: int
    bi_compression: int

    def image_size(self, width: int, height: int) -> int:
        """Bytes of one frame."""
        return width * height * (self.bits if self.bi_compression else self.bi_bit_count) // 8


CINE_FORMATS = {
    "8": CineFormat("8", 8, 8, 0),
    "16": CineFormat("16", 16, 16, 0),
    "p10": CineFormat("p10", 10, 16, 256),
    "p12": CineFormat("p12", 12, 16, 1024),
}


def _time64(base_s: int, offset_s: float = 0.0) -> int:
    """TIME64 of ``base_s + offset_s``, keeping the integer base exact (no float64 loss at 1.7e9 s)."""
    whole = int(np.floor(offset_s))
    frac = int(round((offset_s - whole) * TIME64_FRACTION))
    whole += base_s
    if frac == TIME64_FRACTION:
        whole, frac = whole + 1, 0
    return (whole << 32) | frac


def _setup_block(width: int, height: int, fps: float, real_bpp: int, exposure_s: float,
                 serial: int, description: str) -> bytes:
    buf = bytearray(SETUP_SIZE)
    values = {
        "frame_rate_16": min(int(round(fps)), 0xFFFF), "shutter_16": min(int(round(exposure_s * 1e6)), 0xFFFF),
        "length": SETUP_SIZE, "im_width": width, "im_height": height, "serial": serial,
        "frame_rate": int(round(fps)), "shutter": int(round(exposure_s * 1e6)), "software_version": 0,
        "cfa": 0, "real_bpp": real_bpp, "decimation": 1, "shutter_ns": int(round(exposure_s * 1e9)),
        "description": description.encode("latin-1", "replace")[:4095],
        "black_level": 0, "white_level": (1 << real_bpp) - 1,
    }
    for name, value in values.items():
        offset, fmt = SETUP_FIELDS[name]
        struct.pack_into("<" + fmt, buf, offset, value)
    return bytes(buf)


def _check_args(fmt: str, real_bpp: int | None, fps: float, n: int) -> tuple[CineFormat, int]:
    if fmt not in CINE_FORMATS:
        raise ParameterError("fmt", f"must be one of {sorted(CINE_FORMATS)}", fmt)
    f = CINE_FORMATS[fmt]
    bpp = f.bits if real_bpp is None else int(real_bpp)
    if not (1 <= bpp <= f.bits):
        raise ParameterError("real_bpp", f"must lie in 1..{f.bits} for format {fmt}", real_bpp)
    if not np.isfinite(fps) or fps <= 0:
        raise ParameterError("fps", "must be a finite number > 0", fps)
    if n < 1:
        raise ParameterError("frames", "must hold at least one frame", n)
    return f, bpp


def _encode(frame: np.ndarray, f: CineFormat, bpp: int, shape: tuple[int, int], index: int) -> bytes:
    a = np.asarray(frame)
    if a.shape != shape:
        raise ParameterError(f"frames[{index}]", f"has shape {a.shape}; all frames must be {shape}")
    if a.dtype.kind not in "ui" or (a.size and (a.min() < 0 or a.max() >= (1 << bpp))):
        raise ParameterError(f"frames[{index}]", f"must hold unsigned integers below 2**{bpp}")
    if f.bi_compression == 256:
        return pack10(a).tobytes()
    if f.bi_compression == 1024:
        return pack12(a).tobytes()
    dtype = np.uint8 if f.bi_bit_count == 8 else np.dtype("<u2")
    return np.ascontiguousarray(a[::-1], dtype=dtype).tobytes()  # rows bottom-up


def write_cine(
    path: str | Path,
    frames: Iterable[npt.ArrayLike],
    *,
    fps: float,
    fmt: str = "16",
    real_bpp: int | None = None,
    n_frames: int | None = None,
    timestamps_s: Sequence[float] | npt.ArrayLike | None = None,
    exposure_s: float = 10e-6,
    serial: int = 0,
    description: str = "",
) -> Path:
    """Write frames to a monochrome Phantom ``.cine`` file, atomically.

    Parameters
    ----------
    path
        Output file.
    frames
        2-D integer frames (rows top to bottom), all the same shape. An iterator is fine if
        ``n_frames`` is given; frames are streamed, never stacked.
    fps
        Header frame rate (stored as an integer, as Phantom does).
    fmt
        ``"8"``, ``"16"`` (16-bit words), ``"p10"`` or ``"p12"`` (packed).
    real_bpp
        Significant bits (``RealBPP``), default the format's bits; values must be below ``2**real_bpp``.
    n_frames
        Frame count; default ``len(frames)``.
    timestamps_s
        Per-frame times (s) from the first frame; default ``i / fps``. Gaps show dropped frames.
    exposure_s
        Exposure time (s) for every frame.
    serial
        Camera serial number to record.
    description
        Free text stored in the SETUP description.

    Returns
    -------
    pathlib.Path
        The written file.
    """
    n = len(frames) if n_frames is None else int(n_frames)  # type: ignore[arg-type]
    f, bpp = _check_args(fmt, real_bpp, fps, n)
    stamps = _frame_times(timestamps_s, fps, n)
    it = iter(frames)
    first = _first_frame(next(it), f)
    height, width = first.shape
    img = f.image_size(width, height)
    desc = description or f"written by cageless {__version__}"
    head = _headers(f, (width, height), fps, bpp, stamps, exposure_s, serial, desc)
    with atomic_path(path) as tmp, open(tmp, "wb") as fh:
        fh.write(head)
        _write_images(fh, first, it, n, f, bpp, img)
    return Path(path)


def _frame_times(timestamps_s: Sequence[float] | npt.ArrayLike | None, fps: float,
                 n: int) -> npt.NDArray[np.float64]:
    """The ``n`` frame times (s): ``timestamps_s`` checked, or ``i / fps``."""
    stamps = np.arange(n) / fps if timestamps_s is None else np.asarray(timestamps_s, dtype=np.float64)
    if stamps.shape != (n,) or not np.all(np.isfinite(stamps)) or np.any(np.diff(stamps) <= 0):
        raise ParameterError("timestamps_s", f"must be {n} finite, strictly increasing times")
    return stamps


def _first_frame(frame: npt.ArrayLike, f: CineFormat) -> np.ndarray:
    """The first frame as an array, checked: 2-D, and a pixel count the packed formats can group."""
    first = np.asarray(frame)
    if first.ndim != 2:
        raise ParameterError("frames[0]", f"must be 2-D, got shape {first.shape}")
    height, width = first.shape
    if f.bi_compression and (width * height) % (4 if f.bits == 10 else 2):
        raise ParameterError("frames", f"{width} x {height} pixels cannot be packed in {f.bits}-bit groups")
    return first


def _headers(f: CineFormat, size: tuple[int, int], fps: float, bpp: int, stamps: npt.NDArray[np.float64],
             exposure_s: float, serial: int, desc: str) -> bytes:
    """Everything before the first image: the file header, BITMAPINFOHEADER, SETUP, the tagged blocks and
    the image offsets."""
    width, height = size
    n, img = len(stamps), f.image_size(width, height)
    setup = _setup_block(width, height, fps, bpp, exposure_s, serial, desc)
    tagged = _tagged_blocks(stamps, exposure_s)
    off_offsets = HEADER.size + BITMAPINFO.size + len(setup) + len(tagged)
    first_image = off_offsets + 8 * n
    return b"".join([
        HEADER.pack(MAGIC, HEADER.size, 0, 1, 0, n, 0, n, HEADER.size, HEADER.size + BITMAPINFO.size, off_offsets,
                    _time64(DEFAULT_TRIGGER_S)),
        BITMAPINFO.pack(BITMAPINFO.size, width, height, 1, f.bi_bit_count, f.bi_compression, img, 0, 0, 0, 1 << bpp),
        setup, tagged, (first_image + np.arange(n, dtype="<i8") * (8 + img)).astype("<i8").tobytes()])


def _tagged_blocks(stamps: npt.NDArray[np.float64], exposure_s: float) -> bytes:
    n = len(stamps)
    t64 = np.array([_time64(DEFAULT_TRIGGER_S, s) for s in stamps], dtype="<u8")
    exp = np.full(n, int(round(exposure_s * TIME64_FRACTION)), dtype="<u4")
    return (BLOCK_HEADER.pack(8 + 8 * n, TAG_TIME_ONLY, 1) + t64.tobytes()
            + BLOCK_HEADER.pack(8 + 4 * n, TAG_EXPOSURE_ONLY, 0) + exp.tobytes())


def _write_images(fh: BinaryIO, first: np.ndarray, rest: Iterable[npt.ArrayLike], n: int,
                  f: CineFormat, bpp: int, img: int) -> None:
    shape = first.shape
    annotation = struct.pack("<II", 8, img)
    written = 0
    for i, frame in enumerate(_chain(first, rest)):
        if i >= n:
            raise ParameterError("frames", f"holds more than n_frames = {n} frames")
        fh.write(annotation)
        fh.write(_encode(np.asarray(frame), f, bpp, shape, i))  # type: ignore[arg-type]
        written += 1
    if written != n:
        raise ParameterError("frames", f"held {written} frames but n_frames = {n}")


def _chain(first: np.ndarray, rest: Iterable[npt.ArrayLike]) -> Iterable[npt.ArrayLike]:
    yield first
    yield from rest
