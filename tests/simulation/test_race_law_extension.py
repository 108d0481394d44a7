"""A new race-contact force law is one physics module plus its parameters (simulation.models.race_laws).

The example law is defined here, in a test-only module run in a fresh process (the laws compile into the
models' race contacts, so they are registered before the models import): a linear spring f = k_x delta
added along the normal of every race contact, switched by its own row of the effects table, with its
stiffness in its own parameter slot, set from its open parameter ``race_spring_k_n_m`` (``--set`` reaches it
like a built-in parameter). Nothing else of the package is edited. The check is the closed form
(traction off, since it scales with the normal force): the law adds (-k_x delta_o + k_x delta_i n_r) / m to
each ball's radial acceleration (the outer contact pushes the ball inward, the inner one out along its normal,
of radial component n_r), and nothing where a contact is open; a short run with it differs from one without.
Installed as a package (an entry point in the ``cageless.race_laws`` group), the same module is found by the
plain command line.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

#: The example law: one module, the physics and its parameter (written to a file, imported by the scripts).
_LAW_MODULE = r"""
import numba
from cageless.simulation.effects import EffectSpec
from cageless.simulation.models import race_laws

K_X = 2.0e6  # N/m: the example law's parameter's default

@numba.njit(inline="always")
def linear_spring(delta, delta_dot, q, p, s):  # s: the index of the row's first slot, K_X
    return p[s] * delta

race_laws.register_race_law(
    EffectSpec("race_spring", "a linear spring k_x delta at the race contacts (test-only example law)",
               lambda scene: (True, "example law"), flag="F_SPRING", slots=("K_X",),
               fill=lambda par: {"K_X": par.value("race_spring_k_n_m")}, parameters=(("race_spring_k_n_m", K_X),)),
    linear_spring)
"""

_SCRIPT = r"""
import json, numpy as np
import cageless_race_spring  # registers the law (before the models import)

from cageless.conditions import OperatingConditions
from cageless.simulation.scene import Scene
from cageless.simulation.simulation import Choices, Simulation

scene = Scene(conditions=OperatingConditions(3000.0, 500.0), duration_s=1e-3)
on = Simulation(scene)
off = Simulation(scene, choices=Choices(effects={"race_spring": False}, force=True))
# the closed form is for the normal forces alone (traction scales with the normal force)
normal_on = Simulation(scene, choices=Choices(effects={"race_traction": False}, force=True))
normal_off = Simulation(scene, choices=Choices(effects={"race_traction": False, "race_spring": False}, force=True))
pr_on, pr_off = normal_on.build(), normal_off.build()
z = pr_on.n_balls
y = pr_on.y0.copy()
y[3 * z:4 * z] = 120.0
a_on, a_off = pr_on.rhs(0.0, y), pr_off.rhs(0.0, y)
d_o = y[:z] + 0.5 * pr_on.parameter("D") - 0.5 * pr_on.parameter("DO")
th = y[z:2 * z]
sx, sz = y[:z] * np.cos(th) - y[5 * z], y[:z] * np.sin(th) - y[5 * z + 1]
ln = np.hypot(sx, sz)
d_i = 0.5 * pr_on.parameter("DI") + 0.5 * pr_on.parameter("D") - ln
n_r = (sx * np.cos(th) + sz * np.sin(th)) / ln  # radial component of the inner contact normal
trace_on, trace_off = on.run(), off.run()
# its parameter is set like a built-in one: --set on the command line, then in the run's parameters
import contextlib, io, sys, tempfile
from cageless.app.cli import main
from cageless.simulation.parameters import ModelParameters
from cageless.trace import read_trace
out = tempfile.mkdtemp() + "/set.trace.h5"
with contextlib.redirect_stdout(io.StringIO()):
    rc = main(["simulate", "--speed-rpm", "3000", "--radial-load-n", "500", "--duration", "5e-4", "-q",
               "--set", "race_spring_k_n_m=4e6", "-o", out])
    typo = main(["simulate", "--speed-rpm", "3000", "--duration", "5e-4", "-q", "--set", "race_spring_kn_m=4e6",
                 "-o", out + ".typo"])
stiffer = Simulation(scene, ModelParameters().with_overrides({"race_spring_k_n_m": 4e6}),
                     Choices(effects={"race_traction": False}, force=True)).build()
a_stiff = stiffer.rhs(0.0, y)
set_config = read_trace(out).provenance["config"]["parameters"]
print(json.dumps({"cli_rc": rc, "cli_typo_rc": typo, "cli_k": set_config["race_spring_k_n_m"],
                  "k_set": stiffer.parameter("K_X"), "dr_acc_set": (a_stiff[2 * z:3 * z] - a_off[2 * z:3 * z]).tolist(),"active": list(on.model.active), "k_x": pr_on.parameter("K_X"), "m": pr_on.parameter("M"),
                  "d_o": d_o.tolist(), "d_i": d_i.tolist(), "n_r": n_r.tolist(), "dr_acc": (a_on[2 * z:3 * z] - a_off[2 * z:3 * z]).tolist(),
                  "ring_z_on": float(on.solution.y[-1, 5 * z + 1]), "ring_z_off": float(off.solution.y[-1, 5 * z + 1]),
                  "ok": bool(on.solution.success and off.solution.success)}))
"""

_SPATIAL = _SCRIPT[:_SCRIPT.index("from cageless.conditions import OperatingConditions")] + r"""
from cageless.conditions import OperatingConditions
from cageless.simulation.scene import Scene
from cageless.simulation.simulation import Choices, Simulation

scene = Scene(conditions=OperatingConditions(3000.0, 500.0, 200.0), duration_s=5e-4)  # the axial load: spatial
on = Simulation(scene)
off = Simulation(scene, choices=Choices(effects={"race_spring": False}, force=True))
pr_on, pr_off = on.build(), off.build()
y = pr_on.y0.copy()
a_on, a_off = pr_on.rhs(0.0, y), pr_off.rhs(0.0, y)
on.run(), off.run()
print(json.dumps({"level": on.model.level, "active": list(on.model.active), "k_x": pr_on.parameter("K_X"),
                  "rhs_change": float(np.max(np.abs(a_on - a_off))),
                  "final_change": float(np.max(np.abs(on.solution.y[-1] - off.solution.y[-1]))),
                  "ok": bool(on.solution.success and off.solution.success)}))
"""


def _law_on_path(tmp_path) -> dict[str, str]:
    """The example law module in a folder of its own, and an environment whose Python path holds it."""
    (tmp_path / "cageless_race_spring.py").write_text(_LAW_MODULE)
    path = os.pathsep.join([str(tmp_path), os.environ.get("PYTHONPATH", "")]).rstrip(os.pathsep)
    return {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "numba-cache"), "PYTHONPATH": path}


def _run(script: str, tmp_path) -> dict:
    env = _law_on_path(tmp_path)
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env=env, timeout=900)
    assert out.returncode == 0, out.stderr[-2000:]
    return json.loads(out.stdout.strip().splitlines()[-1])


def test_an_example_race_law_enters_the_forces(tmp_path):
    r = _run(_SCRIPT, tmp_path)
    assert "race_spring" in r["active"] and r["k_x"] == 2.0e6 and r["ok"]
    k, m = r["k_x"], r["m"]
    loaded = 0
    for d_o, d_i, n_r, dr in zip(r["d_o"], r["d_i"], r["n_r"], r["dr_acc"], strict=True):
        # closed form: the outer spring pushes the ball inward (-k_x d_o), the inner one out along its normal
        expected = (-k * max(d_o, 0.0) + k * max(d_i, 0.0) * n_r) / m
        assert abs(dr - expected) <= 1e-6 * abs(expected) + 1e-9
        loaded += d_o > 0
    assert loaded >= 3 and max(abs(v) for v in r["dr_acc"]) > 1.0  # the law acts where balls are loaded
    assert r["ring_z_on"] != r["ring_z_off"]  # the stiffer contacts carry the load: the run differs
    # --set race_spring_k_n_m=4e6 reaches the run (exit 0, on record) and the slot; the force doubles
    assert r["cli_rc"] == 0 and r["cli_k"] == 4.0e6 and r["cli_typo_rc"] == 2
    assert r["k_set"] == 4.0e6
    for dr, dr_set in zip(r["dr_acc"], r["dr_acc_set"], strict=True):
        assert abs(dr_set - 2.0 * dr) <= 1e-6 * abs(dr) + 1e-9


@pytest.mark.slow  # a fresh compile of the spatial kernels
def test_the_example_law_runs_at_the_spatial_level(tmp_path):
    """The same law, the same single definition, in the spatial model's race contacts: on, it changes the
    right-hand side at the packed start (the loaded balls' contacts) and the state after 0.5 ms."""
    r = _run(_SPATIAL, tmp_path)
    assert r["level"] == "spatial" and "race_spring" in r["active"] and r["k_x"] == 2.0e6 and r["ok"]
    assert r["rhs_change"] > 1.0  # m/s^2 (or rad/s^2): k_x delta / m at a loaded contact is of order 1e3
    assert r["final_change"] > 0.0


def test_an_installed_law_is_found_by_the_command_line(tmp_path):
    """The same module installed as a package (its entry point in the ``cageless.race_laws`` group, as a
    ``pyproject.toml`` would declare it): the plain ``cageless`` command sees the law's row and its parameter,
    with no other file edited and nothing imported by hand."""
    from cageless.simulation.models.race_laws import ENTRY_POINT_GROUP

    env = _law_on_path(tmp_path)
    info = tmp_path / "cageless_race_spring-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: cageless-race-spring\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text(f"[{ENTRY_POINT_GROUP}]\nrace_spring = cageless_race_spring\n")
    cli = [sys.executable, "-m", "cageless", "simulate", "--speed-rpm", "3000", "--radial-load-n", "500", "--explain"]
    out = subprocess.run([*cli, "--set", "race_spring_k_n_m=4e6"], capture_output=True, text=True, env=env,
                         timeout=300)
    assert out.returncode == 0, out.stderr[-2000:]
    assert "on  race_spring" in out.stdout and "example law" in out.stdout
    typo = subprocess.run([*cli, "--set", "race_spring_kn_m=4e6"], capture_output=True, text=True, env=env,
                          timeout=300)
    assert typo.returncode == 2 and "race_spring_k_n_m" in typo.stderr  # the suggestion names the law's parameter
