"""Point-by-point errors between two aligned profiles, and the slip rate of a condition.

All values are in percentage points of slip (the profiles hold slip as a fraction).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
import pandas as pd

from cageless.errors import CagelessError
from cageless.profiles import PEAK_SMOOTHING_DEG, UNLOADED_ZONE_DEG, unloaded_zone_peak

__all__ = ["ProfileErrors", "profile_errors", "unloaded_peak", "UNLOADED_ZONE_DEG", "SLIP_RATE_DEFINITION"]

#: Printed under every table.
SLIP_RATE_DEFINITION = (
    "Slip rate s = 1 - (ball orbital speed) / (pure-rolling cage speed w_i (1 - D/d_m) / 2). The theoretical "
    "(simulated) and experimental (measured) slip rate of a condition is the peak of the mean slip profile "
    f"(1 deg bins, all balls, smoothed by a periodic Gaussian of sigma {PEAK_SMOOTHING_DEG:g} deg) in the unloaded "
    "zone, 0-180 deg; the smoothing keeps bin noise from raising the peak of short runs. MAE, RMSE and maximum "
    "error compare the two mean profiles point by point over every bin where both have data, in percentage points."
)


@dataclass(frozen=True)
class ProfileErrors:
    """MAE, RMSE and maximum absolute error (pp) over ``n_points`` bins."""

    mae_pp: float
    rmse_pp: float
    max_pp: float
    n_points: int


def profile_errors(measured: npt.ArrayLike, simulated: npt.ArrayLike) -> ProfileErrors:
    """Errors between two profiles given as fractions on the same bins (NaN bins are skipped)."""
    a = np.asarray(measured, dtype=np.float64)
    b = np.asarray(simulated, dtype=np.float64)
    if a.shape != b.shape:
        raise CagelessError(f"profiles of different lengths ({a.shape} and {b.shape}): use the same bin width.")
    both = np.isfinite(a) & np.isfinite(b)
    if not both.any():
        raise CagelessError("the measured and simulated profiles share no angle bin with data.")
    d = 100.0 * np.abs(a[both] - b[both])
    return ProfileErrors(mae_pp=float(d.mean()), rmse_pp=float(np.sqrt(np.mean(d * d))), max_pp=float(d.max()),
                         n_points=int(both.sum()))


def unloaded_peak(profile: pd.DataFrame, sigma_deg: float = PEAK_SMOOTHING_DEG) -> float:
    """Peak slip of the unloaded zone (fraction; NaN without data there): the maximum over 0-180 deg of the
    mean profile smoothed by a periodic Gaussian of ``sigma_deg`` (:func:`cageless.profiles.unloaded_zone_peak`),
    the same estimator for measured and simulated traces."""
    return unloaded_zone_peak(profile, sigma_deg)
