"""Effect flags read at run time against a right-hand side specialised on a flag tuple: RHS cost and compiles.

    python benchmarks/flag_specialisation.py [--calls 20000] [--repeats 7]

The models switch their effects by flags read from the parameter vector at run time (``p[P_F_*] > 0.5``): one
compiled right-hand side per model, whatever the effects. The alternative is one compiled right-hand side per
flag tuple (generated from the effects table), each with the effects that are off removed at compile time.
This prototypes it for the planar model: the source of :mod:`cageless.simulation.models.planar` is copied with
every gate ``p[P_F_NAME] > 0.5`` replaced by the tuple's constant (``True``/``False``) and compiled as a module
of its own (no disk cache), so its right-hand side and its ball-ball force function are compiled for that tuple.
(The gates inside the shared laws, film regime, EHL film and dry friction, stay run-time in the prototype.)

For the default scene (3000 rpm, 500 N, every effect the scene calls for) and the effect combinations of
``benchmarks/trace_hashes.py``'s planar scenes (no ball-ball film; no lubricant damping), it prints the RHS
time per call of ``planar_rhs`` (run-time flags) and of each specialised copy, at the same moving state (40 %
of the ring's speed as orbital speed, a spin, so every law is evaluated), in a compiled loop, best of
``--repeats`` interleaved, CPU time of the process; and the compile time of each (the first call of the loop,
which compiles the right-hand side and its callees; the run-time-flag one into an empty cache directory, so
it is compiled too). The machine was shared when this was measured: the ratios are the figures to keep.
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import tempfile
import time
import types


def specialised_planar(flags: dict[str, bool]) -> types.ModuleType:
    """A copy of the planar model module with its effect gates fixed to ``flags`` (slot name -> on)."""
    from cageless.simulation.models import planar

    with open(planar.__file__, encoding="utf-8") as fh:
        src = fh.read()

    def gate(m: re.Match[str]) -> str:
        return "True" if flags[m.group(1)] else "False"

    src = re.sub(r"p\[P_(F_[A-Z]+)\] > 0\.5", gate, src)
    src = src.replace("cache=True", "cache=False")
    tag = "".join("1" if flags[k] else "0" for k in sorted(flags))
    mod = types.ModuleType(f"cageless.simulation.models._planar_flags_{tag}")
    mod.__file__ = planar.__file__
    sys.modules[mod.__name__] = mod
    exec(compile(src, f"<planar specialised {tag}>", "exec"), mod.__dict__)
    return mod


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--calls", type=int, default=20_000)
    ap.add_argument("--repeats", type=int, default=7)
    args = ap.parse_args()
    if "NUMBA_CACHE_DIR" not in os.environ:  # compile everything: the run-time-flag RHS too
        with tempfile.TemporaryDirectory(prefix="flag-spec-") as cache:
            res = subprocess.run([sys.executable, __file__, *sys.argv[1:]], env={**os.environ, "NUMBA_CACHE_DIR": cache},
                                 check=True, capture_output=True, text=True)
        sys.stdout.write(res.stdout)
        return
    import numba
    import numpy as np

    from cageless.conditions import OperatingConditions
    from cageless.simulation.models import planar
    from cageless.simulation.models.base import LAYOUT
    from cageless.simulation.scene import Scene
    from cageless.simulation.simulation import Choices, Simulation

    @numba.njit
    def loop(rhs, t, y, p, log, dydt, n):  # pragma: no cover - compiled
        for _ in range(n):
            rhs(t, y, p, log, dydt)
        return dydt[0]

    scene = Scene(conditions=OperatingConditions(3000.0, 500.0), duration_s=5e-4)
    cases = {"default": Choices(), "no ball-ball film": Choices(effects={"ball_ball_film": False}, force=True),
             "no lubricant damping": Choices(effects={"lubricant_damping": False}, force=True)}
    rows = []
    for label, choice in cases.items():
        pr = Simulation(scene, choices=choice).build()
        z = pr.n_balls
        y = pr.y0.copy()
        y[3 * z:4 * z] = 0.4 * scene.conditions.speed_rad_s
        y[4 * z:5 * z] = -2.0 * scene.conditions.speed_rad_s
        flags = {name: bool(pr.params[LAYOUT.index(name)] > 0.5) for name in LAYOUT.names if name.startswith("F_")}
        contenders = {"run-time flags": planar.planar_rhs} if not rows else {}
        contenders[f"specialised: {label}"] = specialised_planar(flags).planar_rhs
        for name, rhs in contenders.items():
            dydt = np.zeros_like(y)
            start = time.perf_counter()
            loop(rhs, 1e-3, y, pr.params, pr.log.copy(), dydt, 1)
            rows.append({"name": name, "rhs": rhs, "compile_s": time.perf_counter() - start, "pr": pr, "y": y,
                         "best": np.inf})
        ref = np.zeros_like(y)
        planar.planar_rhs(1e-3, y, pr.params, pr.log.copy(), ref)
        out = np.zeros_like(y)
        rows[-1]["rhs"](1e-3, y, pr.params, pr.log.copy(), out)
        rows[-1]["max_rel_diff"] = float(np.max(np.abs(out - ref) / np.maximum(np.abs(ref), 1e-300)))
    for _ in range(args.repeats):  # interleaved: every contender once per round
        for row in rows:
            log, dydt = row["pr"].log.copy(), np.zeros_like(row["y"])
            start = time.process_time()
            loop(row["rhs"], 1e-3, row["y"], row["pr"].params, log, dydt, args.calls)
            row["best"] = min(row["best"], time.process_time() - start)
    base = rows[0]["best"]
    print(f"{'planar right-hand side':36s}{'ns/call':>10s}{'ratio':>8s}{'compile (s)':>13s}{'max rel diff':>14s}")
    for row in rows:
        ns = 1e9 * row["best"] / args.calls
        diff = f"{row['max_rel_diff']:14.1e}" if "max_rel_diff" in row else f"{'':14s}"
        print(f"{row['name']:36s}{ns:10.0f}{row['best'] / base:8.3f}{row['compile_s']:13.1f}{diff}")


if __name__ == "__main__":
    main()
