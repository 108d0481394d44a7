"""The automatic switch to the stiff backend (simulation.chunks): deterministic, recorded, and taken only
where the cost model says it pays.

Measured on 50 ms runs at 3000 rpm (wall time, auto against DP5 throughout): with R = 0 (ball-ball
damping chi = 1000) DP5 sits at the stability edge and CVODE costs 0.27 of it, so the run switches at
6 ms (1.25 s against 2.16 s); a 20 kN load switches at 6 ms (cost ratio 0.41; 0.80 s against 3.12 s);
the default lubricated 500 N scene probes once (CVODE 0.8 of DP5's cost) and stays on DP5.
"""

from __future__ import annotations

import numpy as np
import pytest

from cageless.conditions import OperatingConditions
from cageless.errors import ParameterError
from simulation.effects import choose_model
from simulation.parameters import ModelParameters
from simulation.run import simulate
from simulation.scene import Scene


def _run(load: float, duration: float = 0.03, **par):
    scene = Scene(conditions=OperatingConditions(3000.0, load), duration_s=duration)
    return simulate(scene, choose_model(scene), parameters=ModelParameters(**par), progress=False)


def test_a_stiff_scene_switches_to_cvode_and_says_so():
    res = _run(500.0, restitution=0.0)
    sol, tr = res.solution, res.trace
    assert sol.success and np.all(np.isfinite(tr.slip))
    assert sol.method.startswith("auto: dp5 -> CVODE at")
    probes = tr.provenance["solver_stats"]["switch_probes"]
    assert probes[0]["switch"] and probes[0]["cost_ratio"] < 0.6 and probes[0]["stiff_fraction"] > 0.6
    assert tr.simulation.solver == sol.method
    solver = tr.provenance["config"]["solver"]  # the resolved settings the switched run used are on record
    assert solver["max_step"] is None and solver["default_max_step_s"]["CVODE"] == 5e-6
    assert solver["rtol_factor"]["CVODE"] == 0.1
    again = _run(500.0, restitution=0.0)  # the decision uses counts, not timing: same trace again
    assert again.solution.method == sol.method and np.array_equal(again.trace.slip, tr.slip, equal_nan=True)


def test_a_switch_that_stops_paying_is_undone():
    """A dry scene at the spatial level: the probe at 2.4 ms, inside the start-up, finds CVODE at 0.58 of
    DP5's cost, but two milliseconds later CVODE costs 1.6 times what DP5 did per simulated second (Newton
    failures on the steep dry friction law), so the run goes back to DP5 for good. Without the way back
    CVODE ran to the end: 1.7 times DP5's wall time and an energy balance off by 2.2e-5 of the input work
    (3.4e-7 with it)."""
    from dataclasses import replace

    scene = Scene(conditions=OperatingConditions(3000.0, 500.0), duration_s=0.02)
    scene = replace(scene, bearing=replace(scene.bearing, lubricant=None))
    res = simulate(scene, choose_model(scene, level="spatial", force=True),
                   parameters=ModelParameters(dry_friction_coefficient=0.1), progress=False)
    probes = res.solution.extra["switches"]
    assert [p["to"] for p in probes if p["switch"]] == ["CVODE", "dp5"]
    assert probes[-1]["cost_ratio"] > 1.0
    assert res.solution.method.endswith("-> dp5 at 0.0044 s")


def test_the_default_scene_stays_compiled():
    sol = _run(500.0).solution
    assert sol.method == "auto: dp5"
    assert all(not p["switch"] for p in sol.extra["switches"])


def test_an_unknown_method_or_a_bad_cap_is_refused_before_anything_runs():
    scene = Scene(conditions=OperatingConditions(3000.0, 500.0))
    with pytest.raises(ParameterError, match="max_step"):
        simulate(scene, choose_model(scene), max_step=0.0, progress=False)
    with pytest.raises(ParameterError, match="Did you mean 'LSODA'"):
        simulate(scene, choose_model(scene), method="LSDOA", progress=False)
