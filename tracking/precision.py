"""How precise a trace is, estimated from the trace alone (no ground truth).

Two views of the same highlight positions, each blind to the true motion:

* **Tangential noise.** Over a millisecond a ball moves along its circle at nearly constant speed, so its
  angle minus a robust local quadratic over :data:`NOISE_FRAMES` frames leaves the localisation error that
  changes faster than that span (and short kinks where balls collide). Its RMS, divided by ``sqrt(1 - h)``
  (``h`` the centre sample's leverage in that quadratic), is the per-sample noise ``sigma_t``: white noise
  added to a smooth track comes back as itself. The track fit (a quadratic over ``track_fit`` frames)
  passes ``sqrt(h_fit) sigma_t`` of it to the trace, and the speed filter ``sigma_t g / dt`` (``g`` the
  Savitzky-Golay slope gain, :func:`savgol_slope_gain`).
* **Radial scatter.** Every highlight travels one circle, so each frame's distances from the orbit centre,
  less that frame's own translation and radius (a least-squares ``r = r0 + dx cos + dy sin`` over the balls),
  are all error. A centroid pulled by a second lobe, a gradient or a saturated plateau is pulled sideways
  as well as along the circle, and slowly: the radial scatter sees drifts that no local fit can. It is
  smoothed by the same quadratic as the track fit (angle) or differentiated by the speed filter (speed),
  over the orbit radius.

The estimate is the two in quadrature times a gain (:data:`ANGLE_GAIN`, :data:`SPEED_GAIN`) measured on the
tuning corpus only (``benchmarks/tracking_precision.py --calibrate``, seeds 1000-1031 and 7600-7631): the median of the
scored error over the two views combined. It is a typical value, not a bound (an error that moves the
highlight exactly along the circle and slowly, or the same for every ball, is invisible to both); its
agreement with the truth on the held-out sets is in docs/tracking.md ("How precise a trace is").

Public API::

    angle_noise(time_s, angle, valid, frames=NOISE_FRAMES) -> (sigma_rad per ball, jump share per ball)
    radial_scatter(u_px, v_px, valid, centre_px, radius_px) -> (T, Z) radial residual over the radius
    assess_precision(time_s, angle, valid, u_px, v_px, centre_px, radius_px, omega_c, window, polyorder,
                     track_fit) -> Precision | None
    assess_table(table, order, time_s, angle, valid, centre_px, radius_px, omega_c, window, polyorder,
                 track_fit) -> Precision | None   (positions from the tracker's table)
    precision_warning(p, bars) -> str | None
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt
import pandas as pd

from cageless.tracking.kinematics import revolution_speed, robust_track_fit

__all__ = ["NOISE_FRAMES", "ANGLE_GAIN", "SPEED_GAIN", "JUMP_SIGMA", "Precision", "angle_noise", "radial_scatter",
           "assess_precision", "assess_table", "precision_warning", "savgol_slope_gain", "centre_leverage"]

#: Frames of the robust local quadratic that stands for each ball's motion (1.1 ms at 10 kfps).
NOISE_FRAMES = 11
#: Estimated angle RMS over the two views in quadrature: the median over the tuning seeds (TUNING 1000-1031 and
#: TUNING2 7600-7631, the 63 clips with a trace) of the scored angle RMS over that combination
#: (benchmarks/tracking_precision.py --calibrate, 2026-11-28, tracker of main 1f6ed9a, whose track fit's window
#: is chosen per clip: 1.24; TUNING alone 1.29, TUNING2 1.16; correlation with the truth 0.866, 0.808 of the
#: logarithms). Before, 1.11 (TUNING only, the 7-frame fit of main 9422302).
ANGLE_GAIN = 1.24
#: The same for the speed RMS (% of the cage speed): 0.86 (TUNING 0.84, TUNING2 0.88; correlation 0.897, 0.899
#: of the logarithms). Before, 0.93.
SPEED_GAIN = 0.86
#: A residual beyond this many robust standard deviations is a jump (a lobe switch, a glint, an impact kink).
JUMP_SIGMA = 5.0
#: Fewest balls measured in a frame for its own translation and radius to be fitted.
_MIN_BALLS = 5


@dataclass(frozen=True)
class Precision:
    """A trace's self-assessed precision.

    Attributes
    ----------
    angle_rms_mrad
        Estimated RMS error of the trace's orbital angles (mrad).
    speed_rms_pct
        Estimated RMS error of the speed, % of the pure-rolling cage speed (also the slip's, in pp).
    noise_mrad
        Per-sample tangential noise of the angles before the track fit, RMS over the balls (mrad).
    radial_mrad
        Radial scatter after the track fit's smoothing, over the orbit radius (mrad).
    worst_ball_noise_mrad
        The tangential noise of the noisiest ball (mrad).
    jump_share
        Share of samples more than :data:`JUMP_SIGMA` robust standard deviations off their ball's local
        quadratic: jumps between highlight lobes, glints crossing, collisions.
    """

    angle_rms_mrad: float
    speed_rms_pct: float
    noise_mrad: float
    radial_mrad: float
    worst_ball_noise_mrad: float
    jump_share: float

    def to_dict(self) -> dict[str, float]:
        """JSON-ready record for QC and the trace's attributes."""
        return {"angle_rms_mrad": round(self.angle_rms_mrad, 4), "speed_rms_pct": round(self.speed_rms_pct, 4),
                "noise_mrad": round(self.noise_mrad, 4), "radial_mrad": round(self.radial_mrad, 4),
                "worst_ball_noise_mrad": round(self.worst_ball_noise_mrad, 4), "jump_share": round(self.jump_share, 5),
                "angle_gain": ANGLE_GAIN, "speed_gain": SPEED_GAIN, "noise_frames": NOISE_FRAMES}


def centre_leverage(frames: int) -> float:
    """Leverage of the centre sample in a least-squares quadratic over ``frames`` equally spaced samples
    (1 for ``frames`` below 4: the sample itself)."""
    if frames < 4:
        return 1.0
    x = np.arange(frames, dtype=np.float64) - frames // 2
    design = np.stack([np.ones_like(x), x, x * x], axis=1)
    hat = design @ np.linalg.solve(design.T @ design, design.T)
    return float(hat[frames // 2, frames // 2])


def savgol_slope_gain(window: int, polyorder: int = 2) -> float:
    """Standard deviation of a Savitzky-Golay first derivative (per frame) of unit white noise.

    For a quadratic (or linear) fit the centre slope's coefficients are ``x / sum(x^2)``, so the gain is
    ``sqrt(12 / (N (N^2 - 1)))`` for ``N = window`` samples; computed here from the design for any order.
    """
    x = np.arange(window, dtype=np.float64) - window // 2
    design = np.stack([x**k for k in range(polyorder + 1)], axis=1)
    coef = np.linalg.solve(design.T @ design, design.T)[1]
    return float(np.sqrt(np.sum(coef**2)))


def angle_noise(time_s: npt.ArrayLike, angle: npt.ArrayLike, valid: npt.ArrayLike, frames: int = NOISE_FRAMES
                ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """Per-ball noise of the angles about their robust local quadratic, and each ball's share of jumps.

    Parameters
    ----------
    time_s
        Sample times (s), shape (T,).
    angle
        Unwrapped angles (rad), shape (T, Z).
    valid
        Measured (True) or interpolated (False) samples, shape (T, Z); only measured ones count.
    frames
        Odd window of the local quadratic (frames), at least 5.

    Returns
    -------
    sigma, jumps
        Per ball: the RMS residual over ``sqrt(1 - h)`` (rad; NaN for a ball with fewer than ``frames``
        measured samples) and the share of its measured samples beyond :data:`JUMP_SIGMA` robust standard
        deviations.
    """
    a = np.asarray(angle, dtype=np.float64)
    ok = np.asarray(valid, dtype=bool)
    fit, _ = robust_track_fit(time_s, a, ok, frames)
    res = a - fit
    z = a.shape[1]
    sigma = np.full(z, np.nan)
    jumps = np.zeros(z)
    scale = 1.0 / math.sqrt(1.0 - centre_leverage(frames))
    for j in range(z):
        r = res[ok[:, j], j]
        if r.size < frames:
            continue
        sigma[j] = scale * float(np.sqrt(np.mean(r * r)))
        robust = 1.4826 * float(np.median(np.abs(r)))
        jumps[j] = float(np.mean(np.abs(r) > JUMP_SIGMA * robust)) if robust > 0 else 0.0
    return sigma, jumps


def radial_scatter(u_px: npt.ArrayLike, v_px: npt.ArrayLike, valid: npt.ArrayLike, centre_px: tuple[float, float],
                   radius_px: float) -> npt.NDArray[np.float64]:
    """Each highlight's distance from the orbit centre less its frame's own radius and translation, over the radius.

    Per frame, ``r = r0 + dx cos(theta) + dy sin(theta)`` is fitted by least squares to the measured balls'
    distances ``r`` at angles ``theta``; the residual is what no common motion of the frame explains.

    Returns
    -------
    ndarray
        Shape (T, Z), dimensionless (rad of arc); NaN where the sample is not valid or its frame has fewer
        than 5 measured balls.
    """
    u = np.asarray(u_px, dtype=np.float64)
    v = np.asarray(v_px, dtype=np.float64)
    ok = np.asarray(valid, dtype=bool) & np.isfinite(u) & np.isfinite(v)
    du, dv = np.where(ok, u - centre_px[0], 0.0), np.where(ok, v - centre_px[1], 0.0)
    r = np.hypot(du, dv)
    theta = np.arctan2(-dv, du)
    design = np.stack([np.ones_like(theta), np.cos(theta), np.sin(theta)], axis=-1) * ok[..., None]
    lhs = np.einsum("tzp,tzq->tpq", design, design) + 1e-9 * np.eye(3)
    coef = np.linalg.solve(lhs, np.einsum("tzp,tz->tp", design, r)[..., None])[..., 0]
    res = (r - np.einsum("tzp,tp->tz", design, coef)) / radius_px
    res[~ok | (ok.sum(axis=1) < _MIN_BALLS)[:, None]] = np.nan
    return res


def _filled(t: np.ndarray, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Columns of ``x`` with NaNs interpolated in time, and the columns that had at least 2 values."""
    out = np.zeros_like(x)
    usable = np.zeros(x.shape[1], dtype=bool)
    for j in range(x.shape[1]):
        ok = np.isfinite(x[:, j])
        if ok.sum() >= 2:
            out[:, j] = np.interp(t, t[ok], x[ok, j])
            usable[j] = True
    return out, usable


def _rms(x: np.ndarray) -> float:
    x = x[np.isfinite(x)]
    return float(np.sqrt(np.mean(x * x))) if x.size else math.nan


def assess_precision(time_s: npt.ArrayLike, angle: npt.ArrayLike, valid: npt.ArrayLike, u_px: npt.ArrayLike,
                     v_px: npt.ArrayLike, centre_px: tuple[float, float], radius_px: float, omega_c: float,
                     window: int, polyorder: int = 2, track_fit: int = 7) -> Precision | None:
    """Estimate a trace's angle and speed RMS error from its angles and highlight positions before the track fit.

    Parameters
    ----------
    time_s
        Sample times (s), shape (T,).
    angle, valid
        The unwrapped angles (rad) before :func:`~cageless.tracking.kinematics.robust_track_fit` and their
        validity, shape (T, Z).
    u_px, v_px
        The highlight positions (px), same shape and ball order as ``angle``.
    centre_px, radius_px
        The fitted orbit circle (px).
    omega_c
        Pure-rolling cage speed (rad/s), positive.
    window, polyorder
        The speed filter's Savitzky-Golay window (frames) and order.
    track_fit
        Frames of the track fit's quadratic (1: none).

    Returns
    -------
    Precision or None
        ``None`` when the clip is shorter than the speed window or :data:`NOISE_FRAMES`, or no ball has
        enough measured samples.
    """
    t = np.asarray(time_s, dtype=np.float64)
    ok = np.asarray(valid, dtype=bool)
    if len(t) < max(NOISE_FRAMES, window, track_fit) or not omega_c > 0 or not radius_px > 0:
        return None
    sigma, jumps = angle_noise(t, angle, ok)
    if not np.isfinite(sigma).any():
        return None
    noise = float(np.sqrt(np.nanmean(sigma**2)))
    step = float(np.median(np.diff(t)))
    radial = radial_scatter(u_px, v_px, ok, centre_px, radius_px)
    have = np.isfinite(radial)
    smooth, _ = robust_track_fit(t, np.nan_to_num(radial), have, track_fit)
    radial_angle = _rms(np.where(have, smooth, np.nan))
    filled, usable = _filled(t, radial)
    radial_speed = _rms(revolution_speed(t, filled[:, usable], window, polyorder)) if usable.any() else math.nan
    tangential_angle = math.sqrt(centre_leverage(track_fit)) * noise
    tangential_speed = noise * savgol_slope_gain(window, polyorder) / step
    angle_rms = math.hypot(tangential_angle, np.nan_to_num(radial_angle))
    speed_rms = math.hypot(tangential_speed, np.nan_to_num(radial_speed))
    return Precision(angle_rms_mrad=1e3 * ANGLE_GAIN * angle_rms, speed_rms_pct=100 * SPEED_GAIN * speed_rms / omega_c,
                     noise_mrad=1e3 * noise, radial_mrad=1e3 * float(np.nan_to_num(radial_angle)),
                     worst_ball_noise_mrad=1e3 * float(np.nanmax(sigma)), jump_share=float(np.mean(jumps)))


def assess_table(table: pd.DataFrame, order: npt.ArrayLike, time_s: npt.ArrayLike, angle: npt.ArrayLike,
                 valid: npt.ArrayLike, centre_px: tuple[float, float], radius_px: float, omega_c: float, window: int,
                 polyorder: int = 2, track_fit: int = 7) -> Precision | None:
    """:func:`assess_precision` with the highlight positions taken from the tracker's table (columns ``ball``,
    ``u_px``, ``v_px``, frame-major) in the trace's ball order (``order[k]``: the table's ball that is ball k)."""
    z = int(table.ball.max()) + 1
    cols = np.asarray(order)
    u_px, v_px = (table[c].to_numpy().reshape(-1, z)[:, cols] for c in ("u_px", "v_px"))
    return assess_precision(time_s, angle, valid, u_px, v_px, centre_px, radius_px, omega_c, window, polyorder,
                            track_fit)


def precision_warning(p: Precision | None, bars: dict[str, Any]) -> str | None:
    """The QC warning when the estimate is worse than a bar (``max_angle_rms_mrad``, ``max_speed_rms_pct``)."""
    if p is None:
        return None
    over_angle = p.angle_rms_mrad > bars["max_angle_rms_mrad"]
    over_speed = p.speed_rms_pct > bars["max_speed_rms_pct"]
    if not (over_angle or over_speed):
        return None
    what = (f"estimated angle precision {p.angle_rms_mrad:.2f} mrad RMS is worse than "
            f"{bars['max_angle_rms_mrad']} mrad" if over_angle else
            f"estimated angle precision {p.angle_rms_mrad:.2f} mrad RMS")
    what += (f", estimated speed precision {p.speed_rms_pct:.2f} % of the cage speed"
             + (f" is worse than {bars['max_speed_rms_pct']} %" if over_speed else ""))
    return (f"low precision: {what}: slip values from this clip are uncertain to about {p.speed_rms_pct:.2f} pp "
            f"per sample and ball angles to about {p.angle_rms_mrad:.2f} mrad (estimated from the trace's own "
            "scatter, typically within a factor of two)")
