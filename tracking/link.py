"""Stage 3: follow every ball through the video, keeping its identity (DESIGN §8.4).

Balls cannot pass each other, so identities come from the cyclic order. The
tracker starts at the first frame where full detection finds all Z balls,
numbers them counter-clockwise about the highlight circle, and then, frame by
frame, predicts each ball's angle with a constant-angular-velocity model and
measures it in a small window around the prediction (detector ``"window"``), or
re-detects the whole frame and assigns detections to the nearest predicted angle
(``"weighted"`` and ``"mask"``). A ball whose window comes up empty coasts on
its prediction and is marked missing; after a few misses the frame is searched
in full. Detections no ball claims are dropped. Frames before the start frame
are tracked backwards in time.

The result is the table :data:`TRACK_COLUMNS` (one row per frame and ball).
"""

from __future__ import annotations

import logging
import math
import warnings
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
import pandas as pd

from cageless.errors import TrackingError
from tracking.detect import Detections, DetectorParams, centroid_windows, detect_full
from tracking.locate import fit_circle

__all__ = ["TRACK_COLUMNS", "TrackSetup", "BallCountWarning", "track_frames", "find_start"]

log = logging.getLogger(__name__)

TRACK_COLUMNS = ("frame", "time_s", "ball", "u_px", "v_px", "mass", "detected")

#: Consecutive misses after which a ball is looked for in a doubled window, and after which the
#: whole frame is searched (a highlight dropout lasts a few frames; the prediction stays good).
_WIDEN_AFTER = 3
_REDETECT_AFTER = 12
#: Frames scanned for a start frame with all balls in view.
_START_SCAN = 64


class BallCountWarning(UserWarning):
    """The video shows a different number of balls than the bearing has."""


@dataclass(frozen=True)
class TrackSetup:
    """Everything the per-frame loop needs, in the cropped image's pixel coordinates."""

    background: np.ndarray
    mask: np.ndarray
    sigma_noise: float
    highlight_sigma: float
    max_area_px: float
    n_balls: int
    params: DetectorParams


@dataclass
class _State:
    theta: np.ndarray  # angle about the circle centre (image frame, counter-clockwise), per ball
    radius: np.ndarray
    omega: np.ndarray
    misses: np.ndarray
    ref_mass: np.ndarray
    t: float


def _angles(u: np.ndarray, v: np.ndarray, c: tuple[float, float]) -> np.ndarray:
    return np.arctan2(-(v - c[1]), u - c[0])


def _full(frame: np.ndarray, s: TrackSetup) -> Detections:
    return detect_full(frame, s.background, s.mask, s.sigma_noise, s.params, s.highlight_sigma or None,
                       s.max_area_px, s.n_balls)


def find_start(frames: Callable[[int], np.ndarray], n_frames: int, s: TrackSetup, path: str,
               strict: bool) -> tuple[int, Detections, int]:
    """The first frame (of the first few) where full detection finds all balls; its detections; the ball count.

    When no scanned frame shows Z balls, the most common count is used, with a
    :class:`BallCountWarning` (or a :class:`TrackingError` under ``strict``).
    """
    counts = []
    for k in np.unique(np.linspace(0, n_frames - 1, min(n_frames, _START_SCAN)).astype(int)):
        d = _full(frames(int(k)), s)
        counts.append(len(d))
        if len(d) == s.n_balls:
            return int(k), d, s.n_balls
    found = int(np.bincount(counts).argmax()) if counts else 0
    if found < 3:
        raise TrackingError(path, f"found at most {max(counts, default=0)} ball highlights per frame; cannot track.",
                            "Check the lighting and that the balls carry specular highlights.")
    msg = f"the video shows {found} balls but the bearing has {s.n_balls}"
    if strict:
        raise TrackingError(path, msg + ".", "Check the ball count in the configuration, or drop --strict.")
    warnings.warn(f"{path}: {msg}; tracking {found}.", BallCountWarning, stacklevel=2)
    for k in np.unique(np.linspace(0, n_frames - 1, min(n_frames, _START_SCAN)).astype(int)):
        d = _full(frames(int(k)), s)
        if len(d) == found:
            return int(k), d, found
    raise TrackingError(path, msg + "; no frame shows them all.")  # pragma: no cover - the mode occurs


def track_frames(frames: Callable[[int], np.ndarray], times: npt.NDArray[np.float64], s: TrackSetup,
                 path: str = "video", strict: bool = False,
                 progress: Callable[[int], None] | None = None) -> tuple[pd.DataFrame, tuple[float, float]]:
    """Track all frames; return the track table and the highlight-circle centre used for prediction.

    ``frames(i)`` returns frame ``i`` (cropped like ``s.background``); ``progress(k)`` is called
    with the number of frames done since the last call.
    """
    n = len(times)
    start, det, z = find_start(frames, n, s, path, strict)
    s = TrackSetup(**{**s.__dict__, "n_balls": z})
    cx, cy, _, _ = fit_circle(det.u, det.v)
    centre = (cx, cy)
    th0 = _angles(det.u, det.v, centre)
    order = np.argsort(th0)
    u = np.full((n, z), np.nan)
    v = np.full((n, z), np.nan)
    mass = np.zeros((n, z))
    u[start], v[start], mass[start] = det.u[order], det.v[order], det.mass[order]
    init = _State(theta=th0[order], radius=np.hypot(det.u - cx, det.v - cy)[order], omega=np.zeros(z),
                  misses=np.zeros(z, dtype=int), ref_mass=det.mass[order].copy(), t=float(times[start]))
    if progress:
        progress(1)
    for direction in (1, -1):
        state = _State(**{k: (val.copy() if isinstance(val, np.ndarray) else val) for k, val in init.__dict__.items()})
        rng = range(start + 1, n) if direction == 1 else range(start - 1, -1, -1)
        for i in rng:
            _step(frames(i), float(times[i]), state, s, centre, (u, v, mass), i)
            if progress:
                progress(1)
    t_col = np.repeat(times, z)
    table = pd.DataFrame({
        "frame": np.repeat(np.arange(n), z), "time_s": t_col, "ball": np.tile(np.arange(z), n),
        "u_px": u.ravel(), "v_px": v.ravel(), "mass": mass.ravel(), "detected": np.isfinite(u).ravel(),
    })
    return table, centre


def _step(frame: np.ndarray, t: float, st: _State, s: TrackSetup, centre: tuple[float, float],
          out: tuple[np.ndarray, np.ndarray, np.ndarray], i: int) -> None:
    dt = t - st.t
    pred = st.theta + st.omega * dt
    pu = centre[0] + st.radius * np.cos(pred)
    pv = centre[1] - st.radius * np.sin(pred)
    half = s.params.window_sigma * s.highlight_sigma
    if s.params.method == "window":
        # Until the speed is known, widen the window by the largest plausible motion.
        # Until the speed is known, or after a few misses, find the highlight in a wider window first,
        # then measure it in the normal one.
        grow = np.where((st.omega == 0.0) | (st.misses >= _WIDEN_AFTER), 2.0, 1.0)
        thr = s.params.weight_sigma * s.sigma_noise
        if np.any(grow > 1.0):
            fu, fv, _ = centroid_windows(frame, s.background, s.mask, pu, pv, half * grow, thr, 1)
            pu, pv = np.where(np.isfinite(fu), fu, pu), np.where(np.isfinite(fv), fv, pv)
        mu, mv, mm = centroid_windows(frame, s.background, s.mask, pu, pv, half, thr, s.params.iterations)
        ok = (mm >= s.params.lost_fraction * st.ref_mass) & (np.hypot(mu - pu, mv - pv) <= half)
        if np.any(st.misses[~ok] + 1 >= _REDETECT_AFTER):
            mu, mv, mm, ok = _assign(_full(frame, s), pred, centre, st, s, mu, mv, mm, ok)
    else:
        mu, mv, mm, ok = _assign(_full(frame, s), pred, centre, st, s, None, None, None, None)
    meas = _angles(mu, mv, centre)
    new_theta = np.where(ok, pred + np.angle(np.exp(1j * (meas - pred))), pred)
    if dt != 0.0:
        rate = (new_theta - st.theta) / dt
        st.omega = np.where(ok, np.where(st.omega == 0.0, rate, 0.5 * st.omega + 0.5 * rate), st.omega)
    st.theta = new_theta
    st.radius = np.where(ok, np.hypot(mu - centre[0], mv - centre[1]), st.radius)
    st.misses = np.where(ok, 0, st.misses + 1)
    st.ref_mass = np.where(ok, 0.9 * st.ref_mass + 0.1 * mm, st.ref_mass)
    st.t = t
    u, v, mass = out
    u[i], v[i], mass[i] = np.where(ok, mu, np.nan), np.where(ok, mv, np.nan), np.where(ok, mm, 0.0)


def _assign(det: Detections, pred: np.ndarray, centre: tuple[float, float], st: _State, s: TrackSetup,
            mu: np.ndarray | None, mv: np.ndarray | None, mm: np.ndarray | None,
            ok: np.ndarray | None) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Give each ball the detection nearest its predicted angle, within a third of the ball spacing."""
    z = pred.size
    mu = np.full(z, np.nan) if mu is None else mu.copy()
    mv = np.full(z, np.nan) if mv is None else mv.copy()
    mm = np.zeros(z) if mm is None else mm.copy()
    ok = np.zeros(z, dtype=bool) if ok is None else ok.copy()
    if len(det) == 0:
        return mu, mv, mm, ok
    ang = _angles(det.u, det.v, centre)
    diff = np.abs(np.angle(np.exp(1j * (ang[None, :] - pred[:, None]))))  # (balls, detections)
    tol = (2 * math.pi / z) / 3
    taken = set()
    for j in np.argsort(diff.min(axis=1)):
        if ok[j] and s.params.method == "window":
            continue
        k = int(np.argmin(diff[j]))
        if diff[j, k] <= tol and k not in taken:
            taken.add(k)
            mu[j], mv[j], mm[j], ok[j] = det.u[k], det.v[k], det.mass[k], True
    return mu, mv, mm, ok
