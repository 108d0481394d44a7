"""The ball circle of the selection: circles through random triples of tracklet points, and the choice among them.

Split from :mod:`cageless.tracking.select`, which calls :func:`_ransac_circle` on the moving tracklets of its
bursts and :func:`_refit` on the chosen ones. ``ctx`` is the selection's context
(:class:`cageless.tracking.select._Context`): the expected centre and radius, the ball size and count.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from cageless.tracking.candidates import Tracklet
from cageless.tracking.locate import fit_circle

if TYPE_CHECKING:
    from cageless.tracking.select import _Context


def _ransac_circle(pts: np.ndarray, burst: np.ndarray, weight: np.ndarray, ctx: _Context, tol: float,
                   seed: int = 0) -> tuple[float, float, float] | None:
    """Circle hypotheses through random triples. Among those holding (nearly) a full ring of balls in the
    most bursts: the ones near the expected radius (when it is known) or whose members are the strongest
    blobs; of these, the nearly full ones; of these, the brightest ring (see :func:`_pick_circle`)."""
    n = len(pts)
    if n < 3:
        return None
    rng = np.random.default_rng(seed)
    n_b = int(burst.max()) + 1
    hyps = []
    for _ in range(min(600, n * (n - 1) * (n - 2) // 6 * 2)):
        i, j, k = rng.choice(n, 3, replace=False)
        c = _circle3(pts[i], pts[j], pts[k])
        if c is None:
            continue
        cx, cy, r = c
        if math.hypot(cx - ctx.centre0[0], cy - ctx.centre0[1]) > 0.5 * ctx.ball_px:
            continue
        if not 0.6 * ctx.r_prior <= r <= 1.4 * ctx.r_prior or abs(r - ctx.r_prior) > ctx.radius_tol_px:
            continue
        res = np.abs(np.hypot(pts[:, 0] - cx, pts[:, 1] - cy) - r)
        inl = res <= tol
        score, ring_weight = 0, 0.0
        for b in range(n_b):
            w = np.sort(weight[inl & (burst == b)])[::-1][:ctx.z]
            score += w.size
            ring_weight += float(w.sum())
        hyps.append((score, abs(r - ctx.r_prior) if ctx.prior_known else -float(np.sum(weight[inl])), ring_weight,
                     cx, cy, r))
    if not hyps:
        return None
    return _pick_circle(hyps, ctx, tol)


def _pick_circle(hyps: list[tuple[int, float, float, float, float, float]], ctx: _Context,
                 tol: float) -> tuple[float, float, float]:
    """The ball circle among hypotheses ``(score, prior distance, ring weight, cx, cy, r)``.

    The expected radius (or, without one, the blob strength) tells the ball circle from circles of other
    things that move with the balls (bright wedges between balls at the band edges, half a ball off it),
    but not circles of one radius from each other: with two lights, each ball's two highlights travel two
    circles of the same radius, their centres a fixed offset apart. Of those within a tenth of a ball
    diameter (or a tenth of the strength) of the best, the nearly full ones (90 % of the fullest) are
    grouped by centre (distinct circles), and the circle of the brighter light (the largest ring weight:
    its members' summed strength) is chosen. The two highlights of a ball can lie closer than the centroid
    window is wide; the window then holds the other light's tail, which pulls a window started on the dim
    highlight over to the bright one (whose own position the dim tail moves far less), so tracks started on
    the dim light switched lights along the orbit. Choosing the circle whose members fit best (least RMS
    residual) picked the dim light on corpus seed 1006 (second light 0.3 of the first, highlights 21 px
    apart, window radius 18 px): 12.4 mrad RMS; the bright light's circle gives 0.30 mrad.
    """
    top = max(h[0] for h in hyps)
    full = [h for h in hyps if h[0] >= 0.8 * top]
    best = min(h[1] for h in full)
    slack = 0.1 * ctx.ball_px if ctx.prior_known else 0.1 * abs(best)
    near = [h for h in full if h[1] <= best + slack]
    most = max(h[0] for h in near)
    fullest = sorted((h for h in near if h[0] >= 0.9 * most), key=lambda h: (-h[0], -h[2]))
    groups: list[tuple[int, float, float, float, float, float]] = []
    for h in fullest:
        if all(math.hypot(h[3] - g[3], h[4] - g[4]) > tol for g in groups):
            groups.append(h)
    _, _, _, cx, cy, r = max(groups, key=lambda g: g[2])
    return cx, cy, r


def _circle3(p: np.ndarray, q: np.ndarray, s: np.ndarray) -> tuple[float, float, float] | None:
    ax, ay = p
    bx, by = q
    cx, cy = s
    d = 2 * (ax * (by - cy) + bx * (cy - ay) + cx * (ay - by))
    if abs(d) < 1e-9:
        return None
    ux = ((ax**2 + ay**2) * (by - cy) + (bx**2 + by**2) * (cy - ay) + (cx**2 + cy**2) * (ay - by)) / d
    uy = ((ax**2 + ay**2) * (cx - bx) + (bx**2 + by**2) * (ax - cx) + (cx**2 + cy**2) * (bx - ax)) / d
    return float(ux), float(uy), float(math.hypot(ax - ux, ay - uy))


def _refit(tracks: list[Tracklet], idx: np.ndarray, circle: tuple[float, float, float], tol: float
           ) -> tuple[float, float, float]:
    """Least-squares circle through every sample of the tracklets within ``tol`` of ``circle``."""
    cx, cy, r = circle
    us, vs = [], []
    for k in idx:
        _, u, v = tracks[k].arrays()
        keep = np.abs(np.hypot(u - cx, v - cy) - r) <= tol
        us.append(u[keep])
        vs.append(v[keep])
    u, v = np.concatenate(us), np.concatenate(vs)
    if u.size < 3:
        return circle
    fx, fy, fr, _ = fit_circle(u, v)
    return fx, fy, fr
