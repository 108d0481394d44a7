"""Simulator speed: wall seconds per simulated second, compiled integrator vs plain numpy + LSODA.

Measures the planar model as it stands (race and ball-ball Hertz contacts, damping, gravity and a
500 N radial load on a ring that starts off equilibrium; traction lands with the next slice) over the
same short window in the same run:

* the compiled Dormand-Prince loop with the compiled right-hand side (rtol 1e-6);
* scipy's LSODA, RK45 and DOP853 on the compiled right-hand side;
* scipy's LSODA on the plain-numpy right-hand side (the baseline of the 50x bar).

    python benchmarks/simulate.py [--window 0.005] [--repeats 3]
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from scipy.integrate import solve_ivp

from cageless.bearing import default_bearing
from simulation.models.planar import packed_start, planar_problem
from simulation.models.planar_reference import reference_rhs
from simulation.solve import solve


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--window", type=float, default=0.005, help="simulated seconds (default 0.005)")
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args()
    b = default_bearing()
    g = b.geometry
    pr = planar_problem(b, packed_start(b, seed=1), np.full(g.n_balls, 0.5 * g.pitch_diameter_m), (0.0, -2e-6),
                        500.0, restitution=0.6)
    t = np.linspace(0, args.window, 51)
    rows = []
    solve(pr, t[:3])  # compile once
    for method in ("dp5", "LSODA", "RK45", "DOP853"):
        best, sol = np.inf, None
        for _ in range(args.repeats):
            sol = solve(pr, t, method=method, rtol=1e-6)
            best = min(best, sol.wall_s)
        rows.append((f"{method} (compiled RHS)", best / args.window, sol.n_rhs))
    aux = pr.aux.copy()
    t0 = time.perf_counter()
    res = solve_ivp(lambda tt, yy: reference_rhs(tt, yy, pr.params, aux), (0, args.window), pr.y0, method="LSODA",
                    t_eval=t, rtol=1e-6, atol=pr.atol)
    numpy_s = time.perf_counter() - t0
    rows.append(("LSODA (plain numpy RHS)", numpy_s / args.window, res.nfev))
    print(f"Planar model core, {g.n_balls} balls, {args.window * 1e3:g} ms simulated, rtol 1e-6, best of {args.repeats}")
    print(f"{'integrator':<26}{'wall s / sim s':>16}{'RHS calls':>12}{'vs numpy+LSODA':>16}")
    for name, per, calls in rows:
        print(f"{name:<26}{per:>16.2f}{calls:>12}{numpy_s / args.window / per:>15.0f}x")


if __name__ == "__main__":
    main()
