"""Static radial load distribution of the paper bearing against Stribeck-Sjövall.

Source: Harris & Kotzalas, *Rolling Bearing Analysis*, 5th ed., vol. 1 (2006), ch. 7: for zero clearance
(load-zone factor 0.5) and point contact, J_r(0.5) = 0.2288, so Q_max = F_r / (Z J_r) = 4.3706 F_r / Z
(rounded to 4.37 in bearing catalogues, e.g. NSK's). The integral assumes many balls; with 14 balls and one
under the load line, the discrete sum must agree to 0.5 %.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from cageless.errors import ParameterError
from cageless.parameter_sets import wang2026
from cageless.simulation.quasistatic import radial_load_distribution

G, M = wang2026.geometry(), wang2026.material()


def angles(z: int, shift: float = 0.0) -> np.ndarray:
    return 1.5 * np.pi + shift + np.arange(z) * 2 * np.pi / z  # ball 0 under the load line (270 deg)


@pytest.mark.parametrize("radial_load_n", [500.0, 1000.0, 2000.0])
def test_stribeck_sjovall_max_load(radial_load_n):
    r = radial_load_distribution(G, M, radial_load_n, angles(14))
    assert r.max_load_n * 14 / radial_load_n == pytest.approx(1 / 0.2288, rel=5e-3)
    # Equilibrium: the ball loads' vertical components carry the radial load.
    psi = angles(14) - 1.5 * np.pi
    assert np.sum(r.loads_n * np.cos(psi)) == pytest.approx(radial_load_n, rel=1e-9)
    assert r.iterations < 20
    # Zero clearance: exactly the lower half carries load (|psi| < 90 deg).
    assert np.all((r.loads_n > 0) == (np.cos(psi) > 1e-12))


def test_clearance_concentrates_the_load():
    loose = dataclasses.replace(G, outer_race_diameter_m=G.outer_race_diameter_m + 20e-6)
    tight = radial_load_distribution(G, M, 1000.0, angles(14)).max_load_n
    assert radial_load_distribution(loose, M, 1000.0, angles(14)).max_load_n > tight


def test_bad_load():
    with pytest.raises(ParameterError, match="radial_load_n"):
        radial_load_distribution(G, M, 0.0, angles(14))
