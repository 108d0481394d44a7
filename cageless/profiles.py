"""Profiles against orbital angle: the mean and spread of a per-ball quantity per angle bin.

Used for slip and revolution-speed profiles: every sample of
every ball and revolution falls into the bin of its orbital angle (mod 360 deg),
and each bin gets the mean, standard deviation and count.

The headline number, the peak slip of the unloaded zone, is taken here, by one function for measured and
simulated traces alike (:func:`unloaded_zone_peak`): the maximum over the zone of the mean profile after a
periodic Gaussian smoothing of :data:`PEAK_SMOOTHING_DEG`. The maximum of raw bins is biased upward by
the bins' noise (the expected maximum of n noisy bins lies about sigma sqrt(2 ln n) above the true peak,
so it grows as runs get shorter and bins narrower); smoothing over a few degrees cuts that noise and makes
the estimate independent of the bin width, at the cost of a small, known downward bias at a sharp peak
(``benchmarks/peak_estimator.py`` measures both).
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
import pandas as pd

from cageless.errors import ParameterError

__all__ = ["PROFILE_COLUMNS", "angle_profile", "smooth_profile", "unloaded_zone_peak", "peak_estimator",
           "peak_of_mean", "peak_standard_error", "PEAK_SMOOTHING_DEG", "UNLOADED_ZONE_DEG", "PEAK_SE_RESAMPLES"]

PROFILE_COLUMNS = ("angle_deg", "mean", "std", "count")

#: The unloaded zone: the upper half of the bearing, opposite the radial load (deg of orbital angle).
UNLOADED_ZONE_DEG = (0.0, 180.0)

#: Standard deviation (deg of orbital angle) of the periodic Gaussian that smooths the mean slip profile
#: before its unloaded-zone peak is taken (:func:`unloaded_zone_peak`).
PEAK_SMOOTHING_DEG = 10.0

#: Bootstrap resamples of the balls behind :func:`peak_standard_error` (its own sampling error is then about
#: 1 / sqrt(2 x 300) = 4 % of the value).
PEAK_SE_RESAMPLES = 300


def angle_profile(
    angle_rad: npt.ArrayLike, values: npt.ArrayLike, bin_deg: float = 1.0, valid: npt.ArrayLike | None = None,
) -> pd.DataFrame:
    """Mean, spread and count of ``values`` per orbital-angle bin.

    Parameters
    ----------
    angle_rad
        Orbital angles (rad), any shape; taken modulo 2 pi.
    values
        Values of the same shape (e.g. slip), NaN ignored.
    bin_deg
        Bin width (deg); 360 must be a whole multiple of it.
    valid
        Optional mask of the same shape; False samples are left out.

    Returns
    -------
    pandas.DataFrame
        One row per bin with columns ``PROFILE_COLUMNS``; ``angle_deg`` is the bin centre.
        Empty bins have NaN mean and std and count 0.
    """
    n_bins = 360.0 / bin_deg
    if not np.isfinite(n_bins) or bin_deg <= 0 or abs(n_bins - round(n_bins)) > 1e-9:
        raise ParameterError("bin_deg", "must divide 360 into a whole number of bins", bin_deg)
    n_bins = int(round(n_bins))
    a = np.asarray(angle_rad, dtype=np.float64).ravel()
    v = np.asarray(values, dtype=np.float64).ravel()
    if a.shape != v.shape:
        raise ParameterError("values", f"must match angle_rad in size ({a.size}), got {v.size}")
    keep = np.isfinite(a) & np.isfinite(v)
    if valid is not None:
        keep &= np.asarray(valid, dtype=bool).ravel()
    deg = np.degrees(a[keep]) % 360.0
    idx = np.minimum((deg / bin_deg).astype(np.int64), n_bins - 1)
    count = np.bincount(idx, minlength=n_bins).astype(np.float64)
    total = np.bincount(idx, weights=v[keep], minlength=n_bins)
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = total / count
        sq = np.bincount(idx, weights=(v[keep] - mean[idx]) ** 2, minlength=n_bins)
        std = np.sqrt(sq / np.maximum(count - 1, 1))
    std[count < 2] = np.nan
    return pd.DataFrame({
        "angle_deg": (np.arange(n_bins) + 0.5) * bin_deg, "mean": mean, "std": std, "count": count.astype(np.int64),
    })


def smooth_profile(mean: npt.ArrayLike, bin_deg: float,
                   sigma_deg: float = PEAK_SMOOTHING_DEG) -> npt.NDArray[np.float64]:
    """A full-circle profile smoothed by a periodic Gaussian of ``sigma_deg`` (deg).

    ``mean`` holds the bins along its first axis (a 2-D array: one profile per column). Empty (NaN) bins are left out by normalised convolution (the smoothed values over the smoothed
    indicator of bins with data, :func:`scipy.ndimage.gaussian_filter1d` with ``mode="wrap"``) and stay
    NaN. ``sigma_deg`` = 0 returns the profile unchanged.
    """
    from scipy.ndimage import gaussian_filter1d

    m = np.asarray(mean, dtype=np.float64)
    if not (np.isfinite(sigma_deg) and sigma_deg >= 0):
        raise ParameterError("sigma_deg", "must be a finite number of degrees >= 0", sigma_deg)
    if sigma_deg == 0 or m.size == 0:
        return m.copy()
    has = np.isfinite(m)
    sigma = sigma_deg / bin_deg
    num = gaussian_filter1d(np.where(has, m, 0.0), sigma, axis=0, mode="wrap")
    den = gaussian_filter1d(has.astype(np.float64), sigma, axis=0, mode="wrap")
    with np.errstate(invalid="ignore", divide="ignore"):
        out = num / den
    out[~has] = np.nan
    return out


def unloaded_zone_peak(profile: pd.DataFrame, sigma_deg: float = PEAK_SMOOTHING_DEG) -> float:
    """The peak slip of the unloaded zone (fraction): the maximum over 0-180 deg of the mean profile smoothed
    by a periodic Gaussian of ``sigma_deg`` (:func:`smooth_profile`); NaN without data in the zone.

    ``profile`` is a full-circle :func:`angle_profile` (columns ``angle_deg`` and ``mean``). ``sigma_deg`` = 0
    gives the raw maximum over bins (biased upward by bin noise; kept for comparison).
    """
    angle = profile["angle_deg"].to_numpy(dtype=np.float64)
    if angle.size < 2:
        raise ParameterError("profile", "needs a full-circle profile of at least two bins", angle.size)
    return peak_of_mean(profile["mean"].to_numpy(dtype=np.float64), float(angle[1] - angle[0]), sigma_deg)


def peak_of_mean(mean: npt.ArrayLike, bin_deg: float, sigma_deg: float = PEAK_SMOOTHING_DEG) -> float:
    """:func:`unloaded_zone_peak` of a full-circle mean profile given as an array of ``bin_deg`` bins."""
    return float(_peaks(np.asarray(mean, dtype=np.float64)[:, None], bin_deg, sigma_deg)[0])


def _peaks(means: npt.NDArray[np.float64], bin_deg: float, sigma_deg: float) -> npt.NDArray[np.float64]:
    """:func:`peak_of_mean` of each column of ``means`` (bins, profiles); NaN for a column without data in the
    unloaded zone."""
    smooth = smooth_profile(means, bin_deg, sigma_deg)
    centres = (np.arange(smooth.shape[0]) + 0.5) * bin_deg
    lo, hi = UNLOADED_ZONE_DEG
    zone = smooth[(centres > lo) & (centres < hi)]
    has = np.isfinite(zone).any(axis=0)
    return np.where(has, np.max(np.where(np.isfinite(zone), zone, -np.inf), axis=0, initial=-np.inf), np.nan)


def peak_standard_error(per_ball: npt.ArrayLike, bin_deg: float, sigma_deg: float = PEAK_SMOOTHING_DEG,
                        n_resamples: int = PEAK_SE_RESAMPLES, seed: int = 0) -> float:
    """Standard error (fraction) of the unloaded-zone peak from the balls it was taken over.

    The balls are resampled with replacement (:func:`scipy.stats.bootstrap`, ``n_resamples`` draws, a fixed
    ``seed`` so the same trace gives the same figure) and the peak (:func:`peak_of_mean`) is taken of each
    draw's mean profile (the balls' profiles averaged per bin, ignoring bins a ball did not visit); the result
    is the standard deviation of those peaks. It says how much the figure would move with other balls, or
    other stretches of the same balls: large for a clip that shows each angle with a few balls only, small
    for a long run. It holds no tracking or model error.

    Parameters
    ----------
    per_ball
        Mean slip per angle bin and ball, shape (bins, balls), NaN where a ball has no sample.
    bin_deg
        Bin width (deg).
    sigma_deg, n_resamples, seed
        The peak's smoothing, the number of draws and the random seed.

    Returns
    -------
    float
        The standard error, NaN with fewer than two balls.
    """
    from scipy.stats import bootstrap

    table = np.asarray(per_ball, dtype=np.float64)
    if table.ndim != 2 or table.shape[1] < 2:
        return float("nan")
    seen = np.isfinite(table)
    values = np.where(seen, table, 0.0)

    def peaks(balls: npt.NDArray[np.float64], axis: int = -1) -> npt.NDArray[np.float64]:
        draws = np.moveaxis(balls, axis, -1).astype(np.intp)  # (..., balls drawn)
        flat = draws.reshape(-1, draws.shape[-1])
        count = seen[:, flat].sum(axis=-1)  # (bins, draws): a bin no drawn ball visited stays NaN
        with np.errstate(invalid="ignore", divide="ignore"):
            means = values[:, flat].sum(axis=-1) / count
        return _peaks(means, bin_deg, sigma_deg).reshape(draws.shape[:-1])

    key = "rng" if "rng" in _parameters(bootstrap) else "random_state"  # scipy < 1.15
    res = bootstrap((np.arange(table.shape[1], dtype=np.float64),), peaks, n_resamples=n_resamples,
                    vectorized=True, method="percentile", **{key: np.random.default_rng(seed)})
    return float(res.standard_error)


def _parameters(func: object) -> set[str]:
    """The names of ``func``'s parameters."""
    import inspect

    return set(inspect.signature(func).parameters)  # type: ignore[arg-type]


def peak_estimator(sigma_deg: float = PEAK_SMOOTHING_DEG) -> dict[str, object]:
    """How the peak slip is estimated, for provenance (configs, calibrations, reports)."""
    return {"name": "max of the periodic-Gaussian-smoothed mean slip profile over 0-180 deg",
            "smoothing_sigma_deg": float(sigma_deg), "unloaded_zone_deg": list(UNLOADED_ZONE_DEG)}
