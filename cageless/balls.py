"""Ball numbering and angle conventions shared by tracking, rendering and simulation.

Balls are numbered 0..Z-1 counter-clockwise; ball 0 is the ball just after the
largest gap at the start. Unwrapped angles start with ball 0 in [0, 2 pi) and
each next ball ahead of the previous one, so the cyclic order reads off the columns.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

__all__ = ["ball_order", "normalise_unwrapped"]


def ball_order(first_angles: npt.ArrayLike) -> npt.NDArray[np.int64]:
    """Column order that numbers balls counter-clockwise from the ball after the largest gap, from their angles (rad) at the start.

    ``order[k]`` is the column that becomes ball k: counter-clockwise, starting with the ball just
    after the largest gap.
    """
    a = np.mod(np.asarray(first_angles, dtype=np.float64), 2 * np.pi)
    ccw = np.argsort(a)
    gaps = np.diff(np.concatenate([a[ccw], [a[ccw][0] + 2 * np.pi]]))
    return np.roll(ccw, -((int(np.argmax(gaps)) + 1) % len(ccw)))


def normalise_unwrapped(angle: npt.ArrayLike) -> npt.NDArray[np.float64]:
    """Shift each column of unwrapped angles (T, Z) by whole turns: ball 0 starts in [0, 2 pi) and
    every next ball starts ahead of (and within one turn of) the previous one."""
    out = np.array(angle, dtype=np.float64, copy=True)
    out -= 2 * np.pi * np.floor(out[0, 0] / (2 * np.pi))
    for j in range(1, out.shape[1]):
        out[:, j] -= 2 * np.pi * np.floor((out[0, j] - out[0, j - 1]) / (2 * np.pi))
    return out
