"""Simulator speed of the compiled IMEX method (``ark4``) against today's ``auto`` and DP5, in one run.

    nice -n 10 python benchmarks/ark_speed.py [--repeats 3] [--window 0.005] [--cases planar,spatial,bunching,20kN]
                                              [--candidates auto,dp5,ark4,ark4-7] [--json out.json]

The cases, the tight reference (DP5, rtol 1e-10, 0.25 us cap), the error measures (slip over all balls and
samples in percentage points of the cage speed; the first 2 ms of the 20 ms runs from the start, which
are chaotic after that; the energy balance's drift over the input work) and the interleaved best-of-N
timing (CPU seconds of the process per simulated second; the machine is shared) are those of
``benchmarks/solver_speed.py``, which this runs with the ``ark4`` rows. Ratios are to the first candidate
(``auto``) in the same run. Before the table it prints, for the settled planar case, the fastest modes of the
Jacobian of the whole right-hand side and of its explicit part (the whole minus the implicit race normal
forces and radial kinematics of :mod:`cageless.simulation.models.implicit_normal`), which set DP5's and
ark4's stability limits.
"""

from __future__ import annotations

import argparse
import json
import logging
from dataclasses import replace
from pathlib import Path

import numpy as np

from cageless.atomic import atomic_write_text
from cageless.simulation.kernels import model_implicit, model_rhs
from solver_speed import _cases, format_rows, measure  # the sibling script (benchmarks/ is on sys.path)

log = logging.getLogger("ark_speed")


def fastest_modes(pr, count: int = 2) -> dict[str, list[complex]]:  # noqa: ANN001
    """The ``count`` largest eigenvalues (1/s) of the Jacobian of f and of f - f_I at the problem's start
    (central differences, steps 1e-2 of each state's absolute tolerance)."""
    n = pr.y0.size
    log_ = pr.log.copy()
    work = np.zeros(12)

    def full(y):  # noqa: ANN001, ANN202
        out = np.empty(n)
        model_rhs(pr.model_id, 0.0, y, pr.params, log_, out)
        return out

    def explicit(y):  # noqa: ANN001, ANN202
        k_i = np.empty(n)
        model_implicit(pr.model_id, 0.0, y.copy(), pr.params, 0.0, k_i, work)
        return full(y) - k_i

    result = {}
    for name, fun in (("f", full), ("f - f_I", explicit)):
        jac = np.empty((n, n))
        for i in range(n):
            e = max(1e-7 * abs(pr.y0[i]), 1e-2 * pr.atol[i])
            up, down = pr.y0.copy(), pr.y0.copy()
            up[i] += e
            down[i] -= e
            jac[:, i] = (fun(up) - fun(down)) / (2 * e)
        ev = np.linalg.eigvals(jac)
        result[name] = list(ev[np.argsort(-np.abs(ev))[:count]])
    return result


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--window", type=float, default=0.005, help="simulated seconds of the settled cases")
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--cases", default="planar,spatial,bunching,20kN")
    ap.add_argument("--candidates", default="auto,dp5,ark4,ark4-7", help="keys of solver_speed.CANDIDATES")
    ap.add_argument("--json", type=Path)
    args = ap.parse_args()
    logging.basicConfig(level=logging.INFO, format="%(message)s")
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
