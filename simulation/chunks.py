"""Long runs in chunks: progress, bounded memory, and the automatic switch to a stiff solver.

:func:`solve_chunks` integrates a problem chunk by chunk (one progress-bar update per chunk, samples
kept, internal steps not). With ``method="auto"`` it starts with the compiled DP5 and watches its
stiffness test (:func:`simulation.integrators.dp5.dp5_integrate`, Hairer & Wanner's h |lambda| > 3.25).
When most steps of a chunk sit at the stability edge (fraction >= :data:`STIFF_FRACTION`), the
step is set by stiffness rather than accuracy, as the paper's "Adams-GSTIFF" scheme switches to its
stiff branch once contacts stiffen (DESIGN §7). The driver then probes the stiff backend, scipy's
LSODA (variable-order BDF), on the same chunk from the same state, and switches for the rest of the run
if its work is clearly smaller. The probe's result is discarded, so the trajectory up to the switch is
DP5's. Probes run only at the chunks in :data:`PROBE_CHUNKS` (10 % and 40 % into a 50-chunk run): the
first chunks are the violent start at full speed, where LSODA restarting from order 1 is not
representative (measured with R = 0: work ratio 2.7 on the first millisecond, 0.46 over 50 ms), and
each probe costs about a chunk and a half of a run that does not switch.

The decision must not depend on timing, or the same scene would give different traces on a busy
machine (the determinism rule of the project). It compares work counts instead: DP5's right-hand-side
evaluations against LSODA's evaluations plus :data:`STEP_OVERHEAD_RHS` evaluations' worth of Python
overhead per step, and switches when LSODA's is below :data:`SWITCH_GAIN` of DP5's. Each probe and switch
is recorded in the solution (``extra["switches"]``) and from there in the trace's solver statistics.

LSODA cannot take a step back, so after a switch contact onsets are resolved by its error control and
``max_step`` only (see :mod:`simulation.solve`).
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np
import numpy.typing as npt
from tqdm.auto import tqdm

from simulation.problem import Problem
from simulation.solve import Solution, solve

__all__ = ["solve_chunks", "STIFF_FRACTION", "STEP_OVERHEAD_RHS", "SWITCH_GAIN", "STIFF_METHOD", "PROBE_CHUNKS"]

#: Share of a chunk's accepted DP5 steps at the stability edge that triggers a probe. Measured over 50 ms
#: at 3000 rpm: the default 500 N scene 0.82 (the race damping: it is probed, LSODA needs 1.16 of DP5's
#: work, and it stays; the probe costs ~3 % of the run), R = 0 0.74, a 20 kN load 0.99; only the first
#: milliseconds after the start, while the balls spread, fall below it.
STIFF_FRACTION = 0.6
#: The stiff backend the switch goes to.
STIFF_METHOD = "LSODA"
#: Python overhead of one scipy step, in compiled right-hand-side evaluations: fitted on this project's
#: planar scenes (a scipy step costs ~21 us against ~4.4 us per evaluation in the compiled loop) and
#: rounded up, so that the switch errs towards staying compiled.
STEP_OVERHEAD_RHS = 6.0
#: Switch only when the stiff backend's work is below this share of DP5's.
SWITCH_GAIN = 0.6
#: The chunks (0-based) after which a stiff DP5 chunk is probed.
PROBE_CHUNKS = (5, 20)


def _work(sol: Solution) -> float:
    """Work of a solve in compiled right-hand-side evaluations (see :data:`STEP_OVERHEAD_RHS`)."""
    if sol.method == "dp5":
        return float(sol.n_rhs)
    return float(sol.n_rhs) + STEP_OVERHEAD_RHS * sol.n_steps


def _probe(part: Problem, t: npt.NDArray[np.float64], sol: Solution, time_s: float, kw: dict[str, Any]) -> dict[str, Any]:
    """Run the stiff backend over the chunk ``sol`` covered and say whether it pays."""
    trial = solve(part, t, method=STIFF_METHOD, **kw)
    ratio = _work(trial) / max(_work(sol), 1.0)
    return {"time_s": time_s, "stiff_fraction": sol.n_stiff_steps / max(sol.n_steps, 1), "work_ratio": ratio,
            "switch": bool(trial.success and ratio < SWITCH_GAIN), "to": STIFF_METHOD, "wall_s": trial.wall_s}


def solve_chunks(pr: Problem, t: npt.NDArray[np.float64], rtol: float, method: str, max_step: float,
                 chunks: int, progress: bool, max_steps: int, force_jump: float) -> Solution:
    """Integrate ``pr`` over the samples ``t`` in about ``chunks`` pieces; ``method`` is a key of
    :data:`simulation.solve.METHODS` or ``"auto"`` (see the module text)."""
    edges = np.unique(np.linspace(0, len(t) - 1, chunks + 1).astype(int))
    ys = [pr.y0[None, :]]
    totals = dict.fromkeys(("n_steps", "n_rejected", "n_rhs", "n_onset_retries", "n_contact_changes",
                            "n_force_jump_retries", "n_stiff_steps"), 0)
    wall = 0.0
    y0, aux, t0 = pr.y0.copy(), pr.aux.copy(), float(t[0])
    current = "dp5" if method == "auto" else method
    probes: list[dict[str, Any]] = []
    sol = None
    with tqdm(total=float(t[-1] - t[0]), desc="simulated s", unit="s", disable=not progress, leave=False) as bar:
        for i, (a, b) in enumerate(zip(edges[:-1], edges[1:], strict=True)):
            part = replace(pr, aux=aux, y0=y0, t0=t0)
            kw = {"rtol": rtol, "max_step": max_step, "force_jump": force_jump,
                  "max_steps": max(1, max_steps - totals["n_steps"] - totals["n_rejected"])}
            sol = solve(part, t[a + 1:b + 1], method=current, **kw)
            ys.append(sol.y)
            for key in totals:
                totals[key] += getattr(sol, key)
            wall += sol.wall_s
            bar.update(float(t[b] - t[a]))
            if not sol.success:
                break
            if (method == "auto" and current == "dp5" and i in PROBE_CHUNKS
                    and sol.n_stiff_steps >= STIFF_FRACTION * max(sol.n_steps, 1)):
                probes.append(_probe(part, t[a + 1:b + 1], sol, float(t[b]), kw))
                wall += probes[-1]["wall_s"]
                if probes[-1]["switch"]:
                    current = STIFF_METHOD
            y0, aux, t0 = sol.y[-1].copy(), sol.extra.get("aux", aux), float(t[b])
    y = np.concatenate(ys)
    if len(y) < len(t):
        y = np.vstack([y, np.full((len(t) - len(y), y.shape[1]), np.nan)])
    assert sol is not None
    used = method if method != "auto" else ("auto: dp5" + "".join(f" -> {p['to']} at {p['time_s']:.4g} s"
                                                                  for p in probes if p["switch"]))
    return Solution(t=t, y=y, status=sol.status, message=sol.message, method=used, wall_s=wall,
                    extra={"aux": aux, "switches": probes}, **totals)
