"""Simulator speed of the compiled IMEX method (``ark4``) against today's ``auto`` and DP5, in one run.

    nice -n 10 python benchmarks/ark_speed.py [--repeats 3] [--window 0.005] [--cases planar,spatial,bunching,20kN]
                                              [--candidates auto,dp5,ark4,ark4-7] [--json out.json]

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
"""

from __future__ import annotations

import argparse
import json
import logging
from dataclasses import replace
from pathlib import Path


from cageless.atomic import atomic_write_text
from cageless.simulation.bench import fastest_modes
from solver_speed import _cases, format_rows, measure  # the sibling script (benchmarks/ is on sys.path)

log = logging.getLogger("ark_speed")


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
