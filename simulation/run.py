"""From a scene to a simulation trace: build the model, start it quasi-statically, solve, write.

This release runs the planar and the spatial level with every effect of the
table; moment loads and a vertical shaft are refused before anything compiles.
The run is split into chunks of simulated time for the progress bar; the
state and the contact bookkeeping carry over between chunks.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt

from cageless.errors import UsageError
from cageless.kinematics import slip_rate, startup_duration, theoretical_cage_speed
from cageless.profiles import PEAK_SMOOTHING_DEG, UNLOADED_ZONE_DEG, angle_profile, unloaded_zone_peak
from cageless.trace import SimulationInfo, Trace
from cageless.simulation.effects import ModelChoice
from cageless.simulation.hertz import compliance, hertz_contact, race_curvatures
from cageless.simulation.models import planar as P
from cageless.simulation.models import spatial as S
from cageless.simulation.models.energy import spatial_energy
from cageless.simulation.models.observables import observables
from cageless.simulation.parameters import ModelParameters
from cageless.simulation.quasistatic import radial_load_distribution
from cageless.simulation.scene import Scene
from cageless.simulation.problem import Problem
from cageless.simulation.solve import FORCE_JUMP, Solution

__all__ = ["SimulationResult", "EnergyBalance", "build_problem", "check_supported", "energy_balance", "initial_state",
           "simulate", "to_trace",
           "peak_unloaded_slip",
           "UNLOADED_ZONE_DEG"]




@dataclass
class SimulationResult:
    """A finished (or failed) run: the solver's result and the trace built from it."""

    solution: Solution
    trace: Trace
    problem: Problem


def peak_unloaded_slip(trace: Trace, settle_s: float = 0.0, bin_deg: float = 1.0,
                       sigma_deg: float = PEAK_SMOOTHING_DEG) -> float:
    """The peak slip of the unloaded zone, as a fraction (:func:`cageless.profiles.unloaded_zone_peak`).

    Samples before ``settle_s`` (the start-up) and invalid samples are left out; the profile is
    the mean over all balls per ``bin_deg`` orbital-angle bin, smoothed by a periodic Gaussian of
    ``sigma_deg`` before its maximum over the zone is taken. NaN when no bin of the zone has data.
    """
    keep = (trace.time >= settle_s)[:, None] & trace.valid
    return unloaded_zone_peak(angle_profile(trace.angle, trace.slip, bin_deg, valid=keep), sigma_deg)


def settled_peak_slip(trace: Trace) -> tuple[float, float]:
    """The peak unloaded-zone slip after the start-up that ``compare`` and ``report`` leave out
    (:func:`cageless.kinematics.startup_duration`), NaN when the run ends within it; and that start-up (s)."""
    startup = startup_duration(trace.speed_rpm, trace.ball_diameter_m, trace.pitch_diameter_m)
    if float(trace.time[-1]) <= startup:
        return math.nan, startup
    return peak_unloaded_slip(trace, settle_s=startup), startup


def check_supported(scene: Scene, choice: ModelChoice | None = None) -> None:
    """Refuse, before any compile or solve, a scene this release cannot run with ``choice``."""
    if scene.orientation == "vertical" and choice is not None and choice.level == "planar" and scene.gravity_m_s2 > 0:
        raise UsageError("a vertical shaft puts gravity along the shaft, which the planar level cannot carry: "
                         "let the scene choose the spatial level (drop --level planar).")


def initial_state(scene: Scene, gravity: bool = True
                  ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], tuple[float, float]]:
    """Balls packed around the loaded zone (gap at the top), ring and balls in quasi-static equilibrium
    (the ring's weight counted when ``gravity``, the gravity effect, is on).

    The ring sinks by the displacement e that carries the radial load and the ring's weight
    (Newton-Raphson, :func:`~cageless.simulation.quasistatic.radial_load_distribution`); each loaded ball sits
    where its inner and outer Hertz forces balance: delta_o = e cos(psi) / (1 + (K_o / K_i)^(2/3)).
    """
    b = scene.bearing
    g = b.geometry
    theta = P.packed_start(b, seed=scene.seed, spread=scene.initial_gap_fraction)
    radius = np.full(g.n_balls, 0.5 * g.pitch_diameter_m)
    across = gravity and scene.orientation == "horizontal"
    weight = b.masses.ring_translational_mass_kg * scene.gravity_m_s2 if across else 0.0
    load = scene.conditions.radial_load_n + weight
    if load <= 0:
        return theta, radius, (0.0, 0.0)
    e = radial_load_distribution(g, b.material, load, theta).displacement_m
    eta = compliance(b.material)
    rc = race_curvatures(g)
    k_i, k_o = (hertz_contact(*rc[r], eta).stiffness for r in ("inner", "outer"))
    total = np.clip(e * np.cos(theta - 1.5 * math.pi) - 0.5 * g.diametral_clearance_m, 0.0, None)
    radius = radius + total / (1.0 + (k_o / k_i) ** (2.0 / 3.0))
    return theta, radius, (0.0, -e)


def build_problem(scene: Scene, choice: ModelChoice, parameters: ModelParameters) -> Problem:
    """The planar or spatial problem of ``choice`` for ``scene``, from the quasi-static start."""
    effects = {e.name: e.on for e in choice.effects}
    theta, radius, ring = initial_state(scene, gravity=effects.get("gravity", False))
    gravity = scene.gravity_m_s2 if effects.get("gravity") else 0.0
    vertical = scene.orientation == "vertical"
    kw = {"gravity_m_s2": 0.0 if vertical else gravity,
          "inner_speed_rad_s": scene.conditions.speed_rad_s, "effects": effects, "parameters": parameters,
          "speed_ramp_s": scene.speed_ramp_s, "oil_air_density_kg_m3": scene.mixture_density_kg_m3}
    if choice.level == "spatial":
        return S.spatial_problem(scene.bearing, theta, radius, ring, scene.conditions.radial_load_n,
                                 axial_load_n=scene.conditions.axial_load_n,
                                 misalignment_rad=(scene.misalignment_rad, 0.0), strips=parameters.strips,
                                 moment_load_nm=scene.moment_load_nm, axial_gravity_m_s2=gravity if vertical else 0.0,
                                 **kw)
    return P.planar_problem(scene.bearing, theta, radius, ring, scene.conditions.radial_load_n, **kw)


@dataclass(frozen=True)
class EnergyBalance:
    """The energy account along a solution's samples (J): the drive's input work, the energy dissipated, and
    ``balance`` = mechanical energy + dissipated - input, constant when the balance closes."""

    balance: npt.NDArray[np.float64]
    input_work: npt.NDArray[np.float64]
    dissipated: npt.NDArray[np.float64]

    @property
    def drift(self) -> float:
        """Largest change of the balance from its start (J)."""
        return float(np.max(np.abs(self.balance - self.balance[0])))


def energy_balance(problem: Problem, y: npt.NDArray[np.float64]) -> EnergyBalance:
    """The energy account of ``problem`` along samples ``y`` (T, n), planar or spatial."""
    sl = P.PlanarLayout(problem.n_balls).slices()  # the counters sit at the same slots in the spatial layout
    work, lost = y[:, sl["input_work"]][:, 0], y[:, sl["dissipated"]][:, 0]
    energy = spatial_energy(problem, y) if problem.model_id == S.MODEL_ID else P.planar_energy(problem, y)
    return EnergyBalance(balance=energy + lost - work, input_work=work, dissipated=lost)


def nominal_contact_angle(scene: Scene, groups: dict[str, dict[str, np.ndarray]]) -> float:
    """The contact angle alpha of the slip rate: 0 unless an axial load sets it; then the median
    inner contact angle of the loaded contacts over the second half of the run (rad, >= 0)."""
    c = groups["contacts"]
    if scene.conditions.axial_load_n <= 0 or "inner_angle" not in c:
        return 0.0
    half = len(c["inner_angle"]) // 2
    angle, load = c["inner_angle"][half:], c["inner_normal"][half:]
    loaded = np.isfinite(angle) & (load > 1.0)
    return float(np.median(np.abs(angle[loaded]))) if loaded.any() else 0.0


def simulate(scene: Scene, choice: ModelChoice, parameters: ModelParameters | None = None, rtol: float = 1e-6,
             sample_rate_hz: float = 10_000.0, method: str = "auto", max_step: float | None = None,
             out: str | Path | None = None, progress: bool = True, config: dict[str, Any] | None = None,
             max_steps: int = 50_000_000, force_jump: float = FORCE_JUMP) -> SimulationResult:
    """Run ``scene`` with the model ``choice``: :class:`cageless.simulation.simulation.Simulation` with these settings
    (see :class:`~cageless.simulation.simulation.Choices` for them), its solution, trace and problem together.

    A solver failure does not raise: the result's ``solution.success`` is False and the trace's
    ``status`` says ``"incomplete: <why>"``; samples after the failure are NaN.
    """
    from cageless.simulation.simulation import Choices, Simulation

    sim = Simulation(scene, parameters, Choices(method=method, rtol=rtol, max_step=max_step,
                                                sample_rate_hz=sample_rate_hz, max_steps=max_steps,
                                                force_jump=force_jump), model=choice)
    trace = sim.run(out=out, progress=progress, config=config)
    assert sim.solution is not None and sim.problem is not None
    return SimulationResult(solution=sim.solution, trace=trace, problem=sim.problem)


def to_trace(scene: Scene, choice: ModelChoice, pr: Problem, sol: Solution, rtol: float, wall: float,
              provenance: dict[str, Any]) -> Trace:
    g = scene.bearing.geometry
    z = g.n_balls
    y = sol.y
    ok = np.all(np.isfinite(y), axis=1)
    angle, speed = y[:, z:2 * z], y[:, 3 * z:4 * z]
    film_on = any(e.name == "ehl_film" and e.on for e in choice.effects)
    groups = observables(pr, sol.t, np.where(ok[:, None], y, np.nan), scene, film_on)
    alpha = nominal_contact_angle(scene, groups)
    provenance["config"]["nominal_contact_angle_rad"] = alpha
    omega_c = theoretical_cage_speed(g, scene.conditions.speed_rad_s, alpha)
    events = P.contact_events(pr, sol.extra["log"], float(sol.t[ok][-1]) if ok.any() else 0.0)
    status = "complete" if sol.success else f"incomplete: {sol.message} at t = {sol.t[ok][-1] if ok.any() else 0:g} s"
    return Trace(
        source="simulation", time=sol.t, angle=angle, speed=speed, slip=slip_rate(speed, omega_c),
        valid=np.repeat(ok[:, None], z, axis=1), speed_rpm=scene.conditions.speed_rpm,
        radial_load_n=scene.conditions.radial_load_n, axial_load_n=scene.conditions.axial_load_n,
        ball_diameter_m=g.ball_diameter_m, pitch_diameter_m=g.pitch_diameter_m, config=provenance["config"],
        simulation=SimulationInfo(scene_json=json.dumps(scene.to_dict(), sort_keys=True), effects_json=choice.to_json(),
                                  solver=sol.method, rtol=rtol, atol=float(pr.atol.min()), n_steps=sol.n_steps,
                                  n_rhs=sol.n_rhs, wall_s=wall),
        groups=groups, events=events, status=status, provenance=provenance,
    )
