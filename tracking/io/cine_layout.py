"""Byte layout of Phantom ``.cine`` files, shared by our reader and writer.

A cine file holds, in order:

1. ``CINEFILEHEADER`` (44 bytes at 0): magic ``"CI"``, compression, image
   count, and the offsets of the next three parts;
2. ``BITMAPINFOHEADER`` (40 bytes): width, height, bit count, packing;
3. ``SETUP`` (``Length`` bytes, which grew across software versions): frame
   rate, exposure, ``RealBPP``, ``CFA``, software version, camera serial, ...;
4. tagged blocks (from ``OffSetup + Length`` to ``OffImageOffsets``): each a
   ``u32 size, u16 type, u16 reserved`` header and a payload; type 1002 holds
   one ``TIME64`` per frame, type 1003 one exposure per frame;
5. ``pImage``: one ``int64`` file offset per frame;
6. per frame: ``u32 AnnotationSize``, annotation, ``u32 ImageSize`` (the last
   4 of the AnnotationSize bytes), then the pixels.

Uncompressed rows are stored bottom-up (BMP convention); packed 10/12-bit rows
are stored top-down. ``TIME64`` is ``seconds << 32 | fraction * 2**32``
(seconds since 1970 UTC).

Offsets inside ``SETUP`` were worked out from the field lists of PIMS
(``pims/cine.py``, BSD) and confirmed on the two real Phantom files of
``shared/reference/cine`` (frame rate 90000 and 35087, RealBPP 12 and 14).
"""

from __future__ import annotations

import struct

__all__ = [
    "HEADER", "HEADER_FIELDS", "BITMAPINFO", "BITMAPINFO_FIELDS", "SETUP_FIELDS", "SETUP_SIZE",
    "BLOCK_HEADER", "TAG_TIME_ONLY", "TAG_EXPOSURE_ONLY", "TAG_RANGE_DATA", "MAGIC", "TIME64_FRACTION",
]

MAGIC = b"CI"

HEADER = struct.Struct("<2sHHHiIiIIIIQ")
HEADER_FIELDS = (
    "type", "header_size", "compression", "version", "first_movie_image", "total_image_count",
    "first_image_no", "image_count", "off_image_header", "off_setup", "off_image_offsets", "trigger_time",
)

BITMAPINFO = struct.Struct("<IiiHHIIiiII")
BITMAPINFO_FIELDS = (
    "bi_size", "bi_width", "bi_height", "bi_planes", "bi_bit_count", "bi_compression",
    "bi_image_size", "bi_x_pels_per_meter", "bi_y_pels_per_meter", "bi_clr_used", "bi_clr_important",
)

#: name -> (byte offset inside SETUP, struct format). Only the fields cageless uses.
SETUP_FIELDS: dict[str, tuple[int, str]] = {
    "frame_rate_16": (0, "H"),
    "shutter_16": (2, "H"),
    "length": (142, "H"),
    "im_width": (737, "H"),
    "im_height": (739, "H"),
    "serial": (743, "I"),
    "b_flip_h": (756, "i"),
    "b_flip_v": (760, "i"),
    "frame_rate": (768, "I"),
    "shutter": (772, "I"),
    "b_enable_color": (788, "i"),
    "camera_version": (792, "I"),
    "firmware_version": (796, "I"),
    "software_version": (800, "I"),
    "cfa": (808, "I"),
    "real_bpp": (896, "I"),
    "decimation": (1556, "I"),
    "shutter_ns": (1568, "I"),
    "description": (1596, "4096s"),
    "black_level": (5732, "i"),
    "white_level": (5736, "i"),
}
#: SETUP bytes our writer emits: up to and including the 256-byte lens description.
SETUP_SIZE = 5996

BLOCK_HEADER = struct.Struct("<IHH")
TAG_TIME_ONLY = 1002
TAG_EXPOSURE_ONLY = 1003
TAG_RANGE_DATA = 1004

#: Width of the TIME64 fraction field.
TIME64_FRACTION = 2**32
