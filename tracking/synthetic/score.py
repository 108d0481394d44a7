"""Score a tracker's trace against a corpus clip's ground truth.

Public API (stable)::

    score_trace(trace: Trace, truth: pd.DataFrame, bearing: Bearing, speed_rpm: float | None = None,
                window: int | None = None, polyorder: int | None = None, bin_deg: float = 1.0) -> Score
    ideal_trace(params: ClipParams, truth: pd.DataFrame, window: int = 21) -> Trace

What is measured (the bars of issue 14 are in :data:`BARS`):

* **balls**: the trace's ball count against Z;
* **matching**: track ids are matched to truth ids by the best cyclic shift
  (tracks and truth balls both in counter-clockwise order; Hungarian
  assignment on the median angular distance when the counts differ);
* **offset**: the constant angle between the trace and the truth common to all
  matched balls (a highlight sits off the ball centre at a light-fixed offset;
  the camera roll if the tracker was not told it), a circular mean, reported and
  removed;
* **swaps**: for every track, the number of frames at which the truth ball
  nearest to it (after the offset) changes: a perfect tracker has 0;
* **angle RMS** (mrad): of the wrapped difference to the matched ball, all samples;
* **speed RMS** (% of the pure-rolling cage speed ``omega_c``): against the
  truth angle differentiated by the same Savitzky-Golay filter the trace states
  it used (``config["tracking"]["window"]``, ``polyorder``), so the bar measures
  tracking, not the filter's bandwidth; the RMS against the instantaneous truth
  speed is reported beside it (``speed_rms_inst_pct``);
* **slip-profile MAE** (pp): 1 deg bins of :func:`cageless.profiles.angle_profile`
  over all matched balls, trace slip at (trace angle - offset) against the
  truth's slip from the same filtered speed at the truth angle, mean absolute
  difference over the bins both fill (``slip_mae_inst_pp`` against the
  instantaneous truth slip).
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np
import pandas as pd
from scipy.optimize import linear_sum_assignment

from cageless.bearing import Bearing
from cageless.kinematics import slip_rate, theoretical_cage_speed
from cageless.profiles import angle_profile
from cageless.trace import Trace, VideoInfo
from cageless.units import rpm_to_rad_s
from cageless.tracking.kinematics import DEFAULT_WINDOW, revolution_speed

__all__ = ["Score", "BARS", "score_trace", "ideal_trace", "truth_arrays", "wrap"]

#: Issue 14's bars on every clip.
BARS = {"swaps": 0, "angle_rms_mrad": 0.5, "speed_rms_pct": 0.5, "slip_mae_pp": 0.3}


def wrap(a: np.ndarray) -> np.ndarray:
    """Angles wrapped to [-pi, pi)."""
    return np.mod(np.asarray(a) + np.pi, 2 * np.pi) - np.pi


@dataclass
class Score:
    """How a trace compares with the truth (see the module docstring)."""

    n_balls: int
    n_found: int
    n_matched: int
    swaps: int
    offset_mrad: float
    angle_rms_mrad: float
    speed_rms_pct: float
    speed_rms_inst_pct: float
    slip_mae_pp: float
    slip_mae_inst_pp: float
    frames_matched: int
    failures: list[str] = field(default_factory=list)

    @property
    def passed(self) -> bool:
        """True when every bar holds."""
        return not self.failures

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready fields plus ``passed``."""
        return asdict(self) | {"passed": self.passed}


def truth_arrays(truth: pd.DataFrame) -> dict[str, np.ndarray]:
    """Truth as (T, Z) arrays: ``frame``, ``time``, ``angle``, ``speed``, ``visible``."""
    z = int(truth.ball.max()) + 1
    t = truth.sort_values(["frame", "ball"], kind="stable")

    def grid(col: str) -> np.ndarray:
        return t[col].to_numpy().reshape(-1, z)

    return {"frame": grid("frame")[:, 0], "time": grid("time_s")[:, 0], "angle": grid("angle_rad"),
            "speed": grid("speed_rad_s"), "visible": grid("highlight_visible").astype(bool)}


def _filter_of(trace: Trace, window: int | None, polyorder: int | None) -> tuple[int, int]:
    cfg = (trace.config or {}).get("tracking", {}) if isinstance(trace.config, dict) else {}
    return int(window or cfg.get("window", DEFAULT_WINDOW)), int(polyorder or cfg.get("polyorder", 2))


def _align_rows(trace: Trace, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Indices (trace rows, truth rows) of the frames both hold, matched by time stamp."""
    step = float(np.median(np.diff(times))) if len(times) > 1 else 1.0
    j = np.clip(np.searchsorted(times, trace.time), 0, len(times) - 1)
    j_lo = np.clip(j - 1, 0, len(times) - 1)
    j = np.where(np.abs(times[j_lo] - trace.time) < np.abs(times[j] - trace.time), j_lo, j)
    ok = np.abs(times[j] - trace.time) < 0.25 * step
    return np.flatnonzero(ok), j[ok]


def _match(a_trk: np.ndarray, a_tru: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Pairs (track column, truth column): the cyclic shift with the smallest mean angular distance when the
    counts agree, else a Hungarian assignment on the median angular distance. Both assume the trace's angles
    lie within half a ball pitch of the ball centres (a highlight offset is smaller than that)."""
    n, z = a_trk.shape[1], a_tru.shape[1]
    if n == z:
        order_trk = np.argsort(np.mod(np.nanmedian(a_trk[:5], axis=0), 2 * np.pi))
        order_tru = np.argsort(np.mod(a_tru[0], 2 * np.pi))

        def cost(m: int) -> float:
            return float(np.nanmean(np.abs(wrap(a_trk[:, order_trk] - a_tru[:, np.roll(order_tru, -m)]))))

        best = min(range(z), key=cost)
        return order_trk, np.roll(order_tru, -best)
    cost_m = np.stack([np.nanmedian(np.abs(wrap(a_trk[:, j, None] - a_tru)), axis=0) for j in range(n)])
    rows, cols = linear_sum_assignment(np.nan_to_num(cost_m, nan=1e9))
    return rows, cols


def _circmean(a: np.ndarray) -> float:
    a = a[np.isfinite(a)]
    return float(np.arctan2(np.mean(np.sin(a)), np.mean(np.cos(a)))) if a.size else 0.0


def score_trace(trace: Trace, truth: pd.DataFrame, bearing: Bearing, speed_rpm: float | None = None,
                window: int | None = None, polyorder: int | None = None, bin_deg: float = 1.0) -> Score:
    """Score ``trace`` against the clip's ``truth`` (see the module docstring)."""
    tr = truth_arrays(truth)
    z = tr["angle"].shape[1]
    omega_c = theoretical_cage_speed(bearing.geometry, rpm_to_rad_s(speed_rpm or trace.speed_rpm))
    rows, trows = _align_rows(trace, tr["time"])
    a_trk, a_tru = trace.angle[rows], tr["angle"][trows]
    ci, ti = _match(a_trk, a_tru)
    diff = wrap(a_trk[:, ci] - a_tru[:, ti])
    offset = _circmean(diff.ravel())
    err = wrap(diff - offset)
    angle_rms = float(np.sqrt(np.nanmean(err**2))) if err.size else math.nan
    swaps = _swaps(a_trk[:, ci] - offset, a_tru, ti)
    win, poly = _filter_of(trace, window, polyorder)
    ref = revolution_speed(tr["time"], tr["angle"], win, poly)
    sp_trk = trace.speed[rows][:, ci]
    speed_rms = float(np.sqrt(np.nanmean((sp_trk - ref[trows][:, ti]) ** 2))) / omega_c * 100
    speed_inst = float(np.sqrt(np.nanmean((sp_trk - tr["speed"][trows][:, ti]) ** 2))) / omega_c * 100
    slip_trk = trace.slip[rows][:, ci]
    prof = angle_profile(a_trk[:, ci] - offset, slip_trk, bin_deg)
    mae = _profile_mae(prof, angle_profile(a_tru[:, ti], slip_rate(ref[trows][:, ti], omega_c), bin_deg))
    mae_inst = _profile_mae(prof, angle_profile(a_tru[:, ti], slip_rate(tr["speed"][trows][:, ti], omega_c), bin_deg))
    score = Score(n_balls=z, n_found=int(trace.n_balls), n_matched=len(ci), swaps=swaps, offset_mrad=1e3 * offset,
                  angle_rms_mrad=1e3 * angle_rms, speed_rms_pct=speed_rms, speed_rms_inst_pct=speed_inst,
                  slip_mae_pp=mae, slip_mae_inst_pp=mae_inst, frames_matched=len(rows))
    score.failures = _failures(score, len(tr["time"]))
    return score


def _profile_mae(a: pd.DataFrame, b: pd.DataFrame) -> float:
    both = (a["count"] > 0) & (b["count"] > 0)
    if not both.any():
        return math.nan
    return float(np.mean(np.abs(a["mean"][both] - b["mean"][both]))) * 100


def _swaps(a_trk: np.ndarray, a_tru: np.ndarray, assigned: np.ndarray) -> int:
    """Frames at which a track's nearest truth ball changes, summed over tracks; a track whose nearest ball
    is never its assigned one counts once."""
    total = 0
    for j in range(a_trk.shape[1]):
        d = np.abs(wrap(a_trk[:, j, None] - a_tru))
        ok = np.isfinite(d).all(axis=1)
        near = np.argmin(np.where(np.isfinite(d), d, np.inf), axis=1)[ok]
        if near.size == 0:
            continue
        changes = int(np.count_nonzero(np.diff(near)))
        total += changes if changes else int(near[0] != assigned[j])
    return total


def _failures(s: Score, n_frames: int) -> list[str]:
    out = []
    if s.n_found != s.n_balls:
        out.append(f"found {s.n_found} balls, not {s.n_balls}")
    if s.frames_matched < n_frames:
        out.append(f"trace covers {s.frames_matched} of {n_frames} frames")
    if s.swaps > BARS["swaps"]:
        out.append(f"{s.swaps} identity swaps")
    for key, unit in (("angle_rms_mrad", "mrad"), ("speed_rms_pct", "% of cage speed"), ("slip_mae_pp", "pp")):
        v = getattr(s, key)
        if not (v <= BARS[key]):
            out.append(f"{key.removesuffix('_mrad').removesuffix('_pct').removesuffix('_pp')} {v:.3g} {unit} "
                       f"> {BARS[key]}")
    return out


def ideal_trace(params: Any, truth: pd.DataFrame, window: int = DEFAULT_WINDOW) -> Trace:
    """The trace a perfect highlight detector would give on a clip (its :class:`ClipParams` and truth).

    It takes the true (distorted) highlight pixel positions, fits one circle to all of them (algebraic
    least squares, Kasa 1976), measures each highlight's angle about it, undoes the mirror and the roll
    the conditions state, unwraps and differentiates with the tracker's Savitzky-Golay filter. Scoring
    it shows what the geometry alone (lens distortion, highlight offset, off-centre bearing) costs:
    a fair corpus lets it pass every bar.
    """
    t = truth.sort_values(["frame", "ball"], kind="stable")
    p = params
    z = p.n_balls
    u = t.highlight_u_px.to_numpy().reshape(-1, z)
    v = t.highlight_v_px.to_numpy().reshape(-1, z)
    times = t.time_s.to_numpy().reshape(-1, z)[:, 0]
    a_mat = np.column_stack([u.ravel(), v.ravel(), np.ones(u.size)])
    sol = np.linalg.lstsq(a_mat, -(u.ravel() ** 2 + v.ravel() ** 2), rcond=None)[0]
    cx, cy = -0.5 * sol[0], -0.5 * sol[1]
    ang = np.arctan2(-(v - cy), u - cx) - math.radians(p.roll_deg)
    if p.direction < 0:
        ang = math.pi - ang
    ang = np.unwrap(ang, axis=0)
    ang -= 2 * np.pi * np.round((ang[0] - t.angle_rad.to_numpy().reshape(-1, z)[0]) / (2 * np.pi))
    speed = revolution_speed(times, ang, window, 2)
    g = p.geometry
    omega_c = theoretical_cage_speed(g, rpm_to_rad_s(p.speed_rpm))
    return Trace(source="video", time=times, angle=ang, speed=speed, slip=slip_rate(speed, omega_c),
                 valid=np.ones_like(ang, bool), speed_rpm=p.speed_rpm, radial_load_n=p.radial_load_n,
                 axial_load_n=0.0, ball_diameter_m=g.ball_diameter_m, pitch_diameter_m=g.pitch_diameter_m,
                 direction=p.direction, config={"tracking": {"window": window, "polyorder": 2}},
                 video=VideoInfo(fps=p.fps, px_per_mm=p.px_per_mm, centre_px=(float(cx), float(cy)),
                                 camera_roll_rad=math.radians(p.roll_deg), input_file=f"seed {p.seed}",
                                 input_sha256=""))
