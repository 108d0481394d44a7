"""Ball numbering (DESIGN §3), checked on cases worked by hand."""

from __future__ import annotations

import numpy as np

from cageless.balls import ball_order, normalise_unwrapped


def test_ball_zero_follows_the_largest_gap():
    # Angles (deg): columns 0..3 at 100, 10, 220, 300. Gaps going CCW: 10->100 (90), 100->220 (120),
    # 220->300 (80), 300->370 (70). The largest gap ends at column 2 (220 deg): ball 0 is column 2,
    # then columns 3 (300), 1 (10) and 0 (100).
    order = ball_order(np.radians([100.0, 10.0, 220.0, 300.0]))
    assert order.tolist() == [2, 3, 1, 0]


def test_normalised_angles_increase_around_the_ring():
    a = np.radians([[380.0, 30.0, 50.0], [381.0, 31.0, 51.0]])
    out = np.degrees(normalise_unwrapped(a))
    np.testing.assert_allclose(out[0], [20.0, 30.0, 50.0])
    np.testing.assert_allclose(out[1] - out[0], [1.0, 1.0, 1.0])
