"""The stiff backend: SUNDIALS CVODE (BDF, through scikit-sundae) on the compiled planar model.

From a state 20 ms after the start at 1800 rpm (bunching, ball-ball impacts), CVODE at rtol 1e-6 and
the default 2 us step cap must follow a DP5 rtol 1e-10 reference over 5 ms (a window short enough for
single trajectories of the chaotic ring, DESIGN §7) and log the same ball-ball contact episodes, since
the accepted-step bookkeeping runs after each of its steps too. Measured: slip error 4.4e-3 pp (DP5 at
rtol 1e-6: 5.6e-4 pp) in 2608 steps against DP5's 4255; 105 episodes logged by both.
"""

from __future__ import annotations

import numpy as np
import pytest

from cageless.simulation.bench import _settled_problem
from cageless.simulation.models import planar as P
from cageless.simulation.solve import solve


@pytest.fixture(scope="module")
def settled():
    return _settled_problem(1800.0, 500.0, 0.02)


def test_cvode_follows_a_tight_reference_through_impacts(settled):
    pr, cage = settled
    z = pr.n_balls
    t = np.linspace(0.0, 0.005, 51)
    ref = solve(pr, t, rtol=1e-10, max_step=2.5e-7)
    sol = solve(pr, t, method="CVODE", rtol=1e-6, max_step=2e-6)
    assert sol.success and sol.method == "CVODE" and sol.n_steps > 0
    slip_error_pp = 100 * np.abs(sol.y[:, 3 * z:4 * z] - ref.y[:, 3 * z:4 * z]).max() / cage
    assert slip_error_pp < 0.02
    assert sol.n_steps < 0.8 * solve(pr, t, rtol=1e-6, max_step=2e-6).n_steps  # not held by stability as DP5 is
    episodes = 5 * z  # the logged-episode counter (simulation.models.planar, auxiliary layout)
    assert sol.extra["log"][episodes] == ref.extra["log"][episodes] > 0


def test_a_run_in_chunks_keeps_one_warm_integrator(settled):
    """In chunks, CVODE continues one integrator (simulation.solve.CvodeSession) instead of restarting cold
    at order 1 with a new Jacobian each time; measured over 20 ms at the spatial level, 50 cold restarts
    cost 35 % more right-hand-side calls (18506 against 13663), warm chunks 13657."""
    from cageless.simulation.auto_switch import solve_chunks

    pr, cage = settled
    z = pr.n_balls
    t = np.linspace(0.0, 0.005, 51)
    one = solve(pr, t, method="CVODE", rtol=3e-8, max_step=5e-6)
    # rtol x 0.03 and the 5 us cap
    chunked = solve_chunks(pr, t, 1e-6, "CVODE", None, 25, False, 50_000_000, 0.5)
    assert chunked.success and abs(chunked.n_rhs - one.n_rhs) < 0.05 * one.n_rhs  # 1813 against 1755
    # a chunk boundary moves when Jacobians are re-evaluated, so the Newton iterates differ at the level of
    # the error control (measured 1.2e-3 pp; CVODE's own error against a tight reference: ~1e-3 pp)
    assert 100 * np.abs(chunked.y[:, 3 * z:4 * z] - one.y[:, 3 * z:4 * z]).max() / cage < 5e-3


def test_cvode_is_stopped_ahead_of_contact_onsets():
    """CVODE cannot take a step back, so it is stopped ahead of predicted contact changes
    (simulation.solve.CvodeSession.stop_time) and the step that crosses one stays within the onset step
    t_H/20 that DP5 retries at. From the packed start at 1800 rpm over 10 ms (balls bunching and
    spreading): measured with the traction curve, 204 contact changes, 9 of them inside longer steps without
    the control, 0 of 194 with it, for 2.6 % more steps. With the traction by film regime (the default) a
    straight-line prediction still let 1 of 156 changes fall inside a longer step (a neighbour pair closing
    faster and faster, 0.42 nm apart: predicted in 4.1 us, closed in 2.9); with the overlaps' curvature in the
    prediction (simulation.solve._onset_update), 0 of 155, for 0.8 % more steps. This check runs on the
    default effects."""
    from cageless.conditions import OperatingConditions
    from cageless.simulation.effects import choose_model
    from cageless.simulation.parameters import ModelParameters
    from cageless.simulation.run import build_problem
    from cageless.simulation.scene import Scene
    from cageless.simulation.solve import step_cvode

    scene = Scene(conditions=OperatingConditions(1800.0, 500.0))
    pr = build_problem(scene, choose_model(scene), ModelParameters())
    assert "film_traction" in pr.effects
    t = np.linspace(0.0, 0.01, 101)
    free = step_cvode(pr, t, 3e-8, max_step=5e-6, onset_control=False)
    held = step_cvode(pr, t, 3e-8, max_step=5e-6)
    assert free.success and held.success and held.n_contact_changes > 100
    assert free.extra["long_onset_steps"] > 0 and held.extra["long_onset_steps"] == 0
    assert held.n_steps < 1.1 * free.n_steps


@pytest.mark.parametrize("coeffs", [(-1.0, 0.0, 1.0), (1.0, -3.0, 2.0), (-2e-10, 1e-4, 5.0), (1.0, 1.0, 1.0),
                                    (2.0, -1.0, 0.0), (1e-9, 2e-4, -8.0), (3.0, 0.0, -1e-30)])
def test_onset_prediction_first_positive_root(coeffs):
    """The curvature term of CVODE's onset prediction (simulation.solve._first_root) gives the smallest positive
    root of c0 + c1 s + c2 s^2, as numpy's companion-matrix roots do, and inf when there is none."""
    from cageless.simulation.solve import _first_root

    c0, c1, c2 = coeffs
    roots = np.roots([c2, c1, c0]) if c2 != 0.0 else np.roots([c1, c0])
    real = [r.real for r in roots if abs(r.imag) <= 1e-12 * max(1.0, abs(r)) and r.real > 0.0]
    got = _first_root(c0, c1, c2)
    if real:
        assert got == pytest.approx(min(real), rel=1e-9)
    else:
        assert got == np.inf
