"""Stage 3: follow every ball through the video, keeping its identity.

Balls cannot pass each other, so identities come from the cyclic order. The
tracker starts at the first frame where full detection finds all Z balls,
numbers them counter-clockwise about the highlight circle, and then, frame by
frame, predicts each ball's angle with a constant-angular-velocity model and
measures it in a small window around the prediction (detector ``"window"``), or
re-detects the whole frame and assigns detections to the nearest predicted angle
(``"weighted"`` and ``"mask"``). A ball whose window comes up empty coasts on
its prediction and is marked missing; after a few misses the frame is searched
in full. Detections no ball claims are dropped. Frames before the start frame
are tracked backwards in time; with the selection's anchors, from a frame :data:`SETTLE_FRAMES`
after it, so that the frames the windows took to settle are tracked again.

The result is the table :data:`TRACK_COLUMNS` (one row per frame and ball).
"""

from __future__ import annotations

import logging
import math
import warnings
from collections.abc import Callable, Iterator
import dataclasses
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import numpy.typing as npt
import pandas as pd

from cageless.errors import TrackingError
from cageless.tracking.candidates import find_candidates
from cageless.tracking.detect import Detections, DetectorParams, centroid_windows, compiled_static, detect_full
from cageless.tracking.link_kernel import MAX_MASS_RATIO, REDETECT_AFTER, WIDEN_AFTER, run_block
from cageless.tracking.locate import fit_circle
from cageless.tracking.select import Anchor, BallRing, anchor_at

__all__ = ["TRACK_COLUMNS", "TrackSetup", "BallCountWarning", "track_frames", "find_start"]

log = logging.getLogger(__name__)

TRACK_COLUMNS = ("frame", "time_s", "ball", "u_px", "v_px", "mass", "detected")

#: Consecutive misses after which a ball is looked for in a doubled window, and after which the
#: whole frame is searched (a highlight dropout lasts a few frames; the prediction stays good).
_WIDEN_AFTER = WIDEN_AFTER
_REDETECT_AFTER = REDETECT_AFTER
#: A window whose mass exceeds this multiple of the ball's usual mass has caught something brighter
#: than a highlight (the ring face between two balls) and counts as a miss.
_MAX_MASS_RATIO = MAX_MASS_RATIO
#: Frames per block handed to the compiled step when the frame source cannot give blocks itself.
_BLOCK = 32
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
    ring: BallRing | None = None  # the chosen ball circle (tracking.select); None: the count-based start
    anchors: tuple[Anchor, ...] = ()  # chosen highlights in sampled frames (absolute frame numbers)
    static: tuple[np.ndarray, float] | None = None  # (pattern, clip) subtracted from the frames (detect.static_pattern)

    @cached_property
    def static_compiled(self) -> tuple[np.ndarray, float, np.ndarray]:
        """``static`` in the compiled centroid's form, with its summed-area table (built once per clip)."""
        return compiled_static(self.static)


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
    if s.ring is not None:
        return _ring_detections(frame, s)
    return detect_full(frame, s.background, s.mask, s.sigma_noise, s.params, s.highlight_sigma or None,
                       s.max_area_px, s.n_balls)


def _ring_detections(frame: np.ndarray, s: TrackSetup,
                     near: tuple[np.ndarray, np.ndarray] | None = None) -> Detections:
    """Blob candidates on the chosen ball circle, measured by weighted centroids.

    With ``near`` (predicted positions), only patches around them are searched: a third of the ball
    spacing along the circle each way, the per-frame cost of a miss.
    """
    ring = s.ring
    assert ring is not None
    if near is None:
        boxes = [(0, frame.shape[0], 0, frame.shape[1])]
    else:
        h = int(math.ceil(ring.radius * 2 * math.pi / s.n_balls / 3 + 4 * ring.sigma_px))
        boxes = [(max(int(v) - h, 0), min(int(v) + h + 1, frame.shape[0]),
                  max(int(u) - h, 0), min(int(u) + h + 1, frame.shape[1])) for u, v in zip(*near, strict=True)]
    us, vs = [], []
    for y0, y1, x0, x1 in boxes:
        if y1 - y0 < 3 or x1 - x0 < 3:
            continue
        c = find_candidates(frame[y0:y1, x0:x1], s.background[y0:y1, x0:x1], s.mask[y0:y1, x0:x1], ring.sigma_px,
                            ring.k_sigma, 4 * s.n_balls + 8, ring.response_sigma)
        cu, cv = c.u + x0, c.v + y0
        on = np.abs(np.hypot(cu - ring.centre[0], cv - ring.centre[1]) - ring.radius) <= ring.radial_tol_px
        us.append(cu[on])
        vs.append(cv[on])
    if not us:
        return Detections(*(np.zeros(0),) * 4)
    return _measure(frame, s, np.concatenate(us), np.concatenate(vs))


def _measure(frame: np.ndarray, s: TrackSetup, u0: np.ndarray, v0: np.ndarray) -> Detections:
    half = s.params.window_sigma * max(s.highlight_sigma, 1.0)
    u, v, m = centroid_windows(frame, s.background, s.mask, u0, v0, half, s.params.weight_sigma * s.sigma_noise,
                               s.params.iterations, static=s.static_compiled)
    ok = m > 0
    return Detections(u[ok], v[ok], m[ok], np.full(int(ok.sum()), s.highlight_sigma))


def _anchor_start(frames: Callable[[int], np.ndarray], times: npt.NDArray[np.float64], s: TrackSetup,
                  offset: int, path: str) -> tuple[int, Detections, np.ndarray]:
    """Start frame, detections (cyclic order) and image angular speeds from the selection's anchors."""
    n = len(times)
    inside = [a for a in s.anchors if offset <= a.frame < offset + n]
    anchor = inside[0] if inside else None
    if anchor is not None:
        anchor = Anchor(anchor.frame - offset, anchor.u, anchor.v, anchor.omega)
    else:
        assert s.ring is not None
        anchor = anchor_at(frames, times, s.background, s.mask, s.ring)
    if anchor is None:
        raise TrackingError(path, f"could not find the {s.n_balls} balls again at frame {offset}.",
                            "Track with one thread, or check the clip for a change of view.")
    frame = frames(anchor.frame)
    half = s.params.window_sigma * max(s.highlight_sigma, 1.0)
    u, v, m = centroid_windows(frame, s.background, s.mask, anchor.u, anchor.v, half,
                               s.params.weight_sigma * s.sigma_noise, s.params.iterations, static=s.static_compiled)
    bad = ~(m > 0) | (np.hypot(u - anchor.u, v - anchor.v) > half)
    u, v = np.where(bad, anchor.u, u), np.where(bad, anchor.v, v)
    m = np.where(bad, np.nanmedian(np.where(bad, np.nan, m)) if (~bad).any() else 1.0, m)
    det = Detections(u, v, m, np.full(u.size, s.highlight_sigma))
    return anchor.frame, det, anchor.omega


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
                 progress: Callable[[int], None] | None = None,
                 offset: int = 0, compiled: bool = True) -> tuple[pd.DataFrame, tuple[float, float]]:
    """Track all frames; return the track table and the highlight-circle centre used for prediction.

    ``frames(i)`` returns frame ``i`` (cropped like ``s.background``); ``progress(k)`` is called
    with the number of frames done since the last call. ``offset`` is the absolute number of frame 0
    (for a segment of a longer video). With a chosen ball circle (``s.ring``) tracking starts from
    the selection's anchors; without, from the first frame showing the expected count. With the
    ``"window"`` detector the frames go through the compiled step in blocks (``compiled=False``: the
    Python step on every frame, the reference it is tested against).
    """
    n = len(times)
    omega0 = None
    if s.ring is not None:
        start, det, omega0 = _anchor_start(frames, times, s, offset, path)
        z = s.n_balls
        centre = s.ring.centre
    else:
        start, det, z = find_start(frames, n, s, path, strict)
        cx, cy, _, _ = fit_circle(det.u, det.v)
        centre = (cx, cy)
    s = dataclasses.replace(s, n_balls=z)
    th0 = _angles(det.u, det.v, centre)
    order = np.argsort(th0)
    u = np.full((n, z), np.nan)
    v = np.full((n, z), np.nan)
    mass = np.zeros((n, z))
    u[start], v[start], mass[start] = det.u[order], det.v[order], det.mass[order]
    omega = np.zeros(z) if omega0 is None else np.asarray(omega0, dtype=np.float64)[order]
    init = _State(theta=th0[order], radius=np.hypot(det.u - centre[0], det.v - centre[1])[order], omega=omega,
                  misses=np.zeros(z, dtype=int), ref_mass=det.mass[order].copy(), t=float(times[start]))
    if progress:
        progress(1)
    _run(frames, times, init, s, centre, (u, v, mass), start, 1, progress, compiled)
    back, redo = init, 0
    if s.ring is not None:  # backwards from where the forward pass has settled (see _settled_state)
        settled = _settled_state(times, u, v, mass, centre, start)
        if settled is not None:
            redo = settled[0] - start  # frames the forward pass has already counted
            start, back = settled
    _run(frames, times, back, s, centre, (u, v, mass), start, -1, _skip_first(progress, redo), compiled)
    t_col = np.repeat(times, z)
    table = pd.DataFrame({
        "frame": np.repeat(np.arange(n), z), "time_s": t_col, "ball": np.tile(np.arange(z), n),
        "u_px": u.ravel(), "v_px": v.ravel(), "mass": mass.ravel(), "detected": np.isfinite(u).ravel(),
    })
    return table, centre


#: Frames after the start at which the backward pass starts, with the state the forward pass reached there.
SETTLE_FRAMES = 16


def _settled_state(times: npt.NDArray[np.float64], u: np.ndarray, v: np.ndarray, mass: np.ndarray,
                   centre: tuple[float, float], start: int) -> tuple[int, _State] | None:
    """The frame :data:`SETTLE_FRAMES` or more after ``start`` where the forward pass found every ball, and the
    state there (angles, radii, speeds over the 5 frames up to it, masses), to track the frames before it again.

    The centroid windows start on the selection's anchors, which a doubled highlight can place between or on
    the other of its two lobes; the windows then slide over a few frames to the fixed point they keep (FRESH2
    seed 7209, two saturated lights 10 px apart: frames 0-2 measured 32, 20 and 2.6 mrad off, the rest under
    0.8). Tracked backwards from a frame where the windows have settled, those first frames are measured
    like every other. ``None`` when no such frame follows (then the backward pass starts at ``start``).
    """
    full = np.flatnonzero(np.isfinite(u).all(axis=1))
    later = full[full >= start + SETTLE_FRAMES]
    if later.size == 0:
        return None
    k = int(later[0])
    recent = np.arange(max(k - 4, start), k + 1)
    th = np.unwrap(_angles(u[recent], v[recent], centre), axis=0)
    ok = np.isfinite(th)
    omega = np.empty(u.shape[1])
    for j in range(u.shape[1]):
        if ok[:, j].sum() < 2:
            return None
        omega[j] = np.polyfit(times[recent][ok[:, j]], th[ok[:, j], j], 1)[0]
    seen = np.where(mass[start:k + 1] > 0, mass[start:k + 1], np.nan)
    state = _State(theta=_angles(u[k], v[k], centre), radius=np.hypot(u[k] - centre[0], v[k] - centre[1]),
                   omega=omega, misses=np.zeros(u.shape[1], dtype=int), ref_mass=np.nanmedian(seen, axis=0),
                   t=float(times[k]))
    return k, state


def _skip_first(progress: Callable[[int], None] | None, k: int) -> Callable[[int], None] | None:
    """``progress`` that ignores the first ``k`` frames reported (frames tracked a second time)."""
    if progress is None or k <= 0:
        return progress
    left = [k]

    def report(m: int) -> None:
        use = max(0, m - left[0])
        left[0] = max(0, left[0] - m)
        if use:
            progress(use)

    return report


def _run(frames: Callable[[int], np.ndarray], times: npt.NDArray[np.float64], init: _State, s: TrackSetup,
         centre: tuple[float, float], out: tuple[np.ndarray, np.ndarray, np.ndarray], start: int, direction: int,
         progress: Callable[[int], None] | None, compiled: bool) -> None:
    """Track from ``start`` (excluded) to the end (``direction`` 1) or to frame 0 (-1), from a copy of ``init``."""
    state = _State(**{k: (val.copy() if isinstance(val, np.ndarray) else val) for k, val in init.__dict__.items()})
    if compiled and s.params.method == "window":
        _run_compiled(frames, times, state, s, centre, out, start, direction, progress)
        return
    rng = range(start + 1, len(times)) if direction == 1 else range(start - 1, -1, -1)
    for i in rng:
        _step(frames(i), float(times[i]), state, s, centre, out, i)
        if progress:
            progress(1)


def _blocks(frames: Callable[[int], np.ndarray], n: int, start: int,
            direction: int) -> Iterator[tuple[int, np.ndarray]]:
    """``(a, block)`` pairs, ``block[k]`` being frame ``a + k``, covering the frames after ``start`` (``direction``
    1) or before it (-1), in tracking order: from the frame source's own blocks (``frames.block``) when it has
    them, else stacked frame by frame."""
    size = int(getattr(frames, "block_size", _BLOCK))
    edges = range(start - start % size, n, size) if direction == 1 else range(start - start % size, -1, -size)
    for a in edges:
        b = min(a + size, n)
        block_of = getattr(frames, "block", None)
        yield a, (block_of(a, b) if block_of is not None else np.stack([frames(i) for i in range(a, b)]))


def _run_compiled(frames: Callable[[int], np.ndarray], times: npt.NDArray[np.float64], st: _State, s: TrackSetup,
                  centre: tuple[float, float], out: tuple[np.ndarray, np.ndarray, np.ndarray], start: int,
                  direction: int, progress: Callable[[int], None] | None) -> None:
    """The ``"window"`` loop: blocks of frames through the compiled step
    (:func:`~cageless.tracking.link_kernel.run_block`), with the Python :func:`_step` for the frames it hands back."""
    n = len(times)
    times = np.ascontiguousarray(times, dtype=np.float64)
    half = s.params.window_sigma * s.highlight_sigma
    thr = s.params.weight_sigma * s.sigma_noise
    static = s.static_compiled
    for a, block in _blocks(frames, n, start, direction):
        k0 = (max(start + 1, a) if direction == 1 else min(start - 1, a + len(block) - 1)) - a
        k1 = len(block) if direction == 1 else -1
        while k0 != k1:
            arrays = [np.ascontiguousarray(x, dtype=d) for x, d in
                      ((st.theta, np.float64), (st.radius, np.float64), (st.omega, np.float64),
                       (st.misses, np.int64), (st.ref_mass, np.float64))]
            st.theta, st.radius, st.omega, st.misses, st.ref_mass = arrays
            t_state = np.array([st.t])
            k = run_block(block, k0, k1, direction, a, times, s.background, s.mask, float(centre[0]), float(centre[1]),
                          float(half), float(thr), int(s.params.iterations), float(s.params.lost_fraction),
                          s.ring is not None, *arrays, t_state, *out, static)
            st.t = float(t_state[0])
            if k != k1:  # a frame the compiled step leaves to Python
                _step(block[k], float(times[a + k]), st, s, centre, out, a + k)
                k += direction
            if progress:
                progress(abs(k - k0))
            k0 = k


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
        # With a chosen ball circle, a ball missing for a few frames is looked for among the blob
        # candidates on that circle near its prediction (a wider centroid window could slide onto the
        # bright ring face seen between two balls).
        widen = st.misses >= _WIDEN_AFTER
        grow = np.where((st.omega == 0.0) | (widen & (s.ring is None)), 2.0, 1.0)
        thr = s.params.weight_sigma * s.sigma_noise
        if np.any(grow > 1.0):
            fu, fv, _ = centroid_windows(frame, s.background, s.mask, pu, pv, half * grow, thr, 1,
                                         static=s.static_compiled)
            pu, pv = np.where(np.isfinite(fu), fu, pu), np.where(np.isfinite(fv), fv, pv)
        mu, mv, mm = centroid_windows(frame, s.background, s.mask, pu, pv, half, thr, s.params.iterations,
                                      static=s.static_compiled)
        ok = (mm >= s.params.lost_fraction * st.ref_mass) & (np.hypot(mu - pu, mv - pv) <= half)
        if s.ring is not None:
            ok &= mm <= _MAX_MASS_RATIO * st.ref_mass
            look = ~ok & (st.misses + 1 >= _WIDEN_AFTER)
            if np.any(look):
                det = _ring_detections(frame, s, (pu[look], pv[look]))
                mu, mv, mm, ok = _assign(det, pred, centre, st, s, mu, mv, mm, ok)
        elif np.any(st.misses[~ok] + 1 >= _REDETECT_AFTER):
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
