"""Stage 4: from tracked pixels to orbital angles in the bearing frame.

Angles are measured about the centre of the circle the tracked highlights travel
over the whole video (a constant highlight offset moves that circle off the
ring contour's centre; measuring about the contour centre would turn the offset
into a once-per-revolution ripple). The camera roll is removed
(bearing angle = image angle - roll), a bearing that turns clockwise in the
image is mirrored (theta -> pi - theta, ``direction = -1``), balls are numbered
counter-clockwise from the one just after the largest gap in the first frame,
and missed samples are interpolated in time and flagged invalid.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
import pandas as pd

from cageless.balls import ball_order, normalise_unwrapped
from cageless.tracking.locate import fit_circle

__all__ = ["Orbit", "fit_orbit", "orbital_angles"]

_MAX_FIT_POINTS = 50_000


@dataclass(frozen=True)
class Orbit:
    """The circle the highlights travel (pixels)."""

    centre: tuple[float, float]
    radius: float
    residual: float


def _grid(table: pd.DataFrame) -> tuple[np.ndarray, np.ndarray]:
    n = int(table.frame.max()) + 1
    z = int(table.ball.max()) + 1
    return table.u_px.to_numpy().reshape(n, z), table.v_px.to_numpy().reshape(n, z)


def fit_orbit(table: pd.DataFrame) -> Orbit:
    """Fit one circle to every detected highlight position of the video."""
    ok = table.detected.to_numpy()
    u, v = table.u_px.to_numpy()[ok], table.v_px.to_numpy()[ok]
    if u.size > _MAX_FIT_POINTS:
        pick = np.linspace(0, u.size - 1, _MAX_FIT_POINTS).astype(int)
        u, v = u[pick], v[pick]
    cx, cy, r, rms = fit_circle(u, v)
    return Orbit(centre=(cx, cy), radius=r, residual=rms)


def _interpolate(t: np.ndarray, a: np.ndarray, ok: np.ndarray) -> np.ndarray:
    """Linear interpolation over missed samples; linear extrapolation from the two nearest at the ends."""
    out = a.copy()
    idx = np.flatnonzero(ok)
    if idx.size == 0:
        return out
    out[~ok] = np.interp(t[~ok], t[idx], a[idx])
    if idx.size >= 2:
        for end, (i0, i1) in (("lo", (idx[0], idx[1])), ("hi", (idx[-2], idx[-1]))):
            slope = (a[i1] - a[i0]) / (t[i1] - t[i0])
            sel = (t < t[idx[0]]) if end == "lo" else (t > t[idx[-1]])
            ref = idx[0] if end == "lo" else idx[-1]
            out[sel] = a[ref] + slope * (t[sel] - t[ref])
    return out


def orbital_angles(table: pd.DataFrame, orbit: Orbit, roll_rad: float = 0.0
                   ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.bool_], int, npt.NDArray[np.int64]]:
    """Unwrapped bearing-frame orbital angles (T, Z), validity, direction and the ball relabelling.

    Returns
    -------
    angle
        Unwrapped orbital angle of each ball (rad), increasing along the rotation.
    valid
        False where the sample was interpolated.
    direction
        +1, or -1 when the video was mirrored because the bearing turns clockwise in the image.
    order
        ``order[k]`` is the tracker's column that became ball k.
    """
    u, v = _grid(table)
    t = table.time_s.to_numpy().reshape(u.shape)[:, 0]
    ok = np.isfinite(u)
    cx, cy = orbit.centre
    theta = np.arctan2(-(v - cy), u - cx) - roll_rad
    angle = np.empty_like(theta)
    for j in range(theta.shape[1]):
        good = ok[:, j]
        col = np.where(good, theta[:, j], np.nan)
        vals = np.unwrap(col[good])
        filled = np.full(len(t), np.nan)
        filled[good] = vals
        angle[:, j] = _interpolate(t, np.nan_to_num(filled), good)
    travel = np.median(angle[-1] - angle[0])
    direction = -1 if travel < 0 else 1
    if direction == -1:
        angle = np.pi - angle
    order = ball_order(angle[0])
    return normalise_unwrapped(angle[:, order]), ok[:, order], direction, order
