"""Compare one measured and one simulated trace: the Table-2 row and what the figures need."""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any

from cageless.trace import Trace
from comparison.align import MismatchError, Profiles, check_compatible, profiles, simulation_settle_s
from comparison.metrics import profile_errors, unloaded_peak

__all__ = ["ComparisonRow", "Comparison", "compare"]


@dataclass(frozen=True)
class ComparisonRow:
    """One row of the Table-2-style table (slips and errors in percentage points)."""

    speed_rpm: float
    radial_load_n: float
    axial_load_n: float
    theoretical_slip_pct: float
    experimental_slip_pct: float
    mae_pp: float
    rmse_pp: float
    max_error_pp: float
    label: str = ""
    status: str = "ok"
    message: str = ""

    def to_dict(self) -> dict[str, Any]:
        """Plain values."""
        return asdict(self)


@dataclass
class Comparison:
    """Everything one comparison computed."""

    row: ComparisonRow
    measured: Profiles
    simulated: Profiles
    mismatches: list[str] = field(default_factory=list)
    settle_s: float = 0.0


def compare(measured: Trace, simulated: Trace, bin_deg: float = 1.0, settle_s: float | None = None,
            force: bool = False, label: str = "") -> Comparison:
    """Align the traces and compute the row.

    ``settle_s`` is the simulated start-up left out of the simulation's profiles; by default three cage
    revolutions (:func:`~comparison.align.simulation_settle_s`).

    Raises
    ------
    MismatchError
        When conditions or bearing differ and ``force`` is False (the message lists the differences).
    """
    mismatches = check_compatible(measured, simulated)
    if mismatches and not force:
        raise MismatchError("the traces differ: " + "; ".join(mismatches)
                            + ". Compare traces of the same condition, or pass --force to compare anyway "
                            "(the report then shows the mismatch).")
    if settle_s is None:
        settle_s = simulation_settle_s(simulated)
    pm = profiles(measured, bin_deg)
    ps = profiles(simulated, bin_deg, settle_s=settle_s)
    err = profile_errors(pm.slip["mean"].to_numpy(), ps.slip["mean"].to_numpy())
    row = ComparisonRow(
        speed_rpm=measured.speed_rpm, radial_load_n=measured.radial_load_n, axial_load_n=measured.axial_load_n,
        theoretical_slip_pct=100 * unloaded_peak(ps.slip), experimental_slip_pct=100 * unloaded_peak(pm.slip),
        mae_pp=err.mae_pp, rmse_pp=err.rmse_pp, max_error_pp=err.max_pp, label=label,
        status="mismatch" if mismatches else "ok", message="; ".join(mismatches))
    return Comparison(row=row, measured=pm, simulated=ps, mismatches=mismatches, settle_s=settle_s)
