"""Layer 1: what the report shows, computed from the traces (no formatting, no plotting)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt
import pandas as pd

from cageless.trace import Trace
from cageless.comparison.compare import Comparison, ComparisonRow, tracking_verdict

__all__ = ["ConditionDescription", "describe_condition", "poincare_section", "tracking_verdict"]


@dataclass
class ConditionDescription:
    """One condition (or one failed one): the row, profiles, events, ring path, QC and provenance."""

    label: str
    row: ComparisonRow
    comparison: Comparison | None = None
    events: pd.DataFrame | None = None
    ring_yz_m: npt.NDArray[np.float64] | None = None
    poincare_yz_m: npt.NDArray[np.float64] | None = None
    qc: dict[str, Any] = field(default_factory=dict)
    video_provenance: dict[str, Any] = field(default_factory=dict)
    simulation_info: dict[str, Any] = field(default_factory=dict)
    #: Spatial simulations only: orbital angle (rad), inner and outer contact angle (rad) and inner
    #: contact point (axial x, y, z in m) of the loaded race contacts after the start-up, flattened.
    contact_track: dict[str, npt.NDArray[np.float64]] | None = None


def poincare_section(time: npt.NDArray[np.float64], yz: npt.NDArray[np.float64], period_s: float,
                     start_s: float = 0.0) -> npt.NDArray[np.float64]:
    """The ring centre strobed once per shaft revolution (interpolated), from ``start_s`` on."""
    if not (math.isfinite(period_s) and period_s > 0):
        return np.empty((0, 2))
    ts = np.arange(max(start_s, time[0]), time[-1], period_s)
    ok = np.all(np.isfinite(yz), axis=1)
    if ok.sum() < 2 or len(ts) == 0:
        return np.empty((0, 2))
    return np.column_stack([np.interp(ts, time[ok], yz[ok, 0]), np.interp(ts, time[ok], yz[ok, 1])])


def describe_condition(label: str, comparison: Comparison, measured: Trace, simulated: Trace) -> ConditionDescription:
    """Collect everything the report needs about one compared condition."""
    settle = comparison.settle_s
    events = simulated.events
    if events is not None:
        events = events[events.time >= settle].reset_index(drop=True)
    ring = simulated.groups.get("inner_ring", {}).get("position")
    ring_yz = poincare = None
    if ring is not None:
        keep = simulated.time >= settle
        ring_yz = np.asarray(ring)[keep][:, 1:3]
        poincare = poincare_section(simulated.time[keep], ring_yz, 60.0 / simulated.speed_rpm, settle)
    sim = simulated.simulation
    track = contact_track(simulated, settle)
    info = {} if sim is None else {"solver": sim.solver, "rtol": sim.rtol, "steps": sim.n_steps,
                                   "wall_s": sim.wall_s, "effects_json": sim.effects_json}
    return ConditionDescription(
        label=label, row=comparison.row, comparison=comparison, events=events, ring_yz_m=ring_yz,
        poincare_yz_m=poincare, qc=measured.qc or {}, video_provenance=measured.provenance or {},
        simulation_info=info, contact_track=track)


def contact_track(trace: Trace, settle_s: float, max_points: int = 4_000) -> dict[str, npt.NDArray[np.float64]] | None:
    """The contact trajectory of a spatial trace (the paper's figure 13) after ``settle_s``, loaded contacts
    only (inner force above 1 N), at most ``max_points`` points (evenly thinned); None for planar traces."""
    c = trace.groups.get("contacts", {})
    if "inner_point" not in c:
        return None
    keep = trace.time >= settle_s
    loaded = np.asarray(c["inner_normal"])[keep] > 1.0
    step = max(1, int(np.ceil(loaded.sum() / max_points)))
    pick = (slice(None, None, step),)

    def flat(a: Any) -> npt.NDArray[np.float64]:
        return np.asarray(a)[keep][loaded][pick]

    return {"orbital_angle": flat(np.mod(trace.angle, 2 * np.pi)), "inner_angle": flat(c["inner_angle"]),
            "outer_angle": flat(c["outer_angle"]), "inner_point": flat(c["inner_point"])}


