"""The structured Jacobian of the implicit backend (simulation.jacobian).

Its grouped difference quotients (Curtis, Powell & Reid, J. Inst. Math. Appl. 13 (1974) 117-119) must
reproduce the one-state-at-a-time difference quotients column by column, and the structure it claims
must hold: a state outside the pattern must leave a row exactly unchanged. Checked on two states where
every kind of contact is closed: the packed start (every ball touching its neighbours) and a state
settled 30 ms after the start. Reference: the plain difference-quotient Jacobian evaluated in the test.
"""

from __future__ import annotations

import numpy as np
import pytest

from cageless.conditions import OperatingConditions
from cageless.errors import ParameterError
from cageless.simulation.bench import _settled_problem
from cageless.simulation.effects import choose_model
from cageless.simulation.jacobian import JacobianStructure, ball_colours, dense_fd_jacobian
from cageless.simulation.models import planar as P
from cageless.simulation.parameters import ModelParameters
from cageless.simulation.run import build_problem
from cageless.simulation.scene import Scene
from cageless.simulation.solve import step_cvode


@pytest.mark.parametrize("n_balls", range(1, 31))
def test_balls_of_one_colour_are_three_apart(n_balls):
    colours = ball_colours(n_balls)
    assert colours.shape == (n_balls,)
    for i in range(n_balls):
        for k in range(i + 1, n_balls):
            gap = min(k - i, n_balls - (k - i))
            assert colours[i] != colours[k] or gap >= 3, (i, k)
    if n_balls == 14:
        assert colours.max() + 1 == 4  # 14 = 4 + 4 + 3 + 3


def _packed(level: str, axial_n: float) -> object:
    scene = Scene(conditions=OperatingConditions(3000.0, 500.0, axial_n), initial_gap_fraction=0.0)
    return build_problem(scene, choose_model(scene, level=level), ModelParameters())


@pytest.mark.parametrize("level, axial_n, state", [("planar", 0.0, "packed"), ("planar", 0.0, "settled"),
                                                   ("spatial", 400.0, "packed"), ("spatial", 400.0, "settled")])
def test_structured_jacobian_matches_plain_difference_quotients(level, axial_n, state):
    pr = _packed(level, axial_n) if state == "packed" else _settled_problem(3000.0, 500.0, 0.03, axial_n,
                                                                              level=level)[0]
    structure = JacobianStructure.for_problem(pr)
    n = len(pr.y0)
    floor = pr.atol / 1e-7
    jac = np.empty((n, n))
    structure.evaluator(pr, pr.log.copy(), floor)(0.01, pr.y0, jac)
    ref = dense_fd_jacobian(pr, 0.01, pr.y0, floor)
    assert np.all(ref[~structure.pattern] == 0.0)  # the claimed structure holds exactly
    z = pr.n_balls
    closed = np.count_nonzero(ref[P.PlanarLayout(z).slices()["r_dot"], z:2 * z])  # d r''/d theta: contacts
    assert closed > z  # ball-ball contacts are closed in this state, so the band is exercised
    scale = np.abs(ref).max(axis=1, keepdims=True) + 1e-300
    # planar: the same differences of the same sums, to round-off; spatial: the ring rows are sums of 14
    # shares against one share, so they differ by the difference quotient's own error, ~sqrt(eps)
    assert (np.abs(jac - ref) / scale).max() < (1e-9 if level == "planar" else 1e-6)
    assert structure.rhs_per_jacobian < n / 2.5  # 25 of 76 planar, 47 of 138 spatial


def test_cvode_with_the_structured_jacobian_follows_its_own_difference_quotients():
    """Same steps within 5 % (measured 570 against 556 over 2 ms), the same slip within 2e-3 percentage
    points, and fewer right-hand sides (over 5 ms at 3000 rpm: 2142 against 3576).

    Another Jacobian changes the Newton iterates, so the two runs differ at the level of the error
    control, not of round-off: measured 3.5e-4 pp over 2 ms. The bound is CVODE's own error against a
    DP5 rtol 1e-10 reference at these settings (7e-4 to 1.1e-3 pp, README work-precision table), doubled.
    """
    pr, cage = _settled_problem(3000.0, 500.0, 0.03)
    z = pr.n_balls
    t = np.linspace(0.0, 0.002, 21)
    own = step_cvode(pr, t, 1e-7, max_step=5e-6, jacobian="dense")
    for jacobian in ("structured", "sparse"):
        sol = step_cvode(pr, t, 1e-7, max_step=5e-6, jacobian=jacobian)
        assert sol.success and abs(sol.n_steps - own.n_steps) <= 0.05 * own.n_steps
        assert 100 * np.abs(sol.y[:, 3 * z:4 * z] - own.y[:, 3 * z:4 * z]).max() / cage < 2e-3
        assert sol.extra["cvode"].n_jac > 0 and sol.n_rhs < 0.8 * own.n_rhs


def test_unknown_jacobian_is_named_with_a_suggestion():
    pr, _ = _settled_problem(3000.0, 500.0, 0.001)
    with pytest.raises(ParameterError, match="jacobian.*sparse"):
        step_cvode(pr, np.linspace(0.0, 1e-4, 3), 1e-7, jacobian="sparce")


@pytest.mark.parametrize("method", ["LSODA", "BDF"])
def test_scipy_implicit_methods_use_it_and_follow_a_tight_reference(method):
    """scipy's implicit steppers get the structured Jacobian on the compiled path (DESIGN §7 asks for the
    sparsity pattern). Over 2 ms from a settled 3000 rpm state they must follow a DP5 rtol 1e-10
    reference; bound 5e-3 pp, above the 1.7e-4 (LSODA) and 2.8e-3 pp (BDF) the README's work-precision
    table measures over 5 ms."""
    from cageless.simulation.solve import solve

    pr, cage = _settled_problem(3000.0, 500.0, 0.03)
    z = pr.n_balls
    t = np.linspace(0.0, 0.002, 21)
    ref = solve(pr, t, rtol=1e-10, max_step=2.5e-7)
    sol = solve(pr, t, method=method, rtol=1e-6, max_step=2e-6)
    assert sol.success
    assert 100 * np.abs(sol.y[:, 3 * z:4 * z] - ref.y[:, 3 * z:4 * z]).max() / cage < 5e-3
