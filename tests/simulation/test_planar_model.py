"""The planar model's conservative core: energy conservation, convergence, and contact overlaps.

DESIGN §7: "With damping and friction off, energy is conserved to the integrator tolerance." The run
starts the 2.06 kg ring 2 um below the centre under a 500 N radial load (its static displacement is
about 6 um), so ring and balls oscillate through the loaded zone and neighbouring balls touch.
"""

from __future__ import annotations

import numpy as np
import pytest

from cageless.bearing import default_bearing
from cageless.simulation.models.planar import PlanarLayout, packed_start, planar_energy, planar_problem
from cageless.simulation.quasistatic import radial_load_distribution
from cageless.simulation.solve import solve

B = default_bearing()
G = B.geometry
T = np.linspace(0, 5e-3, 501)
#: The contacts, gravity and the race damping: the effects these tests build on (the low-level builder turns on
#: only the effects it is given).
CORE = {"race_contact": True, "ball_ball_contact": True, "gravity": True, "lubricant_damping": True}


def _on(**effects: bool) -> dict[str, bool]:
    return {**CORE, **effects}


def _run(rtol: float, restitution: float = 1.0, **kw):
    th = packed_start(B, seed=1)
    kw.setdefault("effects", _on(lubricant_damping=False))
    pr = planar_problem(B, th, np.full(G.n_balls, 0.5 * G.pitch_diameter_m), (0.0, -2e-6), 500.0,
                        restitution=restitution, atol_scale=1e-4, **kw)
    sol = solve(pr, T, rtol=rtol)
    assert sol.success, sol.message
    return pr, sol


def test_energy_is_conserved_to_the_tolerance():
    drifts = []
    for rtol in (1e-6, 1e-8, 1e-10):
        pr, sol = _run(rtol)
        e = planar_energy(pr, sol.y)
        drifts.append(e.max() - e.min())
    work_scale = 500.0 * 6e-6  # load x static displacement (J)
    assert drifts[1] < drifts[0] / 30 and drifts[2] < drifts[1] / 5
    assert drifts[2] / work_scale < 1e-7


def test_no_interpenetration_beyond_the_hertz_scale():
    pr, sol = _run(1e-8)
    z = G.n_balls
    y = sol.y
    assert np.all(np.isfinite(y))
    static = radial_load_distribution(G, B.material, 500.0, packed_start(B, seed=1)).displacement_m
    outer = np.clip(y[:, :z] + 0.5 * G.ball_diameter_m - 0.5 * G.outer_race_diameter_m, 0, None)
    assert outer.max() < 3 * static  # starting 4 um off equilibrium overshoots about 2x, never more
    x, zz = y[:, :z] * np.cos(y[:, z:2 * z]), y[:, :z] * np.sin(y[:, z:2 * z])
    gap = np.hypot(np.roll(x, -1, axis=1) - x, np.roll(zz, -1, axis=1) - zz)
    assert (G.ball_diameter_m - gap).max() < 3 * static  # neighbours touch, at most micrometres deep
    th = y[:, z:2 * z]
    assert np.all(np.diff(th, axis=1) > 0)  # the cyclic order holds


def test_energy_balance_closes_with_damping():
    """Lubricant damping at the races (C_ho = 5000 N s/m) and ball-ball damping (R = 0.5): mechanical
    energy falls, and mechanical energy plus the dissipated energy stays constant to the tolerance."""
    pr, sol = _run(1e-10, restitution=0.5, effects=_on(lubricant_damping=True))
    e = planar_energy(pr, sol.y)
    dissipated = sol.y[:, -1]
    assert dissipated[-1] > 0.2 * (e[0] - e.min())  # the damping takes a real share of the motion
    assert e[-1] < e[0]
    balance = e + dissipated
    assert (balance.max() - balance.min()) / (500.0 * 6e-6) < 1e-6
    assert np.all(np.diff(dissipated) >= -1e-15)  # dissipation never runs backwards


def test_layout():
    lay = PlanarLayout(14)
    assert lay.size == 76
    assert lay.slices()["ring"] == slice(70, 74)
    angles = packed_start(B, seed=3)
    phi = 2 * np.arcsin(G.ball_diameter_m / G.pitch_diameter_m)
    assert np.all(np.diff(angles) >= phi) and angles.mean() == pytest.approx(1.5 * np.pi, abs=0.2)


ALL_ON = _on(race_traction=True, ehl_film=True, ball_ball_film=True, drag=True)


@pytest.mark.parametrize("effects", [CORE, ALL_ON], ids=["core", "all-effects"])
def test_compiled_and_numpy_right_hand_sides_agree(effects):
    """The compiled RHS against the plain-numpy reference, on perturbed states with contacts and motion."""
    from cageless.simulation.models.planar_reference import reference_rhs

    rng = np.random.default_rng(5)
    th = packed_start(B, seed=2, spread=0.0)  # neighbours exactly touching
    pr = planar_problem(B, th, np.full(G.n_balls, 0.5 * G.pitch_diameter_m), (1e-6, -4e-6), 500.0,
                        restitution=0.6, effects=effects, inner_speed_rad_s=300.0, speed_ramp_s=1e-3,
                        oil_air_density_kg_m3=20.0)
    z = G.n_balls
    for _ in range(5):
        y = pr.y0.copy()
        y[:z] += rng.normal(0, 2e-6, z)
        y[z:2 * z] -= np.linspace(0, 1e-4, z)  # squeeze neighbours a little
        y[2 * z:3 * z] = rng.normal(0, 1e-2, z)
        y[3 * z:4 * z] = rng.normal(100.0, 5.0, z)
        y[4 * z:5 * z] = rng.normal(-500.0, 50.0, z)
        y[5 * z + 2:5 * z + 4] = rng.normal(0, 1e-3, 2)
        aux_fast, aux_ref = pr.log.copy(), pr.log.copy()
        fast = pr.rhs(4e-4, y, aux_fast)
        ref = reference_rhs(4e-4, y, pr.params, aux_ref)
        # the compiled kernels reassociate sums (simulation.forces.FASTMATH): an acceleration that is the small
        # sum of contact terms up to ~1e5 m/s^2 differs at their round-off, ~1e-11 of them. A pair inside one of
        # the squeeze film's hand-over bands (simulation.forces.squeeze_film, half-width b = h0 / 6 = 37.5 nm)
        # turns the round-off of its gap, d - |P_k - P_j| (~1e-18 m, computed by hypot here and by a fused
        # sqrt there), into ~1.5 / (2 b) x 1e-18 = 2e-11 of its film force of a few N: ~1e-10 N, ~1e-6 m/s^2 on
        # the ball's angular acceleration (measured 1.05e-6 on one of these states)
        np.testing.assert_allclose(fast, ref, rtol=1e-10, atol=1e-8 if effects is CORE else 1e-5)
        np.testing.assert_allclose(aux_fast[:z], aux_ref[:z], rtol=1e-12)



def test_dry_stribeck_right_hand_sides_agree():
    """A dry bearing with the Coulomb-Stribeck law (static 0.15, Coulomb 0.1, v_s 0.01 m/s): the compiled
    RHS against the plain-numpy reference on states whose contacts slide slower and faster than v_s."""
    from dataclasses import replace

    from cageless.simulation.models.planar_reference import reference_rhs
    from cageless.simulation.parameters import ModelParameters

    rng = np.random.default_rng(7)
    dry = replace(B, lubricant=None)
    par = ModelParameters(dry_friction_coefficient=0.1, dry_static_coefficient=0.15)
    th = packed_start(dry, seed=2, spread=0.0)
    pr = planar_problem(dry, th, np.full(G.n_balls, 0.5 * G.pitch_diameter_m), (1e-6, -4e-6), 500.0,
                        effects=_on(lubricant_damping=False, race_traction=True, dry_friction=True), inner_speed_rad_s=300.0,
                        parameters=par)
    z = G.n_balls
    for _ in range(5):
        y = pr.y0.copy()
        y[:z] += rng.normal(0, 2e-6, z)
        y[3 * z:4 * z] = rng.normal(100.0, 5.0, z)
        # spins that put the ball surfaces within a few v_s of rolling and far from it
        y[4 * z:5 * z] = rng.normal(-0.5 * G.pitch_diameter_m * 100.0 / (0.5 * G.ball_diameter_m), 30.0, z)
        aux_fast, aux_ref = pr.log.copy(), pr.log.copy()
        np.testing.assert_allclose(pr.rhs(4e-4, y, aux_fast), reference_rhs(4e-4, y, pr.params, aux_ref),
                                   rtol=1e-10, atol=1e-8)


def _coasting_ball(v: float, **kw):
    """Ball 3 coasting at ``v`` onto its resting neighbour (no gravity, no load); the problem and a time just
    past the first contact."""
    z = G.n_balls
    th = packed_start(B, seed=4, spread=0.6)
    r0 = np.full(z, 0.5 * G.pitch_diameter_m)
    thd = np.zeros(z)
    thd[3] = v / r0[3]
    pr = planar_problem(B, th, r0, (0.0, 0.0), 0.0, gravity_m_s2=0.0, theta_dot0=thd, **kw)
    return pr, (th[4] - th[3] - 2 * np.arcsin(G.ball_diameter_m / G.pitch_diameter_m)) * r0[3] / v + 1e-4


def test_contact_episodes_are_logged_and_classified():
    """One ball sent at 0.3 m/s into its resting neighbour: the first logged episode is an impact on that pair,
    lasting about the Hertz impact duration (Johnson 1985, sect. 11.4) at that approach speed."""
    from cageless.simulation.models.planar import contact_events

    v = 0.3
    pr, t_end = _coasting_ball(v, restitution=0.9, effects=_on(lubricant_damping=False))
    sol = solve(pr, np.linspace(0, t_end, 11), rtol=1e-8)
    events = contact_events(pr, sol.extra["log"], t_end)
    assert len(events) >= 1
    first = events.iloc[0]
    assert first.pair == 3 and first.kind == "impact"
    k_bb = pr.parameter("KB")
    dmax = (5 * (0.5 * pr.parameter("M")) * v**2 / (4 * k_bb)) ** 0.4
    # Measured: 41 us and 48.6 N against the elastic 36.6 us and 53.6 N; a damped (R = 0.9) contact lasts a
    # little longer and peaks lower than the elastic Hertz values, hence 20 %.
    assert first.duration == pytest.approx(2.943 * dmax / v, rel=0.2)
    assert first.peak_force == pytest.approx(k_bb * dmax**1.5, rel=0.2)
    assert 0 <= first.angle < 2 * np.pi


def test_sustained_contact_is_rubbing():
    """Balls packed in contact under gravity and a radial load press on each other for the whole run."""
    from cageless.simulation.models.planar import contact_events

    th = packed_start(B, seed=1, spread=0.0)
    pr = planar_problem(B, th, np.full(G.n_balls, 0.5 * G.pitch_diameter_m), (0.0, -2e-6), 500.0,
                        restitution=0.6, effects=CORE)
    sol = solve(pr, np.linspace(0, 5e-3, 11), rtol=1e-7)
    events = contact_events(pr, sol.extra["log"], 5e-3)
    assert (events.kind == "rubbing").sum() >= 3
    assert events.duration.max() > 4e-3


def test_contact_onset_is_not_stepped_over():
    """A ball coasting 2 mm onto its neighbour with steps allowed up to 0.5 ms: the integrator rejects the step
    that closes the contact, retries it at the onset step, and the impact's peak matches a run held to small steps
    (elastic Hertz peak k (5 m v^2 / 4k)^0.6, Johnson 1985 sect. 11.4, with m the reduced mass)."""
    from dataclasses import replace

    from cageless.simulation.models.planar import contact_events

    v = 0.3
    pr, t_end = _coasting_ball(v, restitution=1.0, effects=_on(lubricant_damping=False, race_contact=False))
    peaks = {}
    for name, problem, max_step in (("controlled", pr, 5e-4), ("fine", pr, pr.onset_step / 4),
                                    ("uncontrolled", replace(pr, onset_step=0.0), 5e-4)):
        # force_jump=0 isolates the onset control (the force-jump control has its own test below)
        sol = solve(problem, np.linspace(0, t_end, 11), rtol=1e-6, max_step=max_step, force_jump=0.0)
        ev = contact_events(problem, sol.extra["log"], t_end)
        peaks[name] = ev.peak_force.iloc[0] if len(ev) else 0.0
        if name == "controlled":
            assert sol.n_onset_retries >= 1 and sol.n_contact_changes >= 2
    k_bb = pr.parameter("KB")
    v_n = v * np.cos(np.arcsin(G.ball_diameter_m / G.pitch_diameter_m))  # along the line of centres (a chord)
    elastic = k_bb * (5 * (0.5 * pr.parameter("M")) * v_n**2 / (4 * k_bb)) ** 0.6
    assert peaks["fine"] == pytest.approx(elastic, rel=0.01)
    assert peaks["controlled"] == pytest.approx(peaks["fine"], rel=0.005)
    # measured: 0.03 % off with the control, 1.8 % without it
    assert abs(peaks["controlled"] - peaks["fine"]) < abs(peaks["uncontrolled"] - peaks["fine"])


@pytest.mark.parametrize("v", [0.3, 1.0])
def test_force_jumps_are_not_stepped_over(v):
    """An elastic (R = 1) impact at a loose rtol of 1e-3 with steps allowed up to 0.5 ms: the error estimate
    alone lets the steps inside the contact grow until the impact loses energy (measured 1.8e-4 at 0.3 m/s,
    1.1e-3 at 1 m/s); the force-jump control retries the steps across which a contact force more than
    doubles, and the energy after the impact is kept (measured 5.5e-6 and 1.3e-5). An elastic Hertz impact
    conserves energy exactly (Johnson 1985, sect. 11.4)."""
    pr, t_end = _coasting_ball(v, restitution=1.0, effects=_on(lubricant_damping=False, race_contact=False))
    e0 = planar_energy(pr, pr.y0[None, :])[0]
    errors = {}
    for fj in (0.0, 0.5):
        sol = solve(pr, np.array([t_end + 2e-4]), rtol=1e-3, max_step=5e-4, force_jump=fj)
        assert sol.success
        errors[fj] = abs(planar_energy(pr, sol.y)[0] / e0 - 1)
        assert (sol.n_force_jump_retries > 0) == (fj > 0)
    assert errors[0.5] < 5e-5
    assert errors[0.5] < errors[0.0] / 3


def test_force_jump_fraction_is_checked():
    from cageless.errors import ParameterError

    pr, t_end = _coasting_ball(0.3, effects=CORE)
    with pytest.raises(ParameterError, match="force_jump"):
        solve(pr, np.array([t_end]), force_jump=float("nan"))
