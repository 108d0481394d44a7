"""Static defects in front of the balls: hot pixels and fixed glints to mask, lint on the glass to subtract.

Both are found once per video from the median background frame and a few frames spread over the video
(tracking/pipeline.py), before the per-frame loop: :func:`static_defects` gives the pixels the centroid
windows leave out (:mod:`cageless.tracking.detect`), :func:`static_pattern` the additive pattern subtracted
from every frame.
"""

from __future__ import annotations

import cv2
import numpy as np

from cageless.tracking.locate_motion import DROPOUT_GAIN, frame_gains
from cageless.tracking.sample_stats import kth_smallest

__all__ = ["static_defects", "static_pattern"]


def static_defects(background: np.ndarray, sigma_noise: float, k: float = 8.0,
                   frames: np.ndarray | None = None, size: int = 5) -> np.ndarray:
    """Pixels far brighter than their ``size`` x ``size`` median in the background frame (hot pixels, fixed glints).

    With ``frames`` (a few frames spread over the video), a pixel must also stand out so in their
    per-pixel lower quartile, i.e. in three quarters of them: the median background keeps traces of the highlights
    where they pass often and of codec blocks, and masking those cut holes in the highlights' path
    (a highlight crossing a hole moved by up to 0.7 px; 1.0 mrad RMS on corpus seed 1031, MPEG-4).

    The median is over 5 x 5 pixels, so a static glint up to 3 px across stands out of it (a 3 x 3 median is
    the glint's own level there). The centroid's background is a constant (the ring around its window), so an
    unmasked glint in the window pulls the highlight towards it while the two pass: on corpus seed 7020 a
    saturated 3 x 3 glint on the highlights' path gave +10 mrad before each crossing and -6 after.
    """
    bg = background.astype(np.float32)
    out = (bg - cv2.medianBlur(bg, size)) > k * sigma_noise
    if frames is not None and len(frames):
        q = len(frames) // 4  # bright in three quarters of them: a dark frame or a ball passing over a glint
        low = kth_smallest(frames, q).astype(np.float32)  # np.partition's value, sooner (tested)
        out &= (low - cv2.medianBlur(low, size)) > k * sigma_noise
    return out


def static_pattern(background: np.ndarray, frames: np.ndarray, region: np.ndarray, defects: np.ndarray,
                   k: float = 8.0, size: int = 5) -> np.ndarray:
    """The static additive pattern in front of the balls, to subtract from every frame (float32, 0 elsewhere).

    Lint on the glass adds the same small bright spot to every frame, over a ball as over a gap: it stands out
    of its ``size`` x ``size`` median both in the median ``background`` and in the per-pixel minimum of the
    steady ``frames`` (lighting dropouts left out), each against that image's own noise (:func:`_static_noise`
    in ``region``), as a spot in ``region`` no more than ``size`` pixels across (ring texture seen between the
    balls makes larger patches: taking those too, on a machined bright face, took corpus seed 1015 from 0.26
    to 0.44 mrad). Those pixels and their 8 neighbours (the spot's tail) get the background's excess over its
    local median; pixels already in ``defects`` stay masked instead. :func:`static_defects` finds only what
    stands out by 8 times the noise of a frame against the median background, which in the band, where
    balls and gaps take turns, is several times the pixel noise (6.8x on corpus seed 1012, whose lint specks,
    as bright as the dim highlights, were not masked and pulled each passing highlight by up to 3 mrad).
    Subtracted rather than masked, they leave no hole: with a doubled highlight (two lobes, not centrally
    symmetric) a hole's mirrored exclusion moves the centroid (masking these pixels instead took seed 1024
    from 0.41 to 0.50 mrad).
    """
    bg = background.astype(np.float32)
    hp = bg - cv2.medianBlur(bg, size)
    out = np.zeros(bg.shape, np.float32)
    if not region.any() or not len(frames):
        return out
    steady = frame_gains(list(frames)) >= DROPOUT_GAIN
    low = np.min(frames[steady] if steady.sum() >= 2 else frames, axis=0).astype(np.float32)
    low_hp = low - cv2.medianBlur(low, size)
    found = region & (hp > k * _static_noise(hp, region)) & (low_hp > k * _static_noise(low_hp, region))
    n, labels, stats, _ = cv2.connectedComponentsWithStats(found.astype(np.uint8), connectivity=8)
    spots = np.flatnonzero((stats[:, cv2.CC_STAT_WIDTH] <= size) & (stats[:, cv2.CC_STAT_HEIGHT] <= size))
    found = np.isin(labels, spots[spots > 0])  # spots, not texture: the median shows what is under 3 px across
    grown = cv2.dilate(found.astype(np.uint8), np.ones((3, 3), np.uint8)).astype(bool) & ~defects
    out[grown] = hp[grown]
    return out


def _static_noise(excess: np.ndarray, region: np.ndarray) -> float:
    """Robust standard deviation (MAD x 1.4826) of a static image's excess over its local median inside
    ``region``, at least the data's smallest step there (a median of quantised frames is often flat: MAD 0)."""
    d = excess[region]
    spread = 1.4826 * float(np.median(np.abs(d - np.median(d))))
    steps = np.diff(np.unique(np.abs(d)))
    steps = steps[steps > 1e-6]
    return max(spread, float(steps.min()) if steps.size else 1.0)
