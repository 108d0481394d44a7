"""An ensemble of seeds of one scene, run locally on both cores (``cageless simulate --ensemble N``).

Locally the seeds share both cores; ``scheduler`` sends one task per seed to a Dask cluster.
The ball ring is chaotic: runs that differ only in the seeded initial gaps part
after a few milliseconds, so the paper's spread is a property of the ensemble,
not of one trajectory. Each seed writes its own trace,
``<stem>_seed<k>.trace.h5``; the workers are spawned processes (numba's thread
pool does not survive a fork).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from cageless.parallel import gather, job_pool
from cageless.simulation.simulation import Simulation

__all__ = ["run_ensemble", "seed_path"]


def seed_path(out: str | Path, seed: int) -> Path:
    """The trace path of one seed: ``run.trace.h5`` -> ``run_seed3.trace.h5``."""
    out = Path(out)
    name = out.name
    stem, suffix = (name[: -len(".trace.h5")], ".trace.h5") if name.endswith(".trace.h5") else (out.stem, out.suffix)
    return out.with_name(f"{stem}_seed{seed}{suffix}")


def _one(sim: Simulation, out: str, config: dict[str, Any] | None, inputs: Sequence[str] = ()) -> dict[str, Any]:
    """Run one seed; its peak slip leaves out the start-up that ``compare`` leaves out, as the single run's
    summary does (NaN, and said so, when the run ends within it)."""
    from cageless.simulation.run import settled_peak_slip

    tr = sim.run(out=out, progress=False, config=config, inputs=inputs)
    sol = sim.solution
    assert sol is not None
    peak, startup = settled_peak_slip(tr)
    slip = (f"no settled slip: the run is within the {1e3 * startup:.0f} ms start-up" if math.isnan(peak) else
            f"peak slip in the unloaded zone after {1e3 * startup:.0f} ms: {100 * peak:.2f}%")
    return {"seed": sim.scene.seed, "success": sol.success, "path": out, "peak_unloaded_slip": peak,
            "settle_s": startup, "summary": f"{tr.status}, {sol.n_steps} steps, {tr.simulation.wall_s:.1f} s wall, "
                                           f"{slip} -> {out}"}


def run_ensemble(sim: Simulation, n_seeds: int, out: str | Path, workers: int = 2, progress: bool = True,
                 scheduler: str | None = None, config: dict[str, Any] | None = None,
                 inputs: Sequence[str | Path] = ()) -> list[dict[str, Any]]:
    """Run seeds 0..n_seeds-1 of ``sim`` (:meth:`~cageless.simulation.simulation.Simulation.with_seed`); one row per seed,
    in seed order. ``config`` adds to each trace's recorded configuration, ``inputs`` to its recorded inputs.

    Locally the seeds run in ``workers`` spawned processes; with ``scheduler`` (a Dask scheduler
    address) each seed is one task on that cluster, and the traces are written by the workers (so
    ``out`` must be on storage they share).
    """
    members = [sim.with_seed(k) for k in range(n_seeds)]
    paths = [str(Path(seed_path(out, k)).resolve()) for k in range(n_seeds)]
    with job_pool(min(workers, n_seeds), scheduler) as pool:
        files = [str(Path(f).resolve()) for f in inputs]
        return gather([pool.submit(_one, m, p, config, files) for m, p in zip(members, paths, strict=True)], "seeds",
                      progress)
