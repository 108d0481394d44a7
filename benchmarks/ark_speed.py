"""Simulator speed of the compiled IMEX method (``ark4``) against today's ``auto`` and DP5, in one run.

    nice -n 10 python benchmarks/ark_speed.py [--repeats 3] [--window 0.005] [--cases planar,spatial,bunching,20kN]
                                              [--candidates auto,dp5,ark4,ark4-7] [--json out.json]
    nice -n 5 python benchmarks/ark_speed.py --speed-window 0.1 [--peer OTHER_PYTHON] [--rounds 3] [--repeats 2]
                                              [--cases planar,spatial] [--candidates ark4,auto] [--json out.json]

The cases, the tight reference (DP5, rtol 1e-10, 0.25 us cap), the error measures (slip over all balls and
samples in percentage points of the cage speed; the first 2 ms of the 20 ms runs from the start, which
are chaotic after that; the energy balance's drift over the input work) and the interleaved best-of-N
timing (CPU seconds of the process per simulated second; the machine is shared) are those of
``benchmarks/solver_speed.py``, which this runs with the ``ark4`` rows (``auto-cvode``: the switch before ark4 was one
of its backends). Ratios are to the first candidate
(``auto``) in the same run. Before the table it prints, for the settled planar case, the fastest modes of the
Jacobian of the whole right-hand side and of its explicit part (the whole minus the implicit race normal
forces and radial kinematics of :mod:`cageless.simulation.models.implicit_normal`), which set DP5's and
ark4's stability limits.

The slip error here is that of ONE settled state, which moves with round-off (the ring is chaotic);
``benchmarks/ark_accuracy_states.py`` measures it over several (settled 30, 35, ... ms), with the reference's own
error on each.

``--speed-window S`` measures speed only, over S simulated seconds from the settled states of the ``planar`` and
``spatial`` cases (51 samples, as a report's run writes them: ``auto``'s pilot, probes and chunks amortised as
there), with no reference (a 5 ms step of the window would be a 10 ms call, inside the machine's noise; the
accuracy stays measured on ``--window``). Each candidate runs ``--repeats`` times interleaved; wall and CPU
seconds per simulated second (best of the repeats), steps, refused steps by cause (the error test, the onset
control, the force-jump test), right-hand sides and the peak of Python's allocations
during one more solve (``tracemalloc``; over two windows it shows whether memory grows with the duration).
With ``--peer OTHER_PYTHON`` (another checkout's environment, e.g. a wrapper that sets its ``PYTHONPATH``) the
measurement runs in separate processes, this interpreter and the peer in alternation, ``--rounds`` rounds, both
from the same settled states (computed once, here), and the table gives each tree's best and their ratio.
"""

from __future__ import annotations

import argparse
import json
import logging
import os
import subprocess
import sys
import tempfile
import time
import tracemalloc
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from cageless.atomic import atomic_write_text
from cageless.simulation.bench import fastest_modes
from solver_speed import _cases, _run, CANDIDATES, format_rows, measure  # the sibling script (on sys.path)

log = logging.getLogger("ark_speed")

#: The settled cases the speed-only mode runs (the keys of solver_speed's cases).
SPEED_CASES = ("planar", "spatial")


def _settled_states(cases: list[str], folder: Path) -> dict[str, str]:
    """Each settled case's start state and contact log, written to ``folder`` (one .npz each): the peer runs from
    the same states."""
    paths = {}
    for case, (pr, cage, _) in _cases(0.005, cases).items():
        path = folder / f"{case}.npz"
        np.savez(path, y0=pr.y0, log=pr.log, cage=cage)
        paths[case] = str(path)
    return paths


def _problem(case: str, path: str) -> Any:
    """The settled case's problem (this tree's) from a state written by :func:`_settled_states`."""
    from cageless.conditions import OperatingConditions
    from cageless.simulation.parameters import ModelParameters
    from cageless.simulation.scene import Scene
    from cageless.simulation.simulation import Choices, Simulation

    axial, level = (400.0, "spatial") if case == "spatial" else (0.0, "planar")
    scene = Scene(conditions=OperatingConditions(3000.0, 500.0, axial))
    pr = Simulation(scene, ModelParameters(strips=5), Choices(level=level)).build()
    saved = np.load(path)
    return replace(pr, y0=saved["y0"].copy(), log=saved["log"].copy(), t0=0.0)


def speed_only(states: dict[str, str], window: float, repeats: int, keys: list[str]) -> list[dict[str, Any]]:
    """Wall and CPU seconds per simulated second of each candidate over ``window`` from each settled state (best of
    ``repeats``, interleaved), with its steps, right-hand sides and peak traced allocation (MiB)."""
    rows = []
    t = np.linspace(0.0, window, 51)
    for case, path in states.items():
        pr = _problem(case, path)
        for key in keys:  # compile untimed
            _run(pr, t[:2] * 1e-3, *CANDIDATES[key][1:])
        best = {k: [np.inf, np.inf] for k in keys}
        sols = {}
        for _ in range(repeats):
            for key in keys:
                cpu, wall = time.process_time(), time.perf_counter()
                sols[key] = _run(pr, t, *CANDIDATES[key][1:])
                elapsed = (time.perf_counter() - wall, time.process_time() - cpu)
                best[key] = [min(best[key][0], elapsed[0]), min(best[key][1], elapsed[1])]
        for key in keys:
            tracemalloc.start()
            _run(pr, t, *CANDIDATES[key][1:])
            peak = tracemalloc.get_traced_memory()[1] / 2**20
            tracemalloc.stop()
            sol = sols[key]
            rows.append({"case": case, "solver": key, "method": sol.method, "window_s": window,
                         "wall_s_per_sim_s": best[key][0] / window, "cpu_s_per_sim_s": best[key][1] / window,
                         "steps": sol.n_steps, "rejected": sol.n_rejected, "rhs_calls": sol.n_rhs,
                         "onset_retries": sol.n_onset_retries, "jump_retries": sol.n_force_jump_retries,
                         "peak_traced_mib": peak, "ok": bool(sol.success)})
    return rows


def _child(exe: str, args: argparse.Namespace, states: dict[str, str]) -> list[dict[str, Any]]:
    """One speed-only measurement in a separate process of interpreter ``exe``."""
    cmd = [exe, str(Path(__file__).resolve()), "--speed-window", str(args.speed_window), "--repeats",
           str(args.repeats), "--candidates", args.candidates, "--states", json.dumps(states), "--child"]
    res = subprocess.run(cmd, capture_output=True, text=True, check=True, cwd=tempfile.gettempdir())
    return json.loads(res.stdout.strip().splitlines()[-1])


def _peer_table(runs: dict[str, list[list[dict[str, Any]]]]) -> str:
    """Each (case, candidate)'s best wall and CPU time per simulated second on both trees, with their ratios."""
    lines = ["| case | solver | wall this / peer | ratio | CPU this / peer | ratio | steps this / peer | "
             "refused (error, onset, jump) this / peer | RHS this / peer | peak MiB this / peer |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    first = runs["this"][0]
    for i, row in enumerate(first):
        a = [r[i] for r in runs["this"]]
        b = [r[i] for r in runs["peer"]]
        wa, wb = min(x["wall_s_per_sim_s"] for x in a), min(x["wall_s_per_sim_s"] for x in b)
        ca, cb = min(x["cpu_s_per_sim_s"] for x in a), min(x["cpu_s_per_sim_s"] for x in b)
        lines.append(f"| {row['case']} | {row['solver']} ({row['method']}) | {wa:.2f} / {wb:.2f} | {wa / wb:.3f} | "
                     f"{ca:.2f} / {cb:.2f} | {ca / cb:.3f} | {a[0]['steps']} / {b[0]['steps']} | "
                     f"{_refusals(a[0])} / {_refusals(b[0])} | "
                     f"{a[0]['rhs_calls']} / {b[0]['rhs_calls']} | {a[0]['peak_traced_mib']:.1f} / "
                     f"{b[0]['peak_traced_mib']:.1f} |")
    return "\n".join(lines)


def _refusals(row: dict[str, Any]) -> str:
    """A row's refused steps by cause: all (the error test's, the onset control's, the force-jump test's); the
    causes are "?" in rows of a tree that did not record them."""
    onset, jump = row.get("onset_retries"), row.get("jump_retries")
    if onset is None or jump is None:
        return f"{row['rejected']} (?)"
    return f"{row['rejected']} ({row['rejected'] - onset - jump}, {onset}, {jump})"


def _speed_main(args: argparse.Namespace) -> None:
    """The ``--speed-window`` mode (see the module text)."""
    keys = args.candidates.split(",")
    if args.child:
        print(json.dumps(speed_only(json.loads(args.states), args.speed_window, args.repeats, keys)))
        return
    cases = [c for c in args.cases.split(",") if c in SPEED_CASES]
    with tempfile.TemporaryDirectory(prefix="ark-speed-") as folder:
        states = _settled_states(cases, Path(folder))
        if not args.peer:
            rows = speed_only(states, args.speed_window, args.repeats, keys)
            text = "\n".join(f"| {r['case']} | {r['solver']} ({r['method']}) | {r['wall_s_per_sim_s']:.2f} | "
                             f"{r['cpu_s_per_sim_s']:.2f} | {r['steps']} | {r['rhs_calls']} | "
                             f"{r['peak_traced_mib']:.1f} |" for r in rows)
            head = "| case | solver | wall s / sim s | CPU s / sim s | steps | RHS | peak MiB |\n" + "|---" * 7 + "|\n"
            print(head + text)
            result: Any = rows
        else:
            runs: dict[str, list[list[dict[str, Any]]]] = {"this": [], "peer": []}
            for i in range(args.rounds):
                for key, exe in (("this", sys.executable), ("peer", args.peer)):
                    runs[key].append(_child(exe, args, states))
                    log.info("round %d, %s done", i + 1, key)
            print(_peer_table(runs))
            result = runs
    if args.json:
        atomic_write_text(args.json, json.dumps(result, indent=1, default=str))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--window", type=float, default=0.005, help="simulated seconds of the settled cases")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--cases", default="planar,spatial,bunching,20kN")
    ap.add_argument("--candidates", default="auto,dp5,ark4,ark4-7", help="keys of solver_speed.CANDIDATES")
    ap.add_argument("--json", type=Path)
    ap.add_argument("--speed-window", type=float, help="speed only, over this many simulated seconds (see above)")
    ap.add_argument("--peer", help="with --speed-window: another checkout's interpreter, run in alternation")
    ap.add_argument("--rounds", type=int, default=3, help="with --peer: rounds of the alternation")
    ap.add_argument("--states", help=argparse.SUPPRESS)
    ap.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args()
    logging.basicConfig(level=logging.INFO, format="%(message)s", stream=sys.stderr)
    if args.speed_window:
        _speed_main(args)
        return
    rows = []
    for case, (pr, cage, t) in _cases(args.window, args.cases.split(",")).items():
        pr = replace(pr)
        if case == "planar":
            for name, ev in fastest_modes(pr).items():
                print(f"fastest modes of {name}: " + ", ".join(f"{v.real:.3g}{v.imag:+.3g}j 1/s" for v in ev))
        log.info("case %s", case)
        rows += measure(case, pr, cage, t, args.repeats, args.candidates.split(","))
        log.info("%s", format_rows(rows))
    print(format_rows(rows))
    if args.json:
        atomic_write_text(args.json, json.dumps(rows, indent=1, default=str))


if __name__ == "__main__":
    main()
