"""Video files through OpenCV (``.avi``, ``.mp4``, ``.mkv``), and an 8-bit FFV1 writer.

Frames come back as 8-bit luminance (the first channel of OpenCV's gray-as-BGR
decode). Random access seeks by ``CAP_PROP_POS_FRAMES`` in AVI, where it is
exact; in MKV/MP4 it moves forward by grabbing frames and re-opens the file to
go back, which is always exact but slow, so read those sequentially
(:meth:`~cageless.tracking.io.base.FrameSource.iter_chunks`); their ``seekable`` is False, and their frame
count (a whole decode) is kept per file for the process. The last :data:`FRAME_CACHE` frames
decoded are kept, so the frames the tracker's set-up samples more than once are decoded once.

Containers store their frame rate as a rational that may be rounded, so give
the true rate with ``fps`` (the conditions' ``fps`` key or ``--fps``) where it
matters. MKV keeps 10,000 fps exactly; OpenCV's AVI muxer drops frames above
1,000 fps, so :func:`write_ffv1` writes AVI at a container rate of at most
1,000 fps and says so in the log. 16-bit video is not supported
through OpenCV; use ``.cine`` or 16-bit TIFF/PNG sequences.
"""

from __future__ import annotations

import logging
import os
from collections import OrderedDict
from collections.abc import Iterable
from pathlib import Path

import cv2
import numpy as np
import numpy.typing as npt

from cageless.atomic import atomic_path
from cageless.errors import ParameterError, VideoError
from cageless.tracking.io.base import FrameSource, VideoMetadata

# FFmpeg's own log lines ("moov atom not found") would reach the terminal before cageless's one-line error about
# the same file; OpenCV reads this when it first opens a video. Set OPENCV_FFMPEG_LOGLEVEL yourself to see them.
os.environ.setdefault("OPENCV_FFMPEG_LOGLEVEL", "-8")

__all__ = ["OpenCVReader", "write_ffv1"]

log = logging.getLogger(__name__)

try:  # OpenCV's own console warnings (e.g. on a file it cannot open) would leak past our one-line errors
    cv2.utils.logging.setLogLevel(cv2.utils.logging.LOG_LEVEL_ERROR)
except AttributeError:  # pragma: no cover - builds without the logging utilities
    pass

_EXACT_SEEK = {".avi"}
_AVI_MAX_FPS = 1000.0
#: Decoded frames kept (8-bit: 64 MB at 1280 x 800). The tracker's set-up reads the same 25 spread frames for
#: each of its two background frames and the motion map; without the cache a 200-frame AVI was decoded 944 times.
FRAME_CACHE = 64
#: Frame counts of the MKV/MP4 files opened in this process, by (path, size, modification time): counting
#: decodes the whole file, whose header count is not exact.
_COUNTED: dict[tuple[str, int, int], int] = {}


class OpenCVReader(FrameSource):
    """Lazy reader of a video file through OpenCV's FFmpeg backend.

    Parameters
    ----------
    path
        The video file.
    fps
        Frame-rate override (frames/s).

    Raises
    ------
    VideoError
        If OpenCV cannot open or decode the file, or it holds no frame.
    """

    def __init__(self, path: str | Path, fps: float | None = None) -> None:
        super().__init__(path)
        if not self.path.is_file():
            raise VideoError(self.path, "no such file.")
        self._decoded: OrderedDict[int, np.ndarray] = OrderedDict()
        self.seekable = self.path.suffix.lower() in _EXACT_SEEK
        self._cap = self._open()
        first = self._decode(0)
        n = self._count_frames()
        container_fps = float(self._cap.get(cv2.CAP_PROP_FPS)) or None
        fourcc = int(self._cap.get(cv2.CAP_PROP_FOURCC))
        codec = "".join(chr((fourcc >> (8 * k)) & 0xFF) for k in range(4)).strip("\0 ")
        self.metadata = VideoMetadata(
            path=str(self.path), format="opencv", n_frames=n, width=first.shape[1], height=first.shape[0],
            dtype="uint8", bit_depth=8, storage=f"{codec or 'unknown codec'} video, 8-bit luminance",
            header_fps=container_fps, extra={"codec": codec},
        )
        self._apply_timing(fps, None)
        if self.metadata.time_source == "header frame rate":
            self.metadata.time_source = "container frame rate"
        if self._next != 1:  # counted to the end: start again (a count kept from before leaves it at frame 1)
            self._cap = self._open()

    def _open(self) -> cv2.VideoCapture:
        cap = cv2.VideoCapture(str(self.path), cv2.CAP_FFMPEG)
        if not cap.isOpened():
            raise VideoError(self.path, "OpenCV cannot open this video (unknown container or codec, or a damaged file).",
                             hint="Check the file plays, or convert it to FFV1 AVI or a .cine.")
        self._next = 0
        return cap

    def _decode(self, index: int) -> np.ndarray:
        ok, frame = self._cap.read()
        if not ok or frame is None:
            raise VideoError(self.path, f"cannot decode frame {index} (the file may be truncated or corrupt).")
        self._next = index + 1
        return frame[..., 0].copy() if frame.ndim == 3 else frame

    def _count_frames(self) -> int:
        n = self._cap.get(cv2.CAP_PROP_FRAME_COUNT)
        if self.seekable and 0 < n < 1e9:
            return int(n)
        stat = self.path.stat()
        key = (str(self.path.resolve()), stat.st_size, stat.st_mtime_ns)
        if key in _COUNTED:  # the tracker's segments each open the file again
            return _COUNTED[key]
        count = 1  # one frame was decoded already; count the rest without decoding
        while self._cap.grab():
            count += 1
        _COUNTED[key] = count
        self._next = count  # at the end: the next read opens the file again
        return count

    def _read(self, index: int) -> np.ndarray:
        kept = self._decoded.get(index)
        if kept is not None:
            self._decoded.move_to_end(index)
            return kept.copy()
        frame = self._seek_and_decode(index)
        self._decoded[index] = frame
        if len(self._decoded) > FRAME_CACHE:
            self._decoded.popitem(last=False)
        return frame.copy()

    def _seek_and_decode(self, index: int) -> np.ndarray:
        if index != self._next:
            if self.seekable:
                self._cap.set(cv2.CAP_PROP_POS_FRAMES, index)
                self._next = index
            else:
                if index < self._next:
                    self._cap.release()
                    self._cap = self._open()
                while self._next < index:
                    if not self._cap.grab():
                        raise VideoError(self.path, f"cannot reach frame {index}: the file ends early.")
                    self._next += 1
        return self._decode(index)

    def prefetch(self, indices: Iterable[int]) -> None:
        """Decode frames ``indices`` in one pass and keep them (all of them, up to :data:`FRAME_CACHE`), on a
        video that is not seekable: spread sample frames asked for in another order each cost a pass."""
        asked = {int(i) for i in indices}
        if self.seekable or len(asked) > FRAME_CACHE:
            return
        for i in asked & set(self._decoded):  # kept already: kept longer than the ones decoded now
            self._decoded.move_to_end(i)
        for i in sorted(asked - set(self._decoded)):
            self._read(i)

    def close(self) -> None:
        """Release the OpenCV capture."""
        cap = getattr(self, "_cap", None)
        if cap is not None:
            cap.release()


def write_ffv1(path: str | Path, frames: Iterable[npt.ArrayLike], fps: float) -> Path:
    """Write 8-bit gray frames as lossless FFV1 in an AVI or MKV container, atomically.

    The container may round ``fps``; record the true rate in the conditions.
    """
    path = Path(path)
    if path.suffix.lower() not in (".avi", ".mkv"):
        raise ParameterError("path", "FFV1 goes in an .avi or .mkv file", str(path))
    if path.suffix.lower() == ".avi" and fps > _AVI_MAX_FPS:
        log.warning("%s: AVI cannot hold %g fps; the container says %g fps; give the true rate in the conditions",
                    path, fps, _AVI_MAX_FPS)
        fps = _AVI_MAX_FPS
    writer = None
    count = 0
    with atomic_path(path) as tmp:
        tmp_named = tmp.with_suffix(path.suffix)
        try:
            for i, frame in enumerate(frames):
                a = np.asarray(frame)
                if a.ndim != 2 or a.dtype != np.uint8:
                    raise ParameterError(f"frames[{i}]", "must be a 2-D uint8 array for 8-bit FFV1")
                if writer is None:
                    writer = cv2.VideoWriter(str(tmp_named), cv2.CAP_FFMPEG, cv2.VideoWriter_fourcc(*"FFV1"),
                                             float(fps), (a.shape[1], a.shape[0]), False)
                    if not writer.isOpened():
                        raise VideoError(path, "OpenCV cannot write FFV1 here.")
                writer.write(a)
                count += 1
            if writer is None:
                raise ParameterError("frames", "must hold at least one frame")
            writer.release()
            _verify_count(tmp_named, count, path)
            tmp_named.replace(tmp)
        finally:
            if writer is not None:
                writer.release()
            tmp_named.unlink(missing_ok=True)
    return path


def _verify_count(written: Path, expected: int, final: Path) -> None:
    """Re-open a freshly written video and check that every frame made it into the container."""
    cap = cv2.VideoCapture(str(written), cv2.CAP_FFMPEG)
    found = 0
    while cap.grab():
        found += 1
    cap.release()
    if found != expected:
        raise VideoError(final, f"the video writer stored {found} of {expected} frames.",
                         hint="Use an .mkv container, or a lower container frame rate.")
