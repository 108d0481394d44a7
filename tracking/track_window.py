"""The track fit's window chosen from the data: leave-one-out cross-validation over a ladder of windows.

Each ball's angle is read from a robust local quadratic over an odd number of frames
(:func:`~cageless.tracking.kinematics.robust_track_fit`). A short window follows fast changes of speed (a
ball-ball impact is a kink in the angle) but passes more of the localisation noise: white scatter of
``sigma`` comes through as ``sqrt(h) sigma``, with ``h`` the centre sample's leverage (0.33 for 7 frames, 0.11
for 21, 0.055 for 41); a long one is quiet but smooths the kinks. Which wins depends on the clip: on the
tuning corpus the best fixed window ran from 7 frames (clips with bunching balls and frequent impacts) to over
31 (compressed clips whose error is frame-to-frame scatter).

So the window is chosen per clip by cross-validation (Stone 1974; for local polynomial smoothers e.g.
Fan & Gijbels 1996, sec. 4.2): for each window ``n`` of :data:`LADDER`, every sample's leave-one-out residual
of the fit, ``(y - fit) / (1 - h)``, pooled over the balls; the window with the least mean square wins. ``h``
is the sample's leverage in its window's quadratic with the samples the robust fit dropped left out
(:func:`_leverage`; the identity is exact for a weighted linear smoother, and the biweight's weights of the
samples it keeps are close to 1). It estimates each window's prediction error, the noise plus the
smoothing's bias, from the data alone: where impacts make the motion change within a long window, its
residuals grow and a short window is kept.

The samples scored are the same for every window: measured, kept by the shortest window's fit (so a long
window that drops the samples it cannot follow, at an impact, is still charged for them) and at least
``max(LADDER) // 2`` frames from a block's end. On long clips :data:`BLOCKS` blocks of :data:`BLOCK_FRAMES`
frames spread over the clip are scored, which bounds the cost (10 fits of 1,000 frames: 0.2 s of CPU for
14 balls). The fits of the (block, window) pairs are independent and shared among ``workers`` threads (the
compiled fit releases the GIL); their scores are summed in the same order whatever the number, so the choice
and its record are the same bits.

Public API::

    choose_track_fit(time_s, angle, valid, ladder=LADDER) -> TrackFitChoice
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import Any

import numpy as np
import numpy.typing as npt

from cageless.tracking.kinematics import DEFAULT_TRACK_FIT, robust_track_fit

__all__ = ["LADDER", "BLOCKS", "BLOCK_FRAMES", "TrackFitChoice", "choose_track_fit"]

#: Candidate windows (frames): 7 (the fixed default before) to 41 (4.1 ms at 10,000 frames/s).
LADDER = (7, 9, 11, 13, 15, 17, 21, 25, 31, 41)
#: Blocks of frames scored on a long clip, spread evenly over it, and their length (frames).
BLOCKS = 4
BLOCK_FRAMES = 250
#: Cap on a sample's leverage (a window that kept only 3 samples fits them exactly).
_MAX_LEVERAGE = 0.9
#: A window is a candidate only if the clip (or block) holds this many times its length.
_MIN_SPANS = 4


@dataclass(frozen=True)
class TrackFitChoice:
    """The chosen window and what chose it.

    Attributes
    ----------
    frames
        The chosen window (frames).
    ladder
        The windows compared (frames).
    cv_mrad
        Each window's root mean square leave-one-out residual (mrad), same order as ``ladder``.
    samples
        Samples scored (the same for every window).
    """

    frames: int
    ladder: tuple[int, ...]
    cv_mrad: tuple[float, ...]
    samples: int

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready record for QC."""
        return {"frames": self.frames, "ladder": list(self.ladder),
                "cv_mrad": [round(v, 5) for v in self.cv_mrad], "samples": self.samples}


def _blocks(n_frames: int) -> list[slice]:
    if n_frames <= BLOCKS * BLOCK_FRAMES:
        return [slice(0, n_frames)]
    starts = np.linspace(0, n_frames - BLOCK_FRAMES, BLOCKS).round().astype(int)
    return [slice(int(s), int(s) + BLOCK_FRAMES) for s in starts]


def _leverage(keep: np.ndarray, frames: int) -> np.ndarray:
    """Each sample's leverage in its own window's quadratic, with the samples the fit dropped (``keep``
    False) at weight 0 and the others at 1, shape (T, Z); :func:`centre_leverage` where none was dropped.
    A dropped sample has leverage 0 (its fit is already a prediction without it). Exact at the interior
    samples (those scored); the ends, where the window slides inwards, get the centred window's value."""
    w = keep.astype(np.float64)
    m = frames // 2
    x = np.arange(-m, m + 1, dtype=np.float64)
    padded = np.pad(w, ((m, m), (0, 0)))
    win = np.lib.stride_tricks.sliding_window_view(padded, frames, axis=0)  # (T, Z, frames)
    s0, s1, s2, s3, s4 = (win @ x**p for p in range(5))
    det = s0 * (s2 * s4 - s3 * s3) - s1 * (s1 * s4 - s2 * s3) + s2 * (s1 * s3 - s2 * s2)
    with np.errstate(divide="ignore", invalid="ignore"):
        h = np.where(det > 1e-9 * s4**3, (s2 * s4 - s3 * s3) / det, 1.0) * w
    return np.minimum(h, _MAX_LEVERAGE)


def choose_track_fit(time_s: npt.ArrayLike, angle: npt.ArrayLike, valid: npt.ArrayLike,
                     ladder: tuple[int, ...] = LADDER, workers: int = 2) -> TrackFitChoice:
    """The window of :data:`LADDER` with the least leave-one-out error of the robust track fit.

    Parameters
    ----------
    time_s
        Sample times (s), shape (T,).
    angle
        Unwrapped angles (rad) before the track fit, shape (T, Z).
    valid
        Measured (True) or interpolated (False) samples, shape (T, Z).
    ladder
        Candidate windows (frames), odd, at least 5, increasing.
    workers
        Threads the trial fits are shared among (the same result with any number).

    Returns
    -------
    TrackFitChoice
        With ``frames`` = :data:`~cageless.tracking.kinematics.DEFAULT_TRACK_FIT` (and no scores) when the clip
        is too short for two candidates or no sample can be scored.
    """
    t = np.asarray(time_s, dtype=np.float64)
    a = np.asarray(angle, dtype=np.float64)
    ok = np.asarray(valid, dtype=bool)
    blocks = _blocks(len(t))
    span = min(b.stop - b.start for b in blocks)
    cands = tuple(n for n in ladder if _MIN_SPANS * n <= span)
    if len(cands) < 2:
        return TrackFitChoice(DEFAULT_TRACK_FIT, cands, (), 0)
    edge = max(cands) // 2
    trials = _trial_residuals(t, a, ok, blocks, cands, workers)
    sse = np.zeros(len(cands))
    count = 0
    for k, b in enumerate(blocks):
        res = np.stack([trials[k * len(cands) + i][0] for i in range(len(cands))])
        scored = ok[b] & trials[k * len(cands)][1]  # kept by the shortest window's fit
        scored[:edge] = False
        scored[len(scored) - edge:] = False
        sse += np.where(scored, res * res, 0.0).sum(axis=(1, 2))
        count += int(scored.sum())
    if count == 0:
        return TrackFitChoice(DEFAULT_TRACK_FIT, cands, (), 0)
    cv = np.sqrt(sse / count)
    return TrackFitChoice(int(cands[int(np.argmin(cv))]), cands, tuple(float(1e3 * v) for v in cv), count)


def _trial_residuals(t: np.ndarray, a: np.ndarray, ok: np.ndarray, blocks: list[slice], cands: tuple[int, ...],
                     workers: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """Each (block, window) pair's leave-one-out residuals and kept samples, block-major, on ``workers``
    threads."""
    def one(job: tuple[slice, int]) -> tuple[np.ndarray, np.ndarray]:
        b, n = job
        fit, keep = robust_track_fit(t[b], a[b], ok[b], n, workers=1)
        return (a[b] - fit) / (1.0 - _leverage(keep, n)), keep

    jobs = [(b, n) for b in blocks for n in cands]
    if workers <= 1:
        return [one(job) for job in jobs]
    with ThreadPoolExecutor(max_workers=workers) as pool:
        return list(pool.map(one, jobs))
