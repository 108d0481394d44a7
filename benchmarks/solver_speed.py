"""Simulator speed: today's `auto` and DP5 against the compiled Rosenbrock-W method, in one run.

    python benchmarks/solver_speed.py [--repeats 3] [--window 0.005] [--cases planar,spatial,bunching,20kN]
                                      [--candidates auto,dp5,rosw6,...] [--json out.json]

Cases (every effect of a lubricated scene):

* ``planar``: 3000 rpm, 500 N, from the state 30 ms after the start, a ``--window`` long;
* ``spatial``: 3000 rpm, 500 N radial + 400 N axial, 5 strips, the same;
* ``bunching``: 1800 rpm, 500 N, from the packed start (the balls bunch), 20 ms;
* ``20kN``: 3000 rpm, 20 kN, from the start, 20 ms;
* ``axial-only``, ``tilt``: the spatial hard cases of tests/validation/test_spatial.py, 3000 rpm with 500 N axial
  load only, and 500 N radial with the ring misaligned by 1 mrad, from the start, 20 ms;
* ``planar-start``, ``spatial-start``, ``6000rpm``, ``lowload``: 3000 rpm 500 N (planar), 500 N + 400 N
  axial (spatial, 5 strips), 6000 rpm 500 N and 3000 rpm 5 N, from the start, 30 ms (``--duration``).

``--candidates`` picks rows by key (:data:`CANDIDATES`); ``auto-before`` is the automatic switch as it was
before it probed from the start (no pilot, probes at chunks 5 and 20, a way back for good, the earlier cost
figures: :data:`cageless.simulation.auto_switch.RHS_COST_US_BEFORE`), and ``auto-cvode`` as it was before it
probed ``ark4`` beside CVODE (:data:`cageless.simulation.auto_switch.STIFF_METHODS`), and ``auto-planar-ark`` as it
was before it probed ``ark4`` at the spatial level (:data:`cageless.simulation.auto_switch.ARK_MODELS`, no
:data:`~cageless.simulation.auto_switch.ARK_REFUSAL_BOUND`, ark4's force-jump test on the ring's rows), all run in
the same process.

The settled cases measure the slip error as ``cageless bench accuracy`` does (largest difference of the
balls' orbital speed over all balls and samples, in percentage points of the cage speed) against a DP5
reference at rtol 1e-10 and a 0.25 us cap. The ball ring is chaotic, so the 20 ms runs from the start are
compared with the reference over their first 2 ms only (``early_slip_error_pp``), and by their energy
balance (drift over input work).

Candidates are run interleaved (every candidate once per round, ``--repeats`` rounds) and each keeps its
shortest wall time (of the whole call, timed here: ``auto``'s ``Solution.wall_s`` summed only its solver calls
before 2026-11-27, without the driver between them, which made its CPU time exceed its wall time) and its
shortest CPU time (the process's, ``time.process_time``): the machine is
shared, and noise only adds time; on an oversubscribed machine the CPU time is the steadier of the two.
Ratios are to ``auto`` in the same run, by CPU time.
"""

from __future__ import annotations

import argparse
import json
import logging
import time
from contextlib import contextmanager
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

import cageless.simulation.auto_switch as switch
from cageless.atomic import atomic_write_text
from cageless.conditions import OperatingConditions
from cageless.kinematics import theoretical_cage_speed
from cageless.simulation.bench import _errors, _settled_problem
from cageless.simulation.kernels import PLANAR
from cageless.simulation.parameters import ModelParameters
from cageless.simulation.run import energy_balance
from cageless.simulation.scene import Scene
from cageless.simulation.simulation import Choices, Simulation
from cageless.simulation.solve import solve

log = logging.getLogger("solver_speed")

#: key: (label, method, rtol, max_step; None: the method's default as ``simulate`` runs it).
CANDIDATES = {
    "auto": ("auto (today's default)", "auto", 1e-6, None),
    "auto-before": ("auto before (probes at chunks 5, 20)", "auto-before", 1e-6, None),
    "auto-cvode": ("auto, CVODE the only stiff backend (before ark4 was one)", "auto-cvode", 1e-6, None),
    "auto-planar-ark": ("auto, ark4 planar only (before it was probed at the spatial level)", "auto-planar-ark", 1e-6,
                        None),
    "dp5": ("dp5, rtol 1e-6, cap 2 us", "dp5", 1e-6, 2e-6),
    "CVODE": ("CVODE throughout (rtol 1e-6, cap 5 us; auto runs it at 0.03 x rtol)", "CVODE", 1e-6, None),
    "rosw6": ("rosw, rtol 1e-6 (cap 10 us)", "rosw", 1e-6, None),
    "rosw7": ("rosw, rtol 1e-7 (cap 10 us)", "rosw", 1e-7, None),
    "rosw3e-7": ("rosw, rtol 3e-7 (cap 10 us)", "rosw", 3e-7, None),
    "rosw8": ("rosw, rtol 1e-8 (cap 10 us)", "rosw", 1e-8, None),
    "ark4": ("ark4 (IMEX), rtol 1e-6 (error test at 0.2 x rtol, cap 50 us)", "ark4", 1e-6, None),
    "ark4-3e-7": ("ark4 (IMEX), rtol 3e-7 (error test at 0.2 x rtol, cap 50 us)", "ark4", 3e-7, None),
    "ark4-7": ("ark4 (IMEX), rtol 1e-7 (error test at 0.2 x rtol, cap 50 us)", "ark4", 1e-7, None),
    "ark4-8": ("ark4 (IMEX), rtol 1e-8 (error test at 0.2 x rtol, cap 50 us)", "ark4", 1e-8, None),
    "ark4-onset10": ("ark4 (IMEX), rtol 1e-6, a tenth of the contact-onset step", "ark4-onset10", 1e-6, None),
    "ark4-7-onset10": ("ark4 (IMEX), rtol 1e-7, a tenth of the contact-onset step", "ark4-onset10", 1e-7, None),
}
DEFAULT_CANDIDATES = "auto,dp5,rosw6,rosw7,rosw3e-7,rosw8"


@contextmanager
def _switch_before():  # noqa: ANN202
    """The automatic switch as it was: probes at chunks 5 and 20 only, a way back for good, the earlier costs."""
    saved = (switch.PROBE_CHUNKS, switch.PROBE_BACKOFF, switch.RHS_COST_US, switch.STEP_COST_US, switch.SWITCH_GAIN,
             switch.PILOT_FRACTION)
    switch.PROBE_CHUNKS, switch.PROBE_BACKOFF, switch.SWITCH_GAIN, switch.PILOT_FRACTION = (5, 20), None, 0.6, None
    switch.RHS_COST_US, switch.STEP_COST_US = switch.RHS_COST_US_BEFORE, switch.STEP_COST_US_BEFORE
    try:
        yield
    finally:
        (switch.PROBE_CHUNKS, switch.PROBE_BACKOFF, switch.RHS_COST_US, switch.STEP_COST_US,
         switch.SWITCH_GAIN, switch.PILOT_FRACTION) = saved


@contextmanager
def _cvode_only():  # noqa: ANN202
    """The automatic switch with CVODE as its only stiff backend, as it was before ark4 became a candidate."""
    saved = switch.STIFF_METHODS
    switch.STIFF_METHODS = ("CVODE",)
    try:
        yield
    finally:
        switch.STIFF_METHODS = saved


@contextmanager
def _ark_planar_only():  # noqa: ANN202
    """The automatic switch as it was before it probed ark4 at the spatial level: ark4 at the planar level only, no
    bound on its refusals, and ark4 with the force-jump test on the ring's rows (commit 4536761)."""
    import cageless.simulation.solve as solve_module

    saved = switch.ARK_MODELS, switch.ARK_REFUSAL_BOUND, solve_module._ark_jump_floor
    switch.ARK_MODELS, switch.ARK_REFUSAL_BOUND = frozenset({PLANAR}), {}
    solve_module._ark_jump_floor = lambda pr: pr
    try:
        yield
    finally:
        switch.ARK_MODELS, switch.ARK_REFUSAL_BOUND, solve_module._ark_jump_floor = saved


def _from_start(rpm: float, load_n: float, axial_n: float = 0.0, level: str | None = None,
                **scene_kw: Any):  # noqa: ANN202
    scene = Scene(conditions=OperatingConditions(rpm, load_n, axial_n), **scene_kw)
    pr = Simulation(scene, ModelParameters(), Choices(level=level)).build()
    return pr, theoretical_cage_speed(scene.bearing.geometry, scene.conditions.speed_rad_s)


def _cases(window: float, names: list[str], duration: float = 0.03) -> dict[str, tuple[Any, float, np.ndarray]]:
    start = np.linspace(0, duration, int(round(duration / 1e-4)) + 1)
    table = {
        "planar": lambda: (*_settled_problem(3000, 500, 0.03, level="planar"), np.linspace(0, window, 51)),
        "spatial": lambda: (*_settled_problem(3000, 500, 0.03, axial_n=400, level="spatial", strips=5),
                            np.linspace(0, window, 51)),
        "bunching": lambda: (*_from_start(1800, 500), np.linspace(0, 0.02, 201)),
        "20kN": lambda: (*_from_start(3000, 20000), np.linspace(0, 0.02, 201)),
        "planar-start": lambda: (*_from_start(3000, 500), start),
        "spatial-start": lambda: (*_from_start(3000, 500, 400, level="spatial"), start),
        "6000rpm": lambda: (*_from_start(6000, 500), start),
        "lowload": lambda: (*_from_start(3000, 5), start),
        "axial-only": lambda: (*_from_start(3000, 0, 500, level="spatial"), np.linspace(0, 0.02, 201)),
        "tilt": lambda: (*_from_start(3000, 500, level="spatial", misalignment_rad=1e-3), np.linspace(0, 0.02, 201)),
    }
    return {name: table[name]() for name in names}


def _run(pr: Any, t: np.ndarray, method: str, rtol: float, cap: float | None) -> Any:
    kw = {} if cap is None else {"max_step": cap}
    if method == "auto-before":
        with _switch_before(), _cvode_only():
            return solve(pr, t, method="auto", rtol=rtol)
    if method == "auto-cvode":
        with _cvode_only():
            return solve(pr, t, method="auto", rtol=rtol)
    if method == "auto-planar-ark":
        with _ark_planar_only():
            return solve(pr, t, method="auto", rtol=rtol)
    if method == "ark4-onset10":  # the onset control's step (Problem.onset_step) a tenth of the problem's
        return _run(replace(pr, onset_step=0.1 * pr.onset_step), t, "ark4", rtol, cap)
    if method == "auto" and cap is None:
        return solve(pr, t, method="auto", rtol=rtol)
    if cap is None:
        from cageless.simulation.auto_switch import default_max_step
        kw = {"max_step": default_max_step(method)}
    return solve(pr, t, method=method, rtol=rtol, **kw)


def measure(case: str, pr: Any, cage: float, t: np.ndarray, repeats: int,
            keys: list[str] | None = None, keep: dict[str, Any] | None = None) -> list[dict[str, Any]]:
    """The candidates ``keys`` (the first is the base of the ratios) on one case, interleaved, best of
    ``repeats``; into ``keep`` (if given) the tight reference (key ``"reference"``) and each candidate's last
    solution (by label)."""
    chosen = [CANDIDATES[k] for k in (keys or DEFAULT_CANDIDATES.split(","))]
    ref = solve(pr, t, rtol=1e-10, max_step=2.5e-7)
    z = pr.n_balls
    radius = float(np.mean(pr.y0[:z]))
    early = t <= t[0] + 0.002
    best: dict[str, float] = {}
    cpu: dict[str, float] = {}
    sols: dict[str, Any] = {}
    for _ in range(repeats):
        for label, method, rtol, cap in chosen:
            start, wall = time.process_time(), time.perf_counter()
            sol = _run(pr, t, method, rtol, cap)
            cpu[label] = min(cpu.get(label, np.inf), time.process_time() - start)
            sols[label] = sol
            best[label] = min(best.get(label, np.inf), time.perf_counter() - wall)
    if keep is not None:
        keep.update(sols, reference=ref)
    rows = []
    span = float(t[-1] - t[0])
    for label, *_ in chosen:
        sol = sols[label]
        slip, pos = _errors(sol.y, ref.y, z, cage, radius)
        slip_early = _errors(sol.y[early], ref.y[early], z, cage, radius)[0]
        energy = energy_balance(pr, sol.y)
        rows.append({"case": case, "solver": label, "method": sol.method, "ok": bool(sol.success),
                     "wall_s_per_sim_s": best[label] / span, "cpu_s_per_sim_s": cpu[label] / span,
                     "slip_error_pp": slip, "early_slip_error_pp": slip_early,
                     "position_error_um": pos, "steps": sol.n_steps, "rejected": sol.n_rejected,
                     "rhs_calls": sol.n_rhs, "energy_drift": float(energy.drift / max(energy.input_work[-1], 1e-30))})
    base = rows[0]["cpu_s_per_sim_s"]
    for r in rows:
        r["speedup_vs_auto"] = base / r["cpu_s_per_sim_s"]
    return rows


def format_rows(rows: list[dict[str, Any]]) -> str:
    lines = ["| case | solver | wall s / sim s | CPU s / sim s | speed-up vs first row (CPU) | slip error (pp) | "
             "first 2 ms (pp) | energy drift | steps | RHS |", "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        flag = "" if r["ok"] else " (failed)"
        lines.append(f"| {r['case']} | {r['solver']}{flag} | {r['wall_s_per_sim_s']:.2f} | {r['cpu_s_per_sim_s']:.2f} | "
                     f"{r['speedup_vs_auto']:.2f} | "
                     f"{r['slip_error_pp']:.2g} | {r['early_slip_error_pp']:.2g} | {r['energy_drift']:.1e} | "
                     f"{r['steps']} | {r['rhs_calls']} |")
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--window", type=float, default=0.005, help="simulated seconds of the settled cases")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--cases", default="planar,spatial,bunching,20kN")
    ap.add_argument("--candidates", default=DEFAULT_CANDIDATES, help="keys of CANDIDATES; the first is the base")
    ap.add_argument("--duration", type=float, default=0.03, help="simulated seconds of the 30 ms cases")
    ap.add_argument("--json", type=Path)
    args = ap.parse_args()
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    rows = []
    keys = args.candidates.split(",")
    for case, (pr, cage, t) in _cases(args.window, args.cases.split(","), args.duration).items():
        pr = replace(pr)
        log.info("case %s", case)
        rows += measure(case, pr, cage, t, args.repeats, keys)
        log.info("%s", format_rows(rows))
    print(format_rows(rows))
    if args.json:
        atomic_write_text(args.json, json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
