"""From a scene to a simulation trace: build the model, start it quasi-statically, solve, write.

This release runs the planar level with the effects listed in :data:`IMPLEMENTED`;
a scene that needs another effect (race traction, films, drag) or the spatial
level is refused before anything compiles, with the way to force those effects
off. The run is split into chunks of simulated time for the progress bar; the
state and the contact bookkeeping carry over between chunks.
"""

from __future__ import annotations

import json
import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import numpy.typing as npt
from tqdm.auto import tqdm

from cageless.errors import UsageError
from cageless.kinematics import slip_rate, theoretical_cage_speed
from cageless.provenance import Provenance
from cageless.trace import SimulationInfo, Trace, write_trace
from simulation.effects import ModelChoice
from simulation.hertz import compliance, hertz_contact, race_curvatures
from simulation.models import planar as P
from simulation.quasistatic import radial_load_distribution
from simulation.scene import Scene
from simulation.problem import Problem
from simulation.solve import Solution, solve

__all__ = ["IMPLEMENTED", "SimulationResult", "check_supported", "initial_state", "simulate"]

#: Effects this release can evaluate (the planar core).
IMPLEMENTED = frozenset({"race_contact", "lubricant_damping", "ball_ball_contact", "gravity"})


@dataclass
class SimulationResult:
    """A finished (or failed) run: the solver's result and the trace built from it."""

    solution: Solution
    trace: Trace
    problem: Problem


def check_supported(choice: ModelChoice) -> None:
    """Refuse, before any compile or solve, a model this release cannot run."""
    if choice.level != "planar":
        raise UsageError("the spatial level lands with the next simulator issue; this release runs planar scenes "
                         "(pure radial load, aligned bearing, horizontal shaft).")
    missing = [e for e in choice.active if e not in IMPLEMENTED]
    if missing:
        flags = " ".join(f"--effect {e}=off" for e in missing)
        raise UsageError(f"effects not in this release yet: {', '.join(missing)}. To run without them, add "
                         f"{flags} --force (the trace records that they were forced off).")


def initial_state(scene: Scene) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], tuple[float, float]]:
    """Balls packed around the loaded zone (gap at the top), ring and balls in quasi-static equilibrium.

    The ring sinks by the displacement e that carries the radial load and the ring's weight
    (Newton-Raphson, :func:`~simulation.quasistatic.radial_load_distribution`); each loaded ball sits
    where its inner and outer Hertz forces balance: delta_o = e cos(psi) / (1 + (K_o / K_i)^(2/3)).
    """
    b = scene.bearing
    g = b.geometry
    theta = P.packed_start(b, seed=scene.seed)
    radius = np.full(g.n_balls, 0.5 * g.pitch_diameter_m)
    load = scene.conditions.radial_load_n + b.masses.ring_translational_mass_kg * scene.gravity_m_s2
    if load <= 0:
        return theta, radius, (0.0, 0.0)
    e = radial_load_distribution(g, b.material, load, theta).displacement_m
    eta = compliance(b.material)
    rc = race_curvatures(g)
    k_i, k_o = (hertz_contact(*rc[r], eta).stiffness for r in ("inner", "outer"))
    total = np.clip(e * np.cos(theta - 1.5 * math.pi) - 0.5 * g.diametral_clearance_m, 0.0, None)
    radius = radius + total / (1.0 + (k_o / k_i) ** (2.0 / 3.0))
    return theta, radius, (0.0, -e)


def _observables(pr: Problem, y: npt.NDArray[np.float64]) -> dict[str, dict[str, np.ndarray]]:
    """Normal contact forces (elastic part) and positions along the samples."""
    p = pr.params
    z = int(p[P.P_Z])
    d = p[P.P_D]
    r, th = y[:, :z], y[:, z:2 * z]
    cy, cz = y[:, 5 * z], y[:, 5 * z + 1]
    outer = p[P.P_KO] * np.clip(r + 0.5 * d - 0.5 * p[P.P_DO], 0, None) ** 1.5
    ln = np.hypot(r * np.cos(th) - cy[:, None], r * np.sin(th) - cz[:, None])
    inner = p[P.P_KI] * np.clip(0.5 * p[P.P_DI] + 0.5 * d - ln, 0, None) ** 1.5
    x, zz = r * np.cos(th), r * np.sin(th)
    gap = np.hypot(np.roll(x, -1, axis=1) - x, np.roll(zz, -1, axis=1) - zz)
    bb = p[P.P_KB] * np.clip(d - gap, 0, None) ** 1.5
    spin = np.zeros((len(y), z, 3))
    spin[:, :, 0] = y[:, 4 * z:5 * z]
    ring = np.column_stack([np.zeros(len(y)), cy, cz])
    return {
        "balls": {"radius": r, "axial": np.zeros_like(r), "spin": spin},
        "contacts": {"inner_normal": inner, "outer_normal": outer, "ball_ball_normal": bb},
        "inner_ring": {"position": ring, "tilt": np.zeros((len(y), 2))},
    }


def _solve_chunks(pr: Problem, t: npt.NDArray[np.float64], rtol: float, method: str, max_step: float,
                  chunks: int, progress: bool, max_steps: int) -> Solution:
    edges = np.unique(np.linspace(0, len(t) - 1, chunks + 1).astype(int))
    ys, steps, rej, rhs, wall = [pr.y0[None, :]], 0, 0, 0, 0.0
    y0, aux, t0 = pr.y0.copy(), pr.aux.copy(), float(t[0])
    sol = None
    with tqdm(total=float(t[-1] - t[0]), desc="simulated s", unit="s", disable=not progress, leave=False) as bar:
        for a, b in zip(edges[:-1], edges[1:], strict=True):
            part = Problem(model_id=pr.model_id, params=pr.params, aux=aux, y0=y0, t0=t0, atol=pr.atol,
                           name=pr.name)
            sol = solve(part, t[a + 1:b + 1], method=method, rtol=rtol, max_step=max_step,
                        max_steps=max(1, max_steps - steps - rej))
            ys.append(sol.y)
            steps, rej, rhs, wall = steps + sol.n_steps, rej + sol.n_rejected, rhs + sol.n_rhs, wall + sol.wall_s
            bar.update(float(t[b] - t[a]))
            if not sol.success:
                break
            y0, aux, t0 = sol.y[-1].copy(), sol.extra.get("aux", aux), float(t[b])
    y = np.concatenate(ys)
    if len(y) < len(t):
        y = np.vstack([y, np.full((len(t) - len(y), y.shape[1]), np.nan)])
    assert sol is not None
    return Solution(t=t, y=y, status=sol.status, message=sol.message, method=method, n_steps=steps,
                    n_rejected=rej, n_rhs=rhs, wall_s=wall, extra={"aux": aux})


def simulate(scene: Scene, choice: ModelChoice, restitution: float = 0.8, rtol: float = 1e-6,
             sample_rate_hz: float = 10_000.0, method: str = "dp5", max_step: float = 2e-6,
             out: str | Path | None = None, progress: bool = True, config: dict[str, Any] | None = None,
             max_steps: int = 50_000_000) -> SimulationResult:
    """Run ``scene`` with the model ``choice`` and (with ``out``) write the trace atomically.

    ``max_steps`` bounds the accepted plus rejected steps of the whole run.

    A solver failure does not raise: the result's ``solution.success`` is False and the trace's
    ``status`` says ``"incomplete: <why>"``; samples after the failure are NaN.
    """
    check_supported(choice)
    prov = Provenance.start(config={"scene": scene.to_dict(), "model": json.loads(choice.to_json()),
                                    "solver": {"method": method, "rtol": rtol, "max_step": max_step},
                                    "restitution": restitution, **(config or {})})
    theta, radius, ring = initial_state(scene)
    effects = {e.name: e.on for e in choice.effects}
    pr = P.planar_problem(scene.bearing, theta, radius, ring, scene.conditions.radial_load_n, restitution,
                          scene.gravity_m_s2 if effects.get("gravity") else 0.0, scene.conditions.speed_rad_s,
                          effects)
    t = np.arange(0.0, scene.duration_s + 0.5 / sample_rate_hz, 1.0 / sample_rate_hz)
    start = time.perf_counter()
    sol = _solve_chunks(pr, t, rtol, method, max_step, min(50, len(t) - 1), progress, max_steps)
    wall = time.perf_counter() - start
    trace = _to_trace(scene, choice, pr, sol, rtol, wall, prov.finish().to_dict())
    if out is not None:
        write_trace(out, trace)
    return SimulationResult(solution=sol, trace=trace, problem=pr)


def _to_trace(scene: Scene, choice: ModelChoice, pr: Problem, sol: Solution, rtol: float, wall: float,
              provenance: dict[str, Any]) -> Trace:
    g = scene.bearing.geometry
    z = g.n_balls
    y = sol.y
    ok = np.all(np.isfinite(y), axis=1)
    angle, speed = y[:, z:2 * z], y[:, 3 * z:4 * z]
    omega_c = theoretical_cage_speed(g, scene.conditions.speed_rad_s)
    groups = _observables(pr, np.where(ok[:, None], y, np.nan))
    events = P.contact_events(pr, sol.extra["aux"], float(sol.t[ok][-1]) if ok.any() else 0.0)
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
