"""The automatic switch to a stiff backend, CVODE or ark4 (simulation.auto_switch): deterministic, recorded, and
taken only where the cost model says it pays.

The first probe is on the first chunk, and a probe that does not switch, or a way back to DP5, makes the
next wait twice as long (simulation.auto_switch.PROBE_BACKOFF). Same-run ratios of the switch before
(probes at chunks 5 and 20 only, a way back for good) and now are in ``benchmarks/solver_speed.py``.
"""

from __future__ import annotations

import numpy as np
import pytest

from cageless.conditions import OperatingConditions
from cageless.errors import ParameterError
from cageless.simulation.auto_switch import SWITCH_GAIN
from cageless.simulation.effects import choose_model
from cageless.simulation.parameters import ModelParameters
from cageless.simulation.run import simulate
from cageless.simulation.scene import Scene


def _run(load: float, duration: float = 0.03, **par):
    scene = Scene(conditions=OperatingConditions(3000.0, load), duration_s=duration)
    return simulate(scene, choose_model(scene), parameters=ModelParameters(**par), progress=False)


def test_a_stiff_scene_switches_to_cvode_and_says_so():
    res = _run(500.0, restitution=0.0)
    sol, tr = res.solution, res.trace
    assert sol.success and np.all(np.isfinite(tr.slip))
    assert sol.method.startswith("auto: dp5 -> CVODE at")
    probes = tr.provenance["solver_stats"]["switch_probes"]
    taken = next(p for p in probes if p["switch"])
    assert taken["to"] == "CVODE" and taken["cost_ratio"] < 0.8 and taken["stiff_fraction"] > 0.6
    assert tr.simulation.solver == sol.method
    solver = tr.provenance["config"]["solver"]  # the resolved settings the switched run used are on record
    assert solver["max_step"] is None and solver["default_max_step_s"]["CVODE"] == 5e-6
    assert solver["rtol_factor"]["CVODE"] == 0.03
    again = _run(500.0, restitution=0.0)  # the decision uses counts, not timing: same trace again
    assert again.solution.method == sol.method and np.array_equal(again.trace.slip, tr.slip, equal_nan=True)


def test_a_switch_that_stops_paying_is_undone(monkeypatch):
    """A dry scene at the spatial level: a probe inside the start-up finds CVODE cheaper; its chunks then
    grow dearer (Newton failures on the steep dry friction law) until the mean of the last two costs more
    per simulated second than DP5 did on the probed chunk, and the run goes back to DP5. It probes again
    later, each wait twice the last (simulation.auto_switch.PROBE_BACKOFF), so the switches alternate and
    thin out. Dry scenes do not switch at all by default (simulation.auto_switch.SWITCH_WHEN_DRY: CVODE's
    energy balance drifts there), so the test allows it."""
    from dataclasses import replace

    import cageless.simulation.auto_switch

    monkeypatch.setattr(cageless.simulation.auto_switch, "SWITCH_WHEN_DRY", True)

    scene = Scene(conditions=OperatingConditions(3000.0, 500.0), duration_s=0.02)
    scene = replace(scene, bearing=replace(scene.bearing, lubricant=None))
    res = simulate(scene, choose_model(scene, level="spatial", force=True),
                   parameters=ModelParameters(dry_friction_coefficient=0.1), progress=False)
    probes = res.solution.extra["switches"]
    switched = [p for p in probes if p["switch"]]
    assert [p["to"] for p in switched][:2] == ["CVODE", "dp5"]
    assert all(a["to"] != b["to"] for a, b in zip(switched, switched[1:], strict=False))  # alternating
    assert all(p["cost_ratio"] > 1.0 for p in switched if p["to"] == "dp5")
    # the waits (in 0.4 ms chunks) from a way back to the next probe grow: 2, 4, 8, ... times one chunk
    backs = [p["time_s"] for p in switched if p["to"] == "dp5"]
    nxt = [min((q["time_s"] for q in probes if q["time_s"] > t and q["to"] == "CVODE"), default=None) for t in backs]
    waits = [round((b - a) / 4e-4) for a, b in zip(backs, nxt, strict=True) if b is not None]
    assert waits and waits == sorted(waits) and len(set(waits)) == len(waits)


def test_the_default_scene_switches_once_past_its_start_up():
    """The default lubricated scene over 50 ms (1 ms chunks): DP5 is not held by stability over the first two
    chunks, while the balls spread, so nothing is probed there; the first stiff chunk (ending at 3 ms) is
    probed: ark4 costs 0.11 of DP5 there, below SWITCH_GAIN of the least CVODE could cost (its probe measured
    0.30 before it was skipped there), and the run switches to ark4. A burst of contacts then makes its chunks
    2.5 times dearer than DP5 on the probed chunk, the run goes back to DP5 at 6 ms, and the next stiff chunk's
    probe (before ark4 was kept across chunks: CVODE 0.52, ark4 0.19; now ark4 0.13 and CVODE skipped) switches
    to ark4 again at 9 ms for the rest of the run (measured; the cost model is deterministic). With CVODE as the
    only candidate the switches were the same, to CVODE (0.30, then 3.7 times dearer, then 0.52).
    The pilot over the first 0.1 ms: CVODE's cold start costs DP5's rate there, and ark4 runs out of its step
    budget in the start-up."""
    sol = _run(500.0, duration=0.05).solution
    assert sol.method == "auto: dp5 -> ark4 at 0.003 s -> dp5 at 0.006 s -> ark4 at 0.009 s"
    pilot, *probes = sol.extra["switches"]
    assert not pilot["switch"] and pilot["pilot_s"] == pytest.approx(1e-4) and 0.9 < pilot["cost_ratio"] < 1.1
    assert pilot["to"] == "CVODE" and pilot["costs"]["ark4"] == np.inf
    assert [p["to"] for p in probes] == ["ark4", "dp5", "ark4"]
    # ark4 is probed first: below SWITCH_GAIN of CVODE's least possible cost (under the 0.30 its probe measured
    # before) CVODE is not probed, and the choice is the one both probes made
    assert set(probes[0]["costs"]) == {"ark4"} and 0.08 < probes[0]["cost_ratio"] < 0.15
    assert probes[0]["cost_ratio"] < SWITCH_GAIN * probes[0]["skipped"]["CVODE"] < SWITCH_GAIN * 0.35
    assert probes[1]["cost_ratio"] > 1.0 and probes[0]["stiff_fraction"] > 0.6
    # measured 0.13, CVODE skipped; 0.084 once the planar implicit solves took the fast-math flags (the ark4 run
    # over 3-6 ms changed at round-off, and the start-up is chaotic)
    assert probes[2]["to"] == "ark4" and 0.05 < probes[2]["cost_ratio"] < 0.25


def test_a_scene_stiff_from_the_start_starts_on_cvode(monkeypatch):
    """Under 20 kN DP5 is held by stability from the first step (stiff fraction 0.98 on the first chunk): the
    pilot over a tenth of the first chunk finds CVODE far cheaper and the run starts on it, instead of paying
    DP5 for the whole first chunk (about half of the run's time over 20 ms with CVODE after it)."""
    import cageless.simulation.auto_switch

    sol = _run(20000.0, duration=0.005).solution
    pilot = sol.extra["switches"][0]
    assert sol.method == "auto: dp5 -> CVODE at 0 s" and pilot["switch"] and pilot["time_s"] == 0.0
    assert pilot["pilot_s"] == pytest.approx(0.1 * 0.005 / 50) and pilot["cost_ratio"] < 0.8
    monkeypatch.setattr(cageless.simulation.auto_switch, "PILOT_FRACTION", None)
    later = _run(20000.0, duration=0.005).solution  # without the pilot: the first chunk's probe
    assert later.method == "auto: dp5 -> CVODE at 0.0001 s" and later.n_rhs > sol.n_rhs


def test_a_dry_scene_stays_on_dp5():
    """CVODE's energy balance drifts in dry scenes (simulation.auto_switch.SWITCH_WHEN_DRY), so the switch leaves
    them on DP5: the dry spatial scene above probes nothing and runs DP5 throughout."""
    from dataclasses import replace

    scene = Scene(conditions=OperatingConditions(3000.0, 500.0), duration_s=0.006)
    scene = replace(scene, bearing=replace(scene.bearing, lubricant=None))
    sol = simulate(scene, choose_model(scene, level="spatial", force=True),
                   parameters=ModelParameters(dry_friction_coefficient=0.1), progress=False).solution
    assert sol.method == "auto: dp5" and sol.extra["switches"] == []


def test_an_unknown_method_or_a_bad_cap_is_refused_before_anything_runs():
    scene = Scene(conditions=OperatingConditions(3000.0, 500.0))
    with pytest.raises(ParameterError, match="max_step"):
        simulate(scene, choose_model(scene), max_step=0.0, progress=False)
    with pytest.raises(ParameterError, match="Did you mean 'LSODA'"):
        simulate(scene, choose_model(scene), method="LSDOA", progress=False)


def test_ark4_is_left_once_the_runs_refusals_reach_the_hard_cases_bound():
    """At both levels the run's refused steps, judged from simulation.auto_switch.ARK_JUDGE_STEPS (50) accepted steps on,
    may not reach ARK_REFUSAL_BOUND (0.2, the hard cases' bound on a run: tests/validation/test_hard_cases.py and
    test_spatial.py) of them while ark4 runs: a run that reaches it leaves ark4, to CVODE where the probe that chose
    ark4 found CVODE paying (below SWITCH_GAIN, 0.8, of DP5), else to DP5; the record carries the run's refused
    share."""
    from cageless.simulation.auto_switch import _ark_refusing, _leave_ark
    from cageless.simulation.kernels import PLANAR, SPATIAL

    chosen = {"costs": {"CVODE": 0.3, "ark4": 0.1}}
    for level in (SPATIAL, PLANAR):
        assert _leave_ark(60, 11, level, chosen, 0.01) is None  # 18.3 %
        assert _leave_ark(49, 30, level, chosen, 0.01) is None  # too few steps to judge
        assert _leave_ark(60, 12, level, chosen, 0.01)["to"] == "CVODE"
    # a probe that skipped CVODE (ark4 first) leaves to DP5
    assert _leave_ark(60, 12, PLANAR, {"costs": {"ark4": 0.1}, "skipped": {"CVODE": 0.25}}, 0.01)["to"] == "dp5"
    left = _leave_ark(60, 12, SPATIAL, chosen, 0.01)
    assert left["switch"] and left["to"] == "CVODE" and left["run_refused"] == pytest.approx(0.2)
    assert left["time_s"] == 0.01 and left["cost_ratio"] == pytest.approx(0.3)
    assert _leave_ark(60, 12, SPATIAL, {"costs": {"CVODE": 0.85, "ark4": 0.1}}, 0.01)["to"] == "dp5"
    assert _ark_refusing(500, 100, SPATIAL) and not _ark_refusing(500, 99, SPATIAL)


def test_ark4_runs_without_the_force_jump_test_on_the_ring_rows():
    """The ring's accelerations are a small difference of every ball's race forces (simulation.solve._ark_jump_floor):
    at the spatial level ark4 keeps the force-jump test on every other row that has one, DP5 on all of them."""
    from cageless.simulation.kernels import ring_rows
    from cageless.simulation.simulation import Choices, Simulation
    from cageless.simulation.solve import _ark_jump_floor

    scene = Scene(conditions=OperatingConditions(3000.0, 0.0, 500.0))
    pr = Simulation(scene, None, Choices()).build()
    ark = _ark_jump_floor(pr)
    rows = ring_rows(pr.model_id, pr.n_balls)
    changed = np.flatnonzero(ark.jump_floor != pr.jump_floor)
    assert changed.tolist() == sorted(r for r in rows if pr.jump_floor[r] > 0)  # ring y'', z'', x'', tilt''
    assert len(changed) == 5 and np.all(ark.jump_floor[rows] == 0.0)
