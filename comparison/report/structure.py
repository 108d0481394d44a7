"""Layer 2: the report as a neutral structure (sections, key-value tables, figures), free of HTML."""

from __future__ import annotations

import json
import math
import platform
import sys
from collections.abc import Mapping, Sequence
from datetime import datetime, timezone
from typing import Any

from cageless import __version__
from cageless.comparison.compare import SLIP_REFERENCES, ComparisonRow
from cageless.comparison.metrics import SLIP_RATE_DEFINITION
from cageless.profiles import PEAK_SMOOTHING_DEG
from cageless.provenance import HASH_ALGORITHMS, git_commit
from cageless.comparison.report import figures
from cageless.comparison.report.describe import ConditionDescription, tracking_verdict
from cageless.comparison.table import number_cell, slip_reference_note, table_frame, to_html

__all__ = ["build_report"]


def _effects(info: Mapping[str, Any]) -> list[str]:
    try:
        data = json.loads(info.get("effects_json", "{}"))
    except json.JSONDecodeError:
        return []
    return [f"{e['name']}: {'on' if e['on'] else 'off'} ({e['reason']})" for e in data.get("effects", [])]


def _section(d: ConditionDescription) -> dict[str, Any]:
    r = d.row
    facts = [("speed", f"{r.speed_rpm:g} r/min"), ("radial load", f"{r.radial_load_n:g} N"),
             ("axial load", f"{r.axial_load_n:g} N"), ("status", r.status)]
    if r.message:
        facts.append(("message", r.message))
    section: dict[str, Any] = {"title": d.label, "status": r.status, "facts": facts, "figures": []}
    if d.comparison is not None:
        section["figures"] = [
            {"caption": "Revolution speed against orbital angle: the mean over balls and passes, and a band of "
                        "plus and minus one standard deviation of the single samples. Look for "
                        "the dip in the unloaded zone (0-180 deg, shaded) and whether the two curves share it.",
             "svg": figures.speed_figure(d)},
            {"caption": "Slip rate against orbital angle: mean, and a band of one standard deviation of the single "
                        "samples (how much balls and passes differ, not how uncertain the mean is: the table's "
                        "plus-minus is the standard error of the peak). The table's slip rates are the peaks "
                        "of these curves in the unloaded zone, each smoothed by a periodic Gaussian of sigma "
                        f"{PEAK_SMOOTHING_DEG:g} deg first; the MAE is their mean distance.",
             "svg": figures.slip_figure(d)},
            {"caption": "Ball-ball contact episodes (simulated): peak force by orbital angle. Collisions should "
                        "gather in the unloaded and transition zones, with none at 240-300 deg.",
             "svg": figures.contact_polar_figure(d)},
            {"caption": "Inner-ring centre orbit and its Poincare section (simulated, one point per shaft "
                        "revolution). A scattered cloud means aperiodic motion, a closed curve quasi-periodic.",
             "svg": figures.ring_figure(d)},
        ]
        if d.contact_track is not None:
            section["figures"].append({"caption": "Contact trajectory on the raceways (simulated, spatial model; "
                                                  "the paper's figure 13): how far the contact angle swings "
                                                  "around the orbit.", "svg": figures.contact_track_figure(d)})
        section["facts"] += [("settling time left out of the simulation", f"{1e3 * d.comparison.settle_s:.0f} ms"),
                             ("slip reference", SLIP_REFERENCES.get(r.slip_reference, r.slip_reference)),
                             ("peak slip estimator", f"maximum over 0-180 deg of the 1 deg mean profile smoothed by "
                                                     f"a periodic Gaussian of sigma {PEAK_SMOOTHING_DEG:g} deg "
                                                     "(measured and simulated alike)")]
    return section


def _summary(d: ConditionDescription) -> dict[str, Any]:
    r = d.row
    passed, reasons = tracking_verdict(d.qc)
    return {"title": d.label, "condition": f"{r.speed_rpm:g} r/min, {r.radial_load_n:g} N radial, "
                                           f"{r.axial_load_n:g} N axial",
            "theoretical": _slip_text(r.theoretical_slip_pct, r.theoretical_slip_se_pp),
            "experimental": _slip_text(r.experimental_slip_pct, r.experimental_slip_se_pp),
            "mae": f"{r.mae_pp:.2f} pp", "qc_pass": passed, "qc_reasons": reasons,
            "svg": figures.slip_figure(d, size=(3.4, 3.4)) if d.comparison is not None else None}


def _slip_text(value_pct: float, se_pp: float) -> str:
    """``"6.52 ± 1.30 %"`` (the standard error from the balls), or ``"6.52 %"`` when it is not known."""
    return f"{value_pct:.2f} ± {se_pp:.2f} %" if math.isfinite(se_pp) else f"{value_pct:.2f} %"


def _qc(d: ConditionDescription) -> dict[str, Any]:
    qc = d.qc or {}
    rate = qc.get("detection_rate") or []
    facts = [("video", d.video_provenance.get("inputs", [{}])[0].get("name", d.label) if d.video_provenance
              else d.label)]
    if qc:
        facts += [("balls found", f"{qc.get('n_balls_found')} of {qc.get('n_balls_expected')}"),
                  ("detection rate (min / mean)", f"{100 * min(rate):.1f} % / {100 * sum(rate) / len(rate):.1f} %"
                   if rate else "-"),
                  ("interpolated samples", f"{100 * qc.get('interpolated_share', 0):.2f} %"),
                  ("orbit fit residual", f"{qc.get('orbit_residual_px', float('nan')):.3f} px"),
                  ("scale", f"{qc.get('px_per_mm', float('nan')):.3f} px/mm"),
                  ("estimated precision (from the trace alone)", _precision_text(qc.get("precision") or {})),
                  ("warnings", "; ".join(qc.get("warnings", [])) or "none")]
    return {"title": d.label, "facts": facts}


def _precision_text(p: Mapping[str, Any]) -> str:
    """The trace's self-assessed angle and speed precision, or "-" for a trace that does not carry one."""
    if "angle_rms_mrad" not in p or "speed_rms_pct" not in p:
        return "-"
    return f"angle {p['angle_rms_mrad']:.2f} mrad RMS, speed {p['speed_rms_pct']:.2f} % of the cage speed RMS"


def build_report(descriptions: Sequence[ConditionDescription], failed_rows: Sequence[ComparisonRow] = (),
                 reproduction: Mapping[str, Any] | None = None, timings: Mapping[str, float] | None = None,
                 title: str = "cageless: model against experiment", notices: Sequence[str] = ()) -> dict[str, Any]:
    """The report's structure: conditions (with ``notices``, the warnings said about the inputs), the
    Table-2-style table, one section per condition, QC, reproduction."""
    descriptions = sorted(descriptions, key=lambda d: (d.row.speed_rpm, d.row.radial_load_n, d.row.axial_load_n,
                                                       d.row.label))  # the slip table's order
    rows = [d.row for d in descriptions] + list(failed_rows)
    frame = table_frame(rows)
    commit = git_commit()
    repro = [("software version", __version__), *([("git commit", commit)] if commit else []),
             ("Python", f"{sys.version.split()[0]} on {platform.platform()}")] + [(k, v if isinstance(v, str) else json.dumps(v, sort_keys=True))
                                                    for k, v in (reproduction or {}).items()]
    for d in descriptions:
        info = d.simulation_info
        if info:
            repro.append((f"{d.label}: solver", f"{info['solver']} rtol {info['rtol']:g}, {info['steps']} steps, "
                                                 f"{info['wall_s']:.1f} s"))
            repro.append((f"{d.label}: effects", "; ".join(_effects(info))))
        for item in d.video_provenance.get("inputs", []):
            algorithm = next((a for a in reversed(HASH_ALGORITHMS) if a in item), "sha256")
            repro.append((f"input {item.get('name')}", f"{algorithm} {item.get(algorithm)}"))
    return {
        "title": title,
        "generated_utc": datetime.now(timezone.utc).strftime("%Y-%m-%d %H:%M:%S UTC"),
        "conditions": [[*(number_cell(v) for v in (r.speed_rpm, r.radial_load_n, r.axial_load_n)), r.label, r.status]
                       for r in table_frame(rows).itertuples()],
        "table_html": to_html(frame),
        "definition": f"{SLIP_RATE_DEFINITION} {slip_reference_note(frame)}",
        "summary": [_summary(d) for d in descriptions],
        "sections": [_section(d) for d in descriptions],
        "failures": [{"title": r.label, "message": r.message} for r in failed_rows],
        "qc": [_qc(d) for d in descriptions if d.qc],
        "reproduction": repro,
        "notices": list(notices),
        "timings": [(k, f"{v:.1f} s") for k, v in (timings or {}).items()],
    }
