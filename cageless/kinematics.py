"""Pure-rolling kinematics and characteristic frequencies of a ball bearing.

Closed forms for a rotating inner ring and a fixed outer ring, from Harris &
Kotzalas, *Rolling Bearing Analysis*, 5th ed., vol. 1 (2006), ch. 8
("Bearing kinematics"). With ``gamma = D cos(alpha) / d_m``:

* cage (fundamental train) speed: ``omega_c = omega_i (1 - gamma) / 2``;
* ball spin about its own axis, relative to the cage:
  ``omega_R = omega_i (d_m / 2D) (1 - gamma^2)``;
* FTF = f_i (1 - gamma)/2, BPFO = Z FTF, BPFI = Z f_i (1 + gamma)/2,
  BSF = f_i (d_m / 2D)(1 - gamma^2).

The theoretical cage speed is the reference of the slip rate
``s = 1 - theta_dot / omega_c``.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass

import numpy as np
import numpy.typing as npt

from cageless.bearing import Geometry, Masses
from cageless.errors import ParameterError
from cageless.units import rpm_to_hz

__all__ = [
    "KinematicRatios",
    "CharacteristicFrequencies",
    "kinematic_ratios",
    "characteristic_frequencies",
    "theoretical_cage_speed",
    "startup_duration",
    "STARTUP_REVOLUTIONS",
    "slip_rate",
    "rereference_slip",
    "loaded_zone_speed",
    "LOADED_ZONE_HALF_WIDTH_DEG",
    "centrifugal_force",
]


def _check_angle(contact_angle_rad: float) -> None:
    if not math.isfinite(contact_angle_rad) or not (0.0 <= contact_angle_rad < 0.5 * math.pi):
        raise ParameterError("contact_angle_rad", "must be finite and in [0, pi/2)", contact_angle_rad)


def _check_speed(name: str, value: float) -> None:
    if not math.isfinite(value):
        raise ParameterError(name, "must be finite", value)


@dataclass(frozen=True)
class KinematicRatios:
    """Dimensionless pure-rolling ratios, all relative to the inner-ring speed.

    Attributes
    ----------
    gamma
        D cos(alpha) / d_m.
    cage_ratio
        omega_c / omega_i = (1 - gamma) / 2.
    ball_spin_ratio
        Ball rotation about its own axis relative to the cage, over omega_i:
        (d_m / 2D)(1 - gamma^2) (Harris & Kotzalas).
    ball_spin_ratio_inertial
        Ball rotation about the bearing axis in the fixed frame, over omega_i:
        -(d_m / D) cage_ratio. Negative: the ball turns against the ring.
    """

    gamma: float
    cage_ratio: float
    ball_spin_ratio: float
    ball_spin_ratio_inertial: float

    def to_dict(self) -> dict[str, float]:
        """Return the ratios as a plain dict."""
        return asdict(self)


@dataclass(frozen=True)
class CharacteristicFrequencies:
    """Characteristic frequencies (Hz) at one inner-ring speed.

    Attributes
    ----------
    shaft_hz
        Inner-ring rotation frequency f_i.
    ftf_hz
        Fundamental train (cage) frequency.
    bpfo_hz
        Ball-pass frequency, outer race.
    bpfi_hz
        Ball-pass frequency, inner race.
    bsf_hz
        Ball spin frequency (rotation of a ball about its own axis relative to the cage).
    """

    shaft_hz: float
    ftf_hz: float
    bpfo_hz: float
    bpfi_hz: float
    bsf_hz: float

    def to_dict(self) -> dict[str, float]:
        """Return the frequencies as a plain dict."""
        return asdict(self)


def kinematic_ratios(geometry: Geometry, contact_angle_rad: float = 0.0) -> KinematicRatios:
    """Pure-rolling speed ratios for a turning inner ring and a fixed outer ring.

    Parameters
    ----------
    geometry
        The bearing geometry.
    contact_angle_rad
        Contact angle alpha (rad); 0 for a radially loaded deep-groove bearing.

    Returns
    -------
    KinematicRatios
    """
    _check_angle(contact_angle_rad)
    d, dm = geometry.ball_diameter_m, geometry.pitch_diameter_m
    gamma = d * math.cos(contact_angle_rad) / dm
    cage = 0.5 * (1.0 - gamma)
    return KinematicRatios(
        gamma=gamma,
        cage_ratio=cage,
        ball_spin_ratio=dm / (2.0 * d) * (1.0 - gamma**2),
        ball_spin_ratio_inertial=-(dm / d) * cage,
    )


def characteristic_frequencies(
    geometry: Geometry, speed_rpm: float, contact_angle_rad: float = 0.0
) -> CharacteristicFrequencies:
    """Characteristic defect frequencies at an inner-ring speed.

    Parameters
    ----------
    geometry
        The bearing geometry.
    speed_rpm
        Inner-ring speed (rpm).
    contact_angle_rad
        Contact angle alpha (rad).

    Returns
    -------
    CharacteristicFrequencies
    """
    _check_speed("speed_rpm", speed_rpm)
    r = kinematic_ratios(geometry, contact_angle_rad)
    f_i = rpm_to_hz(speed_rpm)
    ftf = r.cage_ratio * f_i
    return CharacteristicFrequencies(
        shaft_hz=f_i,
        ftf_hz=ftf,
        bpfo_hz=geometry.n_balls * ftf,
        bpfi_hz=geometry.n_balls * 0.5 * (1.0 + r.gamma) * f_i,
        bsf_hz=r.ball_spin_ratio * f_i,
    )


def theoretical_cage_speed(
    geometry: Geometry, inner_speed_rad_s: float, contact_angle_rad: float = 0.0
) -> float:
    """Pure-rolling cage speed omega_c = omega_i (1 - D cos(alpha)/d_m) / 2 (rad/s).

    This is the reference speed of the slip rate.
    """
    _check_speed("inner_speed_rad_s", inner_speed_rad_s)
    return kinematic_ratios(geometry, contact_angle_rad).cage_ratio * inner_speed_rad_s


def slip_rate(
    orbital_speed_rad_s: npt.ArrayLike, cage_speed_rad_s: float
) -> npt.NDArray[np.float64]:
    """Slip rate s = 1 - theta_dot / omega_c.

    Parameters
    ----------
    orbital_speed_rad_s
        Ball revolution speeds theta_dot (rad/s), any shape.
    cage_speed_rad_s
        The pure-rolling cage speed omega_c (rad/s), non-zero.

    Returns
    -------
    numpy.ndarray
        The slip rates, same shape as ``orbital_speed_rad_s`` (dimensionless; x100 for %).
    """
    if not math.isfinite(cage_speed_rad_s) or cage_speed_rad_s == 0.0:
        raise ParameterError(
            "cage_speed_rad_s", "must be finite and non-zero to define a slip rate", cage_speed_rad_s
        )
    return 1.0 - np.asarray(orbital_speed_rad_s, dtype=np.float64) / cage_speed_rad_s


def rereference_slip(slip: npt.ArrayLike, ball_diameter_m: float, pitch_diameter_m: float,
                     from_angle_rad: float, to_angle_rad: float) -> npt.NDArray[np.float64]:
    """Slip rates referred to the cage speed of another contact angle.

    A slip rate s = 1 - theta_dot / omega_c(alpha) depends on alpha through omega_c; with
    gamma = D / d_m, omega_c(a) / omega_c(b) = (1 - gamma cos a) / (1 - gamma cos b), so the same orbital
    speeds give 1 - (1 - s) omega_c(from) / omega_c(to).
    """
    _check_angle(from_angle_rad)
    _check_angle(to_angle_rad)
    gamma = ball_diameter_m / pitch_diameter_m
    ratio = (1.0 - gamma * math.cos(from_angle_rad)) / (1.0 - gamma * math.cos(to_angle_rad))
    return 1.0 - (1.0 - np.asarray(slip, dtype=np.float64)) * ratio


#: Half-width of the window about the loaded-zone centre (270 deg) whose balls set the loaded-zone speed.
LOADED_ZONE_HALF_WIDTH_DEG = 45.0


def loaded_zone_speed(angle: npt.ArrayLike, speed: npt.ArrayLike, valid: npt.ArrayLike | None = None,
                      min_samples: int = 10) -> float | None:
    """Median orbit speed (rad/s) of the balls within 45 deg of the loaded-zone centre, 270 deg.

    There the inner ring drives the balls under load and they roll nearly purely (their slip is about
    0-2 %: Wang et al. 2026, figure 18), so this speed is the cage speed the trace itself shows.

    Parameters
    ----------
    angle, speed
        Orbital angles (rad) and orbit speeds (rad/s), same shape ((T, Z) for a trace).
    valid
        Which samples to use (default all); non-finite speeds are left out too.
    min_samples
        Fewest samples in the window for an answer.

    Returns
    -------
    float or None
        The median speed, or None when fewer than ``min_samples`` samples fall in the window.
    """
    a = np.asarray(angle, dtype=np.float64)
    v = np.asarray(speed, dtype=np.float64)
    keep = np.sin(a) < -math.cos(math.radians(LOADED_ZONE_HALF_WIDTH_DEG))
    keep &= np.isfinite(v)
    if valid is not None:
        keep &= np.asarray(valid, dtype=bool)
    if int(keep.sum()) < min_samples:
        return None
    return float(np.median(v[keep]))


def centrifugal_force(masses: Masses, geometry: Geometry, cage_speed_rad_s: float) -> float:
    """Centrifugal force m (d_m/2) omega_c^2 on one ball orbiting at the pitch radius (N)."""
    _check_speed("cage_speed_rad_s", cage_speed_rad_s)
    return masses.ball_mass_kg * 0.5 * geometry.pitch_diameter_m * cage_speed_rad_s**2



#: Cage revolutions a simulation takes to forget its packed start.
STARTUP_REVOLUTIONS = 3.0


def startup_duration(speed_rpm: float, ball_diameter_m: float, pitch_diameter_m: float,
                     revolutions: float = STARTUP_REVOLUTIONS, minimum_s: float = 0.04) -> float:
    """Simulated time (s) to leave out before a simulation's statistics: ``revolutions`` pure-rolling cage
    revolutions, at least ``minimum_s``.

    Measured on the paper bearing (500 N, every effect): the peak slip in the unloaded zone is steady
    after 0.2 s at 1800 rpm, 0.15 s at 3000 rpm and 0.04 s at 6000 rpm, while the balls packed at the
    bottom spread around the ring; three cage revolutions are 0.25, 0.15 and 0.075 s.
    """
    for name, value in (("speed_rpm", speed_rpm), ("ball_diameter_m", ball_diameter_m),
                        ("pitch_diameter_m", pitch_diameter_m)):
        if not (math.isfinite(value) and value > 0):
            raise ParameterError(name, "must be a finite number > 0", value)
    cage = 0.5 * speed_rpm * math.pi / 30.0 * (1.0 - ball_diameter_m / pitch_diameter_m)
    return max(minimum_s, revolutions * 2.0 * math.pi / cage)
