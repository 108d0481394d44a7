"""Find the ball band from what moves, when the ring faces do not frame a dark band.

The brightness-based localisation (:mod:`cageless.tracking.locate`) needs bright ring faces around a dark
ball band. Footage from another set-up may show dark ring faces, or balls over bright faces. What
every such video shares is that the balls move and the ring faces do not (the inner ring turns, but
its face is nearly rotationally symmetric). The per-pixel temporal spread of a sample of frames is
therefore high on an annulus about the bearing centre, the width of the visible part of a ball:

1. the spread (standard deviation) of frames sampled over the clip;
2. Otsu's threshold on it and the larger connected moving regions;
3. a circle fit to each region's outer contour; the outermost ring-shaped one gives the centre
   (glints turning with the inner ring make a moving ring inside the balls');
4. the radial mean profile of the spread about that centre; the search annulus spans every radius
   where it exceeds a fifth of its peak above the floor (the highlights' circle, and glints turning
   with the inner ring, which the selection rejects by their speed).

The annulus is only a search region: its middle is not the pitch circle, so the selection then
chooses the ball circle by its support rather than by its radius.
"""

from __future__ import annotations

import logging
from pathlib import Path

import cv2
import numpy as np

from cageless.tracking.io.base import FrameSource
from cageless.tracking.locate import _STRETCH_TOPS, BearingLocation, _to_u8, fit_circle

__all__ = ["motion_map", "moving_pixels", "frame_gains", "frame_level", "dropout_frames", "DROPOUT_GAIN", "locate_by_motion",
           "plausible_band", "holds_the_motion"]

log = logging.getLogger(__name__)

#: Largest RMS residual of a moving region's outer contour from its circle, as a share of the radius. The
#: contour of the region the balls sweep is scalloped by the balls' silhouettes (up to about a tenth of the
#: radius on a small bearing: seed 1002's is 8 %); the selection refits the circle to the highlights.
_MAX_RMS = 0.12


def motion_map(video: FrameSource, n_sample: int = 25) -> np.ndarray:
    """Per-pixel standard deviation of up to ``n_sample`` frames spread over the video, lighting dropouts
    left out (:func:`frame_gains`): a dark frame changes every lit pixel, which is not motion. Two dark
    frames among the 25 gave the lit background of corpus seed 7010's long clip a spread that Otsu's
    threshold could not tell from the balls': the whole background became one moving region, whose outer
    contour, the image border, was taken for the bearing, and no ball was found."""
    n = len(video)
    idx = np.unique(np.linspace(0, n - 1, min(n, n_sample)).round().astype(int))
    acc = np.zeros(video.frame_shape, np.float64)
    acc2 = np.zeros(video.frame_shape, np.float64)
    levels = np.empty(idx.size)
    for k, i in enumerate(idx):
        f = video[int(i)].astype(np.float64)
        levels[k] = frame_level(f)
        acc += f
        acc2 += f * f
    dropouts = idx[dropout_frames(levels)]
    for i in dropouts:  # taken out again (a few frames read twice, not 25 frames held)
        f = video[int(i)].astype(np.float64)
        acc -= f
        acc2 -= f * f
    used = idx.size - dropouts.size
    mean = acc / used
    return np.sqrt(np.maximum(acc2 / used - mean * mean, 0.0)).astype(np.float32)


#: A frame whose overall level (:func:`frame_level`) is below this share of the median level of the sampled
#: frames is a lighting dropout (a dark frame).
DROPOUT_GAIN = 0.5


def frame_level(frame: np.ndarray) -> float:
    """A frame's overall level: the mean of the frame subsampled 4 x 4 (the few moving highlights hardly change
    it; a mean, not a median, so that a dark 8-bit scene's level is not rounded to a few DN)."""
    return float(np.mean(frame[::4, ::4], dtype=np.float64))


def dropout_frames(levels: np.ndarray) -> np.ndarray:
    """Which of the sample frames of these :func:`frame_level` values are lighting dropouts, below
    :data:`DROPOUT_GAIN` of their median level; none when fewer than two frames would be left (no steady level
    to compare with) or the median level is 0."""
    ref = float(np.median(levels))
    drop = levels < DROPOUT_GAIN * ref if ref > 0 else np.zeros(len(levels), dtype=bool)
    return drop if len(levels) - int(drop.sum()) >= 2 else np.zeros(len(levels), dtype=bool)


def frame_gains(frames: list[np.ndarray]) -> np.ndarray:
    """Each frame's :func:`frame_level` over the median level of ``frames``: a dropout shows as a gain far
    below 1 (all ones when the median level is 0)."""
    levels = np.array([frame_level(f) for f in frames])
    ref = float(np.median(levels))
    return levels / ref if ref > 0 else np.ones(len(frames))


#: Otsu's threshold on the spread must stand this many robust standard deviations above the median spread (most
#: of the frame does not move, so the median and MAD of the spread are those of the still pixels' noise).
NOISE_MARGIN = 5.0


def moving_pixels(spread: np.ndarray) -> np.ndarray | None:
    """Pixels whose temporal spread is above Otsu's threshold on the spread stretched to 8 bits (None when
    the spread is flat).

    The stretch runs to the 99.5th percentile, so that a few extreme pixels do not crush the rest into a few
    levels; but where the balls cover less than half a per cent of the frame (a small bearing in a wide frame:
    corpus seed 1011 without compression, 1 % of a 1280 x 720 frame holding the bearing) that percentile is
    the still pixels' noise, and Otsu's threshold then splits the noise (there, 1.66 DN against a median spread
    of 1.57 and a robust deviation of 0.25: 41 % of the frame "moved", and closed into one region, the whole
    frame). When the threshold is within :data:`NOISE_MARGIN` robust deviations of the median spread, the
    stretch runs to the largest spread instead.
    """
    med = float(np.median(spread))
    floor = med + NOISE_MARGIN * 1.4826 * float(np.median(np.abs(spread - med)))
    moving = None
    for top in _STRETCH_TOPS:  # the same stretches as the bright-face test of locate_bearing
        lo, hi = np.percentile(spread, [0.5, top])
        img8 = _to_u8(spread, top)
        if img8.max() == img8.min():
            return moving
        t, binary = cv2.threshold(img8, 0, 255, cv2.THRESH_BINARY + cv2.THRESH_OTSU)
        moving = binary > 0
        if lo + t * (hi - lo) / 255.0 >= floor:
            break
    return moving


def plausible_band(loc: BearingLocation, ball_over_pitch_radius: float) -> bool:
    """True when the band's width over its mid radius fits a visible ball: 0.3 to 1.3 ball diameters."""
    mid = 0.5 * (loc.band_inner + loc.band_outer)
    if mid <= 0:
        return False
    frac = (loc.band_outer - loc.band_inner) / mid / ball_over_pitch_radius
    return 0.3 <= frac <= 1.3


def holds_the_motion(spread: np.ndarray, loc: BearingLocation, share: float = 0.3) -> bool:
    """True when the band of ``loc`` (widened by a quarter of its width each way) holds at least ``share`` of
    the moving pixels (temporal spread above Otsu's threshold): the balls move in the band, and glints
    turning with the inner ring move only inside it. A bright region that is not the bearing's faces (dark
    faces with bright lands or cavity) gives a band where little moves."""
    moving = moving_pixels(spread)
    if moving is None:
        return True  # nothing moves measurably: no evidence against the band
    pad = 0.25 * (loc.band_outer - loc.band_inner)
    h, w = spread.shape
    v, u = np.ogrid[0:h, 0:w]
    r = np.hypot(u - loc.centre[0], v - loc.centre[1])
    inside = moving & (r >= loc.band_inner - pad) & (r <= loc.band_outer + pad)
    return bool(np.count_nonzero(inside) >= share * max(np.count_nonzero(moving), 1))


def locate_by_motion(spread: np.ndarray, path: str | Path = "video",
                     ball_over_pitch_radius: float = 0.414) -> BearingLocation | None:
    """The ball band from the temporal spread (see the module docstring), widened by half a ball
    diameter each way (``ball_over_pitch_radius`` = D / (d_m / 2)); None when no ring-shaped moving
    region is found."""
    moving = moving_pixels(spread)
    if moving is None:
        return None
    binary = moving.astype(np.uint8) * np.uint8(255)
    binary = cv2.morphologyEx(binary, cv2.MORPH_CLOSE, np.ones((5, 5), np.uint8))
    n, labels, stats, _ = cv2.connectedComponentsWithStats(binary, connectivity=8)
    if n < 2:
        return None
    rings = []
    for k in 1 + np.argsort(-stats[1:, cv2.CC_STAT_AREA])[:6]:
        if stats[k, cv2.CC_STAT_AREA] < 0.1 * stats[1:, cv2.CC_STAT_AREA].max():
            break
        contours, _ = cv2.findContours((labels == k).astype(np.uint8), cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
        outer = max(contours, key=cv2.contourArea).reshape(-1, 2).astype(np.float64)
        if len(outer) < 20:
            continue
        cx, cy, r_out, rms = fit_circle(outer[:, 0], outer[:, 1])
        if rms <= _MAX_RMS * r_out and r_out >= 20:
            rings.append((r_out, cx, cy, rms))
    if not rings:
        return None
    r_out, cx, cy, rms = max(rings)  # the outermost moving ring: balls travel outside the inner ring
    h, w = spread.shape
    v, u = np.mgrid[0:h, 0:w]
    r = np.hypot(u - cx, v - cy).astype(np.int64)
    inside = r <= int(r_out) + 2
    prof = np.bincount(r[inside], weights=spread[inside], minlength=int(r_out) + 3)
    cnt = np.bincount(r[inside], minlength=int(r_out) + 3)
    prof = np.where(cnt > 0, prof / np.maximum(cnt, 1), np.nan)
    floor, peak = np.nanpercentile(prof, 10), np.nanmax(prof)
    moving = np.flatnonzero(np.nan_to_num(prof) > floor + 0.2 * (peak - floor))
    if moving.size == 0 or moving[-1] - moving[0] < 3:
        return None
    a, b = int(moving[0]), int(moving[-1])
    pad = max(2, int(np.ceil(0.5 * ball_over_pitch_radius * b)))
    a, b = max(a - pad, 0), b + pad
    log.debug("%s: moving annulus at (%.1f, %.1f), %d..%d px", path, cx, cy, a, b)
    return BearingLocation(centre=(cx, cy), outer_radius=r_out, band_inner=float(a), band_outer=float(b),
                           contour_residual=rms, source="motion")
