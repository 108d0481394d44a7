"""Hamrock-Dowson film thickness: the formula evaluated by hand (Hamrock & Dowson, J. Lubr. Technol. 99 (1977)).

The published worked example of Hamrock & Dowson is not yet checked here (see the simulator issue).
"""

from __future__ import annotations

import math

import pytest

from cageless.errors import ParameterError
from cageless.simulation.film import hamrock_dowson


def test_film_by_hand():
    # Q = 500 N, u = 5 m/s, Rx = 4 mm, k = 8, eta0 = 0.04 Pa s, alpha = 1.5e-8 1/Pa, E' = 228.57 GPa:
    # U = 0.04*5/(2.2857e11*4e-3) = 2.1875e-10, G = 1.5e-8*2.2857e11 = 3428.6, W = 500/(2.2857e11*1.6e-5) = 1.3672e-4
    e = 208e9 / (1 - 0.09)
    f = hamrock_dowson(500.0, 5.0, 4e-3, 8.0, 0.04, 1.5e-8, e)
    assert f.speed_u == pytest.approx(2.1875e-10, rel=1e-4)
    assert f.material_g == pytest.approx(3428.57, rel=1e-5)
    assert f.load_w == pytest.approx(1.36719e-4, rel=1e-4)
    h_min = 3.63 * 2.1875e-10**0.68 * 3428.571**0.49 * 1.36719e-4**-0.073 * (1 - math.exp(-0.68 * 8)) * 4e-3
    h_c = 2.69 * 2.1875e-10**0.67 * 3428.571**0.53 * 1.36719e-4**-0.067 * (1 - 0.61 * math.exp(-0.73 * 8)) * 4e-3
    assert f.minimum_m == pytest.approx(h_min, rel=1e-4)
    assert f.central_m == pytest.approx(h_c, rel=1e-4)
    assert 0.1e-6 < f.minimum_m < f.central_m < 1e-6  # sub-micron films, central above minimum


def test_film_rejects_bad_input():
    with pytest.raises(ParameterError, match="entraining_speed_m_s"):
        hamrock_dowson(500.0, 0.0, 4e-3, 8.0, 0.04, 1.5e-8, 2e11)
