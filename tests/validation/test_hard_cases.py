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
from cageless.simulation.run import UNLOADED_ZONE_DEG, energy_balance, peak_unloaded_slip, simulate
from cageless.simulation.scene import Scene

#: "a few times the static Hertz deflection"
OVERLAP_FACTOR = 8.0
#: Window of the convergence statistics after the start-up (s). The check's three runs (the seed run added, at the
#: default settings: 0.4 of the tightened run's cost, measured) over 0.2 s cost what its two runs over 0.3 s did;
#: the shorter window's larger sampling spread is measured by the seed run.
STATISTICS_S = 0.2
#: DESIGN §7's bar on the statistics' change when the tolerance is tightened (pp).
BAR_PP = 0.5
#: A change of the peak from tightening the tolerance within this many seed-to-seed per-bin rms changes of the
#: unloaded zone is the chaos's sampling spread, not a tolerance error (test_hard_case_statistics_converge). The
#: per-bin rms is the larger scale (every ball starting in contact, 0.45 s: the seed moved the peak by 0.34 pp, the
#: zone's bins by 0.51 pp rms), so twice it is a wide bound on one number without being a loose one.
PEAK_SPREAD = 2.0
#: The same for the profile's mean |change|, a mean over 360 bins: two independent draws give the same value within
#: tens of per cent (the same case: tolerance 0.37 pp, seed 0.26 pp).
PROFILE_SPREAD = 2.0
#: The seed run's initial gap fraction for a case that starts every ball in contact (gap fraction 0, where the seed
#: changes nothing): a few nanometres between neighbours (the default 0.05 keeps them micrometres apart), a
#: thousandth of the start's Hertz overlaps.
SEED_GAP_FRACTION = 1e-4

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


def tolerance_against_seed(runs: dict[str, tuple[np.ndarray, float]], bins_deg: np.ndarray) -> dict[str, float]:
    """The statistics' change from tightening the tolerance, beside their spread from changing the seed (pp).

    ``runs`` maps "default", "tight" (seed 0 at the default and the tightened tolerance) and "seed" (another
    seed at the default tolerance) to (1-degree mean slip profile, peak slip in the unloaded zone). Returns
    the tolerance's change of the peak and the mean |change| of the profile; the seed's mean |change| of the
    profile; and the seed's per-bin rms change over the unloaded zone, the scale of a change of the peak (the
    peak is the largest bin of that zone, so two independent draws of it differ by about one per-bin spread).
    """
    (p_d, k_d), (p_t, k_t), (p_s, _) = runs["default"], runs["tight"], runs["seed"]
    lo, hi = UNLOADED_ZONE_DEG
    zone = (bins_deg > lo) & (bins_deg < hi)
    return {"peak_tol": 100 * abs(k_t - k_d), "profile_tol": 100 * np.nanmean(np.abs(p_t - p_d)),
            "profile_seed": 100 * np.nanmean(np.abs(p_s - p_d)),
            "peak_seed": 100 * np.sqrt(np.nanmean((p_s - p_d)[zone] ** 2))}


def converged(d: dict[str, float]) -> tuple[bool, bool]:
    """Whether the peak and the profile have converged in tolerance: their change from tightening is below the
    0.5 pp bar, or within ``PEAK_SPREAD`` (``PROFILE_SPREAD``) times the spread that changing the seed alone
    produces."""
    return (d["peak_tol"] < max(BAR_PP, PEAK_SPREAD * d["peak_seed"]),
            d["profile_tol"] < max(BAR_PP, PROFILE_SPREAD * d["profile_seed"]))


@pytest.mark.slow
@pytest.mark.parametrize("name", list(CASES))
def test_hard_case_statistics_converge(name):
    """Settled runs (start-up plus STATISTICS_S), three of them: seed 0 at the default tolerance, seed 0 with rtol
    1e-6 -> 1e-7 and the largest step halved, and seed 1 at the default settings. The peak slip in the
    unloaded zone and the 1-degree slip profile have converged when the tightening moves them by < 0.5 pp
    (DESIGN §7), or by less than PEAK_SPREAD (PROFILE_SPREAD) times what changing the seed alone moves them.

    Why the seed: the ball ring is chaotic, so two runs that differ by a tolerance part after a few milliseconds
    as two runs that differ by a seed do; neither trajectory converges, their statistics do (Teixeira, Reynolds
    & Judd, "Time step sensitivity of nonlinear atmospheric models", J. Atmos. Sci. 64 (2007) 175-189: for a
    chaotic model, time-step convergence holds only up to a decoupling time, after which a time-step change acts
    as an initial-condition perturbation; Hammel, Yorke & Grebogi, J. Complexity 3 (1987) 136-145: a numerical
    orbit is shadowed by a true orbit of nearby initial state, not by the one it started from). A finite window's
    statistic then carries a sampling spread, which the seed run measures in the same test; a tolerance is
    converged when tightening it moves the statistics no more than that. A solver that biases the statistics
    biases the default and the seed runs alike and fails (test_convergence_criterion_separates_bias_from_chaos);
    the validation page gives the measured changes, loose tolerances and broken solvers included."""
    g = default_bearing().geometry
    rpm = CASES[name][0]
    settle = startup_duration(rpm, g.ball_diameter_m, g.pitch_diameter_m)
    scene, par = _scene(name, settle + STATISTICS_S)
    runs = {}
    # default caps (2 us; CVODE 5 us), then at most half; the seed run at the default settings (the cheaper run).
    # A case starting every ball in contact has no gap for the seed to vary: its seed run opens them by
    # SEED_GAP_FRACTION.
    seeded = replace(scene, seed=1, initial_gap_fraction=scene.initial_gap_fraction or SEED_GAP_FRACTION)
    for key, sc, rtol, max_step in (("default", scene, 1e-6, None), ("tight", scene, 1e-7, 1e-6),
                                    ("seed", seeded, 1e-6, None)):
        tr = simulate(sc, choose_model(sc), parameters=par, rtol=rtol, max_step=max_step, progress=False).trace
        keep = (tr.time >= settle)[:, None] & tr.valid
        prof = angle_profile(tr.angle, tr.slip, 1.0, valid=keep)
        runs[key] = (prof["mean"].to_numpy(), peak_unloaded_slip(tr, settle))
    d = tolerance_against_seed(runs, prof["angle_deg"].to_numpy())
    peak_ok, profile_ok = converged(d)
    assert peak_ok, d
    assert profile_ok, d


def test_convergence_criterion_separates_bias_from_chaos():
    """The criterion of test_hard_case_statistics_converge on synthetic profiles: three independent draws of the
    same noisy profile (1 pp per bin; a hard case over 0.3 s gives about 0.4 pp) pass, though the peaks of two of
    them differ by more than the 0.5 pp bar; the two runs at the default tolerance shifted by 5 pp over the
    unloaded zone (a default tolerance that biases the statistics) fail on both the peak and the profile."""
    rng = np.random.default_rng(7)
    bins = (np.arange(360) + 0.5) * 1.0
    truth = 0.05 + 0.03 * np.sin(np.radians(bins)) ** 2  # a slip profile peaking at 90 degrees

    def run(shift: float) -> tuple[np.ndarray, float]:
        prof = truth + 0.01 * rng.standard_normal(360) + shift * ((bins > 0) & (bins < 180))
        return prof, float(prof[(bins > 0) & (bins < 180)].max())

    runs = {"default": run(0.0), "tight": run(0.0), "seed": run(0.0)}
    d = tolerance_against_seed(runs, bins)
    assert d["peak_tol"] > BAR_PP or d["profile_tol"] > BAR_PP  # the absolute bar alone would fail this chaos
    assert converged(d) == (True, True), d
    biased = dict(runs, default=run(0.05), seed=run(0.05))
    assert converged(tolerance_against_seed(biased, bins)) == (False, False)
