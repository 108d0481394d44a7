"""Candidate highlights and short tracklets, for choosing which blobs are the balls.

Detection here must not depend on one rendering style, so it asks one question of each pixel:
is this a small bright *blob* at the scale a ball highlight has? The frame minus the temporal-median
background (which removes the static ring texture, static glints, vignetting and hot pixels) is
smoothed at the expected highlight scale and the smallest eigenvalue of the negative Hessian is taken,
scale-normalised (``sigma^2 lambda_min``, Lindeberg 1998, "Feature detection with automatic scale
selection", IJCV 30:79). A blob curves down in every direction, so both eigenvalues are large; the
edge of a dark ball on a bright ring face, or a bright gap between two balls, curves in one direction
only and gives ``lambda_min`` near 0. Two scales (the expected width and twice it) cover small and
saturated, flat-topped highlights. Local maxima above a robust noise level (MAD of the response in the
ball band) are the candidates; the global selection (:mod:`cageless.tracking.select`) does the real filtering.

Tracklets link candidates over a burst of consecutive frames by an optimal assignment
(:func:`scipy.optimize.linear_sum_assignment`) of tracklet predictions (constant velocity) to the next
frame's candidates, gated by the largest plausible motion per frame.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import cv2
import numpy as np
import numpy.typing as npt

__all__ = ["Candidates", "Tracklet", "blob_response", "response_map", "bin_mask", "find_candidates", "refine_candidates",
           "response_noise",
           "link_tracklets"]


@dataclass(frozen=True)
class Candidates:
    """Blob candidates of one frame (pixel coordinates of the image they were found in)."""

    u: npt.NDArray[np.float64]
    v: npt.NDArray[np.float64]
    response: npt.NDArray[np.float64]  # blob response in noise units
    peak: npt.NDArray[np.float64]  # background-subtracted value at the maximum (DN)

    def __len__(self) -> int:
        return int(self.u.size)


@dataclass
class Tracklet:
    """Candidates linked over consecutive frames of one burst."""

    frames: list[int] = field(default_factory=list)
    u: list[float] = field(default_factory=list)
    v: list[float] = field(default_factory=list)
    response: list[float] = field(default_factory=list)
    misses: int = 0

    def predict(self, frame: int | None = None, times: np.ndarray | None = None) -> tuple[float, float]:
        """Position expected at ``frame`` (default: the frame after the last sample), at the constant
        velocity of the last two samples: per frame, or per second when the frame ``times`` are given (a
        dropped frame is then a longer step, not a faster ball)."""
        if len(self.u) < 2:
            return self.u[-1], self.v[-1]
        f0, f1 = self.frames[-2], self.frames[-1]
        f = f1 + 1 if frame is None else frame
        if times is None:
            step = (f - f1) / max(f1 - f0, 1)
        else:
            step = (times[f] - times[f1]) / max(times[f1] - times[f0], 1e-12)
        return (self.u[-1] + step * (self.u[-1] - self.u[-2]), self.v[-1] + step * (self.v[-1] - self.v[-2]))

    def arrays(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Frames, u and v as arrays."""
        return np.asarray(self.frames), np.asarray(self.u), np.asarray(self.v)


def _hessian_min(img: np.ndarray, sigma: float) -> np.ndarray:
    """``sigma^2`` times the smallest eigenvalue of the negative Hessian of ``img`` smoothed at ``sigma``."""
    g = cv2.GaussianBlur(img, (0, 0), sigma, borderType=cv2.BORDER_REPLICATE)
    # (Sobel's own ``scale=0.25`` is not the same: OpenCV's vector path rounds differently on some pixels.)
    dxx = cv2.Sobel(g, cv2.CV_32F, 2, 0, ksize=3, borderType=cv2.BORDER_REPLICATE)
    dyy = cv2.Sobel(g, cv2.CV_32F, 0, 2, ksize=3, borderType=cv2.BORDER_REPLICATE)
    dxy = cv2.Sobel(g, cv2.CV_32F, 1, 1, ksize=3, borderType=cv2.BORDER_REPLICATE)
    dxx *= 0.25
    dyy *= 0.25
    dxy *= 0.25
    # With a = -dxx, c = -dyy: sigma^2 (0.5 (a + c) - sqrt(h^2 + dxy^2)), h = 0.5 (a - c), computed in place
    # (negations and the factors 0.5 are exact, so these are the same float32 values).
    mean = dxx + dyy
    np.multiply(mean, -0.5, out=mean)  # 0.5 (a + c)
    np.subtract(dyy, dxx, out=dyy)
    np.multiply(dyy, 0.5, out=dyy)  # h
    np.multiply(dyy, dyy, out=dyy)
    np.multiply(dxy, dxy, out=dxy)
    np.add(dyy, dxy, out=dyy)
    np.sqrt(dyy, out=dyy)
    np.subtract(mean, dyy, out=mean)
    mean *= sigma * sigma
    return mean


#: Scales searched, in expected highlight widths: small and saturated highlights, and highlights
#: drawn out along the orbit (motion blur, elongated lobes), which look like blobs at a coarser scale.
_SCALES = (1.0, 2.0, 4.0)


def blob_response(diff: np.ndarray, sigma_px: float) -> np.ndarray:
    """Largest scale-normalised blob response over the scales :data:`_SCALES` times ``sigma_px``."""
    d = diff.astype(np.float32, copy=False)
    out = _hessian_min(d, sigma_px)
    for k in _SCALES[1:]:
        np.maximum(out, _hessian_min(d, k * sigma_px), out=out)
    return out


#: The response is computed on an image binned so that the highlight width is at least this (px):
#: the Hessian needs ~1.5 px of sigma to be sampled well, and binning cuts the cost by the factor squared.
_WORK_SIGMA = 1.5


def work_binning(sigma_px: float) -> int:
    """The binning factor :func:`response_map` works at for highlights of width ``sigma_px``."""
    return max(1, int(sigma_px // _WORK_SIGMA))


def response_map(frame: np.ndarray, background: np.ndarray, sigma_px: float) -> tuple[np.ndarray, int]:
    """Blob response of ``frame - background`` and the binning factor it was computed at."""
    f = work_binning(sigma_px)
    diff = np.subtract(frame, background, dtype=np.float32)
    if f > 1:
        h, w = diff.shape
        diff = cv2.resize(diff[: h - h % f, : w - w % f], (w // f, h // f), interpolation=cv2.INTER_AREA)
    return blob_response(diff, sigma_px / f), f


def bin_mask(mask: np.ndarray, f: int) -> np.ndarray:
    """A mask binned by ``f`` (a binned pixel is in when all its pixels are)."""
    if f == 1:
        return mask
    h, w = mask.shape
    m = mask[: h - h % f, : w - w % f].astype(np.uint8) * np.uint8(255)
    return cv2.resize(m, (w // f, h // f), interpolation=cv2.INTER_AREA) == 255


def find_candidates(frame: np.ndarray, background: np.ndarray, mask: np.ndarray, sigma_px: float,
                    k_sigma: float = 5.0, max_n: int = 200, response_sigma: float | None = None,
                    binned_mask: np.ndarray | None = None) -> Candidates:
    """Blob candidates in ``frame`` inside ``mask`` (arrays cropped alike).

    Parameters
    ----------
    sigma_px
        Expected highlight width (Gaussian sigma, px).
    k_sigma
        A candidate's response must exceed this many robust standard deviations of the response.
    max_n
        Keep at most this many, strongest first.
    response_sigma
        The response's noise level, if already known (else measured in ``mask``).
    binned_mask
        ``bin_mask(mask, f)`` at the response's binning ``f``, when the caller has it (a burst's frames share one
        mask: binning it once per burst instead of once per frame).
    """
    resp, f = response_map(frame, background, sigma_px)
    m = bin_mask(mask, f) if binned_mask is None else binned_mask
    if response_sigma is None:
        response_sigma = response_noise(resp, m)
    radius = max(1, int(round(1.5 * sigma_px / f)))
    kernel = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * radius + 1, 2 * radius + 1))
    peak = (resp >= cv2.dilate(resp, kernel)) & m & (resp > k_sigma * response_sigma)
    vv, uu = np.nonzero(peak)
    r = resp[vv, uu]
    order = np.argsort(-r, kind="stable")[:max_n]
    vv, uu = vv[order], uu[order]
    u, v = (uu + 0.5) * f - 0.5, (vv + 0.5) * f - 0.5
    iu = np.clip(np.rint(u).astype(int), 0, frame.shape[1] - 1)
    iv = np.clip(np.rint(v).astype(int), 0, frame.shape[0] - 1)
    return Candidates(u=u.astype(np.float64), v=v.astype(np.float64), response=r[order] / response_sigma,
                      peak=(frame[iv, iu].astype(np.float64) - background[iv, iu]))


def refine_candidates(c: Candidates, frame: np.ndarray, background: np.ndarray, mask: np.ndarray, radius_px: float,
                      threshold: float, merge_px: float, iterations: int = 10) -> Candidates:
    """Move each candidate to the intensity centroid of its blob, then merge those that met.

    A response maximum sits anywhere on an extended highlight (a saturated plateau, an elongated lobe, two
    lights' highlights run together), and which of its maxima is strongest changes from frame to frame, so
    tracklets built on them jump along the blob. The background-subtracted, tapered centroid in a window of
    ``radius_px`` (:func:`cageless.tracking.detect.centroid_windows`), re-centred ``iterations`` times (a
    mean shift), converges to one point per blob whichever maximum it started from. Candidates that end
    within ``merge_px`` of a stronger one are dropped; a window with no signal keeps its start.
    """
    from cageless.tracking.detect import centroid_windows  # the centroid shared with the per-frame tracker

    if len(c) == 0:
        return c
    u, v, m = centroid_windows(frame, background, mask, c.u, c.v, radius_px, threshold, iterations, mirror=False)
    bad = ~(m > 0)
    u[bad], v[bad] = c.u[bad], c.v[bad]
    near = np.hypot(u[:, None] - u[None, :], v[:, None] - v[None, :]) <= merge_px
    gone = np.zeros(len(c), dtype=bool)
    keep = []
    for k in range(len(c)):  # strongest first (find_candidates' order)
        if not gone[k]:
            keep.append(k)
            gone |= near[k]
    idx = np.asarray(keep, dtype=int)
    return Candidates(u=u[idx], v=v[idx], response=c.response[idx], peak=c.peak[idx])


def response_noise(resp: np.ndarray, mask: np.ndarray) -> float:
    """Robust standard deviation (1.4826 MAD) of the blob response inside ``mask``."""
    vals = resp[mask]
    if vals.size == 0:
        return 1e-6
    med = np.median(vals)
    return float(max(1.4826 * np.median(np.abs(vals - med)), 1e-6))


def link_tracklets(cands: list[Candidates], gate_px: float, max_misses: int = 2,
                   track_gate_px: float | None = None, start_response: float = 0.0,
                   times: np.ndarray | None = None) -> list[Tracklet]:
    """Link per-frame candidates of consecutive frames into tracklets.

    Each live tracklet's constant-velocity prediction is assigned to at most one candidate of the
    next frame by minimum total distance (Hungarian method), within ``gate_px`` per frame elapsed; a
    tracklet may miss ``max_misses`` frames in a row. Unclaimed candidates start new tracklets.

    ``track_gate_px`` (default ``gate_px``) is the gate of a tracklet that already has a velocity (two
    samples or more): its prediction is then good to the position noise, so a tight gate keeps it from
    jumping to a neighbouring blob (a second highlight of the same ball, the other end of an elongated one)
    while its own blob is missed; ``gate_px`` only has to cover the first step, from an unknown speed.

    Only candidates of at least ``start_response`` start a tracklet; weaker ones can only extend one
    (hysteresis, as in Canny's edge linking: a blob where a track predicts one needs less evidence than a
    blob anywhere).

    With the frame ``times`` (one per entry of ``cands``), predictions and gates scale with the time
    elapsed rather than the frames counted, so a dropped frame does not break a tracklet.
    """
    live: list[Tracklet] = []
    done: list[Tracklet] = []
    fine = gate_px if track_gate_px is None else min(track_gate_px, gate_px)
    dt = float(np.median(np.diff(times))) if times is not None and len(times) > 1 else 1.0
    for i, c in enumerate(cands):
        if live and len(c):
            rows, cols = _assign(live, c, i, times, dt, (gate_px, fine))
        else:
            rows = cols = np.zeros(0, dtype=int)
        claimed = set(cols.tolist())
        hit = set(rows.tolist())
        for r, k in zip(rows, cols, strict=True):
            t = live[r]
            t.frames.append(i)
            t.u.append(float(c.u[k]))
            t.v.append(float(c.v[k]))
            t.response.append(float(c.response[k]))
            t.misses = 0
        still = []
        for j, t in enumerate(live):
            if j not in hit:
                t.misses += 1
            (still if t.misses <= max_misses else done).append(t)
        live = still
        for k in range(len(c)):
            if k not in claimed and c.response[k] >= start_response:
                live.append(Tracklet([i], [float(c.u[k])], [float(c.v[k])], [float(c.response[k])]))
    return done + live


def _assign(live: list[Tracklet], c: Candidates, i: int, times: np.ndarray | None, dt: float,
            gates: tuple[float, float]) -> tuple[np.ndarray, np.ndarray]:
    """The live tracklets (rows) matched to frame ``i``'s candidates ``c`` (columns) by minimum total distance
    from their predictions, each within its gate (``gates``: before and after it has a velocity, in pixels
    per frame elapsed; ``dt`` the usual frame interval of ``times``)."""
    pred = np.array([t.predict(i, times) for t in live])
    if times is None:
        gap = np.array([i - t.frames[-1] for t in live], dtype=np.float64)
    else:
        gap = np.array([(times[i] - times[t.frames[-1]]) / dt for t in live])
    d = np.hypot(pred[:, :1] - c.u[None, :], pred[:, 1:] - c.v[None, :])
    per = np.array([gates[1] if len(t.frames) >= 2 else gates[0] for t in live])
    gate = (per * gap)[:, None]
    cost = np.where(d <= gate, d, 1e9)
    from scipy.optimize import linear_sum_assignment  # on first use, see locate.fit_circle

    rows, cols = linear_sum_assignment(cost)
    ok = cost[rows, cols] < 1e9
    return rows[ok], cols[ok]
