"""Stage 1: find the bearing in the image and the annulus the balls travel in.

On a background frame (the per-pixel median of a sample of frames, which
removes the moving highlights), a global Otsu binarisation and a
connected-component area threshold keep the bright ring faces and reject small
metallic reflections; a circle fit to the outer contour gives a first centre.
The radial brightness profile about that centre then shows the dark band
between the ring lands where the balls are seen: that band, eroded by a small
margin, is the ball annulus mask.
"""

from __future__ import annotations

import logging
import math
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, replace
from pathlib import Path

import cv2
import numpy as np
import numpy.typing as npt

from cageless.errors import TrackingError
from cageless.tracking.io.base import FrameSource

__all__ = ["BearingLocation", "background_frame", "locate_bearing", "fit_circle"]

log = logging.getLogger(__name__)


#: Least width of the ball search band, in ball diameters: a whole ball, with a tenth of a diameter for lens
#: distortion, the highlight's tail and the margin the search mask takes off each edge.
BALL_BAND = 1.2


@dataclass(frozen=True)
class BearingLocation:
    """Where the bearing is in the image (pixels).

    Attributes
    ----------
    centre
        Centre (u, v) of the bearing contour.
    outer_radius
        Radius of the bearing's outer contour.
    band_inner, band_outer
        Radii of the dark band between the ring lands, where the balls are seen.
    contour_residual
        RMS distance of the contour points from the fitted circle.
    source
        ``"brightness"`` (the dark band between bright ring faces) or ``"motion"`` (where things move:
        a search annulus whose middle is not the pitch circle).
    """

    centre: tuple[float, float]
    outer_radius: float
    band_inner: float
    band_outer: float
    contour_residual: float
    source: str = "brightness"

    def annulus_mask(self, shape: tuple[int, int], margin: float = 0.0) -> npt.NDArray[np.bool_]:
        """Boolean mask of the band, shrunk by ``margin`` px on both sides."""
        v, u = np.ogrid[0:shape[0], 0:shape[1]]
        r = np.hypot(u - self.centre[0], v - self.centre[1])
        return (r >= self.band_inner + margin) & (r <= self.band_outer - margin)

    def holding_balls(self, ball_over_pitch_radius: float) -> BearingLocation:
        """The band widened, about its middle, to at least :data:`BALL_BAND` ball diameters.

        The dark band between the lands is where ball surface is seen, and its middle is the pitch circle;
        but a highlight can sit anywhere on its ball, out to the ball's rim (a light from the side), and where
        the lands hide part of each ball the band is narrower than a ball: then highlights near the rim fall
        outside it over part of the orbit (corpus seed 7021: a band 0.33 ball wide about the pitch circle held
        the highlights of 6 of 18 balls). ``ball_over_pitch_radius`` is D / (d_m / 2).
        """
        mid = 0.5 * (self.band_inner + self.band_outer)
        half = 0.5 * BALL_BAND * ball_over_pitch_radius * mid
        if self.band_outer - self.band_inner >= 2 * half:
            return self
        return replace(self, band_inner=min(self.band_inner, max(mid - half, 0.0)),
                       band_outer=max(self.band_outer, mid + half))

    def crop(self, shape: tuple[int, int], pad: int = 2) -> tuple[slice, slice]:
        """Rows and columns of the band's bounding box, clipped to the image."""
        cu, cv = self.centre
        r = self.band_outer + pad
        return (slice(max(int(cv - r), 0), min(int(cv + r) + 1, shape[0])),
                slice(max(int(cu - r), 0), min(int(cu + r) + 1, shape[1])))


def background_frame(video: FrameSource, n_sample: int = 25, quantile: float = 0.5,
                     workers: int = 1) -> npt.NDArray[np.float32]:
    """Per-pixel median (or another ``quantile``) of up to ``n_sample`` frames spread over the video (removes
    the moving highlights where they cover a pixel less than ``1 - quantile`` of the time), in bands of rows
    shared by ``workers`` threads (numpy's partition releases the GIL; the same values with any number)."""
    n = len(video)
    idx = np.unique(np.linspace(0, n - 1, min(n, n_sample)).round().astype(int))
    frames = [video.frame_view(int(i)) for i in idx]
    out = np.empty(video.frame_shape, dtype=np.float32)
    # In bands of rows: the same medians as over the whole stack, but the working set stays in cache
    # and the memory used is a few MB instead of 25 frames and their sorted copy.
    # The frames stacked along the last axis: each pixel's values contiguous, so numpy's partition runs on
    # contiguous rows (the same values as along the first axis, 2.5-3x faster; tested).
    def one(r0: int) -> None:
        band = np.stack([f[r0:r0 + _MEDIAN_ROWS] for f in frames], axis=-1)
        out[r0:r0 + _MEDIAN_ROWS] = (np.median(band, axis=-1) if quantile == 0.5
                                     else np.quantile(band, quantile, axis=-1, method="inverted_cdf"))

    with ThreadPoolExecutor(max_workers=max(1, workers)) as pool:
        list(pool.map(one, range(0, out.shape[0], _MEDIAN_ROWS)))
    return out


#: Rows per band of the background median (25 frames x 32 rows x 1280 px x 2 B = 2 MB).
_MEDIAN_ROWS = 32


def fit_circle(u: npt.ArrayLike, v: npt.ArrayLike) -> tuple[float, float, float, float]:
    """Least-squares circle through points: algebraic (Kasa) start, then geometric refinement.

    Returns
    -------
    cx, cy, radius, rms
        Centre, radius and the RMS of the geometric residuals (same units as the points).
    """
    u, v = np.asarray(u, dtype=np.float64), np.asarray(v, dtype=np.float64)
    if u.size < 3:
        raise ValueError("a circle needs at least 3 points")
    a = np.column_stack([u, v, np.ones_like(u)])
    sol, *_ = np.linalg.lstsq(a, u**2 + v**2, rcond=None)
    cx, cy = sol[0] / 2, sol[1] / 2
    r0 = np.sqrt(max(sol[2] + cx**2 + cy**2, 1e-12))

    def resid(p: np.ndarray) -> np.ndarray:
        return np.hypot(u - p[0], v - p[1]) - p[2]

    from scipy import optimize  # imported on first use (0.5-0.7 s of CPU): see pipeline._import_late_modules

    res = optimize.least_squares(resid, [cx, cy, r0], method="lm")
    cx, cy, r = res.x
    return float(cx), float(cy), float(abs(r)), float(np.sqrt(np.mean(res.fun**2)))


def _to_u8(img: np.ndarray, top: float = 99.5) -> np.ndarray:
    """``img`` stretched to 8 bits between its 0.5th and ``top`` percentiles."""
    lo, hi = np.percentile(img, [0.5, top])
    if hi - lo < 1e-9:
        return np.zeros(img.shape, np.uint8)
    return np.clip((img - lo) * (255.0 / (hi - lo)), 0, 255).astype(np.uint8)


def locate_bearing(background: np.ndarray, path: str | Path = "video", min_area_frac: float = 0.02) -> BearingLocation:
    """Find the bearing contour and the ball band on a background frame.

    Raises
    ------
    TrackingError
        When no ring-shaped bright region is in view (no bearing, an all-dark or all-saturated video).
    """
    first: TrackingError | None = None
    for top in _STRETCH_TOPS:
        try:
            cx, cy, r_out, rms = _bright_ring(background, path, min_area_frac, top)
            break
        except TrackingError as exc:
            if "no contrast" in exc.message:
                raise
            first = first or exc
    else:
        assert first is not None
        raise first
    band_in, band_out = _dark_band(background, (cx, cy), r_out, path)
    log.debug("%s: bearing at (%.1f, %.1f), r = %.1f px, band %.1f..%.1f px", path, cx, cy, r_out, band_in, band_out)
    return BearingLocation(centre=(cx, cy), outer_radius=r_out, band_inner=band_in, band_outer=band_out,
                           contour_residual=rms)


#: Upper percentiles of the 8-bit stretch before Otsu's threshold: the usual one, which keeps a few extreme pixels
#: from crushing the rest into a few levels, and the largest value, tried when the first finds no ring. Where the
#: bright faces cover less than half a per cent of the frame (a small bearing in a wide, dark frame) the 99.5th
#: percentile is the surroundings' noise, and Otsu's threshold on that stretch splits the noise.
_STRETCH_TOPS = (99.5, 100.0)


def _bright_ring(background: np.ndarray, path: str | Path, min_area_frac: float, top: float
                 ) -> tuple[float, float, float, float]:
    """Centre, radius and fit residual of the outer contour of the bright regions above Otsu's threshold on the
    background stretched to 8 bits up to its ``top`` percentile.

    Raises
    ------
    TrackingError
        When the frame has no contrast, no region is large enough or the contour is not a circle.
    """
    img8 = _to_u8(background.astype(np.float32), top)
    if img8.max() == img8.min():
        raise TrackingError(path, "the frames have no contrast (all dark or all saturated): no bearing in view.",
                            "Check the exposure and the lighting.")
    _, binary = cv2.threshold(img8, 0, 255, cv2.THRESH_BINARY + cv2.THRESH_OTSU)
    n, labels, stats, _ = cv2.connectedComponentsWithStats(binary, connectivity=8)
    big = _bright_regions(stats[:, cv2.CC_STAT_AREA], min_area_frac * binary.size)
    if not big:
        raise TrackingError(path, "no bright ring-shaped region found: no bearing in view.",
                            "Check that the bearing's end face fills a good part of the frame.")
    mask = np.isin(labels, big).astype(np.uint8)
    contours, _ = cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
    outer = max(contours, key=cv2.contourArea).reshape(-1, 2).astype(np.float64)
    cx, cy, r_out, rms = fit_circle(outer[:, 0], outer[:, 1])
    if rms > 0.05 * r_out or r_out < 20:
        raise TrackingError(path, f"the bright region is not circular (fit residual {rms:.1f} px on radius "
                            f"{r_out:.1f} px): no bearing in view.", "Frame the bearing's end face.")
    return cx, cy, r_out, rms


#: Least area of the bright region of a bearing that fills less than ``min_area_frac`` of the frame: a disc of
#: 20 px radius, the smallest outer radius :func:`locate_bearing` accepts.
_MIN_RING_AREA = math.pi * 20.0**2
#: Of such a small bearing, the bright regions kept besides the largest: those of at least this share of its area.
_SMALL_SHARE = 0.25


def _bright_regions(areas: np.ndarray, min_area: float) -> list[int]:
    """Labels of the bright components that may be the bearing's faces (``areas[0]`` is the background).

    Those of at least ``min_area`` px; when none is that large (a small bearing in a wide frame: corpus seed 1011,
    an outer radius of 51 px in a 1280 x 720 frame, 1 % of it), the largest, when it is at least
    :data:`_MIN_RING_AREA`, with the others of at least :data:`_SMALL_SHARE` of its area. The ring-shape test of
    :func:`locate_bearing` then decides, so a small glint or a speck cannot pass for a bearing.
    """
    fg = np.asarray(areas[1:], dtype=np.float64)
    big = [k + 1 for k in np.flatnonzero(fg >= min_area)]
    if big or fg.size == 0 or fg.max() < _MIN_RING_AREA:
        return big
    return [k + 1 for k in np.flatnonzero(fg >= _SMALL_SHARE * fg.max())]


def _dark_band(background: np.ndarray, centre: tuple[float, float], r_out: float, path: str | Path) -> tuple[float, float]:
    """Radii of the widest dark band between bright ring faces, from the radial median profile."""
    h, w = background.shape
    v, u = np.mgrid[0:h, 0:w]
    r = np.hypot(u - centre[0], v - centre[1])
    inside = r < r_out
    rb = r[inside].astype(np.int64)
    vals = background[inside].astype(np.float64)
    n_r = int(r_out) + 1
    order = np.argsort(rb, kind="stable")
    rb, vals = rb[order], vals[order]
    edges = np.searchsorted(rb, np.arange(n_r + 1))
    prof = np.array([np.median(vals[edges[k]:edges[k + 1]]) if edges[k + 1] > edges[k] else np.nan
                     for k in range(n_r)])
    valid = np.isfinite(prof)
    lo, hi = np.nanpercentile(prof, [5, 95])
    thresh = lo + 0.5 * (hi - lo)
    dark = valid & (prof < thresh)
    dark[: int(0.3 * r_out)] = False  # the bore and the shaft are not the ball band
    runs = _runs(dark)
    bright_out = np.flatnonzero(valid & (prof >= thresh))
    # The band is a dark run with bright ring faces on both sides.
    candidates = [(a, b) for a, b in runs if bright_out.size and bright_out.min() < a and (bright_out > b).any()]
    if not candidates:
        raise TrackingError(path, "no dark ball band between two bright ring faces was found.",
                            "Check the lighting: the ring faces must be brighter than the black balls.")
    a, b = max(candidates, key=lambda ab: ab[1] - ab[0])
    return float(a), float(b)


def _runs(flags: np.ndarray) -> list[tuple[int, int]]:
    """Start and end (inclusive) of each run of True."""
    d = np.diff(np.concatenate([[0], flags.astype(np.int8), [0]]))
    return list(zip(np.flatnonzero(d == 1), np.flatnonzero(d == -1) - 1, strict=True))
