"""The compiled Dormand-Prince integrator and the solver registry."""

from __future__ import annotations

import numpy as np
import pytest

from cageless.errors import ParameterError
from cageless.simulation.models.textbook import oscillator_problem, riccati_problem
from cageless.simulation.models.two_balls import two_ball_problem
from cageless.simulation.solve import METHODS, solve


def oscillator(w: float = 2 * np.pi * 50):
    return oscillator_problem(w)


@pytest.mark.parametrize("method", list(METHODS))
def test_every_method_solves_an_oscillator(method):
    w = 2 * np.pi * 50
    t = np.linspace(0, 0.1, 1001)  # five periods; samples fall between steps
    sol = solve(oscillator(w), t, method=method, rtol=1e-8)
    assert sol.success
    assert np.abs(sol.y[:, 0] - np.cos(w * t)).max() < 1e-5


def test_dp5_error_falls_with_the_tolerance():
    w = 2 * np.pi * 50
    t = np.linspace(0, 0.1, 257)
    errors, steps = [], []
    for rtol in (1e-4, 1e-6, 1e-8, 1e-10):
        sol = solve(oscillator(w), t, rtol=rtol)
        errors.append(np.abs(sol.y[:, 0] - np.cos(w * t)).max())
        steps.append(sol.n_steps)
    # A 5th-order method: each 100x tighter tolerance cuts the error by well over 10x, at more steps.
    assert all(b < a / 10 for a, b in zip(errors, errors[1:], strict=False))
    assert all(b > a for a, b in zip(steps, steps[1:], strict=False))
    assert errors[-1] < 1e-8


@pytest.mark.parametrize("method", ["dp5", "CVODE"])
def test_failures_are_results_not_exceptions(method):
    t = np.linspace(0, 0.1, 11)
    sol = solve(oscillator(), t, method=method, max_steps=5)
    assert not sol.success and sol.message == "too many steps"
    assert np.isnan(sol.y[-1]).all()
    # y' = 1e6 y^2 from y = 1 blows up at t = 1e-6 s: the run must stop with a failure, not hang or raise.
    sol = solve(riccati_problem(1e6, 1.0), np.linspace(0, 1e-5, 5), method=method)
    assert not sol.success and sol.status in (2, 3)
    ok = np.isfinite(sol.y[:, 0])
    np.testing.assert_allclose(sol.y[ok, 0], 1 / (1 - 1e6 * sol.t[ok]), rtol=1e-4)


def test_registry_refuses_bad_arguments():
    pr = oscillator()
    with pytest.raises(ParameterError, match="Did you mean 'LSODA'"):
        solve(pr, [0.0, 1.0], method="LSODE")
    with pytest.raises(ParameterError, match="rtol"):
        solve(pr, [0.0, 1.0], rtol=0.0)
    with pytest.raises(ParameterError, match="t_eval"):
        solve(pr, [1.0, 0.5])


def test_reference_methods_agree_on_an_impact():
    pr = two_ball_problem(9.525e-3, 3.5519e-3, 7.4359e9, 0.7, 0.5, gap_m=1e-7)
    t = np.linspace(0, 1e-4, 201)
    ref = solve(pr, t, rtol=1e-9, max_step=1e-7)
    for method in ("DOP853", "LSODA", "CVODE"):
        other = solve(pr, t, method=method, rtol=1e-9, max_step=1e-7)
        v_ref = ref.y[-1, 3] - ref.y[-1, 2]
        assert other.y[-1, 3] - other.y[-1, 2] == pytest.approx(v_ref, rel=2e-3)
