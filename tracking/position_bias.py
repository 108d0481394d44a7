"""Errors tied to a place in the image: measured from the balls that pass it, and removed.

All the balls' highlights travel one circle, so every ball passes the same pixels. An error of the position
estimate that depends on where on that circle the highlight is (compression blocks, pixel locking, a fixed
pattern of the sensor or the glass) is the same for every ball that passes there, while the noise is not.
Each ball's angle minus a robust local quadratic over :data:`SMOOTH_FRAMES` frames (its motion) leaves that
error plus noise; the mean of the other balls' residuals within :data:`BIN_PX` pixels along the circle
estimates the error at each sample, and a share of it is removed. The share is the empirical-Bayes (Wiener)
weight ``var_g / (var_g + var_e / n)``: ``var_g``, the variance of the place-bound error, is the covariance
of each residual with the other balls' mean at its place, ``var_e`` the rest of the residual variance and
``n`` the number of samples in that mean. A clip without such an error gets a covariance near 0 and nothing
is removed (the correction is applied only when the covariance stands :data:`MIN_T` standard errors above 0).

Only errors that change within the quadratic's span along the circle are seen; slower ones (a once-per-
revolution error from a misplaced centre) are indistinguishable from the balls' motion.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from cageless.tracking.kinematics import robust_track_fit

__all__ = ["PlaceBias", "BIN_PX", "SMOOTH_FRAMES", "MIN_T", "remove_place_bias"]

#: Width of a place along the highlight circle (px).
BIN_PX = 0.3
#: Frames of the robust local quadratic that stands for each ball's motion.
SMOOTH_FRAMES = 21
#: The covariance must stand this many standard errors above 0.
MIN_T = 4.0
#: Residuals beyond this many robust standard deviations are clipped before averaging (a glint crossing).
_CLIP = 5.0


@dataclass(frozen=True)
class PlaceBias:
    """What :func:`remove_place_bias` found: the RMS of the place-bound error and of the rest (rad), the
    covariance's t value, and the RMS of what was removed (rad)."""

    rms_place_rad: float
    rms_rest_rad: float
    t_value: float
    rms_removed_rad: float

    def to_dict(self) -> dict[str, float]:
        """JSON-ready summary for QC (mrad)."""
        return {"place_bound_mrad": round(1e3 * self.rms_place_rad, 4), "rest_mrad": round(1e3 * self.rms_rest_rad, 4),
                "t": round(self.t_value, 2), "removed_mrad": round(1e3 * self.rms_removed_rad, 4)}


def _others_mean(res: np.ndarray, ok: np.ndarray, place: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For each sample, the mean of the residuals of the *other* balls at the same place, and their count."""
    z = res.shape[1]
    key = place[ok]
    ball = np.nonzero(ok)[1]
    r = res[ok]
    uniq, inv = np.unique(key, return_inverse=True)
    n_p = uniq.size
    s_all = np.bincount(inv, r, minlength=n_p)
    c_all = np.bincount(inv, minlength=n_p).astype(np.float64)
    flat = inv * z + ball
    s_own = np.bincount(flat, r, minlength=n_p * z)[flat]
    c_own = np.bincount(flat, minlength=n_p * z).astype(np.float64)[flat]
    cnt = c_all[inv] - c_own
    mean = np.where(cnt > 0, (s_all[inv] - s_own) / np.maximum(cnt, 1.0), 0.0)
    out_m, out_n = np.zeros(res.shape), np.zeros(res.shape)
    out_m[ok], out_n[ok] = mean, cnt
    return out_m, out_n


def remove_place_bias(time_s: npt.ArrayLike, angle: npt.ArrayLike, valid: npt.ArrayLike, radius_px: float
                      ) -> tuple[npt.NDArray[np.float64], PlaceBias]:
    """Unwrapped angles (T, Z) with their place-bound error removed (see the module docstring).

    Parameters
    ----------
    time_s
        Frame times (s), (T,).
    angle
        Unwrapped orbital angles (rad), (T, Z); all balls on one circle of ``radius_px``.
    valid
        Measured (True) or interpolated samples; only measured ones are used and corrected.
    radius_px
        Radius of the highlight circle (px), to size the places.
    """
    t = np.asarray(time_s, dtype=np.float64)
    a = np.asarray(angle, dtype=np.float64)
    ok = np.asarray(valid, dtype=bool) & np.isfinite(a)
    none = PlaceBias(0.0, 0.0, 0.0, 0.0)
    if len(t) < SMOOTH_FRAMES or a.shape[1] < 2 or not radius_px > 0:
        return a.copy(), none
    smooth, _ = robust_track_fit(t, a, ok, SMOOTH_FRAMES)
    res = np.where(ok, a - smooth, 0.0)
    scale = 1.4826 * float(np.median(np.abs(res[ok]))) if ok.any() else 0.0
    res = np.clip(res, -_CLIP * scale, _CLIP * scale)
    place = np.floor(np.mod(np.where(ok, a, 0.0), 2 * np.pi) * radius_px / BIN_PX).astype(np.int64)
    mean, cnt = _others_mean(res, ok, place)
    use = ok & (cnt > 0)
    if use.sum() < 10:
        return a.copy(), none
    prod = res[use] * mean[use]
    cov = float(prod.mean())
    se = float(prod.std()) / float(np.sqrt(prod.size))
    var_r = float(np.mean(res[use] ** 2))
    t_value = cov / se if se > 0 else 0.0
    var_e = max(var_r - cov, 0.0)
    if cov <= 0 or t_value < MIN_T:
        return a.copy(), PlaceBias(float(np.sqrt(max(cov, 0.0))), float(np.sqrt(var_e)), t_value, 0.0)
    weight = np.where(use, cov / (cov + var_e / np.maximum(cnt, 1.0)), 0.0)
    removed = weight * mean
    out = a - removed
    return out, PlaceBias(float(np.sqrt(cov)), float(np.sqrt(var_e)), t_value,
                          float(np.sqrt(np.mean(removed[use] ** 2))))
