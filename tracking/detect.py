"""Stage 2: find the ball highlights in a frame and measure them to sub-pixel.

Full detection works on the background-subtracted frame inside the ball
annulus: a local (adaptive) binarisation, dilation and hole filling (so a
saturated, flat-topped highlight is one solid blob), then connected components
filtered by area, shape (glints are long and thin) and peak intensity.

Positions are **background-subtracted, intensity-weighted centroids** in a
circular window, re-centred on the result: each pixel weighs
``max(I - b - t, 0) (1 - d^2 / r^2)^2`` with d its distance from the window's centre
and r the window radius (a biweight taper, so a pixel's weight goes smoothly to 0 as
it leaves the window instead of jumping: with a hard edge the centroid locked to
the pixel grid, 0.56-0.67 mrad RMS orbital angle on corpus seeds 1000 and 1020, 0.37
and 0.29 with the taper), with b the *local* background (the median of a 2-px ring just outside the
window, i.e. the black ball coating around the highlight) and t a threshold of
a few noise standard deviations. A local constant works better than the median
background frame, which in the ball band switches between ball and gap levels
across a window and biases the centroid (2.1-2.4 x the Cramér-Rao bound against
1.1-1.15 x, measured on rendered video). Static defects (hot pixels) are taken
out of the mask by :func:`~cageless.tracking.static.static_defects`; a masked pixel leaves the centroid together with its mirror image
through the window's centre (:func:`_pass`), so a hole does not push it. The centroid of the binary mask is
kept only as the ``"mask"``
detector, for the accuracy-versus-time comparison.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numba
import numpy as np
import numpy.typing as npt

from cageless.errors import ParameterError
from cageless.tracking.static import static_defects, static_pattern  # re-exported: importable from here as before

__all__ = [
    "DetectorParams", "DETECTORS", "Detections", "detect_full", "centroid_windows", "noise_sigma", "pixel_noise",
    "spot_sigma", "static_defects", "static_pattern", "NO_STATIC", "compiled_static",
]

#: The detector choices: binary-mask centroid, weighted centroid after full detection every frame,
#: and weighted centroid in windows around the predicted positions (the default, fastest).
DETECTORS = ("mask", "weighted", "window")


@dataclass(frozen=True)
class DetectorParams:
    """Detection settings (all in units of pixels or of the noise standard deviation).

    Parameters
    ----------
    method
        One of :data:`DETECTORS`.
    detect_sigma
        A blob must rise this many noise sigmas above the background.
    weight_sigma
        Per-pixel threshold t of the centroid weights, in noise sigmas.
    window_sigma
        Centroid window radius, in highlight sigmas.
    iterations
        Most window re-centring passes (it stops once the window moves less than 0.001 px; every second
        pass takes an Aitken delta-squared step). The tapered centroid converges slowly on doubled or
        elongated highlights: two plain passes left the estimate where the prediction put it, a lag that
        decayed over frames (seed 1024: speed RMS 1.06 % of the cage speed with 2 passes, 0.26 % with up
        to 4 accelerated ones, the same as with 10).
    min_area_px
        Smallest blob area kept.
    max_aspect
        Largest bounding-box aspect ratio kept (glints on the rings are elongated).
    min_fill
        Smallest blob area over its bounding-box area.
    lost_fraction
        A window whose mass falls below this fraction of the ball's usual mass counts as a miss.
    relative_peak
        A blob's peak must reach this fraction of the median peak of the brightest blobs (highlights
        are far brighter than gaps between balls seen against a background of balls).
    """

    method: str = "window"
    detect_sigma: float = 6.0
    weight_sigma: float = 2.0
    window_sigma: float = 3.5
    iterations: int = 4
    min_area_px: int = 2
    max_aspect: float = 2.5
    min_fill: float = 0.3
    lost_fraction: float = 0.25
    relative_peak: float = 0.25

    def __post_init__(self) -> None:
        if self.method not in DETECTORS:
            raise ParameterError("detector.method", f"must be one of {DETECTORS}", self.method)
        if self.iterations < 1:
            raise ParameterError("detector.iterations", "must be >= 1", self.iterations)


@dataclass(frozen=True)
class Detections:
    """Highlights found in one frame (pixels; ``mass`` in background-subtracted DN)."""

    u: npt.NDArray[np.float64]
    v: npt.NDArray[np.float64]
    mass: npt.NDArray[np.float64]
    sigma: npt.NDArray[np.float64]

    def __len__(self) -> int:
        return int(self.u.size)


def noise_sigma(frames: np.ndarray, background: np.ndarray, mask: np.ndarray) -> float:
    """Robust spread (MAD x 1.4826) of frame - background inside ``mask``.

    The noise level of the detector's thresholds (tracking/pipeline.py), though not the pixel noise: in the ball
    band, where balls and gaps take turns over the median background, it measures the scene's contrast as much
    as the noise (1.7-43 times the renderer's sensor noise on the TUNING clips; :func:`pixel_noise` measures the
    noise itself). Thresholds from :func:`pixel_noise` were tried (docs/tracking.md) and not adopted: at the same
    multiples they let more of the ball coating, the rim and JPEG ringing into the centroid.
    """
    d = (frames.astype(np.float32) - background)[..., mask]
    mad = np.median(np.abs(d - np.median(d)))
    return float(max(1.4826 * mad, 1e-3))


#: Immerkær's 3 x 3 noise kernel over its norm 6: zero response to any locally planar intensity, and on white
#: noise of standard deviation s a response of standard deviation s.
_NOISE_KERNEL = np.array([[1, -2, 1], [-2, 4, -2], [1, -2, 1]], np.float32) / 6.0
#: Share of the smallest absolute responses averaged, and the mean absolute value of that share of a unit
#: Gaussian's (2 (phi(0) - phi(z)) / p with z its (1 + p) / 2 quantile: 0.32466 for p = 0.5).
_NOISE_SHARE = 0.5
_NOISE_GAIN = 0.324663
#: Standard deviation of the rounding of a value to whole DN (1 / sqrt(12)): the least noise an estimate may report.
_ROUNDING = 12 ** -0.5


def pixel_noise(frames: np.ndarray, mask: np.ndarray) -> float:
    """Standard deviation of the pixel noise (DN) in ``mask``, from the frames' high-pass residual.

    Each frame is filtered with :data:`_NOISE_KERNEL` (Immerkær 1996, "Fast noise variance estimation"), which
    cancels the shading of the balls and of the faces up to first order; what is left at most pixels is noise,
    and at a few (ball edges, highlights, texture) structure. Those few lie in the upper tail of the absolute
    response, so the estimate is the mean of its smaller half (in the pixels whose 3 x 3 neighbourhood lies in
    ``mask``) over what that mean is for Gaussian noise: a trimmed mean rather than a median, because on 8-bit
    data with noise under 1 DN the response takes few values and its median can be 0. The median over frames
    is returned (a lighting dropout makes one frame's noise low), and never less than ``_ROUNDING`` DN: integer
    pixel values carry at least their rounding error, and JPEG, which zeroes the high frequencies of smooth
    blocks, can leave the residual 0 at most pixels (TUNING seeds 1004 and 1018, JPEG q30 and q83: 0.000 DN,
    against 2.8 and 0.47 DN of sensor noise before compression). Against the renderer's own noise on the TUNING clips
    see benchmarks/noise_estimate.py and docs/tracking.md.
    """
    inner = cv2.erode(mask.astype(np.uint8), np.ones((3, 3), np.uint8)).astype(bool)
    if not inner.any():
        return _ROUNDING
    out = []
    for f in frames if frames.ndim == 3 else frames[None]:
        r = np.abs(cv2.filter2D(f.astype(np.float32), -1, _NOISE_KERNEL)[inner])
        k = max(int(r.size * _NOISE_SHARE), 1)
        q = np.partition(r, k - 1)[:k]
        out.append(float(np.mean(q)) / _NOISE_GAIN)
    return float(max(np.median(out), _ROUNDING))


def detect_full(frame: np.ndarray, background: np.ndarray, mask: np.ndarray, sigma_noise: float,
                params: DetectorParams, expected_sigma: float | None = None, max_area_px: float = np.inf,
                n_expected: int = 14) -> Detections:
    """Detect every highlight in ``frame`` (arrays cropped alike; ``mask`` is the annulus).

    ``max_area_px`` rejects blobs larger than a highlight can be; ``n_expected`` (the ball count)
    sets how many of the brightest blobs define the typical highlight peak.
    Returns weighted centroids (or mask centroids for ``params.method == "mask"``).
    """
    diff = frame.astype(np.float32) - background
    diff[~mask] = 0.0
    level = params.detect_sigma * sigma_noise
    scale = 255.0 / max(float(diff.max()), level * 2)
    img8 = np.clip(diff * scale, 0, 255).astype(np.uint8)
    block = 2 * int(max(3.0, 3 * (expected_sigma or 2.0))) + 1
    local = cv2.adaptiveThreshold(img8, 255, cv2.ADAPTIVE_THRESH_MEAN_C, cv2.THRESH_BINARY, block,
                                  -max(1.0, 0.5 * level * scale))
    binary = ((local > 0) & (diff > level) & mask).astype(np.uint8)
    binary = cv2.dilate(binary, np.ones((3, 3), np.uint8))
    binary = _fill_holes(binary) & mask.astype(np.uint8)
    n, labels, stats, cents = cv2.connectedComponentsWithStats(binary, connectivity=8)
    keep, peaks = [], []
    for k in range(1, n):
        w, h, area = stats[k, cv2.CC_STAT_WIDTH], stats[k, cv2.CC_STAT_HEIGHT], stats[k, cv2.CC_STAT_AREA]
        if not (params.min_area_px <= area <= max_area_px):
            continue
        if max(w, h) > params.max_aspect * min(w, h) or area < params.min_fill * w * h:
            continue
        x, y = stats[k, cv2.CC_STAT_LEFT], stats[k, cv2.CC_STAT_TOP]
        peak = diff[y:y + h, x:x + w][labels[y:y + h, x:x + w] == k].max()
        if peak >= level:
            keep.append(k)
            peaks.append(peak)
    if keep:
        top = np.sort(peaks)[::-1][:n_expected]
        floor = params.relative_peak * float(np.median(top))
        keep = [k for k, p in zip(keep, peaks, strict=True) if p >= floor]
    if not keep:
        return Detections(*(np.zeros(0),) * 4)
    areas = stats[keep, cv2.CC_STAT_AREA].astype(np.float64)
    blob_sigma = np.sqrt(areas / np.pi) / 2.0  # a Gaussian blob cut at ~2 sigma
    u0, v0 = cents[keep, 0].astype(np.float64), cents[keep, 1].astype(np.float64)
    if params.method == "mask":
        return Detections(u0, v0, areas, blob_sigma)
    half = np.maximum(params.window_sigma * (expected_sigma or blob_sigma), 2.0)
    u, v, mass = centroid_windows(frame, background, mask, u0, v0, half, params.weight_sigma * sigma_noise,
                                  params.iterations)
    ok = mass > 0
    return Detections(u[ok], v[ok], mass[ok], blob_sigma[ok])


def _fill_holes(binary: np.ndarray) -> np.ndarray:
    """Fill enclosed holes (a saturated flat top can leave a ring after adaptive thresholding)."""
    h, w = binary.shape
    flood = np.zeros((h + 2, w + 2), np.uint8)
    flood[1:-1, 1:-1] = binary
    cv2.floodFill(flood, None, (0, 0), 1)
    holes = (flood[1:-1, 1:-1] == 0).astype(np.uint8)
    return binary | holes


def centroid_windows(frame: np.ndarray, background: np.ndarray, mask: np.ndarray, u0: npt.ArrayLike,
                     v0: npt.ArrayLike, half: npt.ArrayLike | float, threshold: float,
                     iterations: int = 2, mirror: bool = True,
                     static: tuple[np.ndarray, float] | tuple[np.ndarray, float, np.ndarray] | None = None
                     ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Weighted centroids in circular windows of radius ``half`` around (u0, v0), re-centred ``iterations`` times.

    With ``mirror`` (the default) a masked pixel leaves a window together with its mirror image through the
    window's centre (:func:`_pass`); without it, alone (the candidates of the ball selection, where a still
    highlight must stay still: on a noisy still clip, mirrored holes at the band's edge made a few static
    highlights wander enough to pass for moving balls).

    ``static``, ``(pattern, clip)``, is subtracted from every pixel read below ``clip``: the static additive
    pattern of :func:`~cageless.tracking.static.static_pattern` (float32, the frame's shape; lint in front of the balls) and the level at
    which the data saturate (a saturated pixel does not hold the pattern's excess).

    Returns ``(u, v, mass)``; mass 0 where nothing rose above the threshold (u, v are then NaN).
    """
    u0 = np.ascontiguousarray(u0, dtype=np.float64)
    v0 = np.ascontiguousarray(v0, dtype=np.float64)
    half_arr = np.broadcast_to(np.asarray(half, dtype=np.float64), u0.shape).copy()
    return _centroids_core(frame, background, mask, u0, v0, half_arr, float(threshold), int(iterations), bool(mirror),
                           compiled_static(static))


#: The ``static`` argument of the compiled centroid for "nothing to subtract": ``(pattern, clip, table)``.
NO_STATIC = (np.zeros((0, 0), np.float32), np.inf, np.zeros((1, 1), np.int32))


def compiled_static(static: tuple[np.ndarray, float] | tuple[np.ndarray, float, np.ndarray] | None
                    ) -> tuple[np.ndarray, float, np.ndarray]:
    """The compiled centroid's form of ``static`` (``(pattern, clip)`` or None): ``(pattern, clip, table)``
    (a ``static`` already in that form is returned as it is).

    ``table`` is the summed-area table of the pattern's non-zero pixels, ``(h + 1, w + 1)`` int32 with a zero
    first row and column, so that a window tests in O(1) whether it holds any of the pattern and reads the
    pattern only if it does (:func:`_window_has_static`). Testing for the pattern at every pixel instead had
    made the compiled centroid 3.2x slower, even on footage without any (docs/tracking.md).
    """
    if static is None:
        return NO_STATIC
    if len(static) == 3:  # already compiled
        return static  # type: ignore[return-value]
    pattern = np.ascontiguousarray(static[0], dtype=np.float32)
    table = np.zeros((pattern.shape[0] + 1, pattern.shape[1] + 1), np.int32)
    np.cumsum(np.cumsum(pattern != 0, axis=0, dtype=np.int32), axis=1, out=table[1:, 1:])
    return pattern, float(static[1]), table


#: The window re-centring stops once it moves less than this (px).
_CONVERGED_PX = 1e-3


@numba.njit(cache=True, nogil=True, inline="always")
def _span(c, half_sq, dy2, lo_lim, hi_lim):  # pragma: no cover - compiled
    """Columns x with (x - c)^2 <= half_sq - dy2, clipped to [lo_lim, hi_lim)."""
    rem = half_sq - dy2
    if rem < 0.0:
        return 0, -1
    hw = np.sqrt(rem)
    return max(int(np.ceil(c - hw)), lo_lim), min(int(np.floor(c + hw)), hi_lim - 1)


@numba.njit(cache=True, nogil=True)
def _local_background(frame, mask, u, v, r, ring, static):  # pragma: no cover - compiled
    """Median of the masked pixels with r < distance <= r + 2 from (u, v); NaN if fewer than 8.

    Each row visits only the pixels left and right of the window's own run (the run found from the ends of
    its ``_span``, tested exactly as a pixel is), not the whole outer disc: the same pixels in the same
    order (1,850 pixels visited for 290 kept at the benchmark clip's 22 px windows)."""
    h, w = frame.shape
    ro = r + 2.0
    use = _window_has_static(static, u, v, ro)
    cnt = 0
    for y in range(max(int(np.floor(v - ro)), 0), min(int(np.ceil(v + ro)) + 1, h)):
        dy2 = (y - v) * (y - v)
        x0, x1 = _span(u, ro * ro, dy2, 0, w)
        a, b = _span(u, r * r, dy2, 0, w)
        # [a, b]: the pixels of the inner span that lie in the window (one run: the disc is convex in x)
        while a <= b and (a - u) * (a - u) + dy2 > r * r:
            a += 1
        while b >= a and (b - u) * (b - u) + dy2 > r * r:
            b -= 1
        if a > b:
            a, b = x1 + 1, x1
        for x in range(x0, min(a, x1 + 1)):
            if mask[y, x]:
                ring[cnt] = frame[y, x] - _static_at(frame, static, y, x) if use else frame[y, x]
                cnt += 1
        for x in range(max(b + 1, x0), x1 + 1):
            if mask[y, x]:
                ring[cnt] = frame[y, x] - _static_at(frame, static, y, x) if use else frame[y, x]
                cnt += 1
    return np.median(ring[:cnt]) if cnt >= 8 else np.nan


@numba.njit(cache=True, nogil=True, inline="always")
def _static_at(frame, static, y, x):  # pragma: no cover - compiled
    """The static pattern to subtract at pixel (y, x) of a window that holds some of it
    (:func:`_window_has_static`): ``static`` is ``(pattern, clip, table)``; nothing where the pixel reads ``clip``
    or more (a saturated pixel lost the pattern's excess)."""
    if frame[y, x] >= static[1]:
        return 0.0
    return static[0][y, x]


@numba.njit(cache=True, nogil=True)
def _window_has_static(static, u, v, r):  # pragma: no cover - compiled
    """Whether the pattern of ``static`` has a non-zero pixel in the square of half-side ``r`` (plus one pixel)
    about (u, v), from its summed-area table: where it has none, every pixel of the window reads 0 from it."""
    pattern, _, table = static
    h, w = pattern.shape
    if h == 0:
        return False
    y0, y1 = max(int(np.floor(v - r)) - 1, 0), min(int(np.ceil(v + r)) + 2, h)
    x0, x1 = max(int(np.floor(u - r)) - 1, 0), min(int(np.ceil(u + r)) + 2, w)
    if y1 <= y0 or x1 <= x0:
        return False
    return table[y1, x1] - table[y0, x1] - table[y1, x0] + table[y0, x0] > 0


@numba.njit(cache=True, nogil=True, inline="always")
def _kept(mask, x, y):  # pragma: no cover - compiled
    """Bilinear interpolation of ``mask`` (as 0/1, 0 outside the image) at the point (x, y)."""
    h, w = mask.shape
    ix, iy = int(np.floor(x)), int(np.floor(y))
    fx, fy = x - ix, y - iy
    out = 0.0
    for dy, wy in ((0, 1.0 - fy), (1, fy)):
        yy = iy + dy
        if wy <= 0.0 or yy < 0 or yy >= h:
            continue
        for dx, wx in ((0, 1.0 - fx), (1, fx)):
            xx = ix + dx
            if wx > 0.0 and 0 <= xx < w and mask[yy, xx]:
                out += wx * wy
    return out


@numba.njit(cache=True, nogil=True)
def _pass(frame, background, mask, u, v, r, local, threshold, mirror, static):  # pragma: no cover - compiled
    """One weighted-centroid pass over the window of radius r at (u, v): sums (su, sv, m) and whether the
    window holds a masked pixel. With ``mirror``, each pixel's weight is also multiplied by how much of its
    mirror image through the window's centre is unmasked (bilinear, so it varies smoothly with the centre):
    a masked pixel is then left out with its mirror image, and the centroid of a centrally symmetric spot
    stays at its centre. Leaving out a hole on one side only pushes the centroid away from it: the static
    defects masked on the highlights' path (hot pixels, and pixels the highlights leave bright in three
    quarters of the sampled frames) made 1.32 mrad RMS on corpus seed 1029 and 0.55 on seed 1024, against
    0.35 and 0.41 with mirrored holes (and 0.38 and 0.41 with the mirror pixel rounded to the grid instead of
    interpolated, which pulls the centre towards the grid)."""
    h, w = frame.shape
    su = 0.0
    sv = 0.0
    m = 0.0
    holes = False
    use = _window_has_static(static, u, v, r)
    if not mirror:
        if not use and np.isfinite(local):
            return _pass_fast(frame, mask, u, v, r, local + threshold)
        return _pass_plain(frame, background, mask, u, v, r, local, threshold, static, use)
    for y in range(max(int(np.floor(v - r)), 0), min(int(np.ceil(v + r)) + 1, h)):
        dy2 = (y - v) * (y - v)
        x0, x1 = _span(u, r * r, dy2, 0, w)
        for x in range(x0, x1 + 1):
            if not mask[y, x]:
                holes = True
                continue
            base = local if np.isfinite(local) else background[y, x]
            wgt = np.float64(frame[y, x]) - base - threshold
            if use:
                wgt -= _static_at(frame, static, y, x)
            if wgt > 0.0:
                taper = 1.0 - ((x - u) * (x - u) + dy2) / (r * r)  # biweight: 0 at the edge
                wgt *= taper * taper
                if mirror:
                    wgt *= _kept(mask, 2.0 * u - x, 2.0 * v - y)
                su += wgt * x
                sv += wgt * y
                m += wgt
    return su, sv, m, holes


@numba.njit(cache=True, nogil=True, fastmath=True)
def _pass_fast(frame, mask, u, v, r, level):  # pragma: no cover - compiled
    """:func:`_pass_plain` for a window with a local background (``level`` = it plus the threshold) and no static
    pattern: each row's sums in SIMD lanes (``fastmath`` lets them be reassociated), a masked pixel weighted 0.

    The sums differ from :func:`_pass_plain`'s in the last bits (centroids by up to 4e-12 px on the benchmark
    clip), for 0.27 against 0.40 ms of CPU a frame for the per-frame step's 14 windows (benchmarks/centroid_replay.py)."""
    h, w = frame.shape
    su = 0.0
    sv = 0.0
    m = 0.0
    out = 0
    inv = 1.0 / (r * r)
    for y in range(max(int(np.floor(v - r)), 0), min(int(np.ceil(v + r)) + 1, h)):
        dy2 = (y - v) * (y - v)
        x0, x1 = _span(u, r * r, dy2, 0, w)
        ru = 0.0
        rm = 0.0
        for x in range(x0, x1 + 1):
            k = mask[y, x]
            out += 1 - np.int64(k)
            wgt = np.float64(frame[y, x]) - level
            dx = x - u
            taper = 1.0 - (dx * dx + dy2) * inv
            wgt = max(wgt, 0.0) * (taper * taper) * np.float64(k)
            ru += wgt * x
            rm += wgt
        su += ru
        sv += rm * y
        m += rm
    return su, sv, m, out > 0


@numba.njit(cache=True, nogil=True)
def _pass_plain(frame, background, mask, u, v, r, local, threshold, static, use):  # pragma: no cover - compiled
    """:func:`_pass` without ``mirror``, the same sums bit for bit and without a branch on each pixel's weight:
    a pixel at or below the threshold adds ``+0.0`` to each sum (all three sums stay ``>= +0.0``, so adding
    ``+0.0`` leaves them as they are) instead of being skipped, which spares the mispredicted branches (a
    quarter of a window's pixels are below the threshold, scattered)."""
    h, w = frame.shape
    su = 0.0
    sv = 0.0
    m = 0.0
    holes = False
    rr = r * r
    have_local = np.isfinite(local)
    for y in range(max(int(np.floor(v - r)), 0), min(int(np.ceil(v + r)) + 1, h)):
        dy2 = (y - v) * (y - v)
        x0, x1 = _span(u, rr, dy2, 0, w)
        fy = np.float64(y)
        for x in range(x0, x1 + 1):
            if not mask[y, x]:
                holes = True
                continue
            base = local if have_local else np.float64(background[y, x])
            wgt = np.float64(frame[y, x]) - base - threshold
            if use:
                wgt -= _static_at(frame, static, y, x)
            taper = 1.0 - ((x - u) * (x - u) + dy2) / rr
            wgt = (wgt if wgt > 0.0 else 0.0) * (taper * taper)
            su += wgt * x
            sv += wgt * fy
            m += wgt
    return su, sv, m, holes


@numba.njit(cache=True, nogil=True)
def _centroids(frame, background, mask, u0, v0, half, threshold, iterations, static):  # pragma: no cover - compiled
    """:func:`centroid_windows` with mirrored holes, for compiled callers."""
    return _centroids_core(frame, background, mask, u0, v0, half, threshold, iterations, True, static)


@numba.njit(cache=True, nogil=True)
def _centroids_core(frame, background, mask, u0, v0, half, threshold, iterations, mirror, static):  # pragma: no cover
    n = u0.shape[0]
    h, w = frame.shape
    out_u = np.full(n, np.nan)
    out_v = np.full(n, np.nan)
    out_m = np.zeros(n)
    for j in range(n):
        # The start rounded to single precision (about 1e-4 px): the tapered weights make the result depend
        # on it continuously, and callers that predict it in another order must still get the same result.
        u, v = np.float64(np.float32(u0[j])), np.float64(np.float32(v0[j]))
        if not (np.isfinite(u) and np.isfinite(v)):
            continue
        r = half[j]
        ring = np.empty(int(4 * np.pi * (r + 3.0)) + 64)
        # Local background: the black ball coating just outside the window (measured once).
        local = _local_background(frame, mask, u, v, r, ring, static)
        m = 0.0
        pdu, pdv = 0.0, 0.0
        for it in range(iterations):
            su, sv, m, holes = _pass(frame, background, mask, u, v, r, local, threshold, False, static)
            if holes and mirror:
                su, sv, m, _ = _pass(frame, background, mask, u, v, r, local, threshold, True, static)
            if m <= 0.0:
                break
            du, dv = su / m - u, sv / m - v
            gain = 1.0
            if it % 2 == 1:
                # Aitken's delta-squared step: the re-centring contracts by a nearly constant factor r per
                # pass, so the fixed point lies du / (1 - r) away; r from this pass and the previous one.
                den = pdu * pdu + pdv * pdv
                ratio = (du * pdu + dv * pdv) / den if den > 0.0 else 0.0
                if 0.0 < ratio < 0.9:
                    gain = 1.0 / (1.0 - ratio)
            u, v = u + gain * du, v + gain * dv
            if du * du + dv * dv < _CONVERGED_PX * _CONVERGED_PX:
                break
            pdu, pdv = du, dv
        if m > 0.0:
            out_u[j], out_v[j], out_m[j] = u, v, m
    return out_u, out_v, out_m


def spot_sigma(frame: np.ndarray, background: np.ndarray, mask: np.ndarray, u: npt.ArrayLike, v: npt.ArrayLike,
               radius: float, threshold: float) -> npt.NDArray[np.float64]:
    """Gaussian width of each highlight from its mass and peak: mass = 2 pi sigma^2 peak.

    A saturated (flat-topped) highlight reads wider than it is, which only widens its window.
    """
    h, w = frame.shape
    out = np.full(np.size(u), np.nan)
    for j, (uj, vj) in enumerate(zip(np.atleast_1d(u), np.atleast_1d(v), strict=True)):
        r = int(np.ceil(radius))
        y0, y1 = max(int(vj) - r, 0), min(int(vj) + r + 1, h)
        x0, x1 = max(int(uj) - r, 0), min(int(uj) + r + 1, w)
        d = (frame[y0:y1, x0:x1].astype(np.float64) - background[y0:y1, x0:x1]) * mask[y0:y1, x0:x1]
        d = np.where(d > threshold, d, 0.0)
        if d.max() > 0:
            out[j] = np.sqrt(d.sum() / (2 * np.pi * d.max()))
    return out
