"""Which blobs are the balls: exactly Z tracks chosen by their joint consistency.

The bearing description fixes the ball count Z, the ball diameter D and the pitch circle d_m, and
the operating conditions fix the inner-ring speed, hence the pure-rolling cage speed
``omega_c = omega_i (1 - D/d_m) / 2``. The ball highlights share one light, so they all sit at the
same offset from their ball centres: they travel one circle (the pitch circle, shifted by that
offset), in a fixed cyclic order, at least one ball diameter apart (balls cannot overlap, and in a
full-complement bearing they nearly touch), at close to the cage speed. Glints on the outer ring stand
still; glints and marks on the inner ring turn at ``omega_i``, about 2.5 ``omega_c``; the bright
wedges between neighbouring balls travel with the balls but on circles at the edges of the band.

The stage runs once per video on a few bursts of consecutive frames spread over the clip:

1. blob candidates in every burst frame (:func:`cageless.tracking.candidates.find_candidates`, on the frame
   minus a low quantile of the sampled frames, so that a highlight lying along the orbit leaves no ghost in
   it), each moved to its blob's centroid (:func:`~cageless.tracking.candidates.refine_candidates`: one
   point per saturated, elongated or doubled highlight), linked into tracklets with a tight gate once a
   tracklet has a velocity, and with hysteresis (weaker blobs extend a tracklet but do not start one);
2. each tracklet's angular speed about the bearing centre: the plausible band for a ball's mean speed
   is :data:`SPEED_BAND` times ``omega_c`` (0.6-1.1: slip up to 25 % plus the unloaded-zone slow-down,
   and balls pushed ahead after impacts, pass; glints at 0 and at 2.5 ``omega_c`` do not); a
   tracklet's speed over a few milliseconds gets the wider :data:`TRACKLET_BAND` (0.5-1.3), and the
   tracked balls' mean speeds are checked against :data:`SPEED_BAND` after tracking;
3. one common circle by RANSAC over the moving tracklets (Fischler & Bolles 1981), the hypotheses
   with a full complement of balls ranked by their distance from the expected radius (the middle of
   the ball band, or d_m/2 times px/mm when the scale is given, and then only circles within
   :data:`PRIOR_RADIUS_TOL` ball diameters of it are hypotheses); of circles of about that radius (two
   lights give two), the brighter light's;
4. per burst, an exact-Z choice with every cyclic neighbour at least :data:`MIN_SPACING` contact
   spacings apart that maximises the total tracklet weight: a dynamic programme over the cyclic
   order (a global assignment, not per-blob thresholds), and the largest count the spacing allows.

The count found is the largest that at least half of the bursts show (a ball can be hidden or missed in
one stretch, but the spacing cannot invent one); the per-frame tracker interpolates and flags the frames
where a ball is missed. Every tracklet leaves with a status: selected, or rejected with its reason. A clip
that shows a ball count other than Z, or whose chosen tracks fail the checks, raises :class:`SelectionError`, which
carries that table so the QC can show what was found.
"""

from __future__ import annotations

import logging
import math
from collections.abc import Callable
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt
import pandas as pd

from cageless.errors import TrackingError
from cageless.tracking.candidates import (Tracklet, bin_mask, find_candidates, link_tracklets, refine_candidates,
                                          response_map, response_noise, work_binning)
from cageless.tracking.cyclic import cyclic_select
from cageless.tracking.select_circle import _ransac_circle, _refit

__all__ = ["SPEED_BAND", "MIN_SPACING", "PRIOR_RADIUS_TOL", "BallRing", "Anchor", "Selection", "SelectionError",
           "select_balls", "check_radius", "anchor_at", "cyclic_select"]

log = logging.getLogger(__name__)

#: Plausible ball speed over the cage speed, for a ball's mean over the clip (see the module docstring).
SPEED_BAND = (0.6, 1.1)
#: The same for one tracklet's speed over a burst of a few milliseconds, measured about the bearing
#: centre before the ball circle is known: wider, because a ball speeds up and slows down by several
#: per cent between impacts and a highlight offset of 5 % of the radius biases it by as much.
TRACKLET_BAND = (0.5, 1.3)
#: Below this share of the cage speed a tracklet is static; within this share of omega_i it turns with the ring.
STATIC_BELOW = 0.3
INNER_RING_TOL = 0.3
#: Least centre-to-centre angle of two chosen tracks, in contact spacings 2 asin(D/d_m).
MIN_SPACING = 0.85
#: Radial tolerance about the ball circle, in ball diameters (highlight jitter, lens distortion).
RADIAL_TOL = 0.05
#: A tracklet must cover this share of its burst.
MIN_COVER = 0.5
#: A blob at the place a tracklet predicts extends it down to this share of the response that starts one
#: (hysteresis): a highlight over a textured or bright face, whose response noise the moving balls raise,
#: flickers about the start threshold from frame to frame.
EXTEND_SHARE = 0.6
#: Largest distance of the chosen circle's radius from the pitch radius at a stated ``px_per_mm``, in ball
#: diameters. The bright wedges between neighbouring balls travel like balls, Z on one circle, but about a third
#: of a ball off the pitch circle (FRESH2 seed 7218: 0.31 D inside; its dim, doubled highlights gave fewer
#: tracklets, 17.1 mrad RMS); the highlights' circle is the pitch circle shifted (<= 0.017 D off on TUNING).
#: A stated scale off by a fraction e moves it by e d_m / (2 D) ball diameters (7 % at d_m = 4 D). With a stated
#: scale only circles within it are RANSAC hypotheses (the wedges' circle, fuller, had won on fullness), so the
#: highlights' circle is chosen when it is there (7218: 7 of 12 balls in the band between the lands, 12 of 12 in
#: the band of whole balls) and :func:`check_radius` guards the refit.
PRIOR_RADIUS_TOL = 0.15
#: Window radius of the blob centroid that places each candidate, in ball diameters: a highlight (even
#: saturated, elongated or two lights' run together) is a small part of its ball (the per-frame tracker
#: takes blobs up to a quarter ball wide), and distinct blobs of one ball lie further apart than this.
BLOB_RADIUS = 0.2
#: Largest step of a tracklet off its constant-velocity prediction per frame, in ball diameters (position
#: noise; a ball's speed changes by a few per cent over a burst, a small fraction of a ball diameter).
TRACK_GATE = 0.1


class SelectionError(TrackingError):
    """The balls could not be chosen: wrong count or failed consistency checks."""

    def __init__(self, path: object, message: str, hint: str = "", table: pd.DataFrame | None = None,
                 found: int | None = None, ring: BallRing | None = None) -> None:
        super().__init__(path, message, hint)  # type: ignore[arg-type]
        self.table, self.found, self.ring = table, found, ring


@dataclass(frozen=True)
class BallRing:
    """The circle the highlights travel and how to find them (cropped-image pixels)."""

    centre: tuple[float, float]
    radius: float
    direction: int  # +1: counter-clockwise in the image
    omega: float  # median speed of the chosen tracks (rad/s, >0)
    ball_px: float
    sigma_px: float
    radial_tol_px: float
    response_sigma: float
    k_sigma: float
    z: int
    gap: float  # least angle between chosen neighbours (rad)
    omega_c: float  # pure-rolling cage speed (rad/s)
    omega_i: float  # inner-ring speed (rad/s)
    pixel_threshold: float = 0.0  # candidate centroid weight threshold (DN)


@dataclass(frozen=True)
class Anchor:
    """Z chosen highlights in one frame, in cyclic (counter-clockwise) order, with their image speeds."""

    frame: int
    u: npt.NDArray[np.float64]
    v: npt.NDArray[np.float64]
    omega: npt.NDArray[np.float64]  # image-frame angular speed (rad/s, signed)


@dataclass
class Selection:
    """The outcome: the ring, anchors for the per-frame tracker, and every tracklet with its status."""

    ring: BallRing
    anchors: list[Anchor]
    table: pd.DataFrame
    counts: list[int] = field(default_factory=list)


@dataclass(frozen=True)
class _Context:
    z: int
    gap: float  # least angle between chosen neighbours (rad)
    omega_c: float
    omega_i: float
    ball_px: float
    r_prior: float
    centre0: tuple[float, float]
    sigma_px: float
    k_sigma: float
    prior_known: bool = True  # False: r_prior is only a scale guess; the circle is chosen by support
    pixel_threshold: float = 0.0  # centroid weight threshold (DN above the local background)
    workers: int = 1  # threads finding the candidates of a burst's frames (OpenCV, numpy and numba release the GIL)
    radius_tol_px: float = math.inf  # a stated scale: the ball circle lies within this of r_prior (px)


def _burst_plan(n: int, times: np.ndarray, omega_c: float, n_bursts: int) -> list[tuple[int, int]]:
    """Bursts of consecutive frames spread over the clip, each long enough for 0.2 rad of cage travel."""
    dt = float(np.median(np.diff(times))) if n > 1 else 1e-4
    length = int(np.clip(math.ceil(0.2 / max(omega_c * dt, 1e-9)), 24, 60))
    length = min(length, n)
    starts = np.unique(np.linspace(0, n - length, max(1, min(n_bursts, n // length))).astype(int))
    return [(int(a), int(a + length)) for a in starts]


def _features(t: Tracklet, times: np.ndarray, centre: tuple[float, float]) -> dict[str, float]:
    f, u, v = t.arrays()
    th = _unwrap(np.arctan2(-(v - centre[1]), u - centre[0]))
    tt = times[f]
    omega = _slope(tt - tt.mean(), th) if f.size >= 3 else 0.0
    mid = f.size // 2
    return {"u": float(u[mid]), "v": float(v[mid]), "frame": int(f[mid]), "omega": omega,
            "radius": float(np.mean(np.hypot(u - centre[0], v - centre[1]))), "n": int(f.size),
            "response": _median(t.response)}


def _unwrap(th: np.ndarray) -> np.ndarray:
    """:func:`numpy.unwrap`, without its work when no step reaches pi (then it adds zeros: ``th + 0.0``)."""
    if th.size < 2 or bool(np.all(np.abs(np.diff(th)) < math.pi)):
        return th + 0.0
    return np.unwrap(th)


def _slope(x: np.ndarray, y: np.ndarray) -> float:
    """The slope of ``np.polyfit(x, y, 1)``, by the same scaled least squares without its argument checks
    (the same value; many short tracklets made the checks a large share of the selection's time)."""
    lhs = np.empty((x.size, 2))
    lhs[:, 0] = x + 0.0
    lhs[:, 1] = 1.0
    scale = np.sqrt((lhs * lhs).sum(axis=0))
    lhs /= scale
    c = np.linalg.lstsq(lhs, y + 0.0, x.size * np.finfo(np.float64).eps)[0]
    return float(c[0] / scale[0])


def _median(values: list[float]) -> float:
    """:func:`numpy.median` of a short list of finite numbers (the middle one, or the mean of the middle two)."""
    s = sorted(values)
    k = len(s) // 2
    return float(s[k]) if len(s) % 2 else float((s[k - 1] + s[k]) / 2)


def _speed_reason(ratio: float, omega: float, ctx: _Context) -> str:
    if abs(ratio) < STATIC_BELOW:
        return "static"
    if abs(abs(omega) - ctx.omega_i) <= INNER_RING_TOL * ctx.omega_i:
        return "turns with the inner ring"
    if not TRACKLET_BAND[0] <= abs(ratio) <= TRACKLET_BAND[1]:
        return "wrong speed"
    return ""


#: Frames of a burst whose candidates are found together (on ``workers`` threads): as many as a memory-mapped
#: source keeps mapped (tracking/cropped.py), so that the pages of those before are dropped, not held.
_FRAMES_AT_ONCE = 8


def _burst_tracklets(frames: Callable[[int], np.ndarray], span: tuple[int, int], background: np.ndarray,
                     mask: np.ndarray, ctx: _Context, times: np.ndarray, noise: float | None
                     ) -> tuple[list[Tracklet], float]:
    a, b = span
    binned = bin_mask(mask, work_binning(ctx.sigma_px))  # once for the burst's frames
    if noise is None:
        resp, _ = response_map(frames(a), background, ctx.sigma_px)
        noise = response_noise(resp, binned)

    def candidates(frame: np.ndarray) -> Any:
        c = find_candidates(frame, background, mask, ctx.sigma_px, EXTEND_SHARE * ctx.k_sigma, 12 * ctx.z + 32,
                            noise, binned)
        return refine_candidates(c, frame, background, mask, BLOB_RADIUS * ctx.ball_px, ctx.pixel_threshold,
                                 max(1.0, ctx.sigma_px))
    cands = []
    with ThreadPoolExecutor(max_workers=max(1, ctx.workers)) as pool:
        for k in range(a, b, _FRAMES_AT_ONCE):  # fetched in order, a few at a time: a memory map's pages are
            cands += pool.map(candidates, [frames(i) for i in range(k, min(k + _FRAMES_AT_ONCE, b))])  # dropped
    dt = float(np.median(np.diff(times[a:b]))) if b - a > 1 else 1e-4
    r_max = ctx.r_prior + ctx.ball_px
    gate = max(3.0, 1.3 * ctx.omega_i * r_max * dt + 2.0)
    tracks = link_tracklets(cands, gate, max_misses=6, track_gate_px=max(3.0, TRACK_GATE * ctx.ball_px),
                            start_response=ctx.k_sigma, times=np.asarray(times[a:b], dtype=np.float64))
    for t in tracks:
        t.frames = [f + a for f in t.frames]
    return tracks, float(noise)


def _classify(feats: list[dict[str, float]], tracks: list[Tracklet], spans: list[tuple[int, int]],
              burst: np.ndarray, ctx: _Context, direction: int | None) -> tuple[list[str], int]:
    """A rejection reason per tracklet ('' for a mover) from its coverage and speed; the image direction."""
    reasons = []
    for f, b in zip(feats, burst, strict=True):
        a, e = spans[b]
        if f["n"] < MIN_COVER * (e - a):
            reasons.append("too short")
        else:
            reasons.append(_speed_reason(f["omega"] / ctx.omega_c, f["omega"], ctx))
    if direction is None:
        moving = [f["omega"] for f, r in zip(feats, reasons, strict=True) if not r]
        direction = 1 if not moving or np.median(moving) >= 0 else -1
    for k, f in enumerate(feats):
        if not reasons[k] and np.sign(f["omega"]) != direction:
            reasons[k] = "wrong direction"
    return reasons, direction


def _choose_bursts(tracks: list[Tracklet], feats: list[dict[str, float]], reasons: list[str], burst: np.ndarray,
                   spans: list[tuple[int, int]], times: np.ndarray, circle: tuple[float, float, float], tol: float,
                   ctx: _Context) -> tuple[list[Anchor | None], list[int]]:
    """Per burst: the exact-Z choice on the circle (an anchor) and the largest count the spacing allows."""
    cx, cy, r = circle
    anchors: list[Anchor | None] = []
    counts = []
    for b, (a, e) in enumerate(spans):
        idx = []
        for k in np.flatnonzero(burst == b):
            _, u, v = tracks[k].arrays()
            if reasons[k]:
                continue
            if np.mean(np.abs(np.hypot(u - cx, v - cy) - r)) > tol:
                reasons[k] = "off the ball circle"
                continue
            idx.append(int(k))
        t_ref = float(times[(a + e - 1) // 2])
        fits = [_angle_fit(tracks[k], times, (cx, cy)) for k in idx]
        ang = np.array([th0 + om * (t_ref - tm) for th0, om, tm in fits])
        weight = np.array([feats[k]["n"] / (e - a) * math.log1p(feats[k]["response"]) for k in idx])
        pick, count = cyclic_select(ang, weight, ctx.z, ctx.gap) if idx else (None, 0)
        counts.append(count)
        chosen = set() if pick is None else {idx[p] for p in pick}
        for k in idx:
            reasons[k] = "selected" if chosen and k in chosen else "breaks spacing"
        if pick is None:
            anchors.append(None)
            continue
        sel = [idx[p] for p in pick]
        anchors.append(_anchor(tracks, sel, [fits[p] for p in pick], times, (cx, cy), r, a, e))
    return anchors, counts


def _angle_fit(t: Tracklet, times: np.ndarray, centre: tuple[float, float]) -> tuple[float, float, float]:
    """(angle at the mean time, angular speed, mean time) of a tracklet about ``centre``."""
    f, u, v = t.arrays()
    th = np.unwrap(np.arctan2(-(v - centre[1]), u - centre[0]))
    tt = times[f]
    tm = float(tt.mean())
    if f.size < 3:
        return float(th.mean()), 0.0, tm
    slope, icpt = np.polyfit(tt - tm, th, 1)
    return float(icpt), float(slope), tm


def _anchor(tracks: list[Tracklet], sel: list[int], fits: list[tuple[float, float, float]], times: np.ndarray,
            centre: tuple[float, float], r: float, a: int, e: int) -> Anchor:
    """The first burst frame where every chosen tracklet was seen (else the middle frame, filling the
    missing ones from their angle fits)."""
    present = [set(tracks[k].frames) for k in sel]
    common = sorted(set.intersection(*present)) if present else []
    frame = common[0] if common else (a + e - 1) // 2
    u = np.empty(len(sel))
    v = np.empty(len(sel))
    for j, k in enumerate(sel):
        t = tracks[k]
        if frame in present[j]:
            i = t.frames.index(frame)
            u[j], v[j] = t.u[i], t.v[i]
        else:
            th0, om, tm = fits[j]
            th = th0 + om * (float(times[frame]) - tm)
            u[j], v[j] = centre[0] + r * math.cos(th), centre[1] - r * math.sin(th)
    omega = np.array([f[1] for f in fits])
    order = np.argsort(np.arctan2(-(v - centre[1]), u - centre[0]))
    return Anchor(frame=int(frame), u=u[order], v=v[order], omega=omega[order])


def _table(feats: list[dict[str, float]], reasons: list[str], burst: np.ndarray, ctx: _Context,
           direction: int) -> pd.DataFrame:
    rows = [{"burst": int(b), "frame": f["frame"], "u_px": f["u"], "v_px": f["v"], "radius_px": f["radius"],
             "speed_ratio": direction * f["omega"] / ctx.omega_c, "frames_seen": f["n"],
             "response": f["response"], "status": "selected" if r == "selected" else "rejected",
             "reason": "" if r == "selected" else (r or "not chosen")}
            for f, r, b in zip(feats, reasons, burst, strict=True)]
    cols = ["burst", "frame", "u_px", "v_px", "radius_px", "speed_ratio", "frames_seen", "response", "status",
            "reason"]
    return pd.DataFrame(rows, columns=cols)


def _context(z: int, ball_diameter_m: float, pitch_diameter_m: float, omega_i: float,
             centre0: tuple[float, float], r_prior: float, k_sigma: float,
             sigma_px: float | None = None, prior_known: bool = True, pixel_threshold: float = 0.0,
             workers: int = 1, scale_stated: bool = False) -> _Context:
    ratio = ball_diameter_m / pitch_diameter_m
    ball_px = 2.0 * ratio * r_prior
    return _Context(z=z, gap=MIN_SPACING * 2 * math.asin(min(ratio, 1.0)), omega_c=0.5 * omega_i * (1 - ratio),
                    omega_i=omega_i, ball_px=ball_px, r_prior=r_prior, centre0=centre0,
                    sigma_px=sigma_px or max(1.0, 0.05 * ball_px), k_sigma=k_sigma, prior_known=prior_known,
                    pixel_threshold=pixel_threshold, workers=workers,
                    radius_tol_px=PRIOR_RADIUS_TOL * ball_px if scale_stated else math.inf)


def _collect_tracklets(frames: Callable[[int], np.ndarray], spans: list[tuple[int, int]], background: np.ndarray,
                       mask: np.ndarray, ctx: _Context, times: np.ndarray) -> tuple[list[Tracklet], np.ndarray, Any]:
    """Every burst's tracklets, the burst index of each, and the noise level the bursts measured."""
    tracks: list[Tracklet] = []
    burst: list[int] = []
    noise = None
    for b, span in enumerate(spans):
        tr, noise = _burst_tracklets(frames, span, background, mask, ctx, times, noise)
        tracks += tr
        burst += [b] * len(tr)
    return tracks, np.asarray(burst, dtype=int), noise


def _ball_circle(tracks: list[Tracklet], feats: list[dict[str, Any]], movers: np.ndarray, burst_arr: np.ndarray,
                 ctx: _Context, tol: float) -> tuple[float, float, float] | None:
    """The highlights' circle (u, v, r) from the moving candidates (weighted RANSAC, then refitted on the
    tracklets within 2 ``tol`` of it), or ``None`` when fewer than three move or no circle holds them."""
    if movers.size < 3:
        return None
    pts = np.array([[feats[k]["u"], feats[k]["v"]] for k in movers])
    wts = np.array([math.log1p(feats[k]["response"]) for k in movers])
    circle = _ransac_circle(pts, burst_arr[movers], wts, ctx, tol)
    if circle is None:
        return None
    inl = np.array([k for k in movers if np.mean(np.abs(np.hypot(tracks[k].arrays()[1] - circle[0],
                                                                    tracks[k].arrays()[2] - circle[1]) - circle[2]))
                    <= 2 * tol], dtype=int)
    return _refit(tracks, inl, circle, 2 * tol) if inl.size else circle


def select_balls(frames: Callable[[int], np.ndarray], times: np.ndarray, background: np.ndarray,
                 mask: np.ndarray, *, z: int, ball_diameter_m: float, pitch_diameter_m: float, omega_i: float,
                 centre0: tuple[float, float], r_prior: float, path: object = "video", n_bursts: int = 6,
                 k_sigma: float = 4.0, prior_known: bool = True, pixel_threshold: float = 0.0,
                 scale_stated: bool = False, workers: int = 1) -> Selection:
    """Choose exactly ``z`` ball tracks from bursts spread over the clip (see the module docstring).

    Parameters
    ----------
    frames
        ``frames(i)`` returns frame i cropped like ``background`` and ``mask`` (the ball band).
    times
        Frame times (s).
    z, ball_diameter_m, pitch_diameter_m
        The bearing (``z`` may be a user-stated count).
    omega_i
        Inner-ring speed (rad/s).
    centre0, r_prior
        Bearing centre and the expected radius of the highlight circle (px, cropped image).
    prior_known
        False when ``r_prior`` is only a rough scale (then the circle is chosen by its support).
    pixel_threshold
        Per-pixel weight threshold of the centroid that places each candidate (DN; a few noise sigmas).
    scale_stated
        True when ``r_prior`` is the pitch radius at a stated scale: the chosen circle must then lie within
        :data:`PRIOR_RADIUS_TOL` ball diameters of it (:func:`check_radius`).
    workers
        Threads that find the candidates of a burst's frames (the same candidates with any number).

    Raises
    ------
    SelectionError
        When the clip shows a count other than ``z``, the chosen tracks fail the checks, or (``scale_stated``)
        their circle is not the pitch circle.
    """
    ctx = _context(z, ball_diameter_m, pitch_diameter_m, omega_i, centre0, r_prior, k_sigma,
                   prior_known=prior_known, pixel_threshold=pixel_threshold, workers=workers,
                   scale_stated=scale_stated)
    spans = _burst_plan(len(times), times, ctx.omega_c, n_bursts)
    tracks, burst_arr, noise = _collect_tracklets(frames, spans, background, mask, ctx, times)
    feats = [_features(t, times, centre0) for t in tracks]
    reasons, direction = _classify(feats, tracks, spans, burst_arr, ctx, None)
    movers = np.array([k for k, r in enumerate(reasons) if not r], dtype=int)
    tol = max(1.5, RADIAL_TOL * ctx.ball_px)
    circle = _ball_circle(tracks, feats, movers, burst_arr, ctx, tol)
    if circle is None:
        raise _no_circle(path, z, _table(feats, reasons, burst_arr, ctx, direction))
    feats = [_features(t, times, (circle[0], circle[1])) for t in tracks]
    anchors, counts = _choose_bursts(tracks, feats, reasons, burst_arr, spans, times, circle, tol, ctx)
    table = _table(feats, reasons, burst_arr, ctx, direction)
    ring = _ball_ring(circle, direction, table, ctx, tol, float(noise or 1))
    found, good = _majority_count(counts), [a for a in anchors if a is not None]
    log.info("%s: ball circle r = %.1f px, counts per burst %s, %d of %d bursts with %d balls", path, circle[2],
             counts, len(good), len(spans), z)
    _check_count(path, z, found, len(good), len(spans), table, ring)
    if scale_stated:
        check_radius(path, circle[2], r_prior, ctx.ball_px, table=table, ring=ring, found=found)
    return Selection(ring=ring, anchors=good, table=table, counts=counts)


def _no_circle(path: object, z: int, table: pd.DataFrame) -> SelectionError:
    """The error of a clip where no circle of ``z`` highlights moving together was found (0 balls)."""
    return SelectionError(path, f"no {z} highlights moving together along one circle near the cage speed were "
                          "found (0 balls found).", "Check the lighting, the speed_rpm, the frame rate (fps: an "
                          "AVI, MP4 or image sequence holds no camera time stamps, so give the recording rate in "
                          "its sidecar, conditions.csv or --fps; at a rate stated too low the balls look static), "
                          f"px_per_mm (when stated, only circles within {PRIOR_RADIUS_TOL} ball diameters of its "
                          "pitch circle are tried) and the bearing description; the QC image shows every "
                          "candidate and why it was rejected.",
                          table=table, found=0)


def _ball_ring(circle: tuple[float, float, float], direction: int, table: pd.DataFrame, ctx: _Context, tol: float,
               response_sigma: float) -> BallRing:
    """The chosen circle as a :class:`BallRing`, turning at the median speed of the selected tracks."""
    sel_speed = table.loc[table.status == "selected", "speed_ratio"]
    return BallRing(centre=(circle[0], circle[1]), radius=circle[2], direction=direction,
                    omega=float(np.median(sel_speed) * ctx.omega_c) if len(sel_speed) else ctx.omega_c,
                    ball_px=ctx.ball_px, sigma_px=ctx.sigma_px, radial_tol_px=tol, response_sigma=response_sigma,
                    k_sigma=ctx.k_sigma, z=ctx.z, gap=ctx.gap, omega_c=ctx.omega_c, omega_i=ctx.omega_i,
                    pixel_threshold=ctx.pixel_threshold)


def _majority_count(counts: list[int]) -> int:
    """The ball count of the clip from its bursts' counts. A ball can be hidden or missed in a stretch of the clip
    (a land, a dark frame, a glint crossing it), but the spacing cannot invent one: the count is the largest that
    at least half the stretches show."""
    return int(sorted(counts, reverse=True)[(len(counts) - 1) // 2]) if counts else 0


def _check_count(path: object, z: int, found: int, n_good: int, n_spans: int, table: pd.DataFrame,
                 ring: BallRing) -> None:
    """Refuse a clip whose count is not ``z``, or whose ``z`` balls show in fewer than half its ``n_spans``
    sampled stretches (``n_good``).

    Raises
    ------
    SelectionError
        With the candidate ``table`` and the ``ring`` for the QC image.
    """
    if found != z:
        raise SelectionError(path, f"found {found} balls moving together along one circle, but {z} are expected (the "
                             "bearing's ball count, or --n-balls).",
                             f"Check the stated speed (speed_rpm: balls far from the expected cage speed are "
                             f"rejected), px_per_mm (when stated, the balls are looked for near its pitch circle) "
                             f"and the bearing's ball count; if the video really shows {found} balls, "
                             f"state it with --n-balls {found} (same ball and pitch diameters), or describe its "
                             f"bearing (n_balls, ball_diameter_mm, pitch_diameter_mm in its sidecar or "
                             f"conditions.csv). "
                             f"The QC image shows what was found.", table=table,
                             found=found, ring=ring)
    if n_good < 0.5 * n_spans:
        raise SelectionError(path, f"{z} consistent balls were found in only {n_good} of {n_spans} sampled "
                             "stretches of the clip.", "Check the lighting and focus; the QC image shows what "
                             "was found.", table=table, found=found, ring=ring)


def check_radius(path: object, radius: float, r_prior: float, ball_px: float, *, table: pd.DataFrame | None = None,
                 ring: BallRing | None = None, found: int | None = None) -> None:
    """Refuse a ball circle of ``radius`` px more than :data:`PRIOR_RADIUS_TOL` ball diameters (``ball_px``) from
    the pitch radius ``r_prior`` px of the stated scale (:class:`SelectionError`, with ``table`` and ``ring`` for QC).
    """
    off = (radius - r_prior) / ball_px
    if abs(off) <= PRIOR_RADIUS_TOL:
        return
    raise SelectionError(path, f"the tracks chosen as balls travel a circle of radius {radius:.1f} px, but the "
                         f"pitch circle at the stated px_per_mm is {r_prior:.1f} px ({off:+.2f} ball diameters, "
                         f"limit {PRIOR_RADIUS_TOL}): they are not the balls' highlights (the bright gaps between "
                         "balls travel with them, inside or outside the pitch circle).",
                         "Check px_per_mm and the bearing's pitch diameter; if they are right, the highlights are "
                         "too faint to be chosen over the gaps. The QC image shows the circle and every candidate.",
                         table=table, found=found, ring=ring)


def anchor_at(frames: Callable[[int], np.ndarray], times: np.ndarray, background: np.ndarray, mask: np.ndarray,
              ring: BallRing, start: int = 0) -> Anchor | None:
    """An anchor from one burst at ``start`` on a known ring (for a segment without one); None if not found."""
    ctx = _Context(z=ring.z, gap=ring.gap, omega_c=ring.omega_c, omega_i=ring.omega_i, ball_px=ring.ball_px,
                   r_prior=ring.radius, centre0=ring.centre, sigma_px=ring.sigma_px, k_sigma=ring.k_sigma,
                   pixel_threshold=ring.pixel_threshold)
    span = _burst_plan(len(times) - start, times[start:], ctx.omega_c, 1)[0]
    span = (span[0] + start, span[1] + start)
    tracks, _ = _burst_tracklets(frames, span, background, mask, ctx, times, ring.response_sigma)
    burst = np.zeros(len(tracks), dtype=int)
    feats = [_features(t, times, ring.centre) for t in tracks]
    reasons, _ = _classify(feats, tracks, [span], burst, ctx, ring.direction)
    anchors, _ = _choose_bursts(tracks, feats, reasons, burst, [span], times,
                                (ring.centre[0], ring.centre[1], ring.radius), ring.radial_tol_px, ctx)
    return anchors[0]
