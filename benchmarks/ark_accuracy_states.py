"""Slip error of the solvers over several settled states, not one (issue 18's accuracy bar).

    nice -n 10 python benchmarks/ark_accuracy_states.py [--case planar] [--states 5] [--first 0.03] [--spacing 0.005]
                                                         [--window 0.02] [--samples 51] [--check-reference]
                                                         [--repeats 1]
                                                         [--candidates ark4,ark4-3e-7,ark4-7,auto,dp5] [--json out.json]

``benchmarks/ark_speed.py`` measures the slip error on one settled state (30 ms of DP5 from the start). The ball
ring is chaotic, so that state moves with any round-off change, and the error of a method at a fixed tolerance
moves with it. This settles the ``--case`` (``planar``: 3000 rpm, 500 N; ``spatial``: 3000 rpm, 500 N radial +
400 N axial, 5 strips) for ``--first``, ``--first + --spacing``, ... seconds from the start (``--states`` of them,
each from the start as ``ark_speed.py``'s state is: :func:`cageless.simulation.bench._settled_problem`) and on each
runs :func:`solver_speed.measure` over ``--window`` (``--samples`` samples, 51 as there): the same tight
reference (DP5, rtol 1e-10, 0.25 us cap), the same error (largest difference of the balls' orbital speed over all
balls and samples, in percentage points of the cage speed) and the same interleaved best-of-``--repeats`` CPU
time.

It prints a table of each candidate's error per state, their largest and median, and its CPU seconds per simulated
second (median over the states; the ratio to the first candidate is the median of the per-state ratios, each from
the same round). Then, for the first candidate, where its error arises on each state: the sample and ball of the
largest error, the first sample past half of it, the ball-ball contact episodes of the reference in the window
(impacts, rubbing, the largest peak force) and the episode onset nearest before that sample, and its refused steps
by cause; with ``--check-reference``, the reference's own error against DP5 at rtol 1e-11 and a 0.125 us cap (a
state whose reference is off by more than the bar cannot test it).
"""

from __future__ import annotations

import argparse
import json
import logging
import sys
from pathlib import Path
from typing import Any

import numpy as np

from cageless.atomic import atomic_write_text
from cageless.simulation.bench import _settled_problem
from cageless.simulation.models.contact_log import contact_events
from cageless.simulation.solve import solve
from solver_speed import CANDIDATES, _run, measure  # the sibling script (on sys.path)

log = logging.getLogger("ark_accuracy_states")

#: The cases' settling arguments of :func:`cageless.simulation.bench._settled_problem` (as solver_speed's cases).
CASES: dict[str, dict[str, Any]] = {
    "planar": {"level": "planar"},
    "spatial": {"axial_n": 400.0, "level": "spatial", "strips": 5},
}


def settle_times(first: float, spacing: float, count: int) -> list[float]:
    """The settling durations (s): ``count`` of them, ``spacing`` apart from ``first``.

    Parameters
    ----------
    first, spacing : float
        The first duration and the spacing (s).
    count : int
        How many.

    Returns
    -------
    list of float
    """
    return [round(first + i * spacing, 9) for i in range(count)]


def _onset_slip(err_t: np.ndarray, t: np.ndarray) -> float:
    """The first sample time (s) at which the largest-over-balls error passes half of its maximum."""
    return float(t[int(np.argmax(err_t >= 0.5 * np.nanmax(err_t)))])


def diagnose(pr: Any, cage: float, t: np.ndarray, sol: Any, ref: Any) -> dict[str, Any]:
    """Where a solution's slip error arises on one state, against the reference.

    Parameters
    ----------
    pr : Problem
        The settled problem (its contact log holds the settling's episodes).
    cage : float
        The theoretical cage speed (rad/s).
    t : numpy.ndarray
        The sample times (s).
    sol, ref : Solution
        The candidate's and the reference's solutions.

    Returns
    -------
    dict
        ``peak_t_ms``, ``peak_ball``: the sample and ball of the largest error; ``half_t_ms``: the first sample past
        half of it; ``episodes``, ``impacts``, ``largest_peak_n``: the reference's ball-ball contact episodes that
        began in the window (not in the settling's log, nor open at the start); ``onset_before_half_ms``: the last
        onset at or before ``half_t_ms`` (NaN if none);
        ``steps``, ``refused``, ``onset_retries``, ``jump_retries``: the candidate's step counts.
    """
    z = pr.n_balls
    diff = 100 * np.abs(sol.y[:, 3 * z:4 * z] - ref.y[:, 3 * z:4 * z]) / cage
    err_t = np.nanmax(diff, axis=1)
    k, ball = np.unravel_index(int(np.nanargmax(diff)), diff.shape)
    half = _onset_slip(err_t, t)
    at_start = contact_events(pr, pr.log, float(t[0]))  # the settling's episodes, and those open at the start
    seen = set(zip(at_start["time"], at_start["pair"]))
    events = contact_events(pr, ref.extra["log"], float(t[-1]))
    new = events[[(a, b) not in seen for a, b in zip(events["time"], events["pair"])]]
    onsets = new["time"].to_numpy()
    before = onsets[onsets <= half]
    return {"peak_t_ms": 1e3 * float(t[k]), "peak_ball": int(ball), "half_t_ms": 1e3 * half,
            "episodes": int(len(new)), "impacts": int((new["kind"] == "impact").sum()),
            "largest_peak_n": float(new["peak_force"].max()) if len(new) else 0.0,
            "onset_before_half_ms": 1e3 * float(before.max()) if before.size else float("nan"),
            "steps": sol.n_steps, "refused": sol.n_rejected, "onset_retries": sol.n_onset_retries,
            "jump_retries": sol.n_force_jump_retries}


def reference_error(pr: Any, cage: float, t: np.ndarray, ref: Any) -> float:
    """The reference's own slip error (pp): against DP5 at rtol 1e-11 and a 0.125 us cap (half its cap)."""
    tighter = solve(pr, t, rtol=1e-11, max_step=1.25e-7)
    z = pr.n_balls
    return 100 * float(np.nanmax(np.abs(ref.y[:, 3 * z:4 * z] - tighter.y[:, 3 * z:4 * z]))) / cage


def run_states(case: str, times: list[float], window: float, repeats: int, keys: list[str], samples: int = 51,
               check_reference: bool = False) -> list[dict[str, Any]]:
    """:func:`solver_speed.measure` on each settled state, with :func:`diagnose` of the first candidate.

    Parameters
    ----------
    case : str
        A key of :data:`CASES`.
    times : list of float
        The settling durations (s).
    window : float
        Simulated seconds from each state.
    repeats : int
        Interleaved rounds per state (each candidate keeps its shortest CPU time).
    keys : list of str
        Keys of ``solver_speed.CANDIDATES``; the first is the base of the ratios and is diagnosed.
    samples : int
        Sample times over the window (``ark_speed.py``: 51); the error is the largest over them.
    check_reference : bool
        Also the reference's own error (:func:`reference_error`), under ``why["reference_pp"]``.

    Returns
    -------
    list of dict
        ``measure``'s rows, each with ``settle_s``; the first candidate's rows with the diagnosis under ``why``.
    """
    t = np.linspace(0.0, window, samples)
    rows: list[dict[str, Any]] = []
    for i, settle in enumerate(times):
        pr, cage = _settled_problem(3000, 500, settle, **CASES[case])
        pr.log[5 * pr.n_balls] = 0.0  # log the window's episodes from the first slot (the count only places them)
        if i == 0:
            for key in keys:  # compile untimed
                _run(pr, t[:2] * 1e-3, *CANDIDATES[key][1:])
        keep: dict[str, Any] = {}
        state_rows = measure(case, pr, cage, t, repeats, keys, keep)
        for row in state_rows:
            row["settle_s"] = settle
        first = state_rows[0]
        first["why"] = diagnose(pr, cage, t, keep[first["solver"]], keep["reference"])
        if check_reference:
            first["why"]["reference_pp"] = reference_error(pr, cage, t, keep["reference"])
        rows += state_rows
        log.info("settled %.3f s: %s", settle, ", ".join(f"{k} {r['slip_error_pp']:.2g} pp"
                                                         for k, r in zip(keys, state_rows)))
    return rows


def format_table(rows: list[dict[str, Any]], keys: list[str], bar: float = 0.01) -> str:
    """Per candidate: the error on each state, its largest and median, on how many states it is within ``bar``
    (pp; in brackets, of the states whose reference's own error, if checked, is within a tenth of it), CPU s per
    simulated s and the ratio to the first candidate (medians over the states)."""
    times = sorted({r["settle_s"] for r in rows})
    resolved = {r["settle_s"] for r in rows if r.get("why", {}).get("reference_pp", np.inf) <= 0.1 * bar}
    head = ("| solver | " + " | ".join(f"{1e3 * s:g} ms" for s in times) + f" | max (pp) | median (pp) | "
            f"states <= {bar:g} pp (resolved) | CPU s / sim s (median) | CPU vs first (median) | steps (median) |")
    lines = [head, "|---" * (len(times) + 7) + "|"]
    labels = [CANDIDATES[k][0] for k in keys]
    base = {r["settle_s"]: r["cpu_s_per_sim_s"] for r in rows if r["solver"] == labels[0]}
    for key, label in zip(keys, labels):
        mine = sorted((r for r in rows if r["solver"] == label), key=lambda r: r["settle_s"])
        err = np.array([r["slip_error_pp"] for r in mine])
        cpu = np.array([r["cpu_s_per_sim_s"] for r in mine])
        ratio = np.array([r["cpu_s_per_sim_s"] / base[r["settle_s"]] for r in mine])
        flags = ["" if r["ok"] else "!" for r in mine]
        within = sum(e <= bar for e in err)
        within_resolved = sum(e <= bar for e, r in zip(err, mine) if r["settle_s"] in resolved)
        lines.append(f"| {key} | " + " | ".join(f"{e:.2g}{f}" for e, f in zip(err, flags)) +
                     f" | {err.max():.2g} | {np.median(err):.2g} | {within} of {len(err)} "
                     f"({within_resolved} of {len(resolved)}) | {np.median(cpu):.2f} | "
                     f"{np.median(ratio):.2f} | {int(np.median([r['steps'] for r in mine]))} |")
    return "\n".join(lines)


def format_why(rows: list[dict[str, Any]]) -> str:
    """The first candidate's diagnosis per state (:func:`diagnose`)."""
    lines = ["| state | error (pp) | largest at (ms, ball) | half of it by (ms) | episodes (impacts) | "
             "largest peak (N) | last onset before (ms) | steps | refused (onset, jump) | reference's own (pp) |",
             "|---" * 10 + "|"]
    for r in rows:
        if "why" not in r:
            continue
        w = r["why"]
        own = f"{w['reference_pp']:.2g}" if "reference_pp" in w else "not checked"
        lines.append(f"| {1e3 * r['settle_s']:g} ms | {r['slip_error_pp']:.2g} | {w['peak_t_ms']:.1f}, "
                     f"{w['peak_ball']} | {w['half_t_ms']:.1f} | {w['episodes']} ({w['impacts']}) | "
                     f"{w['largest_peak_n']:.3g} | {w['onset_before_half_ms']:.2f} | {w['steps']} | "
                     f"{w['refused']} ({w['onset_retries']}, {w['jump_retries']}) | "
                     f"{own} |")
    return "\n".join(lines)


def main() -> None:
    """The command line (see the module text)."""
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--case", choices=sorted(CASES), default="planar")
    ap.add_argument("--states", type=int, default=5, help="how many settled states")
    ap.add_argument("--first", type=float, default=0.03, help="the first settling duration (s)")
    ap.add_argument("--spacing", type=float, default=0.005, help="between the settling durations (s)")
    ap.add_argument("--window", type=float, default=0.02, help="simulated seconds from each state")
    ap.add_argument("--samples", type=int, default=51, help="sample times over the window")
    ap.add_argument("--check-reference", action="store_true",
                    help="also the reference's own error, against DP5 at rtol 1e-11 and a 0.125 us cap")
    ap.add_argument("--repeats", type=int, default=1)
    ap.add_argument("--candidates", default="ark4,ark4-3e-7,ark4-7,auto,dp5",
                    help="keys of solver_speed.CANDIDATES; the first is the base of the ratios")
    ap.add_argument("--bar", type=float, default=0.01, help="the slip error bar (pp) the table counts states against")
    ap.add_argument("--json", type=Path)
    args = ap.parse_args()
    logging.basicConfig(level=logging.INFO, format="%(message)s", stream=sys.stderr)
    keys = args.candidates.split(",")
    rows = run_states(args.case, settle_times(args.first, args.spacing, args.states), args.window, args.repeats,
                      keys, args.samples, args.check_reference)
    print(f"{args.case}, window {args.window:g} s, {args.samples} samples, {args.states} settled states\n")
    print(format_table(rows, keys, args.bar) + "\n\n" + format_why(rows))
    if args.json:
        atomic_write_text(args.json, json.dumps(rows, indent=1, default=str))


if __name__ == "__main__":
    main()
