"""A stand-in video for tests: an array of frames with what the tracker's stages read from a video."""

from __future__ import annotations

import numpy as np


class ArrayFrames:
    """Frames of an array ``(T, H, W)``: its length, frame shape, frames by index and zero-copy frame views."""

    def __init__(self, frames: np.ndarray) -> None:
        self.frames = frames
        self.frame_shape = frames.shape[1:]

    def __len__(self) -> int:
        return len(self.frames)

    def __getitem__(self, i: int) -> np.ndarray:
        return self.frames[i]

    def frame_view(self, i: int) -> np.ndarray:
        return self.frames[i]
