"""Phantom ``.cine`` reader, written from the file layout (no GPL code involved).

Supported: monochrome 8-bit and 16-bit frames (any ``RealBPP`` up to 16), and
packed 10-bit (P10) and 12-bit (P12L) frames. Per-frame time comes from the
time-stamp tagged block (type 1002) when present, because the header frame
rate is wrong for decimated recordings; the metadata says which was used.

**Colour is refused**: a cine whose ``CFA`` field is non-zero (Bayer or other
colour sensors), or whose frames are 24/48-bit RGB, raises
:class:`~cageless.errors.VideoError` asking for a monochrome export. The
bearing videos cageless is built for are monochrome.

P10 data from real cameras are log-encoded; this reader returns the raw 10-bit
codes (``metadata.storage`` says so) and does not apply Vision Research's
linearisation table.

The file is memory-mapped for random access. Runs of frames (``video[a:b]``,
``iter_chunks``) are read with one ``readinto`` per run, like ``numpy.fromfile``:
8/16-bit runs come back as a row-reversed strided view of that buffer (no
second copy), packed runs are unpacked by a compiled loop.
"""

from __future__ import annotations

import logging
import mmap
import os
import struct
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from cageless.errors import VideoError
from cageless.tracking.io.base import FrameSource, VideoMetadata
from cageless.tracking.io.cine_layout import (
    BITMAPINFO,
    BITMAPINFO_FIELDS,
    BLOCK_HEADER,
    HEADER,
    HEADER_FIELDS,
    MAGIC,
    SETUP_FIELDS,
    TAG_EXPOSURE_ONLY,
    TAG_RANGE_DATA,
    TAG_TIME_ONLY,
    TIME64_FRACTION,
)
from cageless.tracking.io.packing import PACKED_BITS, unpack10, unpack12, unpack_frames_into

__all__ = ["CineReader"]

_UNPACK = {10: unpack10, 12: unpack12}


class CineReader(FrameSource):
    """Lazy, memory-mapped reader of a Phantom ``.cine`` file.

    Parameters
    ----------
    path
        The ``.cine`` file.
    fps
        Frame-rate override (frames/s); replaces the file's timing.
    allow_truncated
        Read the complete frames of a truncated file instead of refusing it.

    Raises
    ------
    VideoError
        For a file that is not a cine (wrong magic), has zero frames, is
        truncated or corrupt (with the byte offset), or is colour or compressed.
    """

    def __init__(self, path: str | Path, fps: float | None = None, allow_truncated: bool = False) -> None:
        super().__init__(path)
        self._size = self.path.stat().st_size if self.path.is_file() else -1
        if self._size < 0:
            raise VideoError(self.path, "no such file.")
        if self._size < HEADER.size:
            raise VideoError(self.path, f"is too short ({self._size} bytes) to hold a cine header.", offset=0)
        self._mm = np.memmap(self.path, dtype=np.uint8, mode="r")
        self._stack: np.ndarray | None | bool = False  # built on first use by frame_stack()
        self.header = self._unpack_named(HEADER, HEADER_FIELDS, 0, "CINEFILEHEADER")
        self._check_header()
        self.bitmap = self._unpack_named(BITMAPINFO, BITMAPINFO_FIELDS, self.header["off_image_header"], "BITMAPINFOHEADER")
        self.setup = self._read_setup(self.header["off_setup"])
        self._layout_pixels()
        stamps, exposures = self._read_tagged_blocks()
        #: Raw per-frame TIME64 values (seconds << 32 | fraction), or ``None``.
        self.raw_timestamps = stamps
        self._locate_frames(allow_truncated)
        self.metadata = self._build_metadata(exposures)
        if stamps is not None:
            stamps = stamps[: self.metadata.n_frames]
        self._apply_timing(fps, stamps)

    # -- parsing ---------------------------------------------------------------------------------
    def _unpack(self, fmt: str | struct.Struct, offset: int, what: str) -> tuple[Any, ...]:
        s = fmt if isinstance(fmt, struct.Struct) else struct.Struct("<" + fmt)
        if offset < 0 or offset + s.size > self._size:
            raise VideoError(self.path, f"is truncated or corrupt: {what} lies past the end of the file "
                             f"({self._size} bytes)", offset=offset,
                             hint="Its headers are incomplete, so no frame can be read: re-copy it from the camera or "
                             "the original disk.")
        return s.unpack_from(self._mm, offset)

    def _unpack_named(self, s: struct.Struct, names: tuple[str, ...], offset: int, what: str) -> dict[str, Any]:
        return dict(zip(names, self._unpack(s, offset, what), strict=True))

    def _check_header(self) -> None:
        h = self.header
        if h["type"] != MAGIC:
            raise VideoError(self.path, f"wrong magic bytes {h['type']!r} (expected b'CI'): not a Phantom cine file.",
                             offset=0)
        if h["compression"] != 0:
            kind = {1: "JPEG-compressed", 2: "uninterpolated colour (raw CFA)"}.get(h["compression"], "compressed")
            raise VideoError(self.path, f"is {kind} (compression = {h['compression']}), which cageless does not read.",
                             offset=4, hint="Save the cine uncompressed and monochrome from PCC.")
        if h["image_count"] == 0:
            raise VideoError(self.path, "has zero frames.", offset=20, hint="Re-export the recording with its frames.")

    def _read_setup(self, offset: int) -> dict[str, Any]:
        (length,) = self._unpack("H", offset + SETUP_FIELDS["length"][0], "SETUP.Length")
        self._unpack(f"{length}s", offset, "SETUP")  # the whole block must be present
        setup: dict[str, Any] = {"length": length}
        for name, (rel, fmt) in SETUP_FIELDS.items():
            if rel + struct.calcsize("<" + fmt) <= length:
                (value,) = struct.unpack_from("<" + fmt, self._mm, offset + rel)
                setup[name] = value.split(b"\0", 1)[0].decode("latin-1") if isinstance(value, bytes) else value
        return setup

    def _layout_pixels(self) -> None:
        b, s = self.bitmap, self.setup
        self.width, height = int(b["bi_width"]), int(b["bi_height"])
        self.height, self._bottom_up = abs(height), height > 0
        if self.width <= 0 or height == 0:
            raise VideoError(self.path, f"has an impossible frame size {self.width} x {height}.", offset=self.header["off_image_header"] + 4)
        if s.get("cfa", 0) != 0 or b["bi_bit_count"] in (24, 48):
            raise VideoError(self.path, f"is a colour cine (CFA = {s.get('cfa', 0)}, {b['bi_bit_count']} bits per pixel); "
                             "cageless reads monochrome cines only.", offset=self.header["off_setup"] + SETUP_FIELDS["cfa"][0],
                             hint="Export a monochrome (luminance) cine from PCC.")
        comp = b["bi_compression"]
        n = self.width * self.height
        if comp in PACKED_BITS:
            self._packed_bits = PACKED_BITS[comp]
            self._dtype = np.dtype(np.uint16)
            self._image_size = n * self._packed_bits // 8
            self._bit_depth = self._packed_bits
            name = "P10, raw log-encoded codes" if comp == 256 else "P12L"
            self._storage = f"packed {self._packed_bits}-bit ({name})"
            real = int(s.get("real_bpp") or 0)
            if real and not 8 <= real <= 16:  # RealBPP is 8..16 in every cine format; 0 means not recorded
                raise VideoError(self.path, f"declares {real} significant bits per pixel (RealBPP) in packed "
                                 f"{self._packed_bits}-bit frames; a cine holds 8 to 16.",
                                 offset=self.header["off_setup"] + SETUP_FIELDS["real_bpp"][0],
                                 hint="The header is corrupt: re-export the cine.")
        elif comp == 0 and b["bi_bit_count"] in (8, 16):
            self._packed_bits = 0
            self._dtype = np.dtype(np.uint8 if b["bi_bit_count"] == 8 else "<u2")
            self._image_size = n * self._dtype.itemsize
            self._bit_depth = int(s.get("real_bpp") or b["bi_bit_count"])
            # The cine format's SETUP.RealBPP is 8 on 8-bit cameras and 8..14 on 14-bit ones, stored in
            # 16-bit words above 8 (Vision Research's SETUP definition); anything else is a corrupt header.
            if not 8 <= self._bit_depth <= b["bi_bit_count"]:
                raise VideoError(self.path, f"declares {self._bit_depth} significant bits per pixel (RealBPP) in "
                                 f"{b['bi_bit_count']}-bit words; a cine holds 8 to {b['bi_bit_count']}.",
                                 offset=self.header["off_setup"] + SETUP_FIELDS["real_bpp"][0],
                                 hint="The header is corrupt: re-export the cine.")
            self._storage = f"{b['bi_bit_count']}-bit words"
        else:
            raise VideoError(self.path, f"has an unsupported pixel format (biCompression = {comp}, "
                             f"biBitCount = {b['bi_bit_count']}).", offset=self.header["off_image_header"] + 14)

    def _read_tagged_blocks(self) -> tuple[npt.NDArray[np.uint64] | None, npt.NDArray[np.float64] | None]:
        pos = self.header["off_setup"] + self.setup["length"]
        end = self.header["off_image_offsets"]
        n = self.header["image_count"]
        stamps = exposures = None
        while pos + BLOCK_HEADER.size <= end:
            size, kind, _ = self._unpack(BLOCK_HEADER, pos, "a tagged block header")
            if size < BLOCK_HEADER.size or kind == TAG_RANGE_DATA:
                break
            count = (size - BLOCK_HEADER.size)
            if kind == TAG_TIME_ONLY and count // 8 >= n:
                self._unpack(f"{8 * n}s", pos + 8, "the time-stamp block")
                stamps = np.frombuffer(self._mm, dtype="<u8", count=n, offset=pos + 8).copy()
            elif kind == TAG_EXPOSURE_ONLY and count // 4 >= n:
                self._unpack(f"{4 * n}s", pos + 8, "the exposure block")
                exposures = np.frombuffer(self._mm, dtype="<u4", count=n, offset=pos + 8) / TIME64_FRACTION
            pos += size
        return stamps, exposures

    def _locate_frames(self, allow_truncated: bool) -> None:
        n = self.header["image_count"]
        off = self.header["off_image_offsets"]
        self._unpack(f"{8 * n}s", off, f"the table of {n} frame offsets")
        starts = np.frombuffer(self._mm, dtype="<i8", count=n, offset=off).astype(np.int64)
        data_start = np.full(n, -1, dtype=np.int64)
        complete = 0
        # The frame headers are read with pread, not through the map: touching one page of every frame
        # would map (and count in the resident memory) a large part of every frame.
        fd = os.open(self.path, os.O_RDONLY)
        try:
            complete = self._check_frames(fd, starts, off, data_start)
        finally:
            os.close(fd)
        if complete < n:
            bad = int(starts[complete])
            if not allow_truncated or complete == 0:
                hint = ("Re-copy the file, or re-run with --allow-truncated to use the complete frames." if complete
                        else "Not one frame is complete, so --allow-truncated cannot help: re-copy the file.")
                raise VideoError(self.path, f"is truncated: frame {complete} of {n} starts at or runs past the end of "
                                 f"the file ({self._size} bytes).", offset=bad, hint=hint)
            _warn_once(f"{self.path}: truncated; using its {complete} complete frames of {n} ({n - complete} dropped).")
        self._data_start = data_start[:complete]
        self._n = complete

    def _check_frames(self, fd: int, starts: np.ndarray, off: int, data_start: np.ndarray) -> int:
        """Fill ``data_start`` from each frame's annotation header; return how many frames are complete."""
        n = len(starts)
        for i, start in enumerate(starts):
            if start < off + 8 * n or start + 8 > self._size:
                return i
            (ann,) = struct.unpack("<I", os.pread(fd, 4, int(start)))
            if ann < 8 or start + ann > self._size:
                return i
            (img,) = struct.unpack("<I", os.pread(fd, 4, int(start + ann - 4)))
            if img != self._image_size:
                raise VideoError(self.path, f"frame {i} declares {img} bytes of pixels but a {self.width} x {self.height} "
                                 f"{self._storage} frame needs {self._image_size}: the file is corrupt.",
                                 offset=int(start + ann - 4))
            if start + ann + img > self._size:
                return i
            data_start[i] = start + ann
        return n

    def _unmap(self, lo: int, hi: int) -> None:
        """Drop the mapped pages of bytes ``lo..hi`` from this process (they stay in the page cache)."""
        mm = getattr(self._mm, "_mmap", None)
        if mm is None or not hasattr(mm, "madvise") or hi <= lo:
            return
        lo -= lo % mmap.PAGESIZE
        mm.madvise(mmap.MADV_DONTNEED, lo, min(hi, self._size) - lo)

    def _build_metadata(self, exposures: npt.NDArray[np.float64] | None) -> VideoMetadata:
        h, s = self.header, self.setup
        header_fps = float(s.get("frame_rate") or s.get("frame_rate_16") or 0) or None
        exposure = s["shutter_ns"] * 1e-9 if s.get("shutter_ns") else (s.get("shutter", 0) * 1e-6 or None)
        meta = VideoMetadata(
            path=str(self.path), format="cine", n_frames=self._n, width=self.width, height=self.height,
            dtype=self._dtype.name, bit_depth=self._bit_depth, storage=self._storage, header_fps=header_fps,
            exposure_s=exposure,
            camera=f"Phantom (camera version {s.get('camera_version', '?')}, serial {s.get('serial', '?')})",
            extra={
                "software_version": s.get("software_version"), "firmware_version": s.get("firmware_version"),
                "cfa": s.get("cfa", 0), "flip_v": s.get("b_flip_v"), "decimation": s.get("decimation"),
                "first_image_no": h["first_image_no"], "total_image_count": h["total_image_count"],
                "trigger_time_utc": _time64_to_iso(h["trigger_time"]), "setup_length": s["length"],
                "description": s.get("description", ""),
            },
        )
        if self._n < h["image_count"]:
            meta.notes.append(f"truncated file: {self._n} of {h['image_count']} frames are complete")
        if exposures is not None:
            meta.extra["exposure_per_frame_s"] = [float(x) for x in exposures[: self._n]]
        return meta

    def _apply_timing(self, fps_override: float | None, stamps: Any) -> None:  # type: ignore[override]
        seconds = None
        if stamps is not None:
            rel = (stamps.astype(np.int64) - np.int64(stamps[0])).astype(np.float64) / TIME64_FRACTION
            seconds = rel  # exact differences, no float64 loss at 1.7e9 s
        super()._apply_timing(fps_override, seconds)

    # -- frames -----------------------------------------------------------------------------------
    def _read(self, index: int) -> np.ndarray:
        start = int(self._data_start[index])
        raw = self._mm[start:start + self._image_size]
        if self._packed_bits:
            return _UNPACK[self._packed_bits](raw, self.width * self.height).reshape(self.height, self.width)
        frame = raw.view(self._dtype).reshape(self.height, self.width)
        return np.array(frame[::-1] if self._bottom_up else frame)

    def frame_view(self, index: int) -> np.ndarray:
        """A read-only view of frame ``index`` into the memory map (8/16-bit frames); a copy for packed ones."""
        n = len(self)
        if not -n <= index < n:
            raise IndexError(f"frame {index} out of range for {n} frames of {self.path}")
        if self._packed_bits:
            return self._read(index % n)
        stack = self.frame_stack()
        if stack is not None:
            return stack[index % n]
        start = int(self._data_start[index % n])
        frame = self._mm[start:start + self._image_size].view(self._dtype).reshape(self.height, self.width)
        return frame[::-1] if self._bottom_up else frame

    def frame_stack(self) -> np.ndarray | None:
        """Every frame as one read-only (n, H, W) array viewing the memory map, upright; ``None`` for
        packed frames or frames not laid out at one pitch.

        Indexing it (``stack[i, rows, cols]``) costs a plain ndarray slice: no ``numpy.memmap``
        objects are made per frame, and only the pages a caller touches are read.
        """
        if self._stack is False:
            self._stack = self._build_stack()
        return self._stack  # type: ignore[return-value]

    def _build_stack(self) -> np.ndarray | None:
        n, h, w, item = len(self), self.height, self.width, self._dtype.itemsize
        if self._packed_bits or n == 0:
            return None
        starts = self._data_start
        step = int(starts[1] - starts[0]) if n > 1 else self._image_size
        if n > 1 and (not np.all(np.diff(starts) == step) or step < self._image_size):
            return None
        first, row = int(starts[0]), w * item
        if self._bottom_up:  # start at the last row of the first frame and walk the rows backwards
            first, row = first + (h - 1) * row, -row
        raw = getattr(self._mm, "_mmap", None)
        if raw is None:
            return None
        return np.ndarray((n, h, w), dtype=self._dtype, buffer=raw, offset=first, strides=(step, row, item))

    def drop_pages(self, first: int, last: int) -> None:
        """Unmap the file pages of frames ``first..last`` (they stay in the page cache), keeping the
        resident memory bounded while frame views stream through a long video."""
        if len(self) == 0:
            return
        lo = int(self._data_start[max(min(first, last), 0)])
        hi = int(self._data_start[min(max(first, last), len(self) - 1)]) + self._image_size
        self._unmap(lo, hi)

    def _read_range(self, start: int, stop: int) -> np.ndarray:
        n = stop - start
        if n <= 1:
            return super()._read_range(start, stop)
        starts = self._data_start[start:stop]
        pitch = np.diff(starts)
        item = self._dtype.itemsize
        if not np.all(pitch == pitch[0]) or pitch[0] < self._image_size or pitch[0] % item:
            return super()._read_range(start, stop)  # frames not evenly laid out: frame by frame
        first, step = int(starts[0]), int(pitch[0])
        buf = np.empty(step * (n - 1) + self._image_size, dtype=np.uint8)
        with open(self.path, "rb", buffering=0) as fh:
            fh.seek(first)
            got = fh.readinto(memoryview(buf))
        if got != buf.size:
            raise VideoError(self.path, f"frames {start}..{stop - 1} end early (file changed while open?).",
                             offset=first + got)
        h, w = self.height, self.width
        if self._packed_bits:
            out = np.empty((n, h, w), dtype=np.uint16)
            unpack_frames_into(buf, np.arange(n, dtype=np.int64) * step, out, self._packed_bits)
            return out
        if self._bottom_up:  # start at the last row of the first frame, walk rows backwards
            return np.lib.stride_tricks.as_strided(
                buf[(h - 1) * w * item:].view(self._dtype), shape=(n, h, w), strides=(step, -w * item, item),
                writeable=True)
        return np.lib.stride_tricks.as_strided(buf.view(self._dtype), shape=(n, h, w),
                                               strides=(step, w * item, item), writeable=True)

    def close(self) -> None:
        """Drop the memory map (the OS unmaps it once no frame view refers to it)."""
        self._mm = None  # type: ignore[assignment]
        self._stack = None


def _time64_to_iso(t: int) -> str:
    """TIME64 (seconds << 32 | fraction) to an ISO-8601 UTC string."""
    secs, frac = t >> 32, (t & 0xFFFFFFFF) / TIME64_FRACTION
    try:
        return datetime.fromtimestamp(secs + frac, UTC).isoformat()
    except (OverflowError, OSError, ValueError):
        return ""


_WARNED: set[str] = set()


def _warn_once(message: str) -> None:
    """Log ``message`` once per process: a tracked video is opened more than once (hashing, segments)."""
    if message not in _WARNED:
        _WARNED.add(message)
        logging.getLogger(__name__).warning("%s", message)
