"""Folders of numbered 8- or 16-bit ``.tif``/``.png`` images, and a writer for them.

Files are ordered by the last number in their name (``frame_9.png`` before
``frame_10.png``). Image files carry no timing: give ``fps`` (the conditions'
``fps`` key or ``--fps``); a ``times.csv`` written beside the images by
:func:`write_image_sequence` (one time in s per line, with a header) is used
when present, so dropped frames survive the round trip.
"""

from __future__ import annotations

import re
from collections.abc import Iterable
from pathlib import Path

import cv2
import numpy as np
import numpy.typing as npt

from cageless.atomic import atomic_path, atomic_write_text
from cageless.conditions import IMAGE_SUFFIXES
from cageless.errors import ParameterError, VideoError
from cageless.tracking.io.base import FrameSource, VideoMetadata

__all__ = ["ImageSequenceReader", "write_image_sequence", "list_images"]

TIMES_FILE = "times.csv"
_NUMBER = re.compile(r"(\d+)(?!.*\d)")


def list_images(folder: Path) -> list[Path]:
    """The numbered images of a folder, in frame order."""
    files = [p for p in folder.iterdir() if p.suffix.lower() in IMAGE_SUFFIXES and _NUMBER.search(p.stem)]
    return sorted(files, key=lambda p: (int(_NUMBER.search(p.stem).group(1)), p.name))  # type: ignore[union-attr]


class ImageSequenceReader(FrameSource):
    """Lazy reader of a folder of numbered images.

    Parameters
    ----------
    path
        The folder.
    fps
        Frame rate (frames/s); overrides ``times.csv``.

    Raises
    ------
    VideoError
        For an empty folder, unreadable images, or images of differing size or depth.
    """

    def __init__(self, path: str | Path, fps: float | None = None) -> None:
        super().__init__(path)
        if not self.path.is_dir():
            raise VideoError(self.path, "is not a folder of images.")
        self._files = list_images(self.path)
        if not self._files:
            raise VideoError(self.path, "holds no numbered .tif/.png images.",
                             hint="Name frames with a number, e.g. frame_00001.tif.")
        first = self._load(0)
        if first.dtype not in (np.uint8, np.uint16):
            raise VideoError(self._files[0], f"has pixel type {first.dtype}; only 8- and 16-bit gray images are read.")
        self.metadata = VideoMetadata(
            path=str(self.path), format="image-sequence", n_frames=len(self._files), width=first.shape[1],
            height=first.shape[0], dtype=first.dtype.name, bit_depth=8 * first.dtype.itemsize,
            storage=f"{self._files[0].suffix.lstrip('.')} images, {8 * first.dtype.itemsize}-bit",
        )
        self._check_numbering(has_times=self._times_count() == len(self._files))
        stamps = self._read_times_file()
        self._apply_timing(fps, stamps)

    def _check_numbering(self, has_times: bool) -> None:
        """Refuse a stray image (another name pattern), a repeated number, or a gap in the numbers.

        A gap is allowed when ``times.csv`` gives each image's time (then the times carry the gap).
        A stray or missing image is named, not reported as a count mismatch with ``times.csv``.
        """
        def pattern(p: Path) -> str:
            return _NUMBER.sub("#", p.stem) + p.suffix.lower()

        patterns = [pattern(p) for p in self._files]
        common = max(set(patterns), key=patterns.count)
        stray = [p for p, pat in zip(self._files, patterns, strict=True) if pat != common]
        if stray:
            raise VideoError(stray[0], f"does not belong to the sequence of {len(self._files) - len(stray)} images "
                             f"named like {self._files[patterns.index(common)].name}.",
                             hint="Move it out of the folder.")
        numbers = [int(_NUMBER.search(p.stem).group(1)) for p in self._files]  # type: ignore[union-attr]
        for a, b, pa, pb in zip(numbers, numbers[1:], self._files, self._files[1:]):
            if b == a:
                raise VideoError(pb, f"repeats frame number {b} of {pa.name}.", hint="Remove one of them.")
            if b != a + 1 and not has_times:
                width = len(_NUMBER.search(pa.stem).group(1))  # type: ignore[union-attr]
                missing = _NUMBER.sub(f"{a + 1:0{width}d}", pa.stem) + pa.suffix
                raise VideoError(self.path / missing, f"is missing: the frame numbers jump from {a} ({pa.name}) to "
                                 f"{b} ({pb.name}).", hint="Restore the frame, or give each image's time in "
                                 f"{TIMES_FILE} beside them.")

    def _times_count(self) -> int | None:
        """Number of times listed in ``times.csv`` (None without one)."""
        try:
            lines = (self.path / TIMES_FILE).read_text().splitlines()
        except OSError:
            return None
        return sum(1 for line in lines[1:] if line.strip())

    def _read_times_file(self) -> npt.NDArray[np.float64] | None:
        p = self.path / TIMES_FILE
        if not p.is_file():
            return None
        try:
            t = np.loadtxt(p, delimiter=",", skiprows=1, ndmin=1)
        except ValueError as exc:
            raise VideoError(p, f"cannot read frame times: {exc}.") from exc
        if len(t) != len(self._files):
            raise VideoError(p, f"lists {len(t)} times for {len(self._files)} images.")
        self.metadata.extra["times_file"] = str(p)
        return t

    def _load(self, index: int) -> np.ndarray:
        path = self._files[index]
        img = cv2.imread(str(path), cv2.IMREAD_UNCHANGED)
        if img is None:
            raise VideoError(path, "cannot be read as an image (damaged or not an image).")
        if img.ndim == 3:
            img = cv2.cvtColor(img, cv2.COLOR_BGR2GRAY if img.shape[2] == 3 else cv2.COLOR_BGRA2GRAY)
        return img

    def _read(self, index: int) -> np.ndarray:
        img = self._load(index)
        if img.shape != self.frame_shape or img.dtype != self.dtype:
            raise VideoError(self._files[index], f"is {img.shape} {img.dtype}, unlike the first image "
                             f"{self.frame_shape} {self.dtype}.")
        return img


def write_image_sequence(
    folder: str | Path, frames: Iterable[npt.ArrayLike], times_s: npt.ArrayLike | None = None,
    suffix: str = ".tif", prefix: str = "frame_",
) -> Path:
    """Write frames as numbered 8/16-bit images (and ``times.csv`` when times are given).

    Each image is written atomically; the folder is created if needed.
    """
    folder = Path(folder)
    if suffix not in IMAGE_SUFFIXES:
        raise ParameterError("suffix", f"must be one of {IMAGE_SUFFIXES}", suffix)
    folder.mkdir(parents=True, exist_ok=True)
    count = 0
    for i, frame in enumerate(frames):
        a = np.asarray(frame)
        if a.ndim != 2 or a.dtype not in (np.uint8, np.uint16):
            raise ParameterError(f"frames[{i}]", "must be a 2-D uint8 or uint16 array")
        target = folder / f"{prefix}{i:06d}{suffix}"
        with atomic_path(target) as tmp:
            ok, buf = cv2.imencode(suffix, a)
            if not ok:
                raise VideoError(target, "OpenCV could not encode this image.")
            tmp.write_bytes(buf.tobytes())
        count += 1
    if times_s is not None:
        t = np.asarray(times_s, dtype=np.float64)
        if t.shape != (count,):
            raise ParameterError("times_s", f"must hold one time per frame ({count})")
        atomic_write_text(folder / TIMES_FILE, "time_s\n" + "".join(f"{x!r}\n" for x in t.tolist()))
    return folder
