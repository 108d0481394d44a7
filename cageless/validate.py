"""Plausible ranges for every user-facing number, and checks of the conditions read from a lab folder.

Each number has a *hard* rule (a value that cannot mean anything: a zero sample rate, a negative seed,
a NaN) and a *plausible* range (values a bearing test rig can produce). A value breaking the hard rule
is always refused; a value outside the plausible range is refused with the range named unless the user
passes ``--force``. Both are usage errors (exit code 2) on the command line.

Where the plausible bounds come from:

* speed: up to 60 000 r/min, a speed factor n * d_m of 2.8e6 mm r/min for the 46 mm pitch circle of the
  default bearing, about the 3e6 that Harris & Kotzalas (*Essential Concepts of Bearing Technology*,
  5th ed., ch. 1) give as the practical limit of oil-lubricated ball bearings;
* loads: up to 100 kN, several times the static load rating of a bearing of this size (a 6206 deep-groove
  bearing, nine 9.525 mm balls, is catalogued at C0 of about 11-12 kN; 14 balls scale that to about
  17-19 kN), beyond which the raceways dent permanently;
* the frame rate: up to 10 million frames/s, above the fastest Phantom cameras (about 1.75 Mfps);
* the simulated sample rate: up to 1 MHz (the solver's default largest step is 2 us).
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass

from cageless.conditions import CONDITION_KEYS, LabEntry, OperatingConditions
from cageless.errors import CagelessError, UsageError

__all__ = ["Limit", "LIMITS", "check_value", "check_options", "conditions_problem", "check_output_size",
           "MAX_OUTPUT_FRACTION", "plausible_entry"]


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
        fmt = "d" if self.integer else "g"
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
    "speed_rpm": Limit("r/min", 0.0, math.inf, 1.0, 60_000.0, lo_open=True),
    "radial_load_n": Limit("N", 0.0, math.inf, 0.0, 100_000.0),
    "axial_load_n": Limit("N", 0.0, math.inf, 0.0, 100_000.0),
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

#: Largest share of the machine's memory that one simulation's samples may take.
MAX_OUTPUT_FRACTION = 0.25


def _option(key: str) -> str:
    return "--" + key.replace("_", "-")


def check_value(key: str, value: float | int | None, force: bool = False, label: str | None = None) -> None:
    """Refuse ``value`` for ``key`` when it breaks the hard rule, or leaves the plausible range without ``force``.

    Raises
    ------
    UsageError
        Naming the option (``label``, default ``--key``), the value and the range.
    """
    if value is None:
        return
    lim = LIMITS[key]
    name = label or _option(key)
    v = float(value)
    below = v <= lim.hard_lo if lim.lo_open else v < lim.hard_lo
    if not math.isfinite(v) or below or v > lim.hard_hi:
        raise UsageError(f"{name} {value:g}: {lim.hard_rule()}." if math.isfinite(v)
                         else f"{name} {value}: must be a finite number.")
    if not force and not lim.lo <= v <= lim.hi:
        raise UsageError(f"{name} {value:g}: outside the plausible range {lim.plausible()}. "
                         "Check the value, or pass --force to run it anyway.")


def check_options(args: object, keys: tuple[str, ...], force: bool | None = None) -> None:
    """Check every ``keys`` attribute of an argparse namespace (``force`` defaults to ``args.force``)."""
    force = bool(getattr(args, "force", False)) if force is None else force
    for key in keys:
        check_value(key, getattr(args, key, None), force)


def conditions_problem(conditions: OperatingConditions, force: bool = False) -> str | None:
    """Describe the first condition outside its plausible range (a sentence), or ``None`` when all are plausible."""
    if force:
        return None
    for key in CONDITION_KEYS:
        value = getattr(conditions, key)
        lim = LIMITS.get(key)
        if value is None or lim is None:
            continue
        if not lim.lo <= float(value) <= lim.hi:
            return (f"'{key}' = {value:g} is outside the plausible range {lim.plausible()}. "
                    "Fix the conditions, or pass --force to run it anyway.")
    return None


def plausible_entry(entry: LabEntry, force: bool = False) -> LabEntry:
    """A lab video whose conditions are outside their plausible ranges becomes a failed one (unless ``force``)."""
    if not entry.ok or entry.resolved is None:
        return entry
    problem = conditions_problem(entry.resolved.conditions, force)
    if problem is None:
        return entry
    origin = ", ".join(sorted(set(entry.resolved.origin.values()))) or "the command line"
    return LabEntry(video=entry.video, error=CagelessError(f"{entry.video}: {problem} (conditions from {origin})"))


def _memory_bytes() -> float:
    try:
        return float(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):  # pragma: no cover - non-POSIX
        return 8e9


def check_output_size(duration_s: float, sample_rate_hz: float, n_balls: int, floats_per_ball: int = 40) -> None:
    """Refuse a simulation whose samples would not fit in memory, before any work.

    The estimate counts ``floats_per_ball`` float64 values per ball and sample (the trace's datasets
    plus the solver's state kept at each sample). Refused even with ``--force``.
    """
    n = duration_s * sample_rate_hz + 1
    need = n * n_balls * floats_per_ball * 8.0
    budget = MAX_OUTPUT_FRACTION * _memory_bytes()
    if need > budget:
        raise UsageError(
            f"--duration {duration_s:g} s at --sample-rate {sample_rate_hz:g}/s is {n:.3g} samples, about "
            f"{need / 1e9:.3g} GB, more than this machine can hold ({budget / 1e9:.3g} GB allowed). "
            "Lower --sample-rate or --duration.")
