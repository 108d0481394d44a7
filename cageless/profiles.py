"""Profiles against orbital angle: the mean and spread of a per-ball quantity per angle bin.

Used for slip and revolution-speed profiles: every sample of
every ball and revolution falls into the bin of its orbital angle (mod 360 deg),
and each bin gets the mean, standard deviation and count.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
import pandas as pd

from cageless.errors import ParameterError

__all__ = ["PROFILE_COLUMNS", "angle_profile"]

PROFILE_COLUMNS = ("angle_deg", "mean", "std", "count")


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
