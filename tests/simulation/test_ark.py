"""The compiled IMEX method ARK4(3)6L[2]SA (``solve(method="ark4")``).

Checked against what it was not built from: the published order conditions of additive Runge-Kutta
methods (Kennedy & Carpenter, Appl. Numer. Math. 44 (2003) 139-181, sect. 2, and Hairer, Norsett & Wanner,
Solving ODEs I, sect. II.2, the Butcher trees to order 4), the closed-form solution of a damped oscillator,
and the tight DP5 reference (rtol 1e-10, 0.25 us cap) on a settled bearing scene.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from cageless.simulation.integrators.ark import AE, AI, B, B_HAT, C, GAMMA
from cageless.simulation.models.textbook import damped_exact, damped_problem
from cageless.simulation.solve import METHODS, solve


def test_tables_satisfy_the_published_conditions():
    """Row sums, the stiffly accurate ESDIRK, and every order condition of the additive pair: order 4 for b
    (including the coupling conditions between the two tables), order 3 for b_hat."""
    one = np.ones(6)
    assert np.allclose(AE @ one, C, atol=1e-15) and np.allclose(AI @ one, C, atol=1e-15)
    assert np.allclose(np.diag(AI)[1:], GAMMA) and AI[0, 0] == 0.0 and np.allclose(AI[5], B)
    assert np.allclose(np.triu(AE), 0.0)
    for w, order in ((B, 4), (B_HAT, 3)):
        assert abs(w @ one - 1) < 1e-14
        for q in range(1, order):  # bushy trees: sum b c^q = 1 / (q + 1)
            assert abs(w @ C**q - 1 / (q + 1)) < 1e-13
        for a in (AE, AI):  # b A c = 1/6 (the order-3 tree), each table
            assert abs(w @ a @ C - 1 / 6) < 1e-13
        if order == 4:
            for a in (AE, AI):
                assert abs(w @ (C * (a @ C)) - 1 / 8) < 1e-13
                assert abs(w @ a @ C**2 - 1 / 12) < 1e-13
            for a1, a2 in itertools.product((AE, AI), repeat=2):  # the coupling conditions: b A1 A2 c = 1/24
                assert abs(w @ a1 @ a2 @ C - 1 / 24) < 1e-13
    assert abs(B @ AE @ AE @ C - 1 / 24) < 1e-13 and abs(B_HAT @ AE @ AI @ C - 1 / 24) > 1e-6  # embedded: order 3


def test_implicit_table_is_l_stable_at_infinity():
    """R(z) = 1 + z b^T (I - z A)^-1 1 of the ESDIRK tends to 0 as z -> -inf (stiffly accurate, L-stable)."""
    zz = -1e8
    r = 1 + zz * B @ np.linalg.solve(np.eye(6) - zz * AI, np.ones(6))
    assert abs(r) < 1e-6


def _fixed_step_error(k, c, n_steps, t_end=2.0):
    pr = damped_problem(k, c)
    h = t_end / n_steps
    sol = solve(pr, np.array([t_end]), method="ark4", rtol=0.5, max_step=h, first_step=h)
    assert sol.n_steps == n_steps and sol.n_rejected == 0
    return abs(sol.y[-1, 0] - damped_exact(k, c, np.array([t_end]))[0, 0])


def test_observed_order_four_on_a_damped_oscillator():
    """x'' = -x - 0.5 x' (damping implicit, spring explicit), fixed steps halved: the error falls by 2^4."""
    errors = [_fixed_step_error(1.0, 0.5, n) for n in (20, 40, 80, 160)]
    orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
    assert np.all((orders > 3.8) & (orders < 4.2)), orders


def test_embedded_order_three_on_the_linear_split():
    """The embedded weights alone, stepped on the same linear split in exact linear algebra (the ARK's stage
    equations for y' = (E + I) y): error falls by 2^3 per halving."""
    k, c, t_end = 1.0, 0.5, 2.0
    e_mat, i_mat = np.array([[0.0, 1.0], [-k, 0.0]]), np.array([[0.0, 0.0], [0.0, -c]])

    def run(weights, n):
        h, y = t_end / n, np.array([1.0, 0.0])
        for _ in range(n):
            fe, fi = [], []
            for i in range(6):
                z = y + h * sum(AE[i, j] * fe[j] + AI[i, j] * fi[j] for j in range(i))
                yi = np.linalg.solve(np.eye(2) - h * AI[i, i] * i_mat, z)
                fe.append(e_mat @ yi)
                fi.append(i_mat @ yi)
            y = y + h * sum(weights[j] * (fe[j] + fi[j]) for j in range(6))
        return abs(y[0] - damped_exact(k, c, np.array([t_end]))[0, 0])

    for weights, expect in ((B, 4), (B_HAT, 3)):
        errors = [run(weights, n) for n in (20, 40, 80)]
        orders = np.log2(np.array(errors[:-1]) / np.array(errors[1:]))
        assert np.all(np.abs(orders - expect) < 0.25), (expect, orders)


def test_stiff_damping_does_not_limit_the_step():
    """c = 1e6 1/s: the slow mode x ~ exp(-k t / c) is followed to 1e-12 in a few hundred steps, where DP5's
    stability region (3.3 on the real axis) needs at least c T / 3.3 = 6e5."""
    k, c, t_end = 1.0, 1e6, 2.0
    pr = damped_problem(k, c)
    t = np.linspace(0.0, t_end, 11)[1:]
    sol = solve(pr, t, method="ark4", rtol=1e-8)
    assert sol.success
    assert np.max(np.abs(sol.y[:, 0] - damped_exact(k, c, t)[:, 0])) < 1e-12
    assert sol.n_steps < 1000 < c * t_end / 3.3 / 100


def test_registered():
    assert "ark4" in METHODS


def test_jump_bound_extrapolates_the_force_jump_test():
    """The step after an accepted one is bounded where the force-jump test (dp5's ``_controls``: |f1 - f0| above
    ``fraction`` (max(|f0|, |f1|) + floor), rows with a floor only) is expected to reach JUMP_AIM of its limit,
    extrapolated linearly; never below the onset step, and unbounded where the test did not run. By hand: the
    row with floor 1 went 10 -> 14, q = 4 / (0.5 (14 + 1)) = 0.5333, so 10 us x 0.8 / 0.5333 = 15 us; the row
    without a floor (5 -> 0) is not tested."""
    from cageless.simulation.integrators.ark import JUMP_AIM, _jump_bound

    floor, f0, f1 = np.array([0.0, 1.0]), np.array([5.0, 10.0]), np.array([0.0, 14.0])
    assert JUMP_AIM == 0.8
    assert _jump_bound(10e-6, 1e-6, f0, f1, floor, 0.5) == pytest.approx(15e-6, rel=1e-12)
    assert _jump_bound(1.1e-6, 1e-6, f0, np.array([0.0, 24.7]), floor, 0.5) == 1e-6  # q = 1.14: 0.77 us -> 1 us
    assert _jump_bound(1e-6, 1e-6, f0, f1, floor, 0.5) == np.inf  # an onset step: the test does not run
    assert _jump_bound(10e-6, 1e-6, f0, f1, floor, 0.0) == np.inf  # the test off
    assert _jump_bound(10e-6, 1e-6, f0, f0, floor, 0.5) == np.inf  # no change


@pytest.fixture(scope="module")
def settled():
    from cageless.simulation.bench import _settled_problem

    return _settled_problem(3000.0, 500.0, 0.01)


def test_bearing_against_the_tight_reference(settled):
    """3000 rpm, 500 N, every effect of a lubricated scene, past the start-up: over 1 ms the slip stays within
    0.01 pp of DP5 at rtol 1e-10 and 0.25 us, the energy balance closes, with steps several times DP5's."""
    from cageless.simulation.models.planar import planar_energy

    pr, cage = settled
    z = pr.n_balls
    t = np.linspace(0.0, 1e-3, 21)[1:]
    ref = solve(pr, t, method="dp5", rtol=1e-10, max_step=0.25e-6)
    sol = solve(pr, t, method="ark4", rtol=1e-6)
    assert sol.success and np.all(np.isfinite(sol.y))
    slip_pp = 100 * np.max(np.abs(sol.y[:, 3 * z:4 * z] - ref.y[:, 3 * z:4 * z])) / cage
    assert slip_pp < 0.01
    e_ref = planar_energy(pr, ref.y) + ref.y[:, -1] - ref.y[:, -2]
    e_ark = planar_energy(pr, sol.y) + sol.y[:, -1] - sol.y[:, -2]
    work = np.max(np.abs(ref.y[:, -2]))
    assert np.max(np.abs(e_ark - e_ref)) < 1e-4 * work  # the same balance as the reference's, to 1e-4 of the input
    dp5 = solve(pr, t, method="dp5", rtol=1e-6)
    assert sol.n_steps < dp5.n_steps / 3


def test_deterministic(settled):
    pr, _ = settled
    t = np.array([2e-4, 4e-4])
    a, b = (solve(pr, t, method="ark4") for _ in range(2))
    assert np.array_equal(a.y, b.y) and a.n_steps == b.n_steps


@pytest.fixture(scope="module")
def settled_spatial():
    from cageless.simulation.bench import _settled_problem

    return _settled_problem(3000.0, 500.0, 0.005, axial_n=400.0, level="spatial", strips=5)


def test_spatial_bearing_against_the_tight_reference(settled_spatial):
    """500 N + 400 N axial, 5 strips (the spatial model, 3 x 3 solves per ball), past 5 ms of start-up: over
    0.5 ms the slip stays within 0.01 pp of DP5 at rtol 1e-10 and 0.25 us, all finite."""
    pr, cage = settled_spatial
    z = pr.n_balls
    t = np.linspace(0.0, 5e-4, 11)[1:]
    ref = solve(pr, t, method="dp5", rtol=1e-10, max_step=0.25e-6)
    sol = solve(pr, t, method="ark4", rtol=1e-6)
    assert sol.success and np.all(np.isfinite(sol.y))
    assert 100 * np.max(np.abs(sol.y[:, 3 * z:4 * z] - ref.y[:, 3 * z:4 * z])) / cage < 0.01


def _implicit(pr, y, hg):
    from cageless.simulation.kernels import model_implicit

    k_i = np.empty_like(y)
    model_implicit(pr.model_id, 0.0, y, pr.params, hg, k_i, np.zeros(12))
    return k_i


def test_stage_equation_is_solved_per_ball(settled):
    """Y = Z + h gamma f_I(Y) at a 20 us stage from the settled state, to the Newton tolerance: the loaded
    balls' normal forces (the Hertz spring and the damping) are implicit, so the stage moves their radii."""
    pr, _ = settled
    z = pr.n_balls
    hg = 20e-6 * GAMMA
    y_z = pr.y0.copy()
    y = y_z.copy()
    k_i = _implicit(pr, y, hg)
    assert np.max(np.abs(y - y_z - hg * k_i)) < 1e-12
    assert np.max(np.abs(y[:z] - y_z[:z])) > 1e-9  # r moved with r' (the radial kinematics are implicit)
    assert np.array_equal(y[z:2 * z], y_z[z:2 * z]) and np.array_equal(y[4 * z:], y_z[4 * z:])


def test_explicit_part_keeps_no_hertz_modes(settled):
    """The fastest modes of f - f_I at the settled 3000 rpm, 500 N state are well below the race Hertz
    oscillations (2.1e5 1/s) and the damping (2.8e6 1/s) that limit an explicit step: 2.1e4 1/s (a loaded
    ball's spin) where no neighbours touch; a ball-ball contact, which stays explicit, gave 6.1e4 1/s
    (-4.06e3 +- 6.09e4j) at the state this fixture settles to on the merged tree."""
    from cageless.simulation.bench import fastest_modes

    pr, _ = settled
    assert max(abs(ev) for ev in fastest_modes(pr, 1)["f - f_I"]) < 1e5
    assert max(abs(ev) for ev in fastest_modes(pr, 1)["f"]) > 1e5  # the whole RHS has them


def test_spatial_newton_jacobian_matches_difference_quotients(settled_spatial):
    """The analytic Jacobian of a ball's race normal forces (spatial model) against central difference quotients
    of the forces themselves (1e-9 m/s), along (r', r theta', x') with the position fixed (the filter's K_v), moving
    with the velocity (hr = 1, the filter's K_v + K_x) and at a stage (hr = 5 us): within 1e-4 of the largest entry
    (2.5e-5 measured: the quotients' rounding, two race forces of hundreds of newtons cancelling to about one;
    without the damping's change through the tilting ring's surface motion it was 5.8e-3). Then the stage equation
    of every ball is solved to the Newton tolerance."""
    from cageless.simulation.models import implicit_normal_spatial as sp
    from cageless.simulation.models.implicit_normal import TOL_V

    pr, _ = settled_spatial
    y, p, z = pr.y0.copy(), pr.params, pr.n_balls
    b = 5 * z + 6
    rot, wt = sp._frame(y, p)
    dv = 1e-9
    loaded, worst = 0, 0.0
    for j in range(z):
        c, s = np.cos(y[z + j]), np.sin(y[z + j])
        st = (y[j], y[2 * z + j], y[3 * z + j], y[b + j], y[b + z + j])
        for hr in (0.0, 1.0, 5e-6):
            _, kv, kr, kx = sp._forces_jacobian(y, p, j, z, rot, wt, c, s, *st)
            jac = np.array(kv).reshape(3, 3)
            jac[:, 0] += hr * (np.array(kr) + st[2] * jac[:, 1])
            jac[:, 2] += hr * np.array(kx)
            fd = np.empty((3, 3))
            for col in range(3):
                d = np.zeros(3)
                d[col] = dv
                plus = (st[0] + hr * d[0], st[1] + d[0], st[2] + d[1] / st[0], st[3] + hr * d[2], st[4] + d[2])
                minus = (st[0] - hr * d[0], st[1] - d[0], st[2] - d[1] / st[0], st[3] - hr * d[2], st[4] - d[2])
                fd[:, col] = (np.array(sp._forces(y, p, j, z, rot, wt, c, s, *plus))
                              - np.array(sp._forces(y, p, j, z, rot, wt, c, s, *minus))) / (2 * dv)
            sp._forces(y, p, j, z, rot, wt, c, s, *st)  # restore y
            if np.abs(fd).max() > 0:
                loaded += 1
                worst = max(worst, np.abs(jac - fd).max() / np.abs(fd).max())
    assert loaded >= z  # every ball touches a race under the axial load
    assert worst < 1e-4, worst
    hg = 20e-6 * GAMMA
    y_z = pr.y0.copy()
    y = y_z.copy()
    k_i = _implicit(pr, y, hg)
    assert np.max(np.abs(y - y_z - hg * k_i)) < TOL_V  # 1.1e-12 measured


def test_an_onset_step_a_few_ulps_long_crosses_a_contact_change(settled):
    """dp5's contact-onset control accepts a contact change in a step at most the onset step long, to
    ONSET_TOL (1e-9, the relative tolerance cvode.py counts long onset steps with): the step that crosses a
    located change is the change's time plus half an onset step, minus t, a few ulps off the onset step, and
    34 % of those crossings were refused for that (planar, 100 ms settled). Half a percent longer is refused.
    ``sig + 1`` stands for the signature before the step (a contact changed in it)."""
    from cageless.simulation.integrators.dp5 import ONSET_TOL, _controls
    from cageless.simulation.kernels import model_signature

    pr, _ = settled
    y, h_onset = pr.y0.copy(), pr.onset_step
    sig = model_signature(pr.model_id, y, pr.params)
    zero = np.zeros_like(y)
    assert ONSET_TOL == 1e-9
    for h, verdict in ((h_onset * (1 + 1e-12), 3), (h_onset * (1 - 1e-12), 3), (h_onset * 1.005, 1)):
        assert _controls(pr.model_id, y, pr.params, sig + 1.0, h, h_onset, zero, zero, zero, 0.5) == (verdict, (
            sig if verdict == 3 else sig + 1.0))


def test_toward_change_crosses_at_the_onset_step():
    """The trial step towards a contact change located at ``t_cross`` (by hand, onset step 1 us): within an onset
    step of it (to ONSET_TOL) the onset step itself, exactly (a retry ends half an onset step before the change,
    and t_cross - t then comes out a few ulps off), else a step ending half an onset step before it, never below
    the onset step; the proposal when none lies ahead or it is shorter."""
    from cageless.simulation.integrators.ark import _toward_change

    t, ho = 1.2345e-2, 1e-6
    assert _toward_change(t, 50e-6, t + 0.5 * ho, ho) == ho
    assert _toward_change(t, 50e-6, t + ho * (1 + 1e-12), ho) == ho
    assert _toward_change(t, 50e-6, t + 3 * ho, ho) == pytest.approx(2.5 * ho, rel=1e-9)
    assert _toward_change(t, 50e-6, t + 1.2 * ho, ho) == ho
    assert _toward_change(t, 0.3 * ho, t + 0.5 * ho, ho) == 0.3 * ho
    assert _toward_change(t, 50e-6, -np.inf, ho) == 50e-6
    assert _toward_change(t, 50e-6, t - ho, ho) == 50e-6


def _outer_gap_closing(pr, frac, h):
    """(y, ynew, f): ball 0's radius moved linearly over a step of length h so that its outer race gap closes at
    ``frac`` of the step (from 1 nm open), nothing else moving; f the constant rate, for the Hermite interpolant."""
    from cageless.simulation.kernels import model_gaps

    z = pr.n_balls
    g = np.zeros(3 * z)
    y = pr.y0.copy()
    model_gaps(pr.model_id, y, pr.params, g)
    y[0] -= g[0] + 1e-9  # the outer overlap is r + d/2 - D_o/2: now -1 nm
    ynew = y.copy()
    ynew[0] += 1e-9 / frac
    f = np.zeros_like(y)
    f[0] = (ynew[0] - y[0]) / h
    g0, g1 = np.zeros(3 * z), np.zeros(3 * z)
    model_gaps(pr.model_id, y, pr.params, g0)
    model_gaps(pr.model_id, ynew, pr.params, g1)
    assert np.flatnonzero((g0 > 0) != (g1 > 0)).tolist() == [0]  # only that contact changes
    return y, ynew, f


def test_a_located_contact_change_is_kept(settled):
    """A change the onset retry locates within 1.5 onset steps of the step's start stays located (its time, the
    gap being linear in time here: t + frac h), and a change located before survives a retry that locates none
    and a refusal by the error test without a contact change; it was -inf (forgotten) on those paths, and
    predicted again from the retry."""
    from cageless.simulation.integrators.ark import _onset_retry, _refused_across
    from cageless.simulation.kernels import model_signature

    pr, _ = settled
    ho = pr.onset_step
    h, t, n = 10 * ho, 0.01, 3 * pr.n_balls
    scratch = [np.zeros(n), np.zeros(n), np.zeros_like(pr.y0)]
    y, ynew, f = _outer_gap_closing(pr, 0.1, h)
    h_retry, t_cross = _onset_retry(pr.model_id, pr.params, t, h, y, ynew, f, f, ho, -np.inf, *scratch)
    assert h_retry == ho and t_cross == pytest.approx(t + 0.1 * h, abs=1e-6 * ho)
    y, ynew, f = _outer_gap_closing(pr, 0.5, h)
    h_retry, t_cross = _onset_retry(pr.model_id, pr.params, t, h, y, ynew, f, f, ho, -np.inf, *scratch)
    assert h_retry == pytest.approx(0.5 * h - 0.5 * ho) and t_cross == pytest.approx(t + 0.5 * h, abs=1e-6 * ho)
    assert _onset_retry(pr.model_id, pr.params, t, h, y, y, f * 0, f * 0, ho, t + 7 * ho, *scratch) == (ho, t + 7 * ho)
    sig = model_signature(pr.model_id, y, pr.params)
    cnt = np.zeros(8, dtype=np.int64)
    assert _refused_across(pr.model_id, pr.params, t, h, y, y, f, f, 0.6 * h, ho, sig, t + 7 * ho, *scratch, 2.0,
                           cnt) == (0.6 * h, t + 7 * ho)
    assert cnt[4] == 0


def test_onset_ahead_stops_predicting_after_passed_predictions(settled):
    """A predicted contact change (the Euler predictor's gap closing at 0.1 of a 10-onset-step step: within 2.5
    onset steps, so the onset step crosses it) is located; after AHEAD_MISSES predictions in a row were passed
    without a change, none is (a grazing gap would hold the loop at onset steps), until a step predicts none or a
    change is accepted (:func:`_passed`)."""
    from cageless.simulation.integrators.ark import AHEAD_MISSES, _onset_ahead, _passed

    pr, _ = settled
    ho = pr.onset_step
    h, t, n = 10 * ho, 0.01, 3 * pr.n_balls
    scratch = [np.zeros(n), np.zeros(n), np.zeros_like(pr.y0)]
    y, _, f = _outer_gap_closing(pr, 0.1, h)
    assert AHEAD_MISSES == 2
    h_ahead, t_cross, misses = _onset_ahead(pr.model_id, pr.params, t, h, y, f, ho, -np.inf, 1, *scratch)
    assert h_ahead == ho and t_cross == pytest.approx(t + 0.1 * h) and misses == 1
    assert _onset_ahead(pr.model_id, pr.params, t, h, y, f, ho, -np.inf, AHEAD_MISSES, *scratch) == (h, -np.inf, 2)
    assert _onset_ahead(pr.model_id, pr.params, t, h, y, f * 0, ho, -np.inf, AHEAD_MISSES, *scratch) == (h, -np.inf, 0)
    cnt = np.zeros(8, dtype=np.int64)
    assert _passed(1, 0, t, ho, t + 0.5 * ho, cnt) == 2  # passed the predicted change without one
    assert _passed(1, 0, t, ho, t + 2 * ho, cnt) == 1  # not yet there
    assert _passed(2, 3, t, ho, t + 0.5 * ho, cnt) == 0 and cnt[5] == 1  # a change accepted


def test_ark4_caps_its_steps_on_a_bearing_by_default(settled):
    """Without ``max_step``, ark4 on a problem with contacts steps at most ARK_MAX_STEP_S (50 us), as ``auto``
    runs it: uncapped it was 0.0156 pp off the tight reference (DP5, rtol 1e-10, 0.25 us) over the settled 20 ms
    planar window at 3000 rpm, 500 N, past the 0.01 pp bar, and 0.0031 pp capped (docs/imex.md, the eighth
    step). A problem without contacts stays uncapped (test_stiff_damping_does_not_limit_the_step)."""
    from cageless.simulation.solve import ARK_MAX_STEP_S

    pr, _ = settled
    t = np.linspace(0.0, 1e-3, 5)[1:]
    default = solve(pr, t, method="ark4")
    capped = solve(pr, t, method="ark4", max_step=ARK_MAX_STEP_S)
    assert ARK_MAX_STEP_S == 5e-5
    assert default.n_steps == capped.n_steps and np.array_equal(default.y, capped.y)
    assert solve(pr, t, method="ark4", max_step=1.0).n_steps < default.n_steps
