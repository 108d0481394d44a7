"""Frame sources: one lazy, random-access interface for every kind of video.

>>> from cageless.tracking.io import open_video
>>> with open_video("n3000_Fr500_Fa0.cine") as video:          # doctest: +SKIP
...     print(len(video), video.frame_shape, video.metadata.time_source)
...     for first, frames in video.iter_chunks(256):
...         ...

:func:`open_video` picks the reader from the path: ``.cine`` (our own reader),
``.avi``/``.mp4``/``.mkv`` (OpenCV), or a folder of numbered ``.tif``/``.png``.
"""

from __future__ import annotations

from pathlib import Path

from cageless.errors import VideoError, is_trace_name, trace_not_video
from cageless.tracking.io.base import FrameSource, VideoMetadata
from cageless.tracking.io.cine import CineReader
from cageless.tracking.io.cine_write import CINE_FORMATS, write_cine
from cageless.tracking.io.images import ImageSequenceReader, write_image_sequence
from cageless.tracking.io.opencv import OpenCVReader, write_ffv1

__all__ = [
    "open_video", "FrameSource", "VideoMetadata", "CineReader", "OpenCVReader", "ImageSequenceReader",
    "write_cine", "write_ffv1", "write_image_sequence", "CINE_FORMATS", "VIDEO_SUFFIXES",
]

VIDEO_SUFFIXES = {".cine": CineReader, ".avi": OpenCVReader, ".mp4": OpenCVReader, ".mkv": OpenCVReader}


def open_video(path: str | Path, fps: float | None = None, allow_truncated: bool = False) -> FrameSource:
    """Open a video lazily with the reader its path calls for.

    Parameters
    ----------
    path
        A ``.cine``, ``.avi``, ``.mp4`` or ``.mkv`` file, or a folder of numbered images.
    fps
        Frame-rate override (frames/s), for files without (or with wrong) timing.
    allow_truncated
        Read the complete frames of a truncated ``.cine`` instead of refusing it.

    Returns
    -------
    FrameSource
        A lazy frame source; use it as a context manager to release the file.

    Raises
    ------
    VideoError
        For a missing path, an unknown kind of file, or a file its reader refuses.
    """
    path = Path(path)
    if path.is_dir():
        return ImageSequenceReader(path, fps=fps)
    if not path.exists():
        raise VideoError(path, "no such file or folder.")
    reader = VIDEO_SUFFIXES.get(path.suffix.lower())
    if reader is None and is_trace_name(path):
        raise trace_not_video(path)
    if reader is None:
        raise VideoError(path, f"is not a video cageless reads (suffix '{path.suffix}').",
                         hint="Use .cine, .avi, .mp4, .mkv, or a folder of numbered .tif/.png images.")
    if allow_truncated and reader is CineReader:
        return CineReader(path, fps=fps, allow_truncated=True)
    return reader(path, fps=fps)
