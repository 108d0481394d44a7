"""Angle profiles: binning, mean and spread against values computed by hand."""

from __future__ import annotations

import numpy as np
import pytest

from cageless.errors import ParameterError
from cageless.profiles import angle_profile


def test_profile_by_hand():
    # Angles 0.5, 0.7 and 360.5 deg fall in bin 0 (values 1, 3, 5: mean 3, sample std 2); 90.2 deg in bin 90.
    a = np.radians([0.5, 0.7, 360.5, 90.2])
    p = angle_profile(a, [1.0, 3.0, 5.0, 7.0])
    assert len(p) == 360
    assert p.loc[0, "angle_deg"] == 0.5
    assert (p.loc[0, "mean"], p.loc[0, "std"], p.loc[0, "count"]) == (3.0, 2.0, 3)
    assert p.loc[90, "mean"] == 7.0 and np.isnan(p.loc[90, "std"])
    assert p["count"].sum() == 4 and np.isnan(p.loc[200, "mean"])


def test_profile_mask_nan_and_bins():
    a = np.radians([[10.0, 10.0], [20.0, 20.0]])
    v = np.array([[1.0, np.nan], [2.0, 4.0]])
    p = angle_profile(a, v, bin_deg=10.0, valid=[[True, True], [True, False]])
    assert len(p) == 36
    assert p.loc[1, "mean"] == 1.0 and p.loc[2, "mean"] == 2.0
    with pytest.raises(ParameterError, match="whole number"):
        angle_profile(a, v, bin_deg=7.0)
