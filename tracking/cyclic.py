"""Choose Z points on a circle with a minimum cyclic spacing and the greatest total weight (the ball selection's
global assignment, :func:`cageless.tracking.select.select_balls`)."""

from __future__ import annotations

import math

import numpy as np
import numpy.typing as npt

__all__ = ["cyclic_select"]


def cyclic_select(angles: npt.ArrayLike, weights: npt.ArrayLike, z: int, gap: float
                  ) -> tuple[npt.NDArray[np.int64] | None, int]:
    """Choose ``z`` points on a circle, cyclic neighbours at least ``gap`` rad apart, of greatest total weight.

    A dynamic programme over the cyclic order: for each choice of first point, the best total of k
    points ending at point j is its weight plus the best total of k-1 points ending at least ``gap``
    before it (a prefix maximum), and the last point must end ``gap`` before the first point comes round
    again. O(n^2 z) for n points.

    Returns
    -------
    chosen, max_count
        Indices of the chosen points (or None when ``z`` do not fit), and the most points the spacing allows.
    """
    a = np.mod(np.asarray(angles, dtype=np.float64), 2 * math.pi)
    w = np.asarray(weights, dtype=np.float64)
    n = a.size
    if n == 0:
        return None, 0
    order = np.argsort(a, kind="stable")
    a, w = a[order], w[order]
    best_val, best_pick, max_count = -np.inf, None, 0
    two_pi = 2 * math.pi
    for s in range(n):
        idx = (np.arange(n) + s) % n
        rel = a[idx] + two_pi * ((np.arange(n) + s) >= n) - a[s]
        ww = w[idx]
        allowed = rel <= two_pi - gap + 1e-12
        allowed[1:] &= rel[1:] >= gap - 1e-12
        max_count = max(max_count, _greedy_count(rel, gap))
        last = np.searchsorted(rel, rel - gap + 1e-12, side="right") - 1
        dp = np.full(n, -np.inf)
        dp[0] = ww[0]
        back = []
        for _ in range(1, z):
            pm = np.maximum.accumulate(dp)
            arg = _prefix_argmax(dp)
            src = np.where(last >= 0, last, 0)
            new = np.where((last >= 0) & allowed, pm[src] + ww, -np.inf)
            new[0] = -np.inf
            back.append(arg[src])
            dp = new
        j = int(np.argmax(dp))
        if np.isfinite(dp[j]) and dp[j] > best_val:
            pick = [j]
            for b in reversed(back):
                j = int(b[j])
                pick.append(j)
            best_val, best_pick = float(dp[pick[0]]), order[idx[np.array(pick[::-1])]]
    return best_pick, max_count


def _prefix_argmax(x: np.ndarray) -> np.ndarray:
    """Index of the first maximum of ``x[:i + 1]`` for every i (x without NaN): each element that beats every
    element before it starts a new run."""
    if x.size == 0:
        return np.zeros(0, dtype=np.int64)
    beats = np.empty(x.size, dtype=bool)
    beats[0] = True
    beats[1:] = x[1:] > np.maximum.accumulate(x)[:-1]
    return np.maximum.accumulate(np.where(beats, np.arange(x.size), 0))


def _greedy_count(rel: np.ndarray, gap: float) -> int:
    """Most points (starting with point 0) at least ``gap`` apart, the last ``gap`` before 2 pi."""
    count, last = 1, 0.0
    for r in rel[1:]:
        if r - last >= gap - 1e-12 and r <= 2 * math.pi - gap + 1e-12:
            count, last = count + 1, r
    return count
