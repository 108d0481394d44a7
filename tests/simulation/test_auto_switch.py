"""The automatic switch to the stiff backend (simulation.chunks): deterministic, recorded, and taken only
where the work counts say it pays.

Measured on 50 ms runs at 3000 rpm: with R = 0 (ball-ball damping chi = 1000) DP5 sits at the stability
edge and LSODA needs 0.32 of its work, so the run switches (2.24 s against 2.78 s of wall time); a 20 kN
load switches at the second probe (2.5 s against 4.6 s); the default lubricated 500 N scene probes once
(LSODA 1.16 of DP5's work) and stays on DP5.
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


def test_a_stiff_scene_switches_to_lsoda_and_says_so():
    res = _run(500.0, restitution=0.0)
    sol, tr = res.solution, res.trace
    assert sol.success and np.all(np.isfinite(tr.slip))
    assert sol.method.startswith("auto: dp5 -> LSODA at")
    probes = tr.provenance["solver_stats"]["switch_probes"]
    assert probes[0]["switch"] and probes[0]["work_ratio"] < 0.6 and probes[0]["stiff_fraction"] > 0.6
    assert tr.simulation.solver == sol.method
    again = _run(500.0, restitution=0.0)  # the decision uses work counts, not timing: same trace again
    assert again.solution.method == sol.method and np.array_equal(again.trace.slip, tr.slip, equal_nan=True)


def test_the_default_scene_stays_compiled():
    sol = _run(500.0).solution
    assert sol.method == "auto: dp5"
    assert all(not p["switch"] for p in sol.extra["switches"])


def test_an_unknown_method_is_refused_before_anything_runs():
    scene = Scene(conditions=OperatingConditions(3000.0, 500.0))
    with pytest.raises(ParameterError, match="Did you mean 'LSODA'"):
        simulate(scene, choose_model(scene), method="LSDOA", progress=False)
