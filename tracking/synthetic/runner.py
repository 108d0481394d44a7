"""Run the current tracker over corpus clips and score it: what the matrix test and the benchmark share.

Public API::

    run_seed(seed: int, folder: Path, long: bool = False) -> ClipResult
    run_seeds(seeds, folder, workers=2, long=False, progress=True) -> list[ClipResult]

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
from cageless.tracking.synthetic.score import BARS, Score, ideal_trace, score_trace

__all__ = ["ClipResult", "run_seed", "run_seeds", "badness", "oracle_trace"]


@dataclass
class ClipResult:
    """One clip's outcome: ``status`` is ``"pass"``, ``"fail"`` (a trace that misses a bar) or ``"error"``."""

    seed: int
    factors: dict[str, Any]
    status: str
    message: str = ""
    score: dict[str, Any] | None = None
    oracle: dict[str, Any] | None = None
    render_s: float = 0.0
    track_s: float = 0.0
    n_frames: int = 0
    warnings: list[str] = field(default_factory=list)


def run_seed(seed: int, folder: str | Path, long: bool = False, keep: bool = True) -> ClipResult:
    """Render (or reuse) the clip of ``seed`` in ``folder``, track it and score the trace.

    With ``keep=False`` the video is deleted afterwards (a long 16-bit clip is up to 3.5 GB); the truth stays.
    """
    spec = render_clip(seed, folder, long=long)
    try:
        return _track_and_score(spec)
    finally:
        if not keep:
            spec.video.unlink(missing_ok=True)


def _track_and_score(spec: ClipSpec) -> ClipResult:
    from cageless.tracking.pipeline import TrackOptions, track_video

    seed = spec.seed
    factors = describe(spec.params)
    oracle = score_trace(oracle_trace(spec), spec.truth, spec.bearing).to_dict()
    start = time.perf_counter()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            res = track_video(spec.video, spec.conditions, spec.bearing, TrackOptions(threads=1), progress=False)
        except CagelessError as exc:
            return ClipResult(seed, factors, "error", str(exc).splitlines()[0][:300], oracle=oracle,
                              render_s=spec.render_s,
                              track_s=time.perf_counter() - start, n_frames=spec.n_frames,
                              warnings=_messages(caught))
    track_s = time.perf_counter() - start
    score: Score = score_trace(res.trace, spec.truth, spec.bearing)
    return ClipResult(seed, factors, "pass" if score.passed else "fail", "; ".join(score.failures),
                      score=score.to_dict(), oracle=oracle, render_s=spec.render_s, track_s=track_s,
                      n_frames=spec.n_frames,
                      warnings=_messages(caught))


def _messages(caught: list[Any]) -> list[str]:
    out = []
    for w in caught:
        text = str(w.message).splitlines()[0][:200]
        if text not in out:
            out.append(text)
    return out


def _run(args: tuple[int, str, bool, bool]) -> ClipResult:
    logging.disable(logging.WARNING)
    return run_seed(*args)


def run_seeds(seeds: Sequence[int], folder: str | Path, workers: int = 2, long: bool = False,
              progress: bool = True, keep: bool = True) -> list[ClipResult]:
    """:func:`run_seed` over ``seeds`` in ``workers`` spawned processes; results in the order of ``seeds``."""
    jobs = [(int(s), str(folder), long, keep) for s in seeds]
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
    """What a plain centroid detector that knows where to look gets from the rendered frames.

    For every frame and ball it takes the intensity-weighted centroid of the upper half of the peak (above
    halfway from the window's 10th percentile to its maximum) within a window that holds the lobe's
    saturated top and two half-widths beyond it, around the true highlight position (only the connected blob
    nearest it) and inside the (blurred) ball (hot pixels, bright in every one of 16 frames spread over the
    clip, masked), skips highlights the truth marks hidden (dark frames), and then does what
    :func:`~cageless.tracking.synthetic.score.ideal_trace` does (one circle fit, angles, the tracker's speed filter).
    Where it passes, the pixels (noise, saturation, JPEG, blur, glints and dust included), not only the
    geometry, support the bars; where it fails, a detector must do better than a plain centroid.
    """
    from cageless.tracking.io import open_video

    p = spec.params
    t = spec.truth.sort_values(["frame", "ball"], kind="stable")
    z = p.n_balls
    hu = t.highlight_u_px.to_numpy().reshape(-1, z)
    hv = t.highlight_v_px.to_numpy().reshape(-1, z)
    vis = t.highlight_visible.to_numpy().reshape(-1, z)
    cu = t.centre_u_px.to_numpy().reshape(-1, z)
    cv = t.centre_v_px.to_numpy().reshape(-1, z)
    ball_px = p.geometry.ball_diameter_m * 1e3 * p.px_per_mm
    g = p.geometry
    blur = 0.5 * p.speed_rpm * math.pi / 30 * p.exposure_s * 0.5 * g.pitch_diameter_m * 1e3 * p.px_per_mm
    r_in = 0.5 * ball_px + 0.5 * blur
    # The lobe's half-widths are sigma D across and sigma D elongation along; a saturated one is flat out to
    # sqrt(2 ln peak) of them. The window holds the flat top and two half-widths beyond it.
    flat = math.sqrt(2 * math.log(max(p.highlight_peak, 1.0)))
    half = max(3.0, (2.0 + flat) * p.highlight_sigma * ball_px * p.elongation + 1.0)
    u = np.full(hu.shape, np.nan)
    v = np.full(hu.shape, np.nan)
    with open_video(spec.video, fps=spec.conditions.fps) as video:
        picks = np.linspace(0, len(video) - 1, min(16, len(video))).astype(int)
        low = np.min(np.stack([video[int(i)] for i in picks]), axis=0)
        stuck = low >= 0.9 * ((1 << p.bit_depth) - 1)  # hot pixels: bright in every sampled frame
        for start, chunk in video.iter_chunks(64):
            for k, frame in enumerate(chunk):
                i = start + k
                frame = np.where(stuck, 0, frame)
                for j in np.flatnonzero(vis[i]):
                    u[i, j], v[i, j] = _centroid(frame, hu[i, j], hv[i, j], half, cu[i, j], cv[i, j], r_in)
    for arr in (u, v):  # fill hidden highlights by interpolation in time, per ball
        for j in range(z):
            ok = np.isfinite(arr[:, j])
            if ok.any():
                arr[:, j] = np.interp(np.arange(len(arr)), np.flatnonzero(ok), arr[ok, j])
    oracle = t.copy()
    oracle["highlight_u_px"], oracle["highlight_v_px"] = u.ravel(), v.ravel()
    return ideal_trace(p, oracle)


def _centroid(frame: np.ndarray, u0: float, v0: float, half: float, uc: float, vc: float,
              r_in: float) -> tuple[float, float]:
    """Centroid of the peak's upper half within ``half`` px of (u0, v0) and ``r_in`` px of the ball centre."""
    h = int(np.ceil(half))
    r0, c0 = int(round(v0)) - h, int(round(u0)) - h
    r1, c1 = r0 + 2 * h + 1, c0 + 2 * h + 1
    if r0 < 0 or c0 < 0 or r1 > frame.shape[0] or c1 > frame.shape[1]:
        return np.nan, np.nan
    win = frame[r0:r1, c0:c1].astype(np.float64)
    vv, uu = np.mgrid[r0:r1, c0:c1]
    inside = (np.hypot(uu - u0, vv - v0) <= half) & (np.hypot(uu - uc, vv - vc) <= r_in)
    base = max(0.0, float(np.percentile(win[inside], 10)))
    w = np.clip(win - (base + 0.5 * (win[inside].max() - base)), 0, None) * inside  # the peak's upper half
    n, labels = cv2.connectedComponents((w > 0).astype(np.uint8), connectivity=8)
    if n > 2:  # keep the blob nearest the true highlight (not a bright ring face at the window's edge)
        ys, xs = np.nonzero(labels)
        k = int(np.argmin(np.hypot(xs + c0 - u0, ys + r0 - v0)))
        w = w * (labels == labels[ys[k], xs[k]])
    total = w.sum()
    if total <= 0:
        return np.nan, np.nan
    return float((w * uu).sum() / total), float((w * vv).sum() / total)
