"""Long videos in segments, one per thread: where they start, and joining their tables.

A video of :data:`MIN_SEGMENT` frames or more is tracked in overlapping segments (:data:`OVERLAP` frames shared),
each from its own anchor; :func:`stitch` matches the balls of neighbouring segments on the frames both tracked.
"""

from __future__ import annotations

import warnings

import numpy as np
import pandas as pd

__all__ = ["MIN_SEGMENT", "OVERLAP", "STITCH_GATE_PX", "bounds_at_anchors", "match_segments", "stitch"]

#: Shortest segment worth a thread, and the frames two segments share to match identities.
MIN_SEGMENT = 500
OVERLAP = 8


def bounds_at_anchors(bounds: np.ndarray, anchors: list[int]) -> np.ndarray:
    """Segment bounds moved onto the selection's anchor frames, for a video that is read in order only.

    A segment is tracked forward and backward from its first anchor; on a video where going back means
    decoding again from the start (MKV/MP4), every chunk before that anchor cost a decode of all the frames
    before it (a 1,009-frame MKV: 11,040 frame decodes for the whole track). Starting each segment at an
    anchor leaves only :data:`~cageless.tracking.link.SETTLE_FRAMES` to track backwards. A bound with no
    anchor within a quarter segment of it is dropped (its neighbours share the frames).
    """
    inner, out = bounds[1:-1], [int(bounds[0])]
    reach = (bounds[-1] - bounds[0]) / (len(bounds) - 1) / 4
    for b in inner:
        near = [a for a in anchors if abs(a - b) <= reach and a > out[-1]]
        if near:
            out.append(min(near, key=lambda a: (abs(a - b), a)))
    return np.array([*out, int(bounds[-1])])


#: Largest distance (px) between one ball's positions in two segments on the frames both tracked.
STITCH_GATE_PX = 2.0


def match_segments(prev_u: np.ndarray, prev_v: np.ndarray, u: np.ndarray, v: np.ndarray) -> np.ndarray | None:
    """This segment's column for each previous ball, by a minimum-cost assignment of the median distances on
    the overlap frames; ``None`` when a ball both segments saw there is matched further than the gate."""
    from scipy.optimize import linear_sum_assignment

    with warnings.catch_warnings():  # a ball missed on every overlap frame by one segment: an all-NaN median
        warnings.simplefilter("ignore", RuntimeWarning)
        d = np.nanmedian(np.hypot(prev_u[:, :, None] - u[:, None, :], prev_v[:, :, None] - v[:, None, :]), axis=0)
    seen = np.isfinite(d)
    rows, cols = linear_sum_assignment(np.where(seen, d, 1e6))  # unseen pairs only take what is left over
    if np.any(seen[rows, cols] & (d[rows, cols] > STITCH_GATE_PX)):
        return None
    mapping = np.empty_like(cols)
    mapping[rows] = cols
    return mapping


def stitch(parts: list[pd.DataFrame], spans: list[tuple[int, int]], times: np.ndarray) -> pd.DataFrame | None:
    """Join segment tables, renaming each segment's balls to the first segment's by position on the overlap;
    ``None`` when the segments disagree (ball counts, or a ball's position on the overlap)."""
    z = int(parts[0].ball.max()) + 1
    grids = []
    for part in parts:
        if int(part.ball.max()) + 1 != z:
            return None
        grids.append({c: part[c].to_numpy().reshape(-1, z) for c in ("u_px", "v_px", "mass")})
    out = {c: grids[0][c] for c in ("u_px", "v_px", "mass")}
    for (a, _), g in zip(spans[1:], grids[1:], strict=True):
        prev_u, prev_v = out["u_px"][a:], out["v_px"][a:]
        mapping = match_segments(prev_u, prev_v, g["u_px"][: len(prev_u)], g["v_px"][: len(prev_v)])
        if mapping is None:
            return None
        for c in out:
            out[c] = np.concatenate([out[c][:a], g[c][:, mapping]])
    n = len(times)
    return pd.DataFrame({
        "frame": np.repeat(np.arange(n), z), "time_s": np.repeat(times, z), "ball": np.tile(np.arange(z), n),
        "u_px": out["u_px"].ravel(), "v_px": out["v_px"].ravel(), "mass": out["mass"].ravel(),
        "detected": np.isfinite(out["u_px"]).ravel(),
    })
