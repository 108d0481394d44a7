"""Where ``auto``'s time goes: the pilot, the probes, the chunks by method, and the driver between them.

    nice -n 5 python benchmarks/auto_profile.py [--cases planar,spatial] [--repeats 2]

On the cases of ``benchmarks/solver_speed.py`` (settled 5 ms windows by default), each solve that the automatic
switch (:mod:`cageless.simulation.auto_switch`) calls is timed from the switch's side (CPU time of the process) and
booked to what called it: the pilot, a probe, or a chunk, by method; what is left is the driver's own time. Best of
``--repeats`` by total, in CPU s per simulated s, beside ``ark4`` in one solve over the same window. The switch's
records (``extra["switches"]``) are printed too.
"""

from __future__ import annotations

import argparse
import time
from collections import defaultdict
from typing import Any

import cageless.simulation.auto_switch as switch
from cageless.simulation.solve import solve
from solver_speed import _cases  # the sibling script (benchmarks/ is on sys.path)


class _Booking:
    """CPU time booked to the phase that called a solve (``pilot``, ``probe``, ``chunk``) and the method run."""

    def __init__(self) -> None:
        self.phase = "driver"
        self.seconds: dict[str, float] = defaultdict(float)

    def phased(self, name: str, fn: Any) -> Any:
        def inner(*args: Any, **kwargs: Any) -> Any:
            outer, self.phase = self.phase, name
            try:
                return fn(*args, **kwargs)
            finally:
                self.phase = outer
        return inner

    def timed(self, method: str | None, fn: Any) -> Any:
        def inner(*args: Any, **kwargs: Any) -> Any:
            start = time.process_time()
            try:
                return fn(*args, **kwargs)
            finally:
                self.seconds[f"{self.phase}/{method or kwargs.get('method', 'dp5')}"] += time.process_time() - start
        return inner


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cases", default="planar,spatial")
    ap.add_argument("--repeats", type=int, default=2)
    args = ap.parse_args()
    book = _Booking()
    switch.solve = book.timed(None, switch.solve)
    switch.step_cvode = book.timed("CVODE", switch.step_cvode)
    switch.step_ark = book.timed("ark4", switch.step_ark)
    switch._pilot = book.phased("pilot", switch._pilot)
    switch._probe = book.phased("probe", switch._probe)
    switch._chunk = book.phased("chunk", switch._chunk)
    for case, (pr, _, t) in _cases(0.005, args.cases.split(",")).items():
        span = float(t[-1] - t[0])
        best: tuple[float, dict[str, float], Any] | None = None
        for _ in range(args.repeats):
            book.seconds.clear()
            start = time.process_time()
            sol = solve(pr, t, method="auto")
            total = time.process_time() - start
            if best is None or total < best[0]:
                best = (total, dict(book.seconds), sol)
        total, seconds, sol = best
        start = time.process_time()
        alone = solve(pr, t, method="ark4", max_step=5e-5)
        ark = time.process_time() - start
        print(f"{case}: auto {total / span:.2f} CPU s / sim s ({sol.method}; {sol.n_steps} steps, {sol.n_rhs} RHS); "
              f"ark4 in one solve {ark / span:.2f} ({alone.n_steps} steps)")
        for key in sorted(seconds, key=lambda k: -seconds[k]):
            print(f"  {key:16s} {seconds[key] / span:7.2f}")
        print(f"  {'driver':16s} {(total - sum(seconds.values())) / span:7.2f}")
        for record in sol.extra["switches"]:
            print("  switch record:", {k: round(v, 3) if isinstance(v, float) else v for k, v in record.items()})


if __name__ == "__main__":
    main()
