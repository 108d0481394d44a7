"""A ball tracked on another light's highlight: found from its own circle, and moved onto the others' lobe.

Under distant lights every ball's highlight sits at the same image offset from the ball's centre (where the
sphere's normal is the half vector of light and camera), so all highlights travel one circle. A second light
puts a second lobe on every ball at another fixed offset: a track that follows that lobe travels a circle of
the same radius whose centre is moved by the difference of the two offsets. Its angles then carry an error
that turns with the ball (the tangential part of a fixed image translation): corpus seed 7605 (two saturated
lights' lobes 7.1 px apart), one ball of 14 on the second lobe, 17.8 mrad RMS while the other 13 balls were
within 0.03 px of their highlights.

Each ball's own circle centre, with the common radius held, is fitted to its detected positions by
Gauss-Newton; its shift from the common centre is tested against its standard error. A ball shifted by more
than :data:`MIN_SHIFT_SIGMAS` highlight widths (two lobes closer than that merge into one spot) and by more
than :data:`MIN_T` standard errors, while more than half of the balls are not, is re-measured in every frame
with the centroid window started at its position moved back by the shift. The move is kept only if the
re-measured track then lies on the common circle; otherwise the table is returned unchanged. Frames where the
re-measure finds nothing keep the ball's other-lobe position moved by its measured lobe offset.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
import pandas as pd

from cageless.tracking.detect import centroid_windows
from cageless.tracking.locate import fit_circle

__all__ = ["LobeShift", "ball_shifts", "relock_lobes", "MIN_SHIFT_SIGMAS", "MIN_T"]

log = logging.getLogger(__name__)

#: A ball's circle must be shifted by more than this many highlight widths (sigma) to count as on another lobe.
MIN_SHIFT_SIGMAS = 2.0
#: ... and by more than this many standard errors of the shift.
MIN_T = 8.0
#: Fewest detected samples a ball needs for its own circle.
_MIN_SAMPLES = 20


@dataclass(frozen=True)
class LobeShift:
    """One ball's circle centre off the common one: the shift (px) and its standard error (px)."""

    du: float
    dv: float
    se: float

    @property
    def size(self) -> float:
        """Length of the shift (px)."""
        return float(np.hypot(self.du, self.dv))


def _own_centre(u: np.ndarray, v: np.ndarray, centre: tuple[float, float], radius: float) -> LobeShift:
    """Centre of the circle of ``radius`` through (u, v), by Gauss-Newton from ``centre``; shift and its error.

    Along an arc too short to fix the shift's component across it, the minimum-norm step leaves that part 0.
    """
    c = np.array(centre, dtype=np.float64)
    jac = np.zeros((u.size, 2))
    res = np.zeros(u.size)
    for _ in range(10):
        du, dv = u - c[0], v - c[1]
        rho = np.maximum(np.hypot(du, dv), 1e-9)
        res = rho - radius
        jac = np.column_stack([-du / rho, -dv / rho])
        step, *_ = np.linalg.lstsq(jac, -res, rcond=1e-3)
        c += step
        if float(np.hypot(*step)) < 1e-6:
            break
    sigma2 = float(np.sum(res**2)) / max(u.size - 2, 1)
    info = jac.T @ jac
    shift = c - np.asarray(centre)
    # Standard error along the shift's direction (the direction the test is about).
    d = shift / max(float(np.hypot(*shift)), 1e-12)
    var = float(d @ np.linalg.pinv(info, rcond=1e-3) @ d) * sigma2
    return LobeShift(float(shift[0]), float(shift[1]), float(np.sqrt(max(var, 0.0))))


def _grid(table: pd.DataFrame, col: str) -> np.ndarray:
    z = int(table.ball.max()) + 1
    return table.sort_values(["frame", "ball"], kind="stable")[col].to_numpy().reshape(-1, z)


def ball_shifts(u: npt.ArrayLike, v: npt.ArrayLike, ok: npt.ArrayLike) -> list[LobeShift | None]:
    """Each ball's :class:`LobeShift` off the common circle of the balls' positions (T, Z): its own centre, with
    the radius of the circle through all positions held, from the median of the balls' centres; None with too
    few samples."""
    u, v, ok = np.asarray(u, float), np.asarray(v, float), np.asarray(ok, bool) & np.isfinite(u) & np.isfinite(v)
    cx, cy, radius, _ = fit_circle(u[ok], v[ok])
    own = [_own_centre(u[ok[:, j], j], v[ok[:, j], j], (cx, cy), radius) if ok[:, j].sum() >= _MIN_SAMPLES
           else None for j in range(u.shape[1])]
    fitted = [s for s in own if s is not None]
    if not fitted:
        return own
    # From the balls' median centre, not the fit to all of them: a ball on another lobe pulls that fit by its
    # shift over Z (0.5 px at seed 7605), the median not at all while most balls share a lobe.
    mu = float(np.median([s.du for s in fitted]))
    mv = float(np.median([s.dv for s in fitted]))
    return [None if s is None else LobeShift(s.du - mu, s.dv - mv, s.se) for s in own]


def _off_lobe(shifts: list[LobeShift | None], sigma_px: float) -> list[int]:
    """Balls whose circle is shifted by more than a lobe could be from the others' (see the module docstring)."""
    off = [j for j, s in enumerate(shifts)
           if s is not None and s.size > MIN_SHIFT_SIGMAS * sigma_px and s.size > MIN_T * s.se]
    fitted = sum(s is not None for s in shifts)
    return off if fitted - len(off) > fitted / 2 else []


def _fill_from_other_lobe(u: np.ndarray, v: np.ndarray, mass: np.ndarray, det: np.ndarray, nu: np.ndarray,
                          nv: np.ndarray, nm: np.ndarray, nd: np.ndarray, kept: list[int]) -> None:
    """Fill, in place, the samples of the moved balls that re-measuring missed: the other lobe's position moved by
    the ball's lobe offset, the median of (other lobe - re-measured) over the frames that have both.

    A lobe's offset from the ball's centre is fixed in the image (distant lights), so the offset measured where
    both lobes were found carries the track across frames where only the other lobe was (the first lobe hidden
    or too faint there); without it those samples were lost (40 % of one ball's with the first lobe missing in
    2 frames of 5, ``tests/tracking/test_lobes.py``). Samples the linker had not detected stay missed (NaN).
    """
    for j in kept:
        both = nd[:, j] & det[:, j]
        miss = ~nd[:, j]
        du = float(np.median(u[both, j] - nu[both, j]))
        dv = float(np.median(v[both, j] - nv[both, j]))
        nu[miss, j] = np.where(det[miss, j], u[miss, j] - du, np.nan)
        nv[miss, j] = np.where(det[miss, j], v[miss, j] - dv, np.nan)
        nm[miss, j] = np.where(det[miss, j], mass[miss, j], 0.0)
        nd[miss, j] = det[miss, j]


def relock_lobes(table: pd.DataFrame, frames: Callable[[int], np.ndarray], background: np.ndarray,
                 mask: np.ndarray, half: float, threshold: float, iterations: int, sigma_px: float,
                 static: tuple[np.ndarray, float, np.ndarray] | None = None) -> tuple[pd.DataFrame, list[int]]:
    """``table`` (the linker's, cropped pixels) with every ball on another light's lobe moved onto the others'.

    Parameters
    ----------
    table
        Track table (``frame`` 0..T-1, ``ball``, ``u_px``, ``v_px``, ``mass``, ``detected``).
    frames
        ``frames(i)``: cropped frame ``i``.
    background, mask, half, threshold, iterations, static
        The centroid's arguments, as the linker uses them (:func:`cageless.tracking.detect.centroid_windows`).
    sigma_px
        The highlight's Gaussian width (px).

    Returns
    -------
    table, moved
        The table (a new one when a ball moved) and the balls moved.
    """
    u, v, det = _grid(table, "u_px"), _grid(table, "v_px"), _grid(table, "detected").astype(bool)
    shifts = ball_shifts(u, v, det)
    off = _off_lobe(shifts, sigma_px)
    if not off:
        return table, []
    mass = _grid(table, "mass")
    nu, nv, nm, nd = u.copy(), v.copy(), mass.copy(), det.copy()
    for i in range(u.shape[0]):
        frame = frames(i)
        pu = np.array([u[i, j] - shifts[j].du for j in off])  # type: ignore[union-attr]
        pv = np.array([v[i, j] - shifts[j].dv for j in off])  # type: ignore[union-attr]
        mu, mv, mm = centroid_windows(frame, background, mask, pu, pv, half, threshold, iterations, static=static)
        good = (mm > 0) & (np.hypot(mu - pu, mv - pv) <= half) & det[i, off]
        for k, j in enumerate(off):
            nu[i, j], nv[i, j] = (mu[k], mv[k]) if good[k] else (pu[k], pv[k])
            nm[i, j], nd[i, j] = (mm[k] if good[k] else 0.0), bool(good[k])
    after = ball_shifts(nu, nv, nd)
    kept = [j for j in off if after[j] is not None and j not in _off_lobe(after, sigma_px)
            and after[j].size < MIN_SHIFT_SIGMAS * sigma_px]  # type: ignore[union-attr]
    if not kept:
        log.info("balls %s look shifted onto another lobe, but re-measuring did not bring them back", off)
        return table, []
    _fill_from_other_lobe(u, v, mass, det, nu, nv, nm, nd, kept)
    out = table.sort_values(["frame", "ball"], kind="stable").reset_index(drop=True)
    z = u.shape[1]
    for name, grid in (("u_px", nu), ("v_px", nv), ("mass", nm), ("detected", nd)):
        col = out[name].to_numpy().reshape(-1, z).copy()
        col[:, kept] = grid[:, kept]
        out[name] = col.ravel()
    log.info("balls %s were tracked on another light's highlight; moved by %s px", kept,
             [round(shifts[j].size, 2) for j in kept])  # type: ignore[union-attr]
    return out, kept
