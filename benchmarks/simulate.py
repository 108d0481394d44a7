"""Simulator accuracy-versus-time: the work-precision study of simulation/bench.py.

    python benchmarks/simulate.py [--window 0.005] [--plot work_precision.png] [--json out.json]

The same study runs as `cageless bench accuracy`. From a state 30 ms after the start
(3000 rpm, 500 N, every effect), each solver and tolerance integrates the same window;
the table gives wall seconds per simulated second, the ratio to the default (compiled
DP5, rtol 1e-6) measured in the same run, and the error against a dp5 rtol 1e-10
reference. The plain-numpy right-hand side under LSODA is the baseline of the
"compiled is >= 50x faster" bar.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from cageless.simulation.bench import accuracy_study, format_accuracy, plot_accuracy


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--window", type=float, default=0.005, help="simulated seconds (default 0.005)")
    ap.add_argument("--plot", type=Path)
    ap.add_argument("--json", type=Path)
    ap.add_argument("--repeats", type=int, default=3, help="timing repeats per candidate, best taken (default 3)")
    args = ap.parse_args()
    result = accuracy_study(window_s=args.window, repeats=args.repeats)
    print(format_accuracy(result))
    if args.plot:
        plot_accuracy(result, str(args.plot))
    if args.json:
        args.json.write_text(json.dumps(result, indent=1))


if __name__ == "__main__":
    main()
