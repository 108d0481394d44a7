"""Bit packing of Phantom's packed pixel formats (big-endian bit order).

* 10-bit (``biCompression = 256``, "P10"): 4 pixels in 5 bytes;
* 12-bit (``biCompression = 1024``, "P12L"): 2 pixels in 3 bytes.

Pixel a, b of a 12-bit pair are stored as ``a[11:4] | a[3:0] b[11:8] | b[7:0]``;
10-bit quads likewise, most significant bits first. This is the bit order of
Vision Research's packed formats as read by PIMS (``pims/cine.py``) and pycine
(``pycine/raw.py``), both consulted for the layout only.
"""

from __future__ import annotations

import threading

import numba
import numpy as np
import numpy.typing as npt

__all__ = ["unpack10", "pack10", "unpack12", "pack12", "PACKED_BITS", "unpack_frames_into"]

#: numba's default (workqueue) threading layer must not run two parallel kernels at once.
_PARALLEL_LOCK = threading.Lock()

#: biCompression code -> bits per pixel
PACKED_BITS = {256: 10, 1024: 12}

U8 = npt.NDArray[np.uint8]
U16 = npt.NDArray[np.uint16]


def unpack12(data: U8, n_pixels: int) -> U16:
    """Unpack ``n_pixels`` (even) 12-bit pixels from ``3 n / 2`` bytes."""
    b = np.asarray(data, dtype=np.uint8)[: n_pixels * 3 // 2].reshape(-1, 3).astype(np.uint16)
    out = np.empty((b.shape[0], 2), dtype=np.uint16)
    out[:, 0] = (b[:, 0] << 4) | (b[:, 1] >> 4)
    out[:, 1] = ((b[:, 1] & 0x0F) << 8) | b[:, 2]
    return out.reshape(-1)


def pack12(pixels: npt.ArrayLike) -> U8:
    """Pack 12-bit pixels (an even count, values < 4096) into bytes."""
    p = np.asarray(pixels, dtype=np.uint16).reshape(-1, 2)
    out = np.empty((p.shape[0], 3), dtype=np.uint8)
    out[:, 0] = p[:, 0] >> 4
    out[:, 1] = ((p[:, 0] & 0x0F) << 4) | (p[:, 1] >> 8)
    out[:, 2] = p[:, 1] & 0xFF
    return out.reshape(-1)


def unpack10(data: U8, n_pixels: int) -> U16:
    """Unpack ``n_pixels`` (a multiple of 4) 10-bit pixels from ``5 n / 4`` bytes."""
    b = np.asarray(data, dtype=np.uint8)[: n_pixels * 5 // 4].reshape(-1, 5).astype(np.uint16)
    out = np.empty((b.shape[0], 4), dtype=np.uint16)
    out[:, 0] = (b[:, 0] << 2) | (b[:, 1] >> 6)
    out[:, 1] = ((b[:, 1] & 0x3F) << 4) | (b[:, 2] >> 4)
    out[:, 2] = ((b[:, 2] & 0x0F) << 6) | (b[:, 3] >> 2)
    out[:, 3] = ((b[:, 3] & 0x03) << 8) | b[:, 4]
    return out.reshape(-1)


def pack10(pixels: npt.ArrayLike) -> U8:
    """Pack 10-bit pixels (a multiple of 4, values < 1024) into bytes."""
    p = np.asarray(pixels, dtype=np.uint16).reshape(-1, 4)
    out = np.empty((p.shape[0], 5), dtype=np.uint8)
    out[:, 0] = p[:, 0] >> 2
    out[:, 1] = ((p[:, 0] & 0x03) << 6) | (p[:, 1] >> 4)
    out[:, 2] = ((p[:, 1] & 0x0F) << 4) | (p[:, 2] >> 6)
    out[:, 3] = ((p[:, 2] & 0x3F) << 2) | (p[:, 3] >> 8)
    out[:, 4] = p[:, 3] & 0xFF
    return out.reshape(-1)


@numba.njit(cache=True, nogil=True, parallel=True)
def _unpack12_into(buf, starts, out):  # pragma: no cover - compiled
    h, w = out.shape[1], out.shape[2]
    row_bytes = w * 3 // 2
    for fr in numba.prange(out.shape[0] * h):  # every row of every frame, over both cores
        f, r = fr // h, fr % h
        b = starts[f] + r * row_bytes
        row = out[f, r]
        for q in range(w // 2):
            b0, b1, b2 = np.int32(buf[b]), np.int32(buf[b + 1]), np.int32(buf[b + 2])
            row[2 * q] = np.uint16((b0 << 4) | (b1 >> 4))
            row[2 * q + 1] = np.uint16(((b1 & 15) << 8) | b2)
            b += 3


@numba.njit(cache=True, nogil=True, parallel=True)
def _unpack10_into(buf, starts, out):  # pragma: no cover - compiled
    h, w = out.shape[1], out.shape[2]
    row_bytes = w * 5 // 4
    for fr in numba.prange(out.shape[0] * h):
        f, r = fr // h, fr % h
        b = starts[f] + r * row_bytes
        row = out[f, r]
        for q in range(w // 4):
            b0, b1, b2 = np.int32(buf[b]), np.int32(buf[b + 1]), np.int32(buf[b + 2])
            b3, b4 = np.int32(buf[b + 3]), np.int32(buf[b + 4])
            row[4 * q] = np.uint16((b0 << 2) | (b1 >> 6))
            row[4 * q + 1] = np.uint16(((b1 & 63) << 4) | (b2 >> 4))
            row[4 * q + 2] = np.uint16(((b2 & 15) << 6) | (b3 >> 2))
            row[4 * q + 3] = np.uint16(((b3 & 3) << 8) | b4)
            b += 5


def unpack_frames_into(buf: U8, starts: npt.NDArray[np.int64], out: U16, bits: int) -> None:
    """Unpack packed frames from ``buf`` (frame k's bytes start at ``starts[k]``) into ``out`` (k, H, W).

    A compiled loop over rows on every core: one pass over the packed bytes, written straight into
    ``out``. Rows must hold whole pixel groups (width a multiple of 2 for 12-bit, 4 for 10-bit);
    otherwise the frames are unpacked whole with :func:`unpack12` / :func:`unpack10`.
    """
    group = 2 if bits == 12 else 4
    if out.shape[2] % group:
        unpack = unpack12 if bits == 12 else unpack10
        n = out.shape[1] * out.shape[2]
        for k, s in enumerate(starts):
            out[k] = unpack(buf[s:s + n * bits // 8], n).reshape(out.shape[1:])
        return
    with _PARALLEL_LOCK:
        (_unpack12_into if bits == 12 else _unpack10_into)(buf, starts, out)
