"""Right-hand-side cost per call and the number of compiled kernel variants, planar and spatial.

    python benchmarks/rhs_speed.py [--calls 20000] [--repeats 7] [--json out.json]
    python benchmarks/rhs_speed.py --compare OTHER_PYTHON [--rounds 3]

For each model (3000 rpm, 500 N, every effect of the scene; the spatial one with a 200 N axial load) the
problem's start state is given an orbital speed of 40 % of the ring's and a spin, so every race and
ball-ball contact law is evaluated; ``model_rhs`` (:mod:`cageless.simulation.kernels`, the entry the
integrators call) runs ``--calls`` times in a compiled loop, best of ``--repeats``, timed in CPU time of the
process (on a shared machine the time spent waiting for a core does not count). Then a short run of each
model (every kernel the run uses, the trace's observables included) and the compiled variants are counted:
the signatures of every numba dispatcher of ``cageless.simulation``. Kernels loaded from numba's cache are
not compiled and do not count, so the count (and the compile time) is taken in a fresh, empty cache
directory (``--fresh``); the times are the same either way.

``--compare OTHER_PYTHON`` runs this script under this interpreter and under ``OTHER_PYTHON`` (another
checkout's environment) in alternation, ``--rounds`` times each, and prints both with the ratio of the best
times (this / other): a same-run ratio, less exposed to the machine's load than absolute times.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time


def measure(calls: int, repeats: int) -> dict[str, object]:
    """RHS nanoseconds per call for both models, and the compiled-variant counts after a short run of each."""
    import numba
    import numpy as np

    from cageless.conditions import OperatingConditions
    from cageless.simulation import kernels
    from cageless.simulation.scene import Scene
    from cageless.simulation.simulation import Choices, Simulation

    @numba.njit
    def loop(model_id, t, y, p, log, dydt, n):  # pragma: no cover - compiled
        for _ in range(n):
            kernels.model_rhs(model_id, t, y, p, log, dydt)
        return dydt[0]

    out: dict[str, object] = {}
    start_all = time.perf_counter()
    scenes = {"planar": Scene(conditions=OperatingConditions(3000.0, 500.0), duration_s=5e-4),
              "spatial": Scene(conditions=OperatingConditions(3000.0, 500.0, 200.0), duration_s=5e-4)}
    for name, scene in scenes.items():
        sim = Simulation(scene, choices=Choices(level=name) if name == "spatial" else Choices())
        pr = sim.build()
        z = pr.n_balls
        y = pr.y0.copy()
        w_i = scene.conditions.speed_rad_s
        y[3 * z:4 * z] = 0.4 * w_i
        y[4 * z:5 * z] = -2.0 * w_i
        dydt = np.zeros_like(y)
        loop(pr.model_id, 1e-3, y, pr.params, pr.log.copy(), dydt, 1)
        best = np.inf
        for _ in range(repeats):
            log = pr.log.copy()
            start = time.process_time()  # CPU time: on a shared machine, waiting for a core does not count
            loop(pr.model_id, 1e-3, y, pr.params, log, dydt, calls)
            best = min(best, time.process_time() - start)
        out[f"{name}_rhs_ns"] = 1e9 * best / calls
        sim.run()
    out["wall_s"] = time.perf_counter() - start_all
    variants: dict[str, int] = {}
    for mod_name, mod in list(sys.modules.items()):
        if not mod_name.startswith("cageless.simulation"):
            continue
        for attr, obj in vars(mod).items():
            if isinstance(obj, numba.core.registry.CPUDispatcher) and obj.__module__ == mod_name:
                variants[f"{mod_name.removeprefix('cageless.simulation.')}.{attr}"] = len(obj.signatures)
    out["variants_total"] = sum(variants.values())
    out["variants_model_rhs"] = variants.get("kernels.model_rhs", 0)
    out["dispatchers_compiled"] = sum(1 for v in variants.values() if v)
    out["variants"] = {k: v for k, v in sorted(variants.items()) if v}
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--calls", type=int, default=20_000)
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--json", type=str)
    ap.add_argument("--compare", type=str, help="another interpreter (another checkout's environment)")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--fresh", action="store_true", help="compile into an empty numba cache directory")
    args = ap.parse_args()
    if args.fresh and "NUMBA_CACHE_DIR" not in os.environ:
        with tempfile.TemporaryDirectory(prefix="rhs-speed-") as cache:
            argv = [a for a in sys.argv[1:] if a != "--fresh"]
            res = subprocess.run([sys.executable, __file__, *argv], env={**os.environ, "NUMBA_CACHE_DIR": cache},
                                 check=True, capture_output=True, text=True)
        sys.stdout.write(res.stdout)
        return
    if not args.compare:
        result = measure(args.calls, args.repeats)
        text = json.dumps(result)
        if args.json:
            with open(args.json, "w") as fh:
                fh.write(text)
        print(text)
        return
    runs: dict[str, list[dict[str, object]]] = {"this": [], "other": []}
    for i in range(args.rounds + 1):  # round 0 compiles into an empty cache: the variant count
        for key, exe in (("this", sys.executable), ("other", args.compare)):
            res = subprocess.run([exe, __file__, "--calls", str(args.calls), "--repeats", str(args.repeats)]
                                 + (["--fresh"] if i == 0 else []), capture_output=True, text=True, check=True)
            runs[key].append(json.loads(res.stdout.strip().splitlines()[-1]))
    print(f"{'':28s}{'this':>12s}{'other':>12s}{'this/other':>12s}")
    for field in ("planar_rhs_ns", "spatial_rhs_ns"):
        a = min(float(r[field]) for r in runs["this"])  # type: ignore[arg-type]
        b = min(float(r[field]) for r in runs["other"])  # type: ignore[arg-type]
        print(f"{field + ' (best)':28s}{a:12.0f}{b:12.0f}{a / b:12.3f}")
    print(f"{'first run, empty cache (s)':28s}{runs['this'][0]['wall_s']:12.1f}{runs['other'][0]['wall_s']:12.1f}")
    for field in ("variants_model_rhs", "variants_total", "dispatchers_compiled"):
        a, b = runs["this"][0][field], runs["other"][0][field]
        print(f"{field:28s}{a:>12}{b:>12}")
    this_v, other_v = runs["this"][0]["variants"], runs["other"][0]["variants"]
    for k in sorted(set(this_v) | set(other_v)):  # type: ignore[arg-type]
        a, b = this_v.get(k, 0), other_v.get(k, 0)  # type: ignore[union-attr]
        if a != b:
            print(f"  {k:40s}{a:>6}{b:>6}")


if __name__ == "__main__":
    main()
