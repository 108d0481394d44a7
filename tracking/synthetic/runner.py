"""Run the current tracker over corpus clips and score it: what the matrix test and the benchmark share.

Public API::

    run_seed(seed: int, folder: Path, long: bool = False, keep=True, oracle=True) -> ClipResult
    run_seeds(seeds, folder, workers=2, long=False, progress=True, keep=True, oracle=True) -> list[ClipResult]

Each clip is rendered into ``folder`` (or reused), tracked by
:func:`cageless.tracking.pipeline.track_video` with the clip's bearing and conditions, and
scored by :func:`cageless.tracking.synthetic.score.score_trace`. A tracker error (no trace)
is a result too: ``status = "error"`` with its message.
"""

from __future__ import annotations

import logging
import math
import time
import warnings
from collections.abc import Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field
from multiprocessing import get_context
from pathlib import Path
from typing import Any

from tqdm.auto import tqdm

from cageless.errors import CagelessError
import cv2
import numpy as np

from cageless.trace import Trace
from cageless.tracking.synthetic.corpus import ClipSpec, describe, render_clip
from cageless.tracking.synthetic.crb import angle_crb_mrad
from cageless.tracking.synthetic.score import BARS, Score, ideal_trace, score_trace

__all__ = ["ClipResult", "run_seed", "run_seeds", "badness", "oracle_trace", "gaussian_mask_centroid"]


@dataclass
class ClipResult:
    """One clip's outcome: ``status`` is ``"pass"``, ``"fail"`` (a trace that misses a bar) or ``"error"``."""

    seed: int
    factors: dict[str, Any]
    status: str
    message: str = ""
    score: dict[str, Any] | None = None
    oracle: dict[str, Any] | None = None
    angle_crb_mrad: float | None = None
    render_s: float = 0.0
    track_s: float = 0.0
    n_frames: int = 0
    warnings: list[str] = field(default_factory=list)
    #: Balls the tracker moved from another light's highlight onto the others' (tracking/lobes.py).
    lobe_moves: list[int] = field(default_factory=list)


def run_seed(seed: int, folder: str | Path, long: bool = False, keep: bool = True, oracle: bool = True) -> ClipResult:
    """Render (or reuse) the clip of ``seed`` in ``folder``, track it and score the trace.

    With ``keep=False`` the video is deleted afterwards (a long 16-bit clip is up to 3.5 GB); the truth stays.
    With ``oracle=False`` the oracle and the Cramér-Rao bound are skipped (``None``): the tracker's score only.
    """
    spec = render_clip(seed, folder, long=long)
    try:
        return _track_and_score(spec, oracle)
    finally:
        if not keep:
            spec.video.unlink(missing_ok=True)


def _track_and_score(spec: ClipSpec, with_oracle: bool = True) -> ClipResult:
    from cageless.tracking.pipeline import TrackOptions, track_video

    seed = spec.seed
    factors = describe(spec.params)
    oracle = score_trace(oracle_trace(spec), spec.truth, spec.bearing).to_dict() if with_oracle else None
    crb = angle_crb_mrad(spec.params, n_frames=2) if with_oracle else None
    start = time.perf_counter()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            res = track_video(spec.video, spec.conditions, spec.bearing, TrackOptions(threads=1), progress=False)
        except CagelessError as exc:
            return ClipResult(seed, factors, "error", str(exc).splitlines()[0][:300], oracle=oracle,
                              angle_crb_mrad=crb, render_s=spec.render_s,
                              track_s=time.perf_counter() - start, n_frames=spec.n_frames,
                              warnings=_messages(caught))
    track_s = time.perf_counter() - start
    score: Score = score_trace(res.trace, spec.truth, spec.bearing)
    return ClipResult(seed, factors, "pass" if score.passed else "fail", "; ".join(score.failures),
                      score=score.to_dict(), oracle=oracle, angle_crb_mrad=crb, render_s=spec.render_s,
                      track_s=track_s,
                      n_frames=spec.n_frames,
                      warnings=_messages(caught),
                      lobe_moves=list(res.qc.selection.get("balls_moved_to_common_lobe", [])))


def _messages(caught: list[Any]) -> list[str]:
    out = []
    for w in caught:
        text = str(w.message).splitlines()[0][:200]
        if text not in out:
            out.append(text)
    return out


def _run(args: tuple[int, str, bool, bool, bool]) -> ClipResult:
    logging.disable(logging.WARNING)
    return run_seed(*args)


def run_seeds(seeds: Sequence[int], folder: str | Path, workers: int = 2, long: bool = False,
              progress: bool = True, keep: bool = True, oracle: bool = True) -> list[ClipResult]:
    """:func:`run_seed` over ``seeds`` in ``workers`` spawned processes; results in the order of ``seeds``."""
    jobs = [(int(s), str(folder), long, keep, oracle) for s in seeds]
    if workers <= 1:
        return [_run(j) for j in tqdm(jobs, desc="clips", disable=not progress)]
    with ProcessPoolExecutor(max_workers=workers, mp_context=get_context("spawn")) as pool:
        return list(tqdm(pool.map(_run, jobs), total=len(jobs), desc="clips", disable=not progress))


def badness(r: ClipResult) -> float:
    """How far a clip is from passing: errors and wrong ball counts first, then the worst bar ratio."""
    if r.status == "error" or r.score is None:
        return 1e9
    s = r.score
    if s["n_found"] != s["n_balls"]:
        return 1e6 + abs(s["n_found"] - s["n_balls"])
    ratios = [s["swaps"] / 1.0 * 10 if s["swaps"] else 0.0]
    ratios += [s[k] / BARS[k] for k in ("angle_rms_mrad", "speed_rms_pct", "slip_mae_pp")]
    return max(ratios)


def oracle_trace(spec: ClipSpec) -> Trace:
    """What a plain spot estimator that knows where to look gets from the rendered frames.

    For every frame and ball it takes the iterated Gaussian-mask centroid (Thompson, Larson & Webb,
    Biophys. J. 82 (2002) 2775, eq. 6: ``x = sum x I w / sum I w`` with ``w`` a Gaussian of the spot's
    width centred at the current estimate, repeated to its fixed point) of the frame minus the local
    background, started at the true highlight position; hot pixels (bright in every one of 16 frames
    spread over the clip) are masked and highlights the truth marks hidden (dark frames) skipped. A position
    off its ball's path (a glint or lint speck crossing the highlight) is dropped as any tracker drops it:
    more than 5 robust standard deviations (and 0.1 px) from the running median of 7 frames. Then it
    does what :func:`~cageless.tracking.synthetic.score.ideal_trace` does (one circle fit, angles, the
    tracker's speed filter).

    Its fixed point is the centre of any centrally symmetric spot (a saturated plateau, an elongated
    or motion-blurred lobe) whatever the constant background under it, so unlike a thresholded centroid
    it does not lock to pixel centres as a thresholded centroid does (the upper-half centroid used before
    erred by 0.6 mrad RMS on noise-free renders of seeds 1000 and 1020). A saturated spot still locks a
    little (its plateau edge is sampled by few pixels): 0.03 px on a 4x saturated 1.2 px spot, a quarter
    of the thresholded centroid's error. Where it passes, the pixels
    (noise, saturation, JPEG, blur, glints, dust and vignetting included) support the bars; where it
    fails, a detector must do better than a plain estimator, or the clip cannot be tracked to the bars
    (compare :func:`~cageless.tracking.synthetic.crb.angle_crb_mrad`).
    """
    from cageless.tracking.io import open_video

    p = spec.params
    t = spec.truth.sort_values(["frame", "ball"], kind="stable")
    z = p.n_balls
    hu = t.highlight_u_px.to_numpy().reshape(-1, z)
    hv = t.highlight_v_px.to_numpy().reshape(-1, z)
    vis = t.highlight_visible.to_numpy().reshape(-1, z)
    ball_px = p.geometry.ball_diameter_m * 1e3 * p.px_per_mm
    # The lobe's half-width across is 2 sigma R = sigma D px (scene3d); a saturated lobe is flat out to
    # sqrt(2 ln peak) of them, and the mask spans that plateau too (at least 1 px).
    flat = math.sqrt(2 * math.log(p.highlight_peak)) if p.highlight_peak > 1 else 0.0
    # At most a tenth of the ball: the mask (3 widths) stays on the ball, off the ring faces around it.
    s_px = max(1.0, min(p.highlight_sigma * ball_px * (1.0 + flat), 0.1 * ball_px))
    u = np.full(hu.shape, np.nan)
    v = np.full(hu.shape, np.nan)
    with open_video(spec.video, fps=spec.conditions.fps) as video:
        picks = np.linspace(0, len(video) - 1, min(16, len(video))).astype(int)
        low = np.min(np.stack([video[int(i)] for i in picks]), axis=0)
        stuck = low >= 0.9 * ((1 << p.bit_depth) - 1)  # hot pixels: bright in every sampled frame
        for start, chunk in video.iter_chunks(64):
            for k, frame in enumerate(chunk):
                i = start + k
                for j in np.flatnonzero(vis[i]):
                    u[i, j], v[i, j] = gaussian_mask_centroid(frame, hu[i, j], hv[i, j], s_px, stuck)
    _drop_outliers(u, v)
    for arr in (u, v):  # fill hidden highlights and outliers by interpolation in time, per ball
        for j in range(z):
            ok = np.isfinite(arr[:, j])
            if ok.any():
                arr[:, j] = np.interp(np.arange(len(arr)), np.flatnonzero(ok), arr[ok, j])
    oracle = t.copy()
    oracle["highlight_u_px"], oracle["highlight_v_px"] = u.ravel(), v.ravel()
    return ideal_trace(p, oracle)


def gaussian_mask_centroid(frame: np.ndarray, u0: float, v0: float, s: float, bad: np.ndarray | None = None,
                           n_iter: int = 20, tol: float = 1e-4) -> tuple[float, float]:
    """Iterated Gaussian-mask centroid of the spot near (u0, v0) (px), mask width ``s`` px.

    Within 3 ``s`` of the estimate, ``I`` is the frame minus the median of the ring 3-4 ``s`` out
    (the local background), clipped at 0; pixels flagged in ``bad`` get no weight. NaN when the mask leaves the image,
    holds no signal or runs more than 6 ``s`` away.
    """
    h = int(np.ceil(4 * s)) + 2
    u, v = float(u0), float(v0)
    for _ in range(n_iter):
        r0, c0 = int(round(v)) - h, int(round(u)) - h
        r1, c1 = min(r0 + 2 * h + 1, frame.shape[0]), min(c0 + 2 * h + 1, frame.shape[1])
        r0, c0 = max(r0, 0), max(c0, 0)
        if min(v, u) < 3 * s or v > frame.shape[0] - 1 - 3 * s or u > frame.shape[1] - 1 - 3 * s:
            return np.nan, np.nan  # the mask would leave the image
        win = frame[r0:r1, c0:c1].astype(np.float64)
        vv, uu = np.mgrid[r0:r1, c0:c1]
        d2 = (uu - u) ** 2 + (vv - v) ** 2
        ok = np.ones(win.shape, bool) if bad is None else ~bad[r0:r1, c0:c1]
        ring = ok & (d2 >= (3 * s) ** 2) & (d2 < (4 * s) ** 2)
        base = float(np.median(win[ring])) if ring.any() else float(np.percentile(win, 20))
        w = np.exp(-0.5 * d2 / s**2) * (ok & (d2 < (3 * s) ** 2)) * np.clip(win - base, 0, None)
        total = w.sum()
        if not total > 0:
            return np.nan, np.nan
        un, vn = float((w * uu).sum() / total), float((w * vv).sum() / total)
        if math.hypot(un - u0, vn - v0) > 6 * s:  # ran off to something else
            return np.nan, np.nan
        done = math.hypot(un - u, vn - v) < tol
        u, v = un, vn
        if done:
            break
    return u, v


def _drop_outliers(u: np.ndarray, v: np.ndarray, k: float = 5.0, half: int = 3) -> None:
    """Set to NaN, in place, the (frame, ball) positions farther than ``k`` robust standard deviations (at
    least 0.1 px) from the running median of ``2 half + 1`` frames of their ball."""
    from scipy.ndimage import median_filter

    for j in range(u.shape[1]):
        ok = np.isfinite(u[:, j]) & np.isfinite(v[:, j])
        if ok.sum() < 2 * half + 2:
            continue
        idx = np.flatnonzero(ok)
        du = u[idx, j] - median_filter(u[idx, j], size=2 * half + 1, mode="nearest")
        dv = v[idx, j] - median_filter(v[idx, j], size=2 * half + 1, mode="nearest")
        d = np.hypot(du, dv)
        limit = max(k * 1.4826 * float(np.median(d)), 0.1)
        bad = idx[d > limit]
        u[bad, j] = np.nan
        v[bad, j] = np.nan
