"""Candidate blobs and tracklets for the ball selection (tracking/candidates.py, tracking/select.py).

Each test builds its input from a closed form (Gaussian spots, constant-velocity paths, exact circles), so
the expected answer is known without the code under test: the centroid of a centrally symmetric spot is its
centre; a constant-velocity path is predicted exactly; the circle through evenly spaced points is the one
they were placed on.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from cageless.tracking.candidates import Candidates, Tracklet, find_candidates, link_tracklets, refine_candidates
from cageless.tracking.select import _Context, _ransac_circle


def _spot(shape, u, v, sx, sy, peak):
    vv, uu = np.mgrid[0:shape[0], 0:shape[1]]
    return peak * np.exp(-0.5 * (((uu - u) / sx) ** 2 + ((vv - v) / sy) ** 2))


def _cands(u, v, response=None):
    u, v = np.atleast_1d(np.asarray(u, float)), np.atleast_1d(np.asarray(v, float))
    r = np.ones(u.size) * 10 if response is None else np.atleast_1d(np.asarray(response, float))
    return Candidates(u=u, v=v, response=r, peak=r)


def test_an_elongated_highlight_gives_one_candidate_at_its_centre():
    """Maxima anywhere along a saturated lobe 3x longer than wide (its plateau has them all along it) move to
    the lobe's centre and merge (the centroid of a centrally symmetric spot is its centre of symmetry). The
    window spans the lobe, as a window of a fifth of a ball spans a highlight."""
    frame = np.minimum(100 + _spot((80, 80), 40.3, 39.6, 5.0, 1.5, 4000.0), 1100).astype(np.float32)
    bg = np.full(frame.shape, 100, np.float32)
    mask = np.ones(frame.shape, bool)
    starts = _cands([33.0, 40.0, 47.0], [40.0, 39.0, 40.0], [12.0, 11.0, 10.0])
    out = refine_candidates(starts, frame, bg, mask, radius_px=16.0, threshold=0.0, merge_px=1.5)
    assert len(out) == 1 and out.response[0] == 12.0  # the strongest start is kept
    assert out.u[0] == pytest.approx(40.3, abs=0.05) and out.v[0] == pytest.approx(39.6, abs=0.05)
    # find_candidates itself gives one candidate on the unsaturated lobe, inside the lobe.
    raw = find_candidates((100 + _spot((80, 80), 40.3, 39.6, 9.0, 1.5, 1000.0)).astype(np.float32), bg, mask, 1.5,
                          k_sigma=4.0, response_sigma=1.0)
    assert len(raw) == 1 and abs(raw.u[0] - 40.3) < 9.0


def test_two_separate_highlights_stay_two_candidates():
    """Two lights' highlights further apart than the window stay two blobs, each at its own centre."""
    frame = (_spot((60, 100), 30.0, 30.0, 2.0, 2.0, 800.0) + _spot((60, 100), 62.0, 30.0, 2.0, 2.0, 300.0))
    frame = frame.astype(np.float32)
    bg = np.zeros(frame.shape, np.float32)
    c = _cands([30.6, 61.5], [29.5, 30.4])
    out = refine_candidates(c, frame, bg, np.ones(frame.shape, bool), radius_px=8.0, threshold=0.0, merge_px=2.0)
    assert np.allclose(out.u, [30.0, 62.0], atol=0.05) and np.allclose(out.v, [30.0, 30.0], atol=0.05)


def test_prediction_counts_frames_between_samples():
    """Samples 4 frames apart at 2 px/frame: the next frame is 2 px on, not 8."""
    t = Tracklet(frames=[0, 4], u=[10.0, 18.0], v=[5.0, 5.0], response=[1.0, 1.0])
    assert t.predict() == pytest.approx((20.0, 5.0))
    assert t.predict(7) == pytest.approx((24.0, 5.0))


def test_an_established_tracklet_does_not_jump_to_a_neighbouring_blob():
    """A highlight at 3 px/frame with a second blob 12 px behind it (a second light): when the first is
    missed for a frame, the tracklet waits instead of jumping to the second (inside the first-step gate)."""
    frames = []
    for i in range(10):
        u = [10.0 + 3 * i, -2.0 + 3 * i] if i != 5 else [-2.0 + 3 * i]
        frames.append(_cands(u, [20.0] * len(u)))
    tracks = link_tracklets(frames, gate_px=20.0, max_misses=3, track_gate_px=3.0)
    lead = max(tracks, key=lambda t: np.mean(t.u))
    assert len(lead.frames) == 9 and 5 not in lead.frames
    assert np.allclose(np.diff(lead.u) / np.diff(lead.frames), 3.0)
    # Without the tight gate, the same tracklet takes the other blob in frame 5.
    loose = link_tracklets(frames, gate_px=20.0, max_misses=3)
    assert any(5 in t.frames and -2.0 + 15 in t.u and 10.0 in t.u for t in loose)


def test_weak_blobs_extend_tracklets_but_do_not_start_them():
    """Hysteresis: a blob of response 3 continues a tracklet started at 6, and starts none of its own."""
    frames = [_cands([10.0 + 2 * i, 50.0], [10.0, 40.0], [6.0 if i < 2 else 3.0, 3.0]) for i in range(8)]
    tracks = link_tracklets(frames, gate_px=5.0, track_gate_px=2.0, start_response=5.0)
    assert len(tracks) == 1 and tracks[0].frames == list(range(8))


def test_of_two_circles_of_one_radius_the_fuller_is_chosen():
    """Two lights: every ball's two highlights travel two circles of the same radius, 20 px apart. The circle
    holding all Z highlights of every burst wins over the one whose highlights are partly missed, though
    both radii match the expected one."""
    z, r = 14, 150.0
    ctx = _Context(z=z, gap=0.3, omega_c=100.0, omega_i=250.0, ball_px=60.0, r_prior=r, centre0=(200.0, 200.0),
                   sigma_px=3.0, k_sigma=4.0)
    pts, burst = [], []
    for b in range(4):
        th = 2 * math.pi * np.arange(z) / z + 0.1 * b
        pts += list(zip(195.0 + r * np.cos(th), 200.0 + r * np.sin(th), strict=True))
        keep = th[::2]  # the second light's highlights, half of them found
        pts += list(zip(215.0 + r * np.cos(keep), 200.0 + r * np.sin(keep), strict=True))
        burst += [b] * (z + keep.size)
    pts_a = np.array(pts)
    cx, cy, rr = _ransac_circle(pts_a, np.array(burst), np.ones(len(pts_a)), ctx, tol=1.5)
    assert (cx, cy, rr) == pytest.approx((195.0, 200.0, r), abs=1e-6)


@pytest.mark.parametrize("stated", [False, True])
def test_a_stated_scale_keeps_the_circle_on_the_pitch_circle(stated):
    """The look of corpus FRESH2 seed 7218: the 12 bright wedges between the balls travel a circle 0.31 ball
    diameters inside the pitch circle and are found in every burst, the dim highlights on the pitch circle only
    7 of 12 a burst. By fullness the wedges' circle wins; with the scale stated, only circles within
    PRIOR_RADIUS_TOL ball diameters of the pitch circle are hypotheses, and the highlights' circle is chosen."""
    from cageless.tracking.select import PRIOR_RADIUS_TOL, _context

    z, r, ball = 12, 99.5, 49.4
    ctx = _context(z, ball / 2e3, r / 1e3, 250.0, (300.0, 240.0), r, 4.0, scale_stated=stated)
    assert ctx.ball_px == pytest.approx(ball)
    assert ctx.radius_tol_px == (pytest.approx(PRIOR_RADIUS_TOL * ball) if stated else math.inf)
    pts, burst = [], []
    for b in range(5):
        th = 2 * math.pi * np.arange(z) / z + 0.1 * b
        wedge = th + math.pi / z
        pts += list(zip(300.0 + (r - 0.31 * ball) * np.cos(wedge), 240.0 + (r - 0.31 * ball) * np.sin(wedge),
                        strict=True))
        seen = th[:7]  # the highlights: 7 of 12 found
        pts += list(zip(305.0 + r * np.cos(seen), 238.0 + r * np.sin(seen), strict=True))
        burst += [b] * (z + seen.size)
    pts_a = np.array(pts)
    circle = _ransac_circle(pts_a, np.array(burst), np.ones(len(pts_a)), ctx, tol=2.5)
    expected = (305.0, 238.0, r) if stated else (300.0, 240.0, r - 0.31 * ball)
    assert circle == pytest.approx(expected, abs=1e-6)


def test_a_dropped_frame_does_not_break_a_tracklet():
    """Frame times 0, 1, 2, 4, 5, ... (one frame dropped): the ball moves 6 px between the third and fourth
    entries. Predicted per second, that is the expected step; counted per frame it would be 3 px off, out of
    a 2 px gate."""
    times = np.array([0.0, 1.0, 2.0, 4.0, 5.0, 6.0, 7.0])
    frames = [_cands([10.0 + 3 * t], [20.0]) for t in times]
    by_time = link_tracklets(frames, gate_px=10.0, track_gate_px=2.0, times=times)
    assert [t.frames for t in by_time] == [list(range(7))]
    by_count = link_tracklets(frames, gate_px=10.0, track_gate_px=2.0)
    assert len(by_count) > 1


@pytest.mark.parametrize("hole", [(2, 0), (1, -2), (-3, 1), (0, 0)])
def test_a_masked_pixel_beside_a_highlight_does_not_push_its_centroid(hole):
    """A static defect masked out of the centroid (a hot pixel, a speck) beside a highlight: the pixel is left
    out together with its mirror image through the window's centre, so the weighted centroid of a centrally
    symmetric spot over a centrally symmetric domain stays at its centre (closed form). The mirror point is
    off the grid, and its mask is interpolated bilinearly (smooth in the centre), which leaves 0.001-0.013 px;
    leaving out the masked pixel alone moves the same tapered, re-centred centroid (computed here in numpy) by
    0.025-0.09 px."""
    from cageless.tracking.detect import centroid_windows

    u0, v0 = 30.2, 29.7
    frame = (100 + _spot((60, 60), u0, v0, 1.8, 1.8, 3000.0)).astype(np.float32)
    bg = np.full(frame.shape, 100, np.float32)
    mask = np.ones(frame.shape, bool)
    hu, hv = int(round(u0)) + hole[0], int(round(v0)) + hole[1]
    mask[hv, hu] = False
    u, v, m = centroid_windows(frame, bg, mask, [u0 + 0.4], [v0 - 0.3], 6.3, 20.0, iterations=30)
    assert m[0] > 0
    assert math.hypot(u[0] - u0, v[0] - v0) < 0.015
    # The same tapered centroid without the mirror, re-centred to its fixed point, is pushed off by more.
    vv, uu = np.mgrid[0:60, 0:60]
    pu, pv = u0, v0
    for _ in range(50):
        taper = np.clip(1 - ((uu - pu) ** 2 + (vv - pv) ** 2) / 6.3**2, 0, None) ** 2
        wgt = np.clip(frame - 100 - 20.0, 0, None) * taper * mask
        pu, pv = (wgt * uu).sum() / wgt.sum(), (wgt * vv).sum() / wgt.sum()
    assert math.hypot(pu - u0, pv - v0) > 1.5 * math.hypot(u[0] - u0, v[0] - v0) + 0.01
