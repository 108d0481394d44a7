"""The spatial level: it reduces to the planar model under pure radial load, and carries axial load.

* Equivalence (DESIGN §6, simulator issue II): on pure radial scenes the spatial model reproduces the
  planar right-hand side to round-off, and its slip profile within 0.2 percentage points, with no axial
  drift and off-axis spin at round-off.
* Axial load: the ring moves along the load, the contact angle opens, and in the settled state the axial
  components of the inner contact forces carry the load (static equilibrium, Harris & Kotzalas, Essential
  Concepts of Bearing Technology, 5th ed., sect. 7.2: F_a = sum Q_j sin(alpha_j)).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from cageless.conditions import OperatingConditions
from cageless.profiles import angle_profile
from cageless.simulation.effects import choose_model
from cageless.simulation.models import planar as P
from cageless.simulation.models import spatial as S
from cageless.simulation.run import build_problem, energy_balance, initial_state, peak_unloaded_slip, simulate
from cageless.simulation.parameters import ModelParameters
from cageless.simulation.scene import Scene
from cageless.simulation.solve import solve

SETTLE_S = 0.04
#: The start-up of a pure radial run at 3000 rpm (cageless.kinematics.startup_duration: three cage revolutions).
RADIAL_SETTLE_S = 0.151


@pytest.mark.parametrize("strips", [1, 5])
def test_spatial_rhs_reduces_to_the_planar_one(strips):
    scene = Scene(conditions=OperatingConditions(3000.0, 500.0))
    choice = choose_model(scene)
    th, r, ring = initial_state(scene)
    eff = {e.name: e.on for e in choice.effects}
    kw = {"inner_speed_rad_s": scene.conditions.speed_rad_s, "effects": eff}
    flat = P.planar_problem(scene.bearing, th, r, ring, 500.0, **kw)
    full = S.spatial_problem(scene.bearing, th, r, ring, 500.0, strips=strips, **kw)
    rng = np.random.default_rng(1)
    z = 14
    for _ in range(3):
        y = flat.y0.copy()
        y[:z] += rng.normal(0, 2e-6, z)  # off the exact zero-overlap ties of the zero-clearance start
        y[2 * z:3 * z] = rng.normal(0, 1e-3, z)
        y[3 * z:4 * z] = 120 + rng.normal(0, 3, z)
        y[4 * z:5 * z] = -560 + rng.normal(0, 20, z)
        ys = np.zeros(full.y0.shape)
        ys[: 5 * z + 6] = y
        a, b = flat.rhs(0.0, y), full.rhs(0.0, ys)
        np.testing.assert_allclose(b[: 5 * z + 6], a, rtol=1e-9, atol=1e-6)
        assert np.max(np.abs(b[5 * z + 6:])) < 1e-9  # round-off (exactly 0 with one strip)


def _profile(trace):
    keep = (trace.time >= SETTLE_S)[:, None] & trace.valid
    return angle_profile(trace.angle, trace.slip, 1.0, valid=keep)["mean"].to_numpy()


@pytest.mark.parametrize("rpm,duration", [pytest.param(1800, 0.65, marks=pytest.mark.slow), (3000, 0.15), (6000, 0.1)])
def test_spatial_matches_planar_under_pure_radial_load(rpm, duration):
    """Measured: RMS 0.03 / 0.03 / 0.002 pp and peak differences 0.04 / 0.009 / 0.001 pp at 1800 / 3000 /
    6000 rpm. 1800 rpm is chaotic: the two models part at round-off within 2 ms of the start, so only
    statistics compare, and they need the longer run (over 0.22 s the RMS is 0.08-0.22 pp depending on
    round-off; over 0.65 s it is 0.03 pp, against 0.05 pp between two planar runs at rtol 1e-6 and 1e-7).
    With the rolling losses and drag on (issue 16) 3000 rpm turns chaotic as well, and its statistics wander:
    two planar runs at rtol 1e-6 and 1e-7 differ by 0.25 pp RMS over 0.15 s and 1.2 pp over 0.4 s, so no run
    length compares them within 0.2 pp. At 1800 and 3000 rpm this test therefore runs without those two effects (the
    right-hand sides, with every default effect on, agree to 1e-9: the test above); 6000 rpm keeps them. The
    traction by film regime does the same at 3000 rpm (0.23 pp RMS over 0.15 s with it on, measured), so it is
    off with them below 6000 rpm. At 1800 rpm the peak of the unloaded zone is one draw of a chaotic statistic
    (measured: planar 5.36 %, spatial 5.12 %, 0.25 pp apart over 0.65 s), so it is held within the 0.2 pp bar
    or twice the per-bin rms change that a second planar seed makes in that zone, as the hard cases' tolerance
    check does (tests/validation/test_hard_cases.py)."""
    scene = Scene(conditions=OperatingConditions(rpm, 500.0), duration_s=duration)
    off = {"rolling_losses": False, "drag": False, "film_traction": False} if rpm < 6000 else {}
    flat = simulate(scene, choose_model(scene, effects=off, force=True), progress=False).trace
    full = simulate(scene, choose_model(scene, level="spatial", effects=off, force=True), progress=False).trace
    d = 100 * np.abs(_profile(flat) - _profile(full))
    assert np.sqrt(np.nanmean(d**2)) < 0.2
    peak = abs(100 * (np.nanmax(_profile(flat)[:180]) - np.nanmax(_profile(full)[:180])))
    bound = 0.2
    if rpm < 3000:  # chaotic: a peak is one draw of a statistic; a second planar seed measures its spread
        seeded = simulate(replace(scene, seed=1), choose_model(scene, effects=off, force=True), progress=False).trace
        bound = max(bound, 2.0 * 100 * np.sqrt(np.nanmean((_profile(seeded) - _profile(flat))[:180] ** 2)))
    assert peak < bound, (peak, bound)
    balls = full.groups["balls"]
    assert np.nanmax(np.abs(balls["axial"])) < 1e-9  # no axial drift
    assert np.nanmax(np.abs(balls["spin"][:, :, 1:])) < 1e-2  # off-axis spin at round-off (rad/s)
    assert np.nanmax(np.abs(full.groups["contacts"]["inner_angle"])) < 1e-6
    assert np.nanmax(np.abs(full.groups["inner_ring"]["tilt"])) < 1e-9  # no moment, no tilt


def test_axial_load_is_carried_by_contact_angles():
    scene = Scene(conditions=OperatingConditions(3000.0, 500.0, 400.0), duration_s=0.06)
    choice = choose_model(scene)
    assert choice.level == "spatial"
    res = simulate(scene, choice, progress=False)
    tr = res.trace
    assert tr.status == "complete"
    ring_x = tr.groups["inner_ring"]["position"][:, 0]
    assert ring_x[-1] > 20e-6  # pushed along +x by the load
    c = tr.groups["contacts"]
    late = tr.time > 0.04
    carried = np.sum(c["inner_normal"][late] * np.sin(np.abs(c["inner_angle"][late])), axis=1)
    assert carried.mean() == pytest.approx(400.0, rel=0.05)
    alpha = tr.config["nominal_contact_angle_rad"]
    assert 0.1 < alpha < 0.3  # about 10 degrees here; the slip rate uses it (DESIGN §3)


def test_spatial_energy_balance_with_axial_load_and_strips():
    scene = Scene(conditions=OperatingConditions(3000.0, 500.0, 400.0))
    pr = build_problem(scene, choose_model(scene), ModelParameters(strips=5))
    sol = solve(pr, np.linspace(0, 2e-3, 21), rtol=1e-10, max_step=5e-7)
    assert sol.success
    energy = energy_balance(pr, sol.y)
    assert energy.input_work[-1] > 1e-4
    assert energy.drift < 1e-6 * max(energy.input_work[-1], energy.dissipated[-1])


@pytest.fixture(scope="module")
def combined():
    """3000 rpm, 500 N radial, with 300 N and 500 N axial load (spatial, 0.1 s), and without (planar, 0.25 s:
    without axial load the packed balls take three cage revolutions, 0.15 s, to spread; see RADIAL_SETTLE_S)."""
    runs = {}
    for fa, duration in ((0.0, RADIAL_SETTLE_S + 0.1), (300.0, 0.1), (500.0, 0.1)):
        scene = Scene(conditions=OperatingConditions(3000.0, 500.0, fa), duration_s=duration)
        runs[fa] = simulate(scene, choose_model(scene), progress=False).trace
    return runs


def test_contact_angle_swing_shrinks_with_axial_load(combined):
    """The paper's figure 13 trend (Wang et al. 2026, §3): the contact point's trajectory on the raceway swings
    less as the axial load grows. Measured over 150 ms after a 150 ms start-up (3000 rpm, 500 N radial), the
    swing being the 1-99 % spread of the loaded inner contact angles: 10.0 deg at 300 N, 9.2 at 400 N, 8.6 at
    500 N. The free tilt of the ring (1-2 mrad under these loads) makes the angle vary around the orbit;
    with the tilt held at 0 the swing was 0.42 / 0.35 / 0.31 deg."""
    swing = {}
    for fa in (300.0, 500.0):
        tr = combined[fa]
        c = tr.groups["contacts"]
        late = tr.time > SETTLE_S
        angle = np.abs(c["inner_angle"][late])[c["inner_normal"][late] > 1.0]
        swing[fa] = angle.max() - angle.min()
    assert swing[500.0] < 0.9 * swing[300.0]


def test_combined_load_turns_impacts_into_rubbing_and_spin(combined):
    """The paper (Wang et al. 2026, §3 and conclusion 2): under pure radial load the ball-ball contact force is
    dominated by impacts; under combined load the contacts become sustained friction (rubbing), and the spin
    about the off-axes (omega_y, omega_z: spin and gyroscopic motion) grows with the axial load.
    Measured (3000 rpm, 500 N radial, after the start-up): 0 N axial: impacts only, off-axis spin 0;
    300 N: rubbing only, off-axis spin RMS 141 rad/s; 500 N: rubbing only, 158 rad/s (100 ms after a 150 ms
    start-up, with the ring free to tilt).
    With the paper's nominal zero clearance (its Table 1) every ball is loaded once the axial load seats it,
    slip is ~0 (-0.01 %) at 300-500 N and rubbing does not grow; with a clearance the paper's trends appear
    (test_with_clearance_slip_falls_and_rubbing_takes_over_as_axial_load_grows)."""
    def kinds(tr, settle=SETTLE_S):
        ev = tr.events[tr.events.time > settle]
        return int((ev.kind == "impact").sum()), int((ev.kind == "rubbing").sum())

    impacts, rubbing = kinds(combined[0.0], RADIAL_SETTLE_S)
    assert impacts > 5 and impacts > 3 * rubbing
    spin = {}
    for fa in (300.0, 500.0):
        impacts, rubbing = kinds(combined[fa])
        assert rubbing >= 3 and rubbing > 3 * impacts, fa  # episodes last ~20 ms: few fit in 60 ms
        sp = combined[fa].groups["balls"]["spin"][combined[fa].time > SETTLE_S]
        spin[fa] = np.sqrt(np.mean(sp[..., 1] ** 2 + sp[..., 2] ** 2))
    assert 20.0 < spin[300.0] < spin[500.0]


#: Diametral clearance of the clearance study (m): inside ISO 5753-1 group C4 for deep-groove ball bearings
#: of bore over 24 up to 30 mm (23-41 um; the table is reproduced e.g. at
#: http://en.shjfbearing.com/news/eventsPage/2525). The paper's Table 1 races give zero clearance, but its
#: section 4 says the test bearing ran with a large clearance.
C4_CLEARANCE_M = 40e-6


@pytest.fixture(scope="module")
def clearance_runs():
    """3000 rpm, 500 N radial, 300 and 500 N axial, with the C4 clearance: 150 ms start-up plus 150 ms."""
    from dataclasses import replace

    from cageless.bearing import default_bearing

    b = default_bearing()
    b = replace(b, geometry=b.geometry.with_diametral_clearance(C4_CLEARANCE_M))
    return {fa: simulate(Scene(bearing=b, conditions=OperatingConditions(3000.0, 500.0, fa), duration_s=0.3),
                         choose_model(Scene(bearing=b, conditions=OperatingConditions(3000.0, 500.0, fa))),
                         progress=False).trace for fa in (300.0, 500.0)}


def test_with_clearance_slip_falls_and_rubbing_takes_over_as_axial_load_grows(clearance_runs):
    """The paper's combined-load trends (Wang et al. 2026, §3, figures 11c, 12, 13): slip falls as the axial load
    grows from 300 to 500 N, continuous rubbing takes over from impacts, the contact trajectory swings less,
    and at 300 N collisions stay out of the loaded zone. With a 40 um (C4) clearance the top balls are unloaded at
    300 N, so these appear. Measured over 150 ms after 150 ms (3000 rpm, 500 N radial, seed 0, 2026-11-27):
    peak slip in the unloaded zone 4.26 % at 300 N, 1.91 % at 400 N, 0.81 % at 500 N; 31 impacts and no
    rubbing at 300 N, 116 impacts and 26 rubbing episodes (mean 2.8 ms) at 400 N, 27 impacts and 51 rubbing
    episodes (mean 4.1 ms) at 500 N; swing of the inner contact angle 23.0, 21.5, 20.1 deg; the 500 N
    impacts at 208-283 deg (the load at 270 deg), the 300 N ones outside 240-300 deg. So contacts are
    more likely to be rubbing (0 % -> 65 % of episodes) and rubbing lasts longer."""
    late = {fa: tr.time > 0.15 for fa, tr in clearance_runs.items()}
    peak = {fa: peak_unloaded_slip(tr, 0.15) for fa, tr in clearance_runs.items()}
    assert peak[300.0] > 0.005 and peak[500.0] < 0.5 * peak[300.0]
    events = {fa: tr.events[tr.events.time > 0.15] for fa, tr in clearance_runs.items()}
    share = {fa: float((ev.kind == "rubbing").mean()) for fa, ev in events.items()}
    assert (events[300.0].kind == "impact").sum() >= 5 and share[500.0] > share[300.0]
    # mean rubbing episode (0 where there is none: with the traction by film regime, 300 N rubs no more after
    # the start-up, 500 N for 4.1 ms on average, measured)
    length = {fa: float(ev.duration[ev.kind == "rubbing"].mean()) if (ev.kind == "rubbing").any() else 0.0
              for fa, ev in events.items()}
    assert length[500.0] > length[300.0]  # seed 0: none at 300 N, 4.1 ms at 500 N
    impact_deg = np.degrees(events[300.0].angle[events[300.0].kind == "impact"].to_numpy()) % 360
    assert not np.any((impact_deg > 240) & (impact_deg < 300))
    swing = {}
    for fa, tr in clearance_runs.items():
        c = tr.groups["contacts"]
        angle = np.abs(c["inner_angle"][late[fa]])[c["inner_normal"][late[fa]] > 1.0]
        swing[fa] = angle.max() - angle.min()
    assert swing[500.0] < 0.95 * swing[300.0]


HARD = {"axial-only": ((3000.0, 0.0, 500.0), {}), "2000N-axial": ((3000.0, 500.0, 2000.0), {}),
        "1mrad-tilt": ((3000.0, 500.0, 0.0), {"misalignment_rad": 1e-3})}


@pytest.mark.parametrize("name", list(HARD))
def test_spatial_hard_cases_are_stable(name):
    """The spatial hard cases of the simulator II issue, with the planar hard cases' criteria
    (tests/validation/test_hard_cases.py): finite states, overlaps below 0.5 % of D, the energy balance to
    1e-5 of the input work (measured 2e-8 to 1.2e-7), < 10 % rejected steps and no stalled stepping."""
    loads, extra = HARD[name]
    scene = Scene(conditions=OperatingConditions(*loads), duration_s=0.02, **extra)
    choice = choose_model(scene)
    assert choice.level == "spatial"
    res = simulate(scene, choice, progress=False)
    sol = res.solution
    assert sol.success and np.all(np.isfinite(sol.y))
    assert sol.n_rejected < 0.2 * sol.n_steps
    assert scene.duration_s / sol.n_steps > res.problem.onset_step / 20
    k_i, d = res.problem.parameter("KI"), res.problem.parameter("D")
    c = res.trace.groups["contacts"]
    assert (np.nanmax(c["inner_normal"]) / k_i) ** (2 / 3) < 0.005 * d  # overlap below 0.5 % of D
    energy = energy_balance(res.problem, sol.y)
    assert energy.drift < 1e-5 * energy.input_work[-1]


@pytest.mark.slow
@pytest.mark.parametrize("name", list(HARD))
def test_spatial_hard_case_statistics_converge(name):
    """rtol 1e-6 -> 1e-7 with the largest step halved: the mean |change| of the 1-degree slip profile over
    0.04-0.14 s and of the median loaded contact angle stay below 0.5 pp and 0.05 deg (DESIGN §7)."""
    loads, extra = HARD[name]
    scene = Scene(conditions=OperatingConditions(*loads), duration_s=0.14, **extra)
    profiles, angles = [], []
    for rtol, max_step in ((1e-6, None), (1e-7, 1e-6)):  # default caps (2 us; CVODE 5 us), then at most half
        tr = simulate(scene, choose_model(scene), rtol=rtol, max_step=max_step, progress=False).trace
        profiles.append(_profile(tr))
        c = tr.groups["contacts"]
        late = tr.time > SETTLE_S
        angles.append(np.degrees(np.median(np.abs(c["inner_angle"][late])[c["inner_normal"][late] > 1.0])))
    assert 100 * np.nanmean(np.abs(profiles[0] - profiles[1])) < 0.5
    assert abs(angles[0] - angles[1]) < 0.05


def test_a_moment_load_tilts_the_ring_until_the_contacts_balance_it():
    """Free tilt of the inner ring (the paper's I_r theta_ry'' = sum M_y, §3.1) under a moment load about y:
    after 30 ms the mean moment of the inner contact forces (elastic normal part, from the trace's contact
    points) about the ring centre balances the load (measured to 0.4 % at 2, 5 and 10 N m), the tilt grows
    with the load (2.4, 3.0, 3.7 mrad: the clearance gives the first mrad freely), and the energy balance
    closes with the tilt's kinetic energy and the load's work (measured 1.4e-7 of the input work)."""
    tilts = []
    for moment in (2.0, 10.0):
        scene = Scene(conditions=OperatingConditions(3000.0, 500.0, 0.0), duration_s=0.05, moment_load_nm=moment)
        choice = choose_model(scene)
        assert choice.level == "spatial"
        res = simulate(scene, choice, progress=False)
        tr, y = res.trace, res.solution.y
        c, balls = tr.groups["contacts"], tr.groups["balls"]
        centre = np.stack([balls["axial"], balls["radius"] * np.cos(tr.angle), balls["radius"] * np.sin(tr.angle)], -1)
        normal = c["inner_point"] - centre
        normal /= np.linalg.norm(normal, axis=-1, keepdims=True)
        arm = c["inner_point"] - tr.groups["inner_ring"]["position"][:, None, :]
        moment_y = np.sum(np.cross(arm, c["inner_normal"][..., None] * normal), axis=1)[:, 1]
        late = tr.time > 0.03
        assert moment_y[late].mean() == pytest.approx(-moment, rel=0.02)
        tilts.append(tr.groups["inner_ring"]["tilt"][late, 0].mean())
        energy = energy_balance(res.problem, y)
        assert energy.drift < 1e-5 * energy.input_work[-1]
    assert 0 < tilts[0] < tilts[1] < 0.01


def test_a_vertical_shaft_carries_the_ring_weight_axially():
    """Vertical shaft, no load: gravity acts along the shaft, so the ring's weight (2.06 kg x 9.81 = 20.2 N) is
    an axial load the contact angles must carry (measured 19.96 N over 30-50 ms); the planar level cannot
    carry it and is refused."""
    from cageless.errors import UsageError

    scene = Scene(conditions=OperatingConditions(3000.0, 0.0, 0.0), duration_s=0.05, orientation="vertical")
    choice = choose_model(scene)
    assert choice.level == "spatial"
    res = simulate(scene, choice, progress=False)
    tr, y = res.trace, res.solution.y
    weight = scene.bearing.masses.ring_translational_mass_kg * scene.gravity_m_s2
    c = tr.groups["contacts"]
    late = tr.time > 0.03
    carried = np.sum(c["inner_normal"][late] * np.sin(np.abs(c["inner_angle"][late])), axis=1)
    assert carried.mean() == pytest.approx(weight, rel=0.03)
    assert tr.groups["inner_ring"]["position"][-1, 0] < -5e-6  # the ring sinks along -x
    energy = energy_balance(res.problem, y)
    assert energy.drift < 1e-5 * energy.input_work[-1]
    with pytest.raises(UsageError, match="vertical shaft"):
        simulate(scene, choose_model(scene, level="planar", force=True), progress=False)
