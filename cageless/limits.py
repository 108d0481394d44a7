"""The rules of every user-facing number: a hard rule and a plausible range each.

A value breaking the hard rule cannot mean anything (a zero sample rate, a negative seed, a NaN, a speed at
which the balls would outrun sound) and is always refused: on the command line
(:func:`cageless.validate.check_value`) and by the objects that hold it, such as
:class:`~cageless.conditions.OperatingConditions` (:func:`hard_problem`). A value outside the plausible range
(values a bearing test rig can produce) is refused on the command line unless the user passes ``--force``.

Where the bounds come from:

* speed: up to 60 000 r/min, a speed factor n * d_m of 2.8e6 mm r/min for the 46 mm pitch circle of the
  default bearing, about the 3e6 that Harris & Kotzalas (*Essential Concepts of Bearing Technology*,
  5th ed., ch. 1) give as the practical limit of oil-lubricated ball bearings;
* loads: up to 100 kN, several times the static load rating of a bearing of this size (a 6206 deep-groove
  bearing, nine 9.525 mm balls, is catalogued at C0 of about 11-12 kN; 14 balls scale that to about
  17-19 kN), beyond which the raceways dent permanently;
* the frame rate: up to 10 million frames/s, above the fastest Phantom cameras (about 1.75 Mfps);
* the simulated sample rate: up to 1 MHz (the solver's default largest step is 2 us);
* the hard upper bounds of the speed and the loads, ten times the plausible ones: at 600 000 r/min the ball
  centres of the default bearing would orbit at about 570 m/s (the cage turns at about 0.4 of the ring's speed
  on a 46 mm pitch circle), faster than sound in air; 1 MN is some fifty times the static load rating.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

__all__ = ["Limit", "LIMITS", "MAX_SPEED_RPM", "MAX_LOAD_N", "hard_problem"]

#: Hard upper bound of the inner-ring speed (r/min): ten times the plausible range.
MAX_SPEED_RPM = 600_000.0
#: Hard upper bound of a load (N): ten times the plausible range.
MAX_LOAD_N = 1_000_000.0


@dataclass(frozen=True)
class Limit:
    """Rules of one number: hard bounds (never allowed beyond) and a plausible range.

    ``lo_open`` / ``hi_open`` make the hard bound exclusive.
    """

    unit: str
    hard_lo: float = -math.inf
    hard_hi: float = math.inf
    lo: float = -math.inf
    hi: float = math.inf
    lo_open: bool = False
    integer: bool = False

    def hard_rule(self) -> str:
        parts = []
        fmt = "d" if self.integer else ".15g"
        if self.hard_lo > -math.inf:
            parts.append(f"{'>' if self.lo_open else '>='} {self.hard_lo:{fmt}}")
        if self.hard_hi < math.inf and not (self.integer and self.hard_hi >= 2**62):
            parts.append(f"<= {self.hard_hi:{fmt}}")
        return "must be " + " and ".join(parts) if parts else "must be finite"

    def plausible(self) -> str:
        unit = f" {self.unit}" if self.unit else ""
        fmt = "d" if self.integer else "g"
        return f"{self.lo:{fmt}} to {self.hi:{fmt}}{unit}"


#: Keyed by the argparse destination (the option is ``--`` + key with ``-`` for ``_``).
LIMITS: dict[str, Limit] = {
    "speed_rpm": Limit("r/min", 0.0, MAX_SPEED_RPM, 1.0, 60_000.0, lo_open=True),
    "radial_load_n": Limit("N", 0.0, MAX_LOAD_N, 0.0, 100_000.0),
    "axial_load_n": Limit("N", 0.0, MAX_LOAD_N, 0.0, 100_000.0),
    "fps": Limit("frames/s", 0.0, math.inf, 1.0, 1e7, lo_open=True),
    "px_per_mm": Limit("px/mm", 0.0, math.inf, 0.1, 1000.0, lo_open=True),
    "camera_roll_deg": Limit("deg", -360.0, 360.0, -180.0, 180.0),
    "duration": Limit("s", 0.0, math.inf, 1e-4, 10.0, lo_open=True),
    "settle": Limit("s", 0.0, math.inf, 0.0, 10.0),
    "sample_rate": Limit("samples/s", 0.0, math.inf, 10.0, 1e6, lo_open=True),
    "seed": Limit("", 0, 2**63 - 1, 0, 2**63 - 1, integer=True),  # numpy seeds are non-negative
    "rtol": Limit("", 0.0, 1.0, 1e-12, 1e-2, lo_open=True),
    "max_step": Limit("s", 0.0, math.inf, 1e-9, 1e-3, lo_open=True),
    "bin_deg": Limit("deg", 0.0, 360.0, 0.01, 45.0, lo_open=True),
    "gravity": Limit("m/s^2", -math.inf, math.inf, 0.0, 100.0),
    "misalignment_rad": Limit("rad", -math.pi / 2, math.pi / 2, -0.05, 0.05),
    "moment_load_nm": Limit("N m", 0.0, math.inf, 0.0, 10_000.0),
    "oil_air_density": Limit("kg/m^3", 0.0, math.inf, 0.0, 1000.0),
    "clearance_um": Limit("um", -math.inf, math.inf, -20.0, 200.0),
    "restitution": Limit("", 0.0, 1.0, 0.0, 1.0),
    "speed_ramp": Limit("s", 0.0, math.inf, 0.0, 10.0),
    "revolutions": Limit("orbits", 0.0, math.inf, 0.001, 100.0, lo_open=True),
    "workers": Limit("", 1, 1024, 1, 256, integer=True),
    "ensemble": Limit("", 1, 2**63 - 1, 1, 10_000, integer=True),
    "window": Limit("frames", 3, 2**63 - 1, 3, 1001, integer=True),
}


def hard_problem(key: str, value: float) -> str | None:
    """The hard rule of :data:`LIMITS` ``[key]`` that ``value`` breaks (``"must be > 0 and <= 600000"``), or None."""
    lim = LIMITS[key]
    v = float(value)
    if not math.isfinite(v):
        return "must be a finite number"
    below = v <= lim.hard_lo if lim.lo_open else v < lim.hard_lo
    return lim.hard_rule() if below or v > lim.hard_hi else None
