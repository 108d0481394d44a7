"""The ball-ball squeeze film: the Reynolds law, its taper at the cut-off, and one law in every model.

The law (:func:`cageless.simulation.forces.squeeze_film`) is F = 6 pi eta R^2 (-dh/dt) / h for two spheres
(Reynolds' squeeze film, the paper's ball-ball film with R = D / 4), h floored at the critical film Delta_r,
acting up to a gap of 4/3 Delta_r and giving way to the Hertz contact at a gap of zero. At both ends it is
handed over smoothly over a band instead of jumping: these tests check the closed form away from the bands,
that force and slope are continuous at every band edge, and that the momentum a closing pair exchanges
through the film (6 pi eta R^2 integral dh / max(h, h_0), a closed form independent of the approach speed)
stays within 0.2 % of the hard ends' 6 pi eta R^2 (1 + ln 4/3).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import quad

from cageless.bearing import default_bearing
from cageless.simulation.forces import SQUEEZE_CUTOFF, SQUEEZE_TAPER, hertz_damped, squeeze_film
from cageless.simulation.models.planar import planar_problem
from cageless.simulation.models.planar_reference import reference_rhs

LAW = squeeze_film.py_func  # the Python source of the compiled law
ETA, R, H0 = 0.04, 0.25 * 9.525e-3, 0.225e-6  # the paper's oil, D / 4 of its balls, the default film
C = 6 * np.pi * ETA * R**2  # N s / m


def test_reynolds_closed_form_inside_and_zero_outside():
    v = 0.05
    for h in (SQUEEZE_TAPER * H0, 0.5 * H0, H0):  # floored at Delta_r
        assert LAW(h, v, ETA, R, H0) == pytest.approx(C * v / H0, rel=1e-14)
    assert LAW(0.0, v, ETA, R, H0) == pytest.approx(0.5 * C * v / H0, rel=1e-14)  # half-way through the hand-over
    assert LAW(-SQUEEZE_TAPER * H0, v, ETA, R, H0) == 0.0  # in contact beyond the band: the Hertz force alone
    inner = (SQUEEZE_CUTOFF - SQUEEZE_TAPER) * H0
    for h in (1.05 * H0, inner):
        assert LAW(h, v, ETA, R, H0) == pytest.approx(C * v / h, rel=1e-14)
    assert LAW((SQUEEZE_CUTOFF + SQUEEZE_TAPER) * H0, v, ETA, R, H0) == 0.0
    assert LAW(2 * H0, v, ETA, R, H0) == 0.0
    assert LAW(0.5 * H0, -v, ETA, R, H0) == 0.0  # an opening gap: no suction
    # linear in the approach speed and the viscosity
    assert LAW(1.3 * H0, 2 * v, 2 * ETA, R, H0) == pytest.approx(4 * LAW(1.3 * H0, v, ETA, R, H0), rel=1e-14)


@pytest.mark.parametrize("edge", [-SQUEEZE_TAPER, SQUEEZE_TAPER, SQUEEZE_CUTOFF - SQUEEZE_TAPER,
                                  SQUEEZE_CUTOFF + SQUEEZE_TAPER])
def test_force_and_slope_continuous_at_the_band_edges(edge):
    """C^1 in the gap: the one-sided values and slopes (differences over 1e-6 h0) agree to the difference
    scheme's error at both ends of both bands; the hard ends jumped by 3/4 of the plateau force (cut-off) and
    by the whole plateau (contact)."""
    v, e = 0.05, 1e-6 * H0
    h = edge * H0
    left, mid, right = (LAW(h + k * e, v, ETA, R, H0) for k in (-1, 0, 1))
    plateau = C * v / H0
    assert abs(right - left) < 1e-5 * plateau
    slope_l = (mid - left) / e
    slope_r = (right - mid) / e
    scale = plateau / H0
    assert abs(slope_r - slope_l) < 1e-4 * scale


def test_film_impulse_is_that_of_the_hard_cut_off():
    """integral F dt over an approach from beyond the film into contact = 6 pi eta R^2 integral dh / max(h, h0)
    w(h): the hard ends give 6 pi eta R^2 (1 + ln 4/3) in closed form; the bands keep it within 0.2 %."""
    b, outer = SQUEEZE_TAPER * H0, (SQUEEZE_CUTOFF + SQUEEZE_TAPER) * H0
    v = 0.03
    brk = [b, H0, (SQUEEZE_CUTOFF - SQUEEZE_TAPER) * H0]
    impulse = quad(lambda h: LAW(h, v, ETA, R, H0) / v, -b, outer, points=brk, epsabs=0, epsrel=1e-12)[0]
    contact = quad(lambda h: LAW(h, v, ETA, R, H0) / v, -b, b, epsabs=0, epsrel=1e-12)[0]
    assert contact == pytest.approx(C * b / H0, rel=1e-10)  # half the plateau over 2 b: the hard end's, exactly
    hard = C * (1 + np.log(4 / 3))
    assert impulse == pytest.approx(hard, rel=2e-3)
    assert impulse != pytest.approx(hard, rel=1e-4)  # the taper is there


def _two_balls_at_gap(gap: float, approach: float):
    """The default bearing's 14 balls on the pitch circle, balls 0 and 1 ``gap`` apart closing at ``approach``
    (ball 1 slower along the orbit), the others spread over the rest, far apart; only ball-ball effects on."""
    bearing = default_bearing()
    g = bearing.geometry
    z, d, rp = g.n_balls, g.ball_diameter_m, 0.5 * g.pitch_diameter_m
    dth = 2 * np.arcsin((d + gap) / (2 * rp))
    th = np.empty(z)
    th[0], th[1] = 0.0, dth
    th[2:] = dth + (2 * np.pi - dth) * np.arange(1, z - 1) / (z - 1)  # the rest evenly over what is left
    effects = {"ball_ball_contact": True, "ball_ball_film": True}
    pr = planar_problem(bearing, th, np.full(z, rp), (0.0, 0.0), 0.0, effects=effects)
    y = pr.y0.copy()
    y[3 * z:4 * z] = 100.0
    # closing speed along the line of centres: the chord between the two balls turns by dth / 2 from the
    # tangent, so a difference dw in orbital speed closes the gap at rp dw cos(dth / 2)
    y[3 * z + 1] = 100.0 - approach / (rp * np.cos(0.5 * dth))
    return pr, y, z


@pytest.mark.parametrize("gap_h0", [-0.1, 0.05, 0.5, 1.1, 1.2, 1.3333, 1.45, 1.52])
def test_one_law_in_the_compiled_model_and_the_numpy_reference(gap_h0):
    """Balls 0 and 1 at a gap across the film's range, and overlapping inside the contact band: the compiled
    planar right-hand side's force on ball 1 is the law's (plus the damped Hertz force in contact), and the
    plain-numpy reference (which runs the law's Python source) agrees."""
    pr, y, z = _two_balls_at_gap(gap_h0 * pr_h0(), 0.02)
    f = pr.rhs(0.0, y, pr.log.copy())
    ref = reference_rhs(0.0, y, pr.params, pr.log.copy())
    np.testing.assert_allclose(f, ref, rtol=1e-10, atol=1e-9)
    m, r, h0, eta0, d = pr.parameter("M"), y[1], pr.parameter("H0"), pr.parameter("ETA0"), pr.parameter("D")
    # ball 1's acceleration minus the centripetal and Coriolis terms: the pair force over the mass
    fr = m * (f[2 * z + 1] - r * y[3 * z + 1] ** 2)
    ft = m * (f[3 * z + 1] * r + 2 * y[2 * z + 1] * y[3 * z + 1])
    expected = LAW(gap_h0 * h0, 0.02, eta0, 0.25 * d, h0)
    if gap_h0 < 0:  # the Hertz force, at the current approach speed until one is recorded (models/planar.py)
        delta = -gap_h0 * h0
        expected += hertz_damped.py_func(delta, 0.02, max(0.02, pr.parameter("V_IN_MIN")), pr.parameter("KB"),
                                         pr.parameter("CHI"))
        assert LAW(gap_h0 * h0, 0.02, eta0, 0.25 * d, h0) > 0
    assert np.hypot(fr, ft) == pytest.approx(expected, rel=1e-6, abs=1e-12)


def pr_h0() -> float:
    """The default critical film h0 of the built problems (the parameters' film thickness)."""
    from cageless.simulation.parameters import ModelParameters

    return ModelParameters().film_thickness_m
