"""``ark4`` kept across output chunks (:class:`cageless.simulation.solve.ArkSession`) and ``auto`` on it.

A run in chunks must take the steps of one solve (the session resumes the integrator where the last chunk's
step ended, and writes the next samples from that step's interpolant): checked bit for bit against one call
of the same compiled loop, the reference it was not built from being the one-call run itself. ``auto``'s
switch to it is checked on the settled scene of benchmarks/ark_speed.py (3000 rpm, 500 N, planar).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from cageless.simulation.auto_switch import SWITCH_GAIN, _chunk
from cageless.simulation.solve import ArkSession, solve, step_ark


@pytest.fixture(scope="module")
def settled():
    from cageless.simulation.bench import _settled_problem

    return _settled_problem(3000.0, 500.0, 0.01)


def test_a_run_in_chunks_takes_the_steps_of_one_solve(settled):
    """1 ms in 20 chunks of one sample each (shorter than ark4's steps at the end: up to 50 us) equals one call:
    the same samples bit for bit, the same steps, right-hand sides and contact log."""
    pr, _ = settled
    t = np.linspace(0.0, 1e-3, 21)
    one = solve(pr, t, method="ark4", max_step=5e-5)
    many = solve(pr, t, method="ark4", max_step=5e-5, chunks=20)
    assert one.success and many.success
    assert np.array_equal(one.y, many.y)
    assert (many.n_steps, many.n_rejected, many.n_rhs) == (one.n_steps, one.n_rejected, one.n_rhs)
    assert np.array_equal(one.extra["log"], many.extra["log"], equal_nan=True)


def test_a_session_resumes_past_the_last_sample(settled):
    """A chunk returns after the step that crosses its last sample, and the next writes its first samples from
    that step: the session's time lies past the chunk's end by less than one step, and a chunk whose samples all
    lie behind it takes no step."""
    pr, _ = settled
    first = step_ark(pr, np.array([2e-4]), 1e-6, 5e-5, t_stop=1e-3)
    session = first.extra["ark4"]
    assert isinstance(session, ArkSession) and 2e-4 < session.t < 2e-4 + 5e-5
    behind = step_ark(pr, np.array([0.5 * (2e-4 + session.t)]), 1e-6, 5e-5, session=session)
    assert behind.n_steps == 0 and behind.n_rhs == 0 and np.all(np.isfinite(behind.y))
    # one solve to the same end (so the same first step, 1e-3 of the span, and no step cut short before it)
    one = solve(pr, np.array([2e-4, 0.5 * (2e-4 + session.t), 1e-3]), method="ark4", max_step=5e-5)
    assert np.array_equal(one.y[:2], np.vstack([first.y, behind.y]))


def test_leaving_a_session_hands_over_its_state_and_log(settled):
    """When the run leaves ark4, the next method goes on from where the session is (its time, state and contact
    log), and the samples behind it come from the session: over 0.4 ms DP5 after 0.2 ms of ark4 stays within the
    0.01 pp slip bar of ark4 throughout (benchmarks/ark_speed.py's measure)."""
    pr, cage = settled
    z = pr.n_balls
    t = np.linspace(0.0, 4e-4, 9)
    ark = solve(pr, t, method="ark4", max_step=5e-5)
    first = step_ark(pr, t[1:5], 1e-6, 5e-5, t_stop=float(t[-1]))
    session = first.extra["ark4"]
    kw = {"rtol": 1e-6, "max_step": None, "force_jump": 0.5, "max_steps": 10 ** 6}
    sol, part, ran, left = _chunk(pr, t[5:], "dp5", kw, None, float(t[-1]), session)
    assert left is None and part.t0 == session.t and ran[0] > session.t
    assert np.array_equal(part.log, session.log, equal_nan=True) and np.array_equal(part.y0, session.rows[0])
    y = np.vstack([first.y, sol.y])
    slip_pp = 100 * np.max(np.abs(y[:, 3 * z:4 * z] - ark.y[1:, 3 * z:4 * z])) / cage
    assert slip_pp < 0.01


def test_auto_runs_one_ark4_session_and_skips_the_cvode_probe_it_cannot_need(settled):
    """On the settled scene ``auto`` probes its first chunk (DP5 at the stability edge), finds ark4 at 0.1 of DP5
    (measured 0.099) below SWITCH_GAIN of the least CVODE could cost there (its 5 us cap), so CVODE
    is not probed, and runs the rest in one ark4 session: after the switch, the steps one ark4 solve from the
    switch takes. Deterministic: a second run gives the same samples bit for bit."""
    pr, _ = settled
    t = np.linspace(0.0, 2e-3, 21)
    sol = solve(pr, t, method="auto")
    assert sol.method == "auto: dp5 -> ark4 at 0.0001 s" and sol.extra["ark4_sessions"] == 1
    probe = sol.extra["switches"][-1]
    assert probe["to"] == "ark4" and set(probe["costs"]) == {"ark4"}
    assert probe["costs"]["ark4"] < SWITCH_GAIN * probe["skipped"]["CVODE"] < SWITCH_GAIN
    assert 0.05 < probe["costs"]["ark4"] < 0.2
    first = solve(pr, t[:2], method="dp5", max_step=2e-6)
    rest = solve(replace(pr, y0=first.y[-1], log=first.extra["log"], t0=float(t[1])), t[1:], method="ark4",
                 max_step=5e-5)
    assert np.array_equal(sol.y[1:], rest.y)
    again = solve(pr, t, method="auto")
    assert np.array_equal(sol.y, again.y) and again.method == sol.method


def test_auto_decides_on_ark4_without_a_dp5_pilot_where_the_race_damping_holds_dp5(settled, monkeypatch):
    """Where the race damping holds DP5 at its stability edge, its cost over the pilot is a closed form
    (simulation.auto_switch._dp5_edge_cost: steps of DP5_EDGE / |lambda|, |lambda| = 2 C_ho / m for a ball between
    both races, six right-hand sides each), within 2 % of DP5's own pilot (measured 1.003 times it over the 0.2 ms
    pilot of the settled window of benchmarks/ark_speed.py). DP5_EDGE is the negative real root of |R(x)| = 1 for DP5's
    stability function R(z) = sum_{k<=5} z^k / k! + z^6 / 600 (Hairer & Wanner, Solving ODEs II, sect. IV.2). ark4's
    probe below SWITCH_GAIN of that and of CVODE's least cost starts the run on ark4 without the DP5 pilot, the
    same choice and the same samples, bit for bit, as the run that pays the pilot (the closed form switched off)."""
    import math

    import cageless.simulation.auto_switch as auto_switch

    coeffs = [1.0 / 600.0] + [1.0 / math.factorial(k) for k in range(5, -1, -1)]
    coeffs[-1] -= 1.0  # R(x) - 1 = 0 (R > 0 there)
    roots = [r.real for r in np.roots(coeffs) if abs(r.imag) < 1e-9 and r.real < -1.0]
    assert roots and auto_switch.DP5_EDGE == pytest.approx(-roots[0], abs=1e-4)
    pr, _ = settled
    t = np.linspace(0.0, 4e-3, 3)  # a 2 ms first chunk: a 0.2 ms pilot
    pilot_s = auto_switch.PILOT_FRACTION * 2e-3
    dp5 = solve(pr, np.array([pilot_s]), method="dp5", max_step=auto_switch.CONTACT_MAX_STEP_S)
    assert dp5.n_stiff_steps > 0.8 * dp5.n_steps  # DP5 held by stability there
    edge = auto_switch._dp5_edge_cost(pr, pilot_s)
    assert edge == pytest.approx(auto_switch._cost(dp5, pr.model_id), rel=0.02)
    sol = solve(pr, t, method="auto")
    pilot = sol.extra["switches"][0]
    assert sol.method == "auto: dp5 -> ark4 at 0 s" and pilot["dp5_edge"] and pilot["stiff_fraction"] is None
    assert pilot["pilot_s"] == pytest.approx(pilot_s) and pilot["cost_ratio"] < SWITCH_GAIN * pilot["skipped"]["CVODE"]
    monkeypatch.setattr(auto_switch, "_dp5_edge_cost", lambda *_: None)
    paid = solve(pr, t, method="auto")
    assert paid.method == sol.method and "dp5_edge" not in paid.extra["switches"][0]
    assert np.array_equal(paid.y, sol.y) and paid.n_rhs == sol.n_rhs
