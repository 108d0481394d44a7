"""Plausible ranges for every user-facing number, and checks of the conditions read from a lab folder.

Each number has a *hard* rule (a value that cannot mean anything: a zero sample rate, a negative seed,
a NaN) and a *plausible* range (values a bearing test rig can produce). A value breaking the hard rule
is always refused; a value outside the plausible range is refused with the range named unless the user
passes ``--force``. Both are usage errors (exit code 2) on the command line.

The rules and ranges themselves are :data:`cageless.limits.LIMITS`, where their sources are given.
"""

from __future__ import annotations

import math
import os

from cageless.conditions import CONDITION_KEYS, LabEntry, OperatingConditions
from cageless.errors import CagelessError, UsageError
from cageless.limits import LIMITS, Limit, hard_problem

__all__ = ["Limit", "LIMITS", "check_value", "check_options", "conditions_problem", "check_output_size",
           "MAX_OUTPUT_FRACTION", "plausible_entry"]


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
    problem = hard_problem(key, v)
    if problem:
        if not math.isfinite(v):
            raise UsageError(f"{name} {value}: {problem}.")
        above = f" (the plausible range is {lim.plausible()})" if v > lim.hard_hi else ""
        raise UsageError(f"{name} {value:g}: {problem}{above}.")
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
