"""Stage 5: revolution speed and slip from the unwrapped orbital angles.

The revolution speed is a Savitzky-Golay derivative of the unwrapped angle:
a polynomial of order ``polyorder`` fitted by least squares over ``window``
frames centred on each sample. The window is the accuracy-versus-noise knob
(benchmarked by ``cageless bench tracking``). Time comes from the reader's time
vector: when frames were dropped the angle is resampled onto a uniform grid at
the median frame period, differentiated there and sampled back.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
from scipy.signal import savgol_filter

from cageless.errors import ParameterError

__all__ = ["DEFAULT_WINDOW", "revolution_speed"]

#: Default Savitzky-Golay window (frames): 2.1 ms at 10 kfps.
DEFAULT_WINDOW = 21

_UNIFORM_TOL = 1e-3


def revolution_speed(time_s: npt.ArrayLike, angle: npt.ArrayLike, window: int = DEFAULT_WINDOW,
                     polyorder: int = 2) -> npt.NDArray[np.float64]:
    """Savitzky-Golay derivative d(angle)/dt along axis 0 (rad/s).

    Parameters
    ----------
    time_s
        Sample times (s), increasing, shape (T,).
    angle
        Unwrapped angles (rad), shape (T,) or (T, Z).
    window
        Odd window length in frames, > polyorder.
    polyorder
        Polynomial order.
    """
    t = np.asarray(time_s, dtype=np.float64)
    a = np.asarray(angle, dtype=np.float64)
    if window % 2 == 0 or window <= polyorder:
        raise ParameterError("window", f"must be odd and larger than polyorder = {polyorder}", window)
    if len(t) < window:
        raise ParameterError("window", f"needs at least {window} frames; the video has {len(t)}", window)
    dt = np.diff(t)
    step = float(np.median(dt))
    if np.all(np.abs(dt - step) <= _UNIFORM_TOL * step):
        return savgol_filter(a, window, polyorder, deriv=1, delta=step, axis=0, mode="interp")
    grid = np.arange(t[0], t[-1] + 0.5 * step, step)
    flat = a.reshape(len(t), -1)
    resampled = np.column_stack([np.interp(grid, t, flat[:, j]) for j in range(flat.shape[1])])
    d = savgol_filter(resampled, window, polyorder, deriv=1, delta=step, axis=0, mode="interp")
    back = np.column_stack([np.interp(t, grid, d[:, j]) for j in range(d.shape[1])])
    return back.reshape(a.shape)
