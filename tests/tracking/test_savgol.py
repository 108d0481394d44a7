"""The speed's Savitzky-Golay filter without ``scipy.signal``: the values of :func:`scipy.signal.savgol_filter`.

:func:`cageless.tracking.kinematics._savgol_filter` repeats the operations of SciPy's ``savgol_filter``
(``mode="interp"``, axis 0; SciPy's ``signal/_savitzky_golay.py`` and ``signal/_polyutils.py``) with the same
library calls, so that a cold ``cageless track`` need not import ``scipy.signal``. The reference is SciPy's own
function, compared bit for bit: a SciPy release that computes the filter otherwise fails here.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.signal import savgol_coeffs, savgol_filter

from cageless.tracking.kinematics import _savgol_coeffs, _savgol_filter, revolution_speed


_CASES = [(shape, window, polyorder) for shape in [(1000,), (1000, 14), (61, 20), (21, 3)] for window in (3, 7, 21, 51)
          for polyorder in (0, 1, 2, 4) if polyorder < window <= shape[0]]


@pytest.mark.parametrize(("shape", "window", "polyorder"), _CASES)
def test_savgol_filter_is_scipys_bit_for_bit(shape, window, polyorder):
    rng = np.random.default_rng(window * 100 + polyorder)
    x = np.cumsum(rng.normal(size=shape), axis=0) + 50.0  # a random walk, like an unwrapped angle
    for delta in (1e-4, 1.0 / 9973.0, 0.37):
        want = savgol_filter(x, window, polyorder, deriv=1, delta=delta, axis=0, mode="interp")
        assert np.array_equal(_savgol_filter(x, window, polyorder, 1, delta), want)


@pytest.mark.parametrize("deriv", [0, 1, 2, 3])
def test_savgol_coefficients_are_scipys(deriv):
    for window, polyorder in ((5, 2), (21, 2), (31, 3)):
        want = savgol_coeffs(window, polyorder, deriv=deriv, delta=1e-4)
        assert np.array_equal(_savgol_coeffs(window, polyorder, deriv, 1e-4), want)


def test_speed_of_a_uniform_rotation_is_its_rate():
    """A ball turning at 100 rad/s, sampled at 10 kHz: the Savitzky-Golay slope of a straight line is exact to
    rounding (the filter reproduces polynomials up to its order, Savitzky & Golay 1964)."""
    t = np.arange(500) * 1e-4
    speed = revolution_speed(t, 100.0 * t[:, None] + np.arange(3)[None, :], 21, 2)
    assert np.allclose(speed, 100.0, rtol=1e-9)
