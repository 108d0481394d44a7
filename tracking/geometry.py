"""Stage 4: from tracked pixels to orbital angles in the bearing frame.

Angles are measured about the centre of the circle the tracked highlights travel
over the whole video (a constant highlight offset moves that circle off the
ring contour's centre; measuring about the contour centre would turn the offset
into a once-per-revolution ripple). The camera roll is removed
(bearing angle = image angle - roll), a bearing that turns clockwise in the
image is mirrored (theta -> pi - theta, ``direction = -1``), balls are numbered
counter-clockwise from the one just after the largest gap in the first frame,
and missed samples are interpolated in time and flagged invalid.

Each frame's angles are measured about that frame's own centre: the whole-video circle moved by the
translation common to the frame's highlights (:func:`frame_shifts`). Whatever moves every highlight of a
frame alike (the camera shaking, or a doubled highlight whose pull on the centroid changes with the light
level under mains flicker) is not ball motion, and about a fixed centre it would read as a different angle
error for each ball.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
import pandas as pd

from cageless.balls import ball_order, normalise_unwrapped
from cageless.tracking.kinematics import DEFAULT_WINDOW, robust_track_fit
from cageless.tracking.locate import fit_circle

__all__ = ["Orbit", "FRAME_JUMP", "fit_orbit", "frame_shifts", "frame_jumps", "orbital_angles"]

#: Fewest highlights a frame needs for its own centre (three fix a circle; the rest make it robust).
MIN_FRAME_BALLS = 6

_MAX_FIT_POINTS = 50_000
#: A frame whose highlights share a translation this far (a share of the orbit radius) from the smoothed one has
#: its samples flagged not valid: every highlight of it was measured off its ball alike. FRESH2 seed 7209 (two
#: saturated lights' highlights 10 px apart): the tracker started on the second light's and drifted to the first
#: over two frames, 0.049 and 0.034 of the radius off (46 mrad); none flagged on the 32 TUNING clips (the largest
#: translation off a clip's median 0.0024, 1014).
FRAME_JUMP = 0.01


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


def frame_shifts(t: np.ndarray, u: np.ndarray, v: np.ndarray, orbit: Orbit,
                 frames: int = DEFAULT_WINDOW) -> npt.NDArray[np.float64]:
    """:func:`frame_jumps`' smoothed translations only (px), shape (T, 2)."""
    return frame_jumps(t, u, v, orbit, frames)[0]


def frame_jumps(t: np.ndarray, u: np.ndarray, v: np.ndarray, orbit: Orbit, frames: int = DEFAULT_WINDOW
                ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """Each frame's common translation (du, dv) of the highlights off the whole-video circle (px), shape (T, 2).

    In each frame with at least :data:`MIN_FRAME_BALLS` highlights, the radial residuals
    ``rho_j - R = (du, dv) . n_j + dR`` (``n_j`` the outward unit vector of highlight j) are solved for the
    translation and a common change of radius by least squares, dropping the worst highlight and solving
    again while it is more than 4 robust standard deviations off (a glint crossing one). Only the radial residuals are used: the
    along-circle positions are the measurement, and a translation shows in both. The per-frame solutions are
    smoothed by the robust local quadratic of :func:`~cageless.tracking.kinematics.robust_track_fit` over
    ``frames`` frames (the pipeline passes the speed filter's window), so that their noise, about
    ``sqrt(2 / Z)`` of a highlight's radial noise in one frame, adds little to any angle (with 7 frames
    instead of 21, corpus seed 1002 read 0.483 instead of 0.450 mrad, an elongated highlight being less
    precise across the orbit than along it); frames without a solution take their neighbours'.
    ``frames = 0`` gives zeros.

    Returns
    -------
    shift, jump
        The smoothed translation (du, dv) of each frame (px), shape (T, 2), and how far each frame's own solution
        lies from it (px), shape (T,): 0 where the frame had no solution or nothing is smoothed.
    """
    n = len(t)
    out = np.zeros((n, 2))
    if frames == 0:
        return out, np.zeros(n)
    cx, cy = orbit.centre
    du, dv = u - cx, v - cy
    rho = np.hypot(du, dv)
    ok = np.isfinite(rho) & (rho > 0)
    nu, nv = np.where(ok, du / np.where(ok, rho, 1.0), 0.0), np.where(ok, dv / np.where(ok, rho, 1.0), 0.0)
    res = np.where(ok, rho - orbit.radius, 0.0)
    scale = 1.4826 * float(np.median(np.abs(res[ok]))) if ok.any() else 0.0
    raw, solved = _frame_solutions(nu, nv, res, ok, 4.0 * max(scale, 1e-6))
    if not solved.any():
        return np.zeros((n, 2)), np.zeros(n)
    out = raw.copy()
    for k in range(2):
        out[~solved, k] = np.interp(t[~solved], t[solved], out[solved, k])
    if not (frames > 1 and n >= frames):
        return out, np.zeros(n)
    out, _ = robust_track_fit(t, out, np.repeat(solved[:, None], 2, axis=1), frames)
    return out, np.where(solved, np.hypot(*(raw - out).T), 0.0)


def _frame_solutions(nu: np.ndarray, nv: np.ndarray, res: np.ndarray, ok: np.ndarray,
                     limit: float) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.bool_]]:
    """Each frame's least-squares (du, dv, dR) of ``res = du nu + dv nv + dR`` over its highlights in ``ok``, all
    frames at once; a frame's worst highlight is dropped and the frame solved again while it is off by more
    than ``limit`` and more than :data:`MIN_FRAME_BALLS` remain. Returns (du, dv) per frame (T, 2) and which
    frames had enough highlights."""
    n = len(res)
    use = ok & (ok.sum(axis=1) >= MIN_FRAME_BALLS)[:, None]
    solved = use.any(axis=1)
    design = np.stack([nu, nv, np.ones_like(nu)], axis=-1)  # (T, Z, 3)
    sol = np.zeros((n, 3))
    active = np.flatnonzero(solved)
    while active.size:
        a = design[active] * use[active][..., None]
        normal = np.einsum("tzi,tzj->tij", a, design[active])
        sol[active] = np.einsum("tij,tj->ti", np.linalg.pinv(normal), np.einsum("tzi,tz->ti", a, res[active]))
        off = np.where(use[active], np.abs(res[active] - np.einsum("tzi,ti->tz", design[active], sol[active])), 0.0)
        worst = np.argmax(off, axis=1)
        drop = (off[np.arange(active.size), worst] > limit) & (use[active].sum(axis=1) > MIN_FRAME_BALLS)
        use[active[drop], worst[drop]] = False
        active = active[drop]
    return sol[:, :2], solved


def orbital_angles(table: pd.DataFrame, orbit: Orbit, roll_rad: float = 0.0, steady: int = DEFAULT_WINDOW
                   ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.bool_], int, npt.NDArray[np.int64]]:
    """Unwrapped bearing-frame orbital angles (T, Z), validity, direction and the ball relabelling.

    The angles are measured about each frame's centre (:func:`frame_shifts` with ``frames = steady``;
    0: about the whole-video centre). A frame whose own translation lies more than :data:`FRAME_JUMP` of the
    radius from the smoothed one has its samples flagged not valid (:func:`frame_jumps`).

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
    shift, jump = frame_jumps(t, u, v, orbit, steady)
    ok = np.isfinite(u) & (jump <= FRAME_JUMP * orbit.radius)[:, None]
    cx, cy = orbit.centre[0] + shift[:, :1], orbit.centre[1] + shift[:, 1:]
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
