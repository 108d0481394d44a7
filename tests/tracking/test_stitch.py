"""Joining the segments that long videos are tracked in on parallel threads (tracking.segments.stitch)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from cageless.tracking.segments import OVERLAP as _OVERLAP, stitch as _stitch


def _part(u: np.ndarray, v: np.ndarray, order: np.ndarray, offset: int) -> pd.DataFrame:
    """A segment's table with its balls numbered in ``order`` (column k holds ball order[k])."""
    n, z = u.shape
    uu, vv = u[:, order], v[:, order]
    return pd.DataFrame({"frame": np.repeat(np.arange(n) + offset, z), "ball": np.tile(np.arange(z), n),
                         "u_px": uu.ravel(), "v_px": vv.ravel(), "mass": np.ones(n * z)})


def _orbit(n: int, z: int = 14) -> tuple[np.ndarray, np.ndarray]:
    t = np.arange(n)[:, None] * 2e-3 + 2 * np.pi * np.arange(z)[None, :] / z
    return 400 + 300 * np.cos(t), 300 + 300 * np.sin(t)


def _split(u, v, order2):
    n = len(u)
    a = n // 2
    spans = [(0, a + _OVERLAP), (a, n)]
    parts = [_part(u[:a + _OVERLAP], v[:a + _OVERLAP], np.arange(u.shape[1]), 0),
             _part(u[a:], v[a:], order2, a)]
    return parts, spans


def test_segments_are_renamed_to_the_first_segments_balls():
    u, v = _orbit(200)
    order2 = np.roll(np.arange(14), 5)
    parts, spans = _split(u, v, order2)
    out = _stitch(parts, spans, np.arange(200) * 1e-4)
    np.testing.assert_array_equal(out.u_px.to_numpy().reshape(200, 14), u)


def test_a_ball_missed_on_every_overlap_frame_is_still_matched():
    """The one ball the second segment never saw on the overlap is the one left over by the assignment
    (before: an all-NaN distance row and 'could not match ball identities')."""
    u, v = _orbit(200)
    order2 = np.roll(np.arange(14), 3)
    parts, spans = _split(u, v, order2)
    a = spans[1][0]
    second = parts[1].copy()
    lost = (second.ball == 6) & (second.frame < a + _OVERLAP)
    second.loc[lost, ["u_px", "v_px"]] = np.nan
    out = _stitch([parts[0], second], spans, np.arange(200) * 1e-4)
    got = out.u_px.to_numpy().reshape(200, 14)
    ok = np.isfinite(got)
    np.testing.assert_array_equal(got[ok], u[ok])
    assert (~ok).sum() == _OVERLAP  # only the missed samples


def test_segments_that_disagree_give_none():
    """Positions further apart than the gate on the overlap: the caller tracks in one pass instead."""
    u, v = _orbit(200)
    parts, spans = _split(u, v, np.arange(14))
    second = parts[1].copy()
    second["u_px"] += 5.0
    assert _stitch([parts[0], second], spans, np.arange(200) * 1e-4) is None
    fewer = parts[1][parts[1].ball < 13]
    assert _stitch([parts[0], fewer], spans, np.arange(200) * 1e-4) is None
