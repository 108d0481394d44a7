"""Unit conversions used at the user-facing boundary.

Inside the code everything is SI; these helpers convert the
user-facing units (rpm, mm, degrees) exactly once, at the boundary.
"""

from __future__ import annotations

import math

__all__ = ["rpm_to_rad_s", "rad_s_to_rpm", "rpm_to_hz", "mm_to_m", "m_to_mm"]

_TWO_PI = 2.0 * math.pi


def rpm_to_rad_s(speed_rpm: float) -> float:
    """Convert revolutions per minute to rad/s."""
    return speed_rpm * _TWO_PI / 60.0


def rad_s_to_rpm(speed_rad_s: float) -> float:
    """Convert rad/s to revolutions per minute."""
    return speed_rad_s * 60.0 / _TWO_PI


def rpm_to_hz(speed_rpm: float) -> float:
    """Convert revolutions per minute to revolutions per second (Hz)."""
    return speed_rpm / 60.0


def mm_to_m(length_mm: float) -> float:
    """Convert millimetres to metres."""
    return length_mm * 1e-3


def m_to_mm(length_m: float) -> float:
    """Convert metres to millimetres."""
    return length_m * 1e3
