"""Hashes of the traces of a few short scenes, planar and spatial: the bit-identity check of a refactor.

    python benchmarks/trace_hashes.py OUT_DIR [SCENE ...]

Runs each scene (all of them by default) with the default parameters and solver, prints and writes to
``OUT_DIR/hashes_*.json`` the SHA-256 (first 16 hex digits) of the solution's states and times, the event
table and every array of the trace's groups, with the step and RHS counts, and saves the arrays to
``OUT_DIR/<scene>.npz`` for a numerical comparison. Run it on two checkouts and compare the JSON files:
a refactor that leaves the physics alone leaves every hash as it was.
"""
import hashlib
import json
import sys
from pathlib import Path

import numpy as np
from cageless.conditions import OperatingConditions
from cageless.simulation.scene import Scene
from cageless.simulation.parameters import ModelParameters
from cageless.simulation.simulation import Choices, Simulation

SCENES = {
    "planar_3000_500": (Scene(conditions=OperatingConditions(3000.0, 500.0), duration_s=4e-3), Choices()),
    "planar_1800_200_seed3": (Scene(conditions=OperatingConditions(1800.0, 200.0), duration_s=4e-3, seed=3), Choices()),
    "planar_ramp": (Scene(conditions=OperatingConditions(3000.0, 300.0), duration_s=3e-3, speed_ramp_s=1e-3),
                    Choices(effects={"ball_ball_film": False}, force=True)),
    "planar_nodamp": (Scene(conditions=OperatingConditions(3000.0, 500.0), duration_s=3e-3),
                      Choices(effects={"lubricant_damping": False}, force=True)),
    "spatial_axial": (Scene(conditions=OperatingConditions(3000.0, 500.0, 200.0), duration_s=2e-3), Choices()),
    "spatial_misaligned": (Scene(conditions=OperatingConditions(3000.0, 500.0), duration_s=2e-3,
                                 misalignment_rad=1e-3), Choices()),
    "spatial_forced": (Scene(conditions=OperatingConditions(3000.0, 500.0), duration_s=2e-3),
                       Choices(level="spatial")),
}


def digest(a):
    a = np.ascontiguousarray(a)
    if a.dtype == object:
        return hashlib.sha256(repr(a.tolist()).encode()).hexdigest()[:16]
    return hashlib.sha256(a.tobytes()).hexdigest()[:16]

if len(sys.argv) < 2 or sys.argv[1] in ("-h", "--help"):
    sys.exit(__doc__)
out_dir = sys.argv[1]
Path(out_dir).mkdir(parents=True, exist_ok=True)
names = sys.argv[2:] or list(SCENES)
res = {}
for name in names:
    scene, ch = SCENES[name]
    sim = Simulation(scene, ModelParameters(), ch)
    tr = sim.run()
    h = {"y": digest(sim.solution.y), "t": digest(sim.solution.t), "n_steps": sim.solution.n_steps,
         "n_rhs": sim.solution.n_rhs, "events": digest(tr.events.to_numpy())}
    flat = {}
    for g, arrs in tr.groups.items():
        for k, v in arrs.items():
            h[f"{g}/{k}"] = digest(v)
            flat[f"{g}/{k}"] = np.asarray(v)
    flat["y"] = sim.solution.y
    np.savez(f"{out_dir}/{name}.npz", **flat)
    res[name] = h
    print(name, sim.model.level, json.dumps(h), flush=True)
with open(f"{out_dir}/hashes_{'_'.join(names) if len(names) < 3 else 'all'}.json", "w") as fh:
    json.dump(res, fh, indent=1, sort_keys=True)
