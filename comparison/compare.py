"""Compare one measured and one simulated trace: the Table-2 row and what the figures need."""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field, replace
from typing import Any

from cageless.errors import CagelessError, ParameterError
from cageless.kinematics import LOADED_ZONE_HALF_WIDTH_DEG, loaded_zone_speed, rereference_slip
from cageless.profiles import peak_standard_error
from cageless.trace import Trace
from cageless.comparison.align import MismatchError, Profiles, check_compatible, profiles, simulation_settle_s
from cageless.comparison.metrics import profile_errors, unloaded_peak

__all__ = ["ComparisonRow", "Comparison", "compare", "tracking_verdict", "QC_FAILED", "match_contact_angle", "slip_contact_angle", "SLIP_REFERENCES",
           "refer_to_loaded_zone"]

#: What a comparison's slip rates are referred to, by name (the table and the report print the text).
SLIP_REFERENCES = {
    "cage": "the pure-rolling cage speed of the stated shaft speed",
    "loaded-zone": (f"each trace's own loaded-zone speed (the median orbit speed of the balls within "
                    f"{LOADED_ZONE_HALF_WIDTH_DEG:g} deg of 270 deg), which removes a flat bias such as a "
                    "stated speed, scale or clearance slightly off"),
}


#: A row's status when its video failed the tracking QC (:func:`tracking_verdict`): the numbers stand, flagged.
QC_FAILED = "tracking QC failed"


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
    slip_reference: str = "cage"
    #: Standard errors (pp) of the two slip rates from the balls they were taken over
    #: (:func:`cageless.profiles.peak_standard_error`); NaN when not known.
    theoretical_slip_se_pp: float = float("nan")
    experimental_slip_se_pp: float = float("nan")

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
            force: bool = False, label: str = "", slip_reference: str = "cage") -> Comparison:
    """Align the traces and compute the row.

    ``settle_s`` is the simulated start-up left out of the simulation's profiles; by default three cage
    revolutions (:func:`~cageless.comparison.align.simulation_settle_s`). ``slip_reference`` is a key of
    :data:`SLIP_REFERENCES`: ``"cage"`` (the pure-rolling cage speed, the paper's definition) or
    ``"loaded-zone"`` (each trace's slip against its own loaded-zone speed, :func:`refer_to_loaded_zone`).

    Raises
    ------
    MismatchError
        When conditions or bearing differ and ``force`` is False (the message lists the differences).
    ParameterError
        When ``measured`` is a simulation trace and ``simulated`` a video trace (the arguments swapped).
    """
    if slip_reference not in SLIP_REFERENCES:
        raise ParameterError("slip_reference", f"must be one of {', '.join(SLIP_REFERENCES)}", slip_reference)
    if (measured.source, simulated.source) == ("simulation", "video"):
        raise ParameterError("measured", "is a simulation trace, and simulated a video trace",
                             hint="Swap them: compare(video_trace, simulation_trace).")
    mismatches = check_compatible(measured, simulated)
    if mismatches and not force:
        raise MismatchError("the traces differ: " + "; ".join(mismatches)
                            + ". Compare traces of the same condition, or pass --force (force=True in Python) to "
                            "compare anyway (the report then shows the mismatch).")
    if settle_s is None:
        settle_s = simulation_settle_s(simulated)
    if slip_reference == "loaded-zone":
        measured, note = refer_to_loaded_zone(measured)
        simulated, note_sim = refer_to_loaded_zone(simulated, settle_s)
        note = f"{note}; {note_sim}"
    else:
        measured, note = match_contact_angle(measured, simulated)
    pm = profiles(measured, bin_deg)
    ps = profiles(simulated, bin_deg, settle_s=settle_s)
    # A video's QC failures go with the row into every table (a trace without a QC record is not a video's)
    qc_reasons = tracking_verdict(measured.qc)[1] if measured.qc else []
    err = profile_errors(pm.slip["mean"].to_numpy(), ps.slip["mean"].to_numpy())
    row = ComparisonRow(
        speed_rpm=measured.speed_rpm, radial_load_n=measured.radial_load_n, axial_load_n=measured.axial_load_n,
        theoretical_slip_pct=100 * unloaded_peak(ps.slip), experimental_slip_pct=100 * unloaded_peak(pm.slip),
        mae_pp=err.mae_pp, rmse_pp=err.rmse_pp, max_error_pp=err.max_pp, label=label,
        status="mismatch" if mismatches else (QC_FAILED if qc_reasons else "ok"),
        message="; ".join(mismatches + qc_reasons + ([note] if note else [])),
        slip_reference=slip_reference,
        theoretical_slip_se_pp=100 * peak_standard_error(ps.slip_per_ball, bin_deg),
        experimental_slip_se_pp=100 * peak_standard_error(pm.slip_per_ball, bin_deg))
    return Comparison(row=row, measured=pm, simulated=ps, mismatches=mismatches, settle_s=settle_s)


def tracking_verdict(qc: dict[str, Any]) -> tuple[bool, list[str]]:
    """Pass or fail a video's tracking QC.

    The tracker judges its own QC against its limits (detection rate, interpolated share, orbit fit,
    speed cross-check, negative slip) and records each breach as a warning; the verdict passes when every
    ball was found and there is no such warning.

    Parameters
    ----------
    qc
        The QC record a video trace carries (``n_balls_found``, ``n_balls_expected``, ``warnings``).

    Returns
    -------
    tuple of (bool, list of str)
        Whether the QC passes, and a plain-language reason for each thing that fails it.
    """
    if not qc:
        return False, ["no tracking QC record"]
    reasons = []
    found, expected = qc.get("n_balls_found"), qc.get("n_balls_expected")
    if found != expected:
        reasons.append(f"{found} balls found, {expected} expected")
    reasons += [f"tracker warning: {w}" for w in qc.get("warnings", [])]
    return not reasons, reasons


def refer_to_loaded_zone(trace: Trace, settle_s: float = 0.0) -> tuple[Trace, str]:
    """``trace`` with its slip referred to its own loaded-zone speed, and a note giving that speed.

    The reference is :func:`cageless.kinematics.loaded_zone_speed` of the valid samples after ``settle_s``;
    the slip becomes ``1 - theta_dot / omega_lz``. A flat error in the stated speed (or an effective
    rolling radius off by scale or clearance) moves ``omega_c`` and ``omega_lz`` alike, so it drops out.

    Raises
    ------
    CagelessError
        When fewer than 10 valid samples lie in the loaded zone (the trace then cannot give its reference).
    """
    keep = (trace.time >= trace.time[0] + settle_s)[:, None] & trace.valid
    omega_lz = loaded_zone_speed(trace.angle, trace.speed, keep)
    if omega_lz is None or not omega_lz > 0:
        raise CagelessError(f"the {trace.source} trace has too few samples in the loaded zone (within "
                            f"{LOADED_ZONE_HALF_WIDTH_DEG:g} deg of 270 deg) to give its own slip reference: "
                            "use a longer trace or the cage-speed reference.")
    omega_c = trace.speed_rpm * math.pi / 30.0 * 0.5 * (
        1.0 - trace.ball_diameter_m * math.cos(slip_contact_angle(trace)) / trace.pitch_diameter_m)
    config = {**trace.config, "slip_reference": "loaded-zone", "slip_reference_speed_rad_s": omega_lz}
    note = (f"{trace.source} slip referred to its loaded-zone speed {omega_lz:.4g} rad/s "
            f"({100 * (omega_lz / omega_c - 1):+.2f} % from the cage speed)")
    return replace(trace, slip=1.0 - trace.speed / omega_lz, config=config), note


def slip_contact_angle(trace: Trace) -> float:
    """The contact angle alpha (rad) a trace's slip rates are referred to: a simulation stores the
    nominal angle it used (``nominal_contact_angle_rad``), a video trace ``slip_contact_angle_rad``; 0 if
    neither is recorded."""
    for key in ("nominal_contact_angle_rad", "slip_contact_angle_rad"):
        value = trace.config.get(key)
        if value is not None:
            return float(value)
    return 0.0


def match_contact_angle(measured: Trace, simulated: Trace) -> tuple[Trace, str]:
    """The measured trace with its slip referred to the simulation's contact angle, and a note saying so.

    Under axial load the model's balls roll at a contact angle (about 10 deg at 400 N), which raises the
    pure-rolling cage speed by ~0.5 %; a video trace referred to alpha = 0 would read that much higher slip.
    """
    a_meas, a_sim = slip_contact_angle(measured), slip_contact_angle(simulated)
    if abs(a_meas - a_sim) < 1e-9:
        return measured, ""
    slip = rereference_slip(measured.slip, measured.ball_diameter_m, measured.pitch_diameter_m, a_meas, a_sim)
    config = {**measured.config, "slip_contact_angle_rad": a_sim}
    note = (f"measured slip referred to the model's contact angle {math.degrees(a_sim):.2f} deg "
            f"(recorded at {math.degrees(a_meas):.2f} deg)")
    return replace(measured, slip=slip, config=config), note
