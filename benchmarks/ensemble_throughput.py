"""Ensemble throughput: seeds per hour with one and with two local worker processes, in one run.

    python benchmarks/ensemble_throughput.py [--seeds 4] [--duration 0.01]

``cageless simulate --ensemble N`` runs the seeds in spawned processes (both cores by default; one task per
seed on a Dask cluster with ``--scheduler``). The ratio of the two rows is what the second core buys,
including each worker's start (imports and loading the compiled kernels from numba's cache).
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

from cageless.conditions import OperatingConditions
from cageless.simulation.ensemble import run_ensemble
from cageless.simulation.parameters import ModelParameters
from cageless.simulation.scene import Scene
from cageless.simulation.simulation import Choices, Simulation


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--duration", type=float, default=0.01, help="simulated seconds per seed")
    args = ap.parse_args()
    sim = Simulation(Scene(conditions=OperatingConditions(3000, 500), duration_s=args.duration), ModelParameters(),
                     Choices())
    rows = []
    with tempfile.TemporaryDirectory(prefix="ensemble-") as tmp:
        run_ensemble(sim, 1, Path(tmp) / "warm.trace.h5", workers=1, progress=False)  # caches warm for both rows
        for workers in (1, 2):
            start = time.perf_counter()
            res = run_ensemble(sim, args.seeds, Path(tmp) / f"w{workers}.trace.h5", workers=workers, progress=False)
            wall = time.perf_counter() - start
            assert all(r["success"] for r in res)
            rows.append((workers, wall, 3600 * args.seeds / wall))
    print(f"| workers | wall s ({args.seeds} seeds of {args.duration} s) | seeds per hour | speed-up |")
    print("|---|---|---|---|")
    for workers, wall, rate in rows:
        print(f"| {workers} | {wall:.1f} | {rate:.0f} | {rows[0][1] / wall:.2f} |")


if __name__ == "__main__":
    main()
