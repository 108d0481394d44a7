"""What tracking accuracy costs in time: the study behind ``cageless bench tracking``.

On full-size rendered footage (1280 x 800 px at 12.5 px/mm, 10,000 fps, 12-bit
data in 16-bit cine words, read from the page cache) it measures:

* end-to-end frames/s of :func:`cageless.tracking.pipeline.track_video` with both cores,
  with the input hash cached (re-runs) and on a first run (hashing included,
  estimated as the slower of tracking and hashing, which overlap);
* per detector (``mask`` / ``weighted`` / ``window``): frames/s, the RMS
  highlight-centroid error against the truth, and its ratio to the Cramér-Rao
  bound (:mod:`cageless.tracking.synthetic.crb`);
* per Savitzky-Golay window: the RMS revolution-speed error against the
  truth's instantaneous speed (a central difference of the noise-free truth
  angles), in % of the cage speed;
* trackpy ``locate`` + ``link`` on a subset of the same frames (cropped to the
  bearing, which only helps trackpy), with its centroid error, and the ratio of
  our throughput to trackpy's;
* peak resident memory of a tracking run in a fresh process.
"""

from __future__ import annotations

import math
import subprocess
import sys
import time
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from cageless.bearing import default_bearing
from cageless.conditions import OperatingConditions
from cageless.kinematics import theoretical_cage_speed
from cageless.provenance import hash_file
from cageless.tracking.detect import DETECTORS, DetectorParams
from cageless.tracking.io import open_video
from cageless.tracking.kinematics import revolution_speed
from cageless.tracking.pipeline import INPUT_HASH, TrackOptions, track_video
from cageless.tracking.synthetic.camera import Appearance, Camera
from cageless.tracking.synthetic.clip import render_clip
from cageless.tracking.synthetic.crb import position_crb
from cageless.tracking.synthetic.motion import KinematicLaw
from cageless.tracking.synthetic.render import Renderer

__all__ = ["prepare_footage", "run_benchmark", "format_tables"]

SPEED_RPM = 3000.0
CAMERA = Camera(width=1280, height=800, px_per_mm=12.5, bit_depth=12, centre_offset_px=(25.0, -12.0))
LOOK = Appearance(highlight_peak=0.85, dropout_rate=0.002)


def prepare_footage(folder: Path, n_frames: int, seed: int = 9, workers: int = 2) -> tuple[Path, pd.DataFrame]:
    """Render (or reuse) the benchmark clip; return its path and ground truth."""
    video = folder / f"bench_{n_frames}_{seed}.cine"
    truth_csv = folder / f"bench_{n_frames}_{seed}.truth.csv"
    if not (video.is_file() and truth_csv.is_file()):
        g = default_bearing().geometry
        render_clip(video, Renderer(g, CAMERA, LOOK, seed=seed), n_frames, law=KinematicLaw(g, SPEED_RPM, seed=seed),
                    fmt="cine-16", workers=workers, progress=True)
    return video, pd.read_csv(truth_csv)


def _centroid_error(res: Any, truth: pd.DataFrame) -> tuple[float, float]:
    """RMS 2-D centroid error (px) of unsaturated, unclipped highlights, and its ratio to the RMS CRB."""
    z = res.trace.n_balls
    col = np.asarray(res.qc.ball_order)
    u = res.table.u_px.to_numpy().reshape(-1, z)[:, col]
    v = res.table.v_px.to_numpy().reshape(-1, z)[:, col]
    return _error_vs_truth(u, v, truth)


def _error_vs_truth(u: np.ndarray, v: np.ndarray, truth: pd.DataFrame) -> tuple[float, float]:
    z = u.shape[1]
    hu, hv = (truth[c].to_numpy().reshape(-1, z)[: len(u)] for c in ("highlight_u_px", "highlight_v_px"))
    peak = truth.highlight_peak.to_numpy().reshape(-1, z)[: len(u)]
    g = default_bearing().geometry
    sigma = LOOK.highlight_sigma * g.ball_diameter_m * CAMERA.px_per_m
    cx, cy = CAMERA.centre_px
    rad = np.hypot(hu - cx, hv - cy) / CAMERA.px_per_m
    rp, d = 0.5 * g.pitch_diameter_m, g.ball_diameter_m
    margin = 4 * sigma / CAMERA.px_per_m
    use = (peak > 0.2) & (peak * (1 + LOOK.flicker_amplitude) < 0.97) & np.isfinite(u)
    use &= (rad > rp - 0.3 * d + margin) & (rad < rp + 0.3 * d - margin)
    err2 = ((u - hu) ** 2 + (v - hv) ** 2)[use]
    crb = [position_crb(p * CAMERA.full_well_e, sigma, LOOK.ball_level * CAMERA.full_well_e, CAMERA.read_noise_e,
                        CAMERA.full_well_e / CAMERA.max_dn) for p in peak[use][::7]]
    rms = math.sqrt(err2.mean())
    return rms, rms / math.sqrt(np.mean(crb))


def _time_track(video: Path, options: TrackOptions, repeats: int) -> tuple[float, Any]:
    """Best wall time of ``repeats`` tracking runs, after one untimed run that loads the compiled kernels these
    options use (the process's first run of them also pays that, which is no part of the tracker's speed)."""
    cond = OperatingConditions(SPEED_RPM, 500.0)
    res = track_video(video, cond, default_bearing(), options, progress=False)
    best = np.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        res = track_video(video, cond, default_bearing(), options, progress=False)
        best = min(best, time.perf_counter() - t0)
    return best, res


def _trackpy(video: Path, truth: pd.DataFrame, n: int) -> dict[str, float]:
    import trackpy as tp

    tp.quiet()
    with open_video(video) as v:
        frames = [v[i][60:740, 300:990].astype(np.float64) for i in range(n)]
    g = default_bearing().geometry
    sigma = LOOK.highlight_sigma * g.ball_diameter_m * CAMERA.px_per_m
    diameter = int(2 * math.ceil(2.5 * sigma) + 1)
    t0 = time.perf_counter()
    feats = tp.batch(frames, diameter, minmass=2e5, separation=2 * diameter, engine="numba", processes=1)
    linked = tp.link(feats, search_range=diameter, memory=3)
    elapsed = time.perf_counter() - t0
    z = g.n_balls
    hu = truth.highlight_u_px.to_numpy().reshape(-1, z)[:n] - 300
    hv = truth.highlight_v_px.to_numpy().reshape(-1, z)[:n] - 60
    u = np.full((n, z), np.nan)
    v = np.full((n, z), np.nan)
    for row in linked.itertuples():
        d = np.hypot(hu[row.frame] - row.x, hv[row.frame] - row.y)
        j = int(np.argmin(d))
        if d[j] < 3.0:
            u[row.frame, j], v[row.frame, j] = row.x, row.y
    rms, ratio = _error_vs_truth(u + 300, v + 60, truth)
    return {"fps": n / elapsed, "centroid_rms_px": rms, "crb_ratio": ratio, "frames": n}


def _peak_memory(video: Path) -> float:
    code = (
        "import resource; from cageless.bearing import default_bearing; "
        "from cageless.conditions import OperatingConditions; from cageless.tracking.pipeline import track_video; "
        f"track_video(r'{video}', OperatingConditions({SPEED_RPM}, 500.0), default_bearing(), progress=False); "
        "print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    return int(out.stdout.strip().splitlines()[-1]) / 1024.0  # MiB


def run_benchmark(folder: Path, n_frames: int = 2400, repeats: int = 3, trackpy_frames: int = 100) -> dict[str, Any]:
    """Run every measurement; returns JSON-ready tables."""
    video, truth = prepare_footage(folder, n_frames)
    hash_file(video, INPUT_HASH)  # warm the page cache and the hash cache
    t_cached, res = _time_track(video, TrackOptions(), repeats)
    z = res.trace.n_balls
    ta = truth.angle_rad.to_numpy().reshape(-1, z)
    tt = truth.time_s.to_numpy().reshape(-1, z)[:, 0]
    out: dict[str, Any] = {"frames": n_frames, "end_to_end": {
        "fps_hash_cached": n_frames / t_cached,
        "angle_rms_mrad": 1e3 * math.sqrt(np.mean((res.trace.angle - ta) ** 2)),
    }}
    t1, _ = _time_track(video, TrackOptions(threads=1), repeats)
    out["end_to_end"]["fps_one_thread"] = n_frames / t1
    sha_s = min(_timed(lambda: hash_file(video, INPUT_HASH, cache=False)) for _ in range(2))
    out["end_to_end"]["hash_s"] = sha_s
    out["end_to_end"]["hash_algorithm"] = INPUT_HASH
    out["end_to_end"]["fps_first_run_estimate"] = n_frames / max(t_cached, sha_s)
    rows = []
    sub = min(n_frames, 600)
    sub_video = video if sub == n_frames else prepare_footage(folder, sub)[0]
    sub_truth = truth if sub == n_frames else prepare_footage(folder, sub)[1]
    hash_file(sub_video, INPUT_HASH)
    for method in DETECTORS:
        opts = TrackOptions(detector=replace(DetectorParams(), method=method))
        t, r = _time_track(sub_video, opts, repeats)
        rms, ratio = _centroid_error(r, sub_truth)
        rows.append({"detector": method, "fps": sub / t, "centroid_rms_px": rms, "crb_ratio": ratio})
    out["detectors"] = rows
    omega_c = theoretical_cage_speed(default_bearing().geometry, OperatingConditions(SPEED_RPM).speed_rad_s)
    exact = np.gradient(ta, tt, axis=0)
    sg_rows = []
    for window in [w for w in (5, 11, 21, 41, 81) if 3 * w < n_frames]:
        t0 = time.perf_counter()
        speed = revolution_speed(res.trace.time, res.trace.angle, window)
        dt = time.perf_counter() - t0
        err = 100 * math.sqrt(np.mean((speed - exact)[window:-window] ** 2)) / omega_c
        noise = 100 * math.sqrt(np.mean((speed - revolution_speed(tt, ta, window))[window:-window] ** 2)) / omega_c
        sg_rows.append({"window": window, "speed_rms_pct_vs_instantaneous": err, "noise_pct": noise,
                        "ms_per_1000_frames": 1e3 * dt / n_frames * 1000})
    out["smoothing"] = sg_rows
    try:
        tpy = _trackpy(video, truth, min(trackpy_frames, n_frames))
        tpy["throughput_ratio"] = out["end_to_end"]["fps_hash_cached"] / tpy["fps"]
        out["trackpy"] = tpy
    except ImportError:
        out["trackpy"] = {"error": "trackpy is not installed: pip install 'cageless[bench]'"}
    out["peak_memory_mib"] = _peak_memory(video)
    return out


def _timed(fn: Any) -> float:
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


def format_tables(r: dict[str, Any]) -> str:
    """Plain-text tables of :func:`run_benchmark`'s result."""
    e = r["end_to_end"]
    lines = [
        f"Tracking, 1280x800 16-bit cine from the page cache, {r['frames']} frames at 3000 rpm (both cores)",
        f"  end to end, input hash cached : {e['fps_hash_cached']:8.0f} frames/s   (one thread: {e['fps_one_thread']:.0f})",
        f"  first run, hashing included    : {e['fps_first_run_estimate']:8.0f} frames/s   ({e['hash_algorithm']} of the file: {e['hash_s']:.2f} s)",
        f"  orbital-angle RMS error        : {e['angle_rms_mrad']:8.4f} mrad",
        f"  peak memory (fresh process)    : {r['peak_memory_mib']:8.0f} MiB",
        "",
        "Detector          frames/s  centroid RMS (px)  x Cramér-Rao",
    ]
    for d in r["detectors"]:
        lines.append(f"  {d['detector']:<14}{d['fps']:9.0f}{d['centroid_rms_px']:19.4f}{d['crb_ratio']:14.2f}")
    tpy = r["trackpy"]
    if "fps" in tpy:
        lines.append(f"  {'trackpy':<14}{tpy['fps']:9.1f}{tpy['centroid_rms_px']:19.4f}{tpy['crb_ratio']:14.2f}"
                     f"   (locate+link, {tpy['frames']} frames; ours is {tpy['throughput_ratio']:.0f}x faster)")
    else:
        lines.append(f"  trackpy: {tpy['error']}")
    lines += ["", "SG window (frames)  speed RMS vs instantaneous (% of cage)  noise only (%)  ms/1000 frames"]
    for s in r["smoothing"]:
        lines.append(f"  {s['window']:>6}{s['speed_rms_pct_vs_instantaneous']:>24.3f}{s['noise_pct']:>28.4f}"
                     f"{s['ms_per_1000_frames']:>16.2f}")
    return "\n".join(lines)
