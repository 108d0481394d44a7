"""What the structured Jacobian buys the implicit backend (simulation/jacobian.py).

    python benchmarks/jacobian.py [--window 0.005] [--repeats 3]

From a state 30 ms after the start at 3000 rpm, CVODE integrates the same window as
``simulate`` runs it (rtol 1e-6 x 0.03, 5 us cap) with each Jacobian of
``simulation.solve.JACOBIANS``: the structured grouped difference quotients in CVODE's
dense LU (the default), the same Jacobian factorised by SuperLU_MT, and CVODE's own
one-state-at-a-time difference quotients. The candidates run interleaved, best of
``--repeats`` (this shared 2-core machine's noise only adds time), and the ratio column
divides by the default measured in the same run. Four scenes: the planar model at 500 N
and 20 kN, the spatial model under 500 N + 400 N axial and under 500 N alone.
"""

from __future__ import annotations

import argparse

import numpy as np

from cageless.simulation.bench import _settled_problem
from cageless.simulation.auto_switch import RTOL_FACTOR
from cageless.simulation.solve import JACOBIAN_DEFAULT, JACOBIANS, step_cvode

SCENES = (("planar, 500 N", "planar", 500.0, 0.0), ("planar, 20 kN", "planar", 20000.0, 0.0),
          ("spatial, 500 N + 400 N axial", "spatial", 500.0, 400.0), ("spatial, 500 N", "spatial", 500.0, 0.0))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--window", type=float, default=0.005, help="simulated seconds (default 0.005)")
    ap.add_argument("--repeats", type=int, default=3, help="interleaved timing repeats, best taken (default 3)")
    args = ap.parse_args()
    rtol = 1e-6 * RTOL_FACTOR["CVODE"]
    t = np.linspace(0.0, args.window, 51)
    print(f"CVODE, rtol {rtol:g}, cap 5 us, {1e3 * args.window:g} ms after 30 ms at 3000 rpm; "
          f"best of {args.repeats}; ratio: to '{JACOBIAN_DEFAULT}'\n")
    print("| scene | Jacobian | wall s / sim s | ratio | steps | RHS calls | Jacobians |")
    print("|---|---|---|---|---|---|---|")
    for label, level, load, axial in SCENES:
        pr, _ = _settled_problem(3000.0, load, 0.03, axial_n=axial, level=level)
        step_cvode(pr, t[:3], rtol, max_step=5e-6)  # compile outside the timing
        best: dict[str, tuple[float, object]] = {}
        for _ in range(args.repeats):
            for jac in JACOBIANS:
                sol = step_cvode(pr, t, rtol, max_step=5e-6, jacobian=jac)
                if jac not in best or sol.wall_s < best[jac][0]:
                    best[jac] = (sol.wall_s, sol)
        base = best[JACOBIAN_DEFAULT][0]
        for jac in JACOBIANS:
            wall, sol = best[jac]
            n_jac = sol.extra["cvode"].n_jac if jac != "dense" else "(CVODE's own)"
            print(f"| {label} | {jac} | {wall / args.window:.2f} | {wall / base:.2f} | {sol.n_steps} | "
                  f"{sol.n_rhs} | {n_jac} |")


if __name__ == "__main__":
    main()
