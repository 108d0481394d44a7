"""Pure-rolling kinematics of the paper bearing against textbook closed forms.

Source of the closed forms: Harris & Kotzalas, *Rolling Bearing Analysis*,
5th ed., vol. 1 (2006), ch. 8, for a rotating inner ring and a fixed outer
ring, gamma = D cos(alpha) / d_m:
    omega_c / omega_i = (1 - gamma) / 2
    omega_R / omega_i = d_m / (2 D) (1 - gamma^2)   (ball about its own axis, relative to the cage)
    FTF = f_i (1 - gamma) / 2,  BPFO = Z FTF,  BPFI = Z f_i (1 + gamma) / 2,  BSF = f_i omega_R / omega_i.
Bearing data: Wang et al. 2026, Table 1 (D = 9.525 mm, d_i = 36.48 mm, d_o = 55.53 mm, Z = 14).

The expected numbers below were worked by hand from those formulas:
    d_m   = (36.48 + 55.53) / 2              = 46.005 mm
    gamma = 9.525 / 46.005                    = 0.2070427
    cage  = (1 - 0.2070427) / 2               = 0.3964786
    spin  = 46.005 / 19.05 * (1 - 0.0428667)  = 2.4149606 * 0.9571333 = 2.3114393
At 3000 rpm, f_i = 50 Hz:
    FTF  = 50 * 0.3964786       = 19.82393 Hz
    BPFO = 14 * 19.82393        = 277.5350 Hz
    BPFI = 14 * 25 * 1.2070427  = 422.4649 Hz
    BSF  = 50 * 2.3114393       = 115.5720 Hz
"""

from __future__ import annotations

import math

import pytest

from cageless.kinematics import (
    centrifugal_force,
    characteristic_frequencies,
    kinematic_ratios,
    slip_rate,
    theoretical_cage_speed,
)
from cageless.parameter_sets import wang2026
from cageless.units import rpm_to_rad_s

REL = 1e-6


@pytest.fixture()
def geometry():
    return wang2026.geometry()


def test_pitch_diameter_and_clearance(geometry):
    assert geometry.pitch_diameter_m == pytest.approx(46.005e-3, rel=1e-12)
    assert geometry.diametral_clearance_m == 0.0  # 55.53 - 36.48 - 2 * 9.525 = 0 (DESIGN §6)


def test_ratios_match_closed_forms(geometry):
    r = kinematic_ratios(geometry)
    assert r.gamma == pytest.approx(0.2070427, rel=REL)
    assert r.cage_ratio == pytest.approx(0.3964786, rel=REL)
    assert r.ball_spin_ratio == pytest.approx(2.3114393, rel=REL)
    # Inertial ball rotation: rolling without slip on the fixed outer race,
    # omega_c * d_m/2 + omega_b * D/2 = 0  ->  omega_b / omega_i = -(d_m / D) * cage = -4.8299213 * 0.3964786 = -1.9149606
    assert r.ball_spin_ratio_inertial == pytest.approx(-1.9149606, rel=REL)


def test_characteristic_frequencies_3000_rpm(geometry):
    f = characteristic_frequencies(geometry, 3000.0)
    assert f.shaft_hz == 50.0
    assert f.ftf_hz == pytest.approx(19.82393, rel=REL)
    assert f.bpfo_hz == pytest.approx(277.5350, rel=REL)
    assert f.bpfi_hz == pytest.approx(422.4649, rel=REL)
    assert f.bsf_hz == pytest.approx(115.5720, rel=REL)
    # Identity of the closed forms: BPFO + BPFI = Z f_i
    assert f.bpfo_hz + f.bpfi_hz == pytest.approx(14 * 50.0, rel=1e-12)


def test_contact_angle_enters_through_cos(geometry):
    # alpha = 15 deg: gamma = 0.2070427 * cos(15 deg) = 0.2070427 * 0.9659258 = 0.1999879
    r = kinematic_ratios(geometry, math.radians(15.0))
    assert r.gamma == pytest.approx(0.1999879, rel=REL)
    assert r.cage_ratio == pytest.approx((1 - 0.1999879) / 2, rel=REL)


def test_theoretical_cage_speed_and_slip(geometry):
    omega_i = rpm_to_rad_s(3000.0)  # 314.15927 rad/s
    omega_c = theoretical_cage_speed(geometry, omega_i)
    assert omega_c == pytest.approx(314.15927 * 0.3964786, rel=REL)
    # A ball orbiting 10 % slower than the cage has slip 0.1 (DESIGN §3).
    assert slip_rate([0.9 * omega_c, omega_c], omega_c) == pytest.approx([0.1, 0.0], abs=1e-12)


@pytest.mark.parametrize(
    ("speed_rpm", "paper_half_speed_n", "pure_rolling_n"),
    [(1800, 0.726, 0.456), (3000, 2.017, 1.268), (6000, 8.069, 5.070)],
)
def test_centrifugal_force_matches_paper(speed_rpm, paper_half_speed_n, pure_rolling_n):
    """Paper §4 (eq. 27) gives 0.726, 2.017 and 8.069 N with cage speed = omega_i / 2;
    DESIGN §11 gives 0.456, 1.268 and 5.070 N at the pure-rolling cage speed. Both are
    checked, to the paper's three significant figures (0.1 %)."""
    g, m = wang2026.geometry(), wang2026.masses()
    omega_i = rpm_to_rad_s(speed_rpm)
    assert centrifugal_force(m, g, omega_i / 2) == pytest.approx(paper_half_speed_n, rel=1e-3)
    assert centrifugal_force(m, g, theoretical_cage_speed(g, omega_i)) == pytest.approx(pure_rolling_n, rel=1e-3)


def test_max_ball_count(geometry):
    # pi / asin(9.525 / 46.005) = pi / 0.2085498 = 15.06 -> 15 balls fit at most.
    assert geometry.max_ball_count == 15
