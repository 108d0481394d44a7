"""Align a measured (video) and a simulated trace.

Both traces become profiles against orbital angle: slip rate and revolution
speed per angle bin (1 deg by default), over all balls and per ball, each with
its spread (:func:`profiles`). A time-domain mode aligns the revolution speed of
one chosen ball by cross-correlation (:func:`align_time`).

Traces are comparable only when they describe the same bearing under the same
conditions; :func:`check_compatible` lists every difference, and the caller
refuses them unless forced (the report then shows the mismatch).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
import pandas as pd

from cageless.errors import CagelessError, ParameterError
from cageless.kinematics import startup_duration
from cageless.profiles import angle_profile
from cageless.trace import Trace

__all__ = ["Profiles", "profiles", "TimeAlignment", "align_time", "check_compatible", "MismatchError",
           "simulation_settle_s"]

_CONDITIONS = (("speed_rpm", "rpm"), ("radial_load_n", "N"), ("axial_load_n", "N"))
_GEOMETRY = (("n_balls", ""), ("ball_diameter_m", "m"), ("pitch_diameter_m", "m"))


def simulation_settle_s(trace: Trace) -> float:
    """The start-up a simulation trace's profiles leave out: three cage revolutions, at least 40 ms
    (:func:`cageless.kinematics.startup_duration`; the packed start takes that long to be forgotten)."""
    return startup_duration(trace.speed_rpm, trace.ball_diameter_m, trace.pitch_diameter_m)


class MismatchError(CagelessError):
    """The two traces describe different conditions or bearings."""


@dataclass(frozen=True)
class Profiles:
    """Slip and speed against orbital angle for one trace.

    ``slip`` and ``speed`` have the columns of :data:`cageless.profiles.PROFILE_COLUMNS` (over all
    balls); ``slip_per_ball`` is (n_bins, Z) of per-ball means (NaN where a ball never was).
    """

    slip: pd.DataFrame
    speed: pd.DataFrame
    slip_per_ball: npt.NDArray[np.float64]
    bin_deg: float


def profiles(trace: Trace, bin_deg: float = 1.0, settle_s: float = 0.0) -> Profiles:
    """Profiles of ``trace`` from its valid samples after ``settle_s`` seconds."""
    if not (math.isfinite(settle_s) and settle_s >= 0):
        raise ParameterError("settle_s", "must be a finite number >= 0", settle_s)
    keep = (trace.time >= trace.time[0] + settle_s)[:, None] & trace.valid
    if not keep.any():
        raise CagelessError(f"no valid samples after the first {settle_s:g} s of the {trace.source} trace "
                            f"({trace.time[-1] - trace.time[0]:.4g} s long). Simulate longer than the start-up left out (e.g. "
                            f"`cageless simulate --duration {settle_s + 0.1:.2g}`), or, to compare the start-up "
                            "itself, lower --settle.")
    slip = angle_profile(trace.angle, trace.slip, bin_deg, valid=keep)
    speed = angle_profile(trace.angle, trace.speed, bin_deg, valid=keep)
    per_ball = np.column_stack([
        angle_profile(trace.angle[:, j], trace.slip[:, j], bin_deg, valid=keep[:, j])["mean"].to_numpy()
        for j in range(trace.n_balls)])
    return Profiles(slip=slip, speed=speed, slip_per_ball=per_ball, bin_deg=bin_deg)


@dataclass(frozen=True)
class TimeAlignment:
    """The lag that best aligns the simulated speed of one ball with the measured one."""

    ball: int
    lag_s: float
    correlation: float


def align_time(measured: Trace, simulated: Trace, ball: int = 0, max_lag_s: float | None = None,
               min_overlap: float = 0.5) -> TimeAlignment:
    """Cross-correlate the revolution speed of ``ball`` in both traces.

    The simulated series is resampled onto the measured sampling interval. The returned lag is the
    shift (s) for which measured(t) best matches simulated(t + lag): the Pearson correlation of the
    overlapping parts, over every lag whose overlap keeps at least ``min_overlap`` of the measured
    series (and, with ``max_lag_s``, |lag| <= max_lag_s).
    """
    if not 0 <= ball < min(measured.n_balls, simulated.n_balls):
        raise ParameterError("ball", f"must lie in 0..{min(measured.n_balls, simulated.n_balls) - 1}", ball)
    dt = float(np.median(np.diff(measured.time)))
    a = _series(measured, ball)
    t_sim = measured.time[0] + dt * np.arange(
        math.floor((simulated.time[0] - measured.time[0]) / dt), math.ceil((simulated.time[-1] - measured.time[0]) / dt) + 1)
    t_sim = t_sim[(t_sim >= simulated.time[0] - 1e-12) & (t_sim <= simulated.time[-1] + 1e-12)]
    b = np.interp(t_sim, simulated.time, _series(simulated, ball))
    offset = int(round((t_sim[0] - measured.time[0]) / dt))  # b[i] is at measured index i + offset
    n = len(a)
    best = (-np.inf, 0)
    for k in range(-(n - 1), len(b) + offset):  # measured index i <-> simulated index i + k - offset
        i0, i1 = max(0, offset - k), min(n, len(b) + offset - k)
        if i1 - i0 < max(2, min_overlap * n) or (max_lag_s is not None and abs(k) * dt > max_lag_s):
            continue
        x, y = a[i0:i1], b[i0 + k - offset:i1 + k - offset]
        sx, sy = x.std(), y.std()
        if sx == 0 or sy == 0:
            continue
        r = float(np.mean((x - x.mean()) * (y - y.mean())) / (sx * sy))
        if r > best[0]:
            best = (r, k)
    if not np.isfinite(best[0]):
        raise CagelessError("the speed series do not overlap enough to align (or one is constant): "
                            "use longer traces or a larger max_lag_s.")
    return TimeAlignment(ball=ball, lag_s=float(best[1] * dt), correlation=best[0])


def _series(trace: Trace, ball: int) -> npt.NDArray[np.float64]:
    s = trace.speed[:, ball].astype(np.float64).copy()
    s[~trace.valid[:, ball]] = np.nan
    if np.isnan(s).any():
        good = ~np.isnan(s)
        s = np.interp(trace.time, trace.time[good], s[good]) if good.any() else np.zeros_like(s)
    return s


def check_compatible(measured: Trace, simulated: Trace, rel_tol: float = 1e-6) -> list[str]:
    """Every difference in conditions or bearing between the traces, in words (empty when they match)."""
    issues = []
    for name, unit in _CONDITIONS + _GEOMETRY:
        a, b = float(getattr(measured, name)), float(getattr(simulated, name))
        if not math.isclose(a, b, rel_tol=rel_tol, abs_tol=1e-12):
            issues.append(f"{name}: measured {a:g}{' ' + unit if unit else ''}, simulated {b:g}"
                          f"{' ' + unit if unit else ''}")
    return issues
