"""The simulator issue's hard cases, each from the packed start over 20 ms (the fast set).

Cases (simulator issue "Stability tests: hard cases", DESIGN §7): 1800 rpm bunching; 6000 and 12000 rpm;
radial loads of 10 N and 20 kN; R = 0 and R = 0.95; no lubricant (Coulomb, and Coulomb-Stribeck); every
ball starting in contact with its neighbours; an instantaneous start at full speed (every case but ``ramped`` starts so, and
``ramped`` reaches speed in 10 ms).

Every case asserts:

* finite states to the end;
* no interpenetration beyond a few times the static Hertz deflection: every overlap stays below
  ``OVERLAP_FACTOR`` times the deflection of the most loaded outer contact under the static radial load
  (Stribeck/Sjovall distribution, :func:`cageless.simulation.quasistatic.radial_load_distribution`) plus the
  centrifugal force m (d_m/2) omega_c^2 (Harris & Kotzalas, *Essential Concepts*, 5th ed., sect. 10.2),
  and never below 2 um. Measured: 1.1-7.1 times; the largest are ball-ball impacts right after the
  instantaneous start (22 um at R = 0.95, the Hertz overlap of a ~1 m/s impact);
* the energy balance: kinetic + potential + dissipated - drive input stays constant to 1e-5 of the
  input work (DESIGN §7);
* bounded stepping: fewer than 20 % of steps rejected, and a mean step no shorter than 1/20 of the
  contact-onset step (no stalled or Zeno stepping).

Convergence of these cases is a statistic of long runs (the ball ring is chaotic: DESIGN §7), so it is
in ``test_hard_case_statistics_converge`` below, marked slow.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from cageless.bearing import default_bearing
from cageless.conditions import OperatingConditions
from cageless.kinematics import startup_duration, theoretical_cage_speed
from cageless.profiles import angle_profile
from cageless.simulation.effects import choose_model
from cageless.simulation.hertz import compliance, hertz_contact, race_curvatures
from cageless.simulation.parameters import ModelParameters
from cageless.simulation.quasistatic import radial_load_distribution
from cageless.simulation.run import energy_balance, peak_unloaded_slip, simulate
from cageless.simulation.scene import Scene

#: "a few times the static Hertz deflection"
OVERLAP_FACTOR = 8.0
#: Window of the convergence statistics after the start-up (s). At 10 N the ring is chaotic enough that a
#: 150 ms window moved the peak by 0.51 pp between the two tolerances; the statistics need longer.
STATISTICS_S = 0.3

CASES = {
    "1800rpm-bunching": (1800, 500, {}, {}),
    "6000rpm": (6000, 500, {}, {}),
    "12000rpm": (12000, 500, {}, {}),
    "10N": (3000, 10, {}, {}),
    "20kN": (3000, 20000, {}, {}),
    "R=0": (3000, 500, {"restitution": 0.0}, {}),
    "R=0.95": (3000, 500, {"restitution": 0.95}, {}),
    # no lubricant: Coulomb friction 0.1, a value given for the test (dry steel has no cited default)
    "dry": (3000, 500, {"dry_friction_coefficient": 0.1}, {"dry": True}),
    # the same with the Stribeck effect (simulation.traction.dry_friction): static 0.15 over 0.01 m/s
    "dry-stribeck": (3000, 500, {"dry_friction_coefficient": 0.1, "dry_static_coefficient": 0.15}, {"dry": True}),
    "all-in-contact": (3000, 500, {}, {"initial_gap_fraction": 0.0}),
    "ramped": (3000, 500, {}, {"speed_ramp_s": 0.01}),
}


def _scene(name: str, duration: float) -> tuple[Scene, ModelParameters]:
    rpm, load, par, extra = CASES[name]
    kw = {k: v for k, v in extra.items() if k != "dry"}
    scene = Scene(conditions=OperatingConditions(rpm, load), duration_s=duration, **kw)
    if extra.get("dry"):
        scene = replace(scene, bearing=replace(scene.bearing, lubricant=None))
    return scene, ModelParameters(**par)


def static_deflection(scene: Scene) -> float:
    """Outer-race Hertz deflection (m) of the most loaded ball: static radial load plus the ring's weight,
    plus the centrifugal force at the pure-rolling cage speed."""
    b = scene.bearing
    g = b.geometry
    load = scene.conditions.radial_load_n + b.masses.ring_translational_mass_kg * scene.gravity_m_s2
    theta = 1.5 * np.pi + 2 * np.pi * np.arange(g.n_balls) / g.n_balls
    q = radial_load_distribution(g, b.material, load, theta).max_load_n
    w_c = theoretical_cage_speed(g, scene.conditions.speed_rad_s)
    q += b.masses.ball_mass_kg * 0.5 * g.pitch_diameter_m * w_c**2
    k_o = hertz_contact(*race_curvatures(g)["outer"], compliance(b.material)).stiffness
    return float((q / k_o) ** (2 / 3))


def impact_overlap(scene: Scene, k_b: float) -> float:
    """Largest Hertz overlap (m) of two balls closing head-on at the pure-rolling orbital speed v (a ball
    driven up to it meeting one still at rest after the packed start):
    delta = (5 m_eff v^2 / (4 K))^(2/5), m_eff = m / 2 (Johnson, *Contact Mechanics*, 1985, §11.4)."""
    g = scene.bearing.geometry
    v = 0.5 * g.pitch_diameter_m * theoretical_cage_speed(g, scene.conditions.speed_rad_s)
    return float((5 * 0.5 * scene.bearing.masses.ball_mass_kg * v * v / (4 * k_b)) ** 0.4)


@pytest.mark.parametrize("level", ["auto", "spatial"])
@pytest.mark.parametrize("name", list(CASES))
def test_hard_case_is_stable(name, level):
    """Each case with the level the scene picks (planar: pure radial load) and forced to the spatial level,
    which must pass the same criteria (simulator issue II: "everything in Simulator I's hard-case list")."""
    scene, par = _scene(name, 0.02)
    choice = choose_model(scene) if level == "auto" else choose_model(scene, level=level, force=True)
    r = simulate(scene, choice, parameters=par, progress=False)
    sol, tr, pr = r.solution, r.trace, r.problem
    assert sol.success and np.all(np.isfinite(sol.y)), sol.message
    # interpenetration
    k_b, k_i, k_o = (pr.parameter(name) for name in ("KB", "KI", "KO"))
    c = tr.groups["contacts"]
    overlap = max(np.nanmax(c["inner_normal"] / k_i) ** (2 / 3), np.nanmax(c["outer_normal"] / k_o) ** (2 / 3))
    assert overlap < max(OVERLAP_FACTOR * static_deflection(scene), 2e-6), (overlap, static_deflection(scene))
    # ball-ball: the same, or the Hertz overlap of a head-on impact closing at the orbital speed, whichever
    # is larger. With the rolling losses (issue 16) balls leave the loaded zone slowed, and at 12000 rpm the
    # start-up has a 33 um impact (measured; 17 um without the losses): 4.6 m/s closing, 0.4 of the orbital speed.
    # With the traction by film regime the balls slide more while the film builds in the start-up: 35.7 um at
    # 6000 rpm (measured, planar and spatial), closing at 0.88 of the orbital speed; the bound was half of it.
    bb = np.nanmax(c["ball_ball_normal"] / k_b) ** (2 / 3)
    assert bb < max(OVERLAP_FACTOR * static_deflection(scene), 2e-6, impact_overlap(scene, k_b)), bb
    # energy balance
    energy = energy_balance(pr, sol.y)
    assert energy.input_work[-1] > 0 and energy.drift < 1e-5 * energy.input_work[-1]
    # bounded stepping
    assert sol.n_rejected < 0.2 * sol.n_steps
    assert scene.duration_s / sol.n_steps > pr.onset_step / 20


@pytest.mark.slow
@pytest.mark.parametrize("name", list(CASES))
def test_hard_case_statistics_converge(name):
    """Settled runs (start-up plus STATISTICS_S): rtol 1e-6 -> 1e-7 with the largest step halved moves the peak slip
    in the unloaded zone by < 0.5 pp and the mean |change| of the 1-degree slip profile by < 0.5 pp (DESIGN §7)."""
    g = default_bearing().geometry
    rpm = CASES[name][0]
    settle = startup_duration(rpm, g.ball_diameter_m, g.pitch_diameter_m)
    scene, par = _scene(name, settle + STATISTICS_S)
    profiles, peaks = [], []
    for rtol, max_step in ((1e-6, None), (1e-7, 1e-6)):  # default caps (2 us; CVODE 5 us), then at most half
        tr = simulate(scene, choose_model(scene), parameters=par, rtol=rtol, max_step=max_step, progress=False).trace
        keep = (tr.time >= settle)[:, None] & tr.valid
        profiles.append(angle_profile(tr.angle, tr.slip, 1.0, valid=keep)["mean"].to_numpy())
        peaks.append(peak_unloaded_slip(tr, settle))
    assert 100 * abs(peaks[0] - peaks[1]) < 0.5
    assert 100 * np.nanmean(np.abs(profiles[0] - profiles[1])) < 0.5
