"""One run object: ``Simulation(scene, parameters, choices).run() -> Trace``.

Every run is set up here and nowhere else, whoever asks for it (``cageless simulate``, its
ensembles, ``cageless sweep``, the lab workflow, the benchmarks): the scene decides the model
(:func:`cageless.simulation.effects.choose_model`, with the user's level and effect overrides from the
choices), the parameters fill its named slots, and the solver settings of the choices run it. All
checks happen when the object is made, before anything compiles; :meth:`Simulation.run` builds the
problem from the quasi-static start, solves it (:func:`cageless.simulation.auto_switch.solve_chunks`) and
returns the trace, written atomically when asked. Shaped after PyBaMM's ``Simulation``
(model, parameter values, solver; Sulzer et al., J. Open Res. Softw. 9 (2021) 14).
"""

from __future__ import annotations

import dataclasses
import json
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from cageless.errors import ParameterError, suggest
from cageless.profiles import peak_estimator
from cageless.provenance import Provenance
from cageless.trace import Trace, write_trace
from cageless.simulation.effects import ModelChoice, choose_model
from cageless.simulation.parameters import ModelParameters
from cageless.simulation.problem import Problem
from cageless.simulation.scene import Scene
from cageless.simulation.solve import FORCE_JUMP, METHODS, Solution

__all__ = ["Choices", "Simulation"]


@dataclass(frozen=True)
class Choices:
    """How to run a scene: the model overrides and the solver settings.

    Parameters
    ----------
    level
        Force the model level (``"planar"`` or ``"spatial"``); None lets the scene choose.
    effects
        Effect overrides, name -> on (see :func:`cageless.simulation.effects.choose_model`).
    force
        Allow overrides that contradict the scene.
    method
        A key of :data:`cageless.simulation.solve.METHODS`: ``"auto"`` (compiled DP5, switching to a stiff solver when
        that pays: see :mod:`cageless.simulation.auto_switch`), ``"dp5"``, ``"CVODE"``, or one of scipy's.
    rtol
        Relative tolerance; CVODE runs at ``rtol x 0.03`` to match DP5's accuracy
        (:data:`cageless.simulation.auto_switch.RTOL_FACTOR`).
    max_step
        Step cap (s) for every step; None gives each method its default
        (:func:`cageless.simulation.auto_switch.default_max_step`: 2 us, 5 us for CVODE, also after a switch).
    sample_rate_hz
        Samples of the trace per simulated second.
    max_steps
        Bound on the accepted plus rejected steps of the whole run.
    force_jump
        The force-jump fraction of :func:`cageless.simulation.solve.solve`.
    """

    level: str | None = None
    effects: Mapping[str, bool] = field(default_factory=dict)
    force: bool = False
    method: str = "auto"
    rtol: float = 1e-6
    max_step: float | None = None
    sample_rate_hz: float = 10_000.0
    max_steps: int = 50_000_000
    force_jump: float = FORCE_JUMP

    def check(self) -> None:
        """Refuse an unknown method or a bad step cap (before anything compiles)."""
        if self.method not in METHODS:
            raise ParameterError("method", "is not a solver" + (suggest(self.method, METHODS) or
                                                                f"; use one of {list(METHODS)}"), self.method)
        if self.max_step is not None and not (0 < self.max_step < np.inf):
            raise ParameterError("max_step", "must be a positive number of seconds, or None for the defaults",
                                 self.max_step)

    def solver_config(self) -> dict[str, Any]:
        """The solver settings as the trace records them."""
        from cageless.simulation.auto_switch import CONTACT_MAX_STEP_S, MAX_STEP_S, RTOL_FACTOR

        return {"method": self.method, "rtol": self.rtol, "max_step": self.max_step,
                "default_max_step_s": {**MAX_STEP_S, "others": CONTACT_MAX_STEP_S}, "rtol_factor": RTOL_FACTOR,
                "force_jump": self.force_jump}


class Simulation:
    """One run of a scene: the model it calls for, its parameters and the solver settings.

    Parameters
    ----------
    scene
        What to simulate.
    parameters
        The open model parameters (default :class:`~cageless.simulation.parameters.ModelParameters`).
    choices
        Model overrides and solver settings (default :class:`Choices`).
    model
        A model choice made earlier (``cageless simulate --explain`` shows it); default: decided from
        ``scene`` and the overrides in ``choices``.

    Raises
    ------
    UsageError, ParameterError
        For overrides that contradict the scene, a scene this release cannot run, an unknown method or a
        bad step cap: all before anything compiles.
    """

    def __init__(self, scene: Scene, parameters: ModelParameters | None = None, choices: Choices | None = None,
                 model: ModelChoice | None = None) -> None:
        from cageless.simulation.run import check_supported

        self.scene = scene
        self.parameters = parameters or ModelParameters()
        self.choices = choices or Choices()
        self.model = model or choose_model(scene, self.choices.level, self.choices.effects, self.choices.force)
        check_supported(scene, self.model)
        self.choices.check()
        #: Set by :meth:`run`: the problem solved, the solver's result and the trace.
        self.problem: Problem | None = None
        self.solution: Solution | None = None
        self.trace: Trace | None = None

    def with_seed(self, seed: int) -> Simulation:
        """The same run from the start perturbed by ``seed`` (an ensemble member)."""
        return Simulation(dataclasses.replace(self.scene, seed=seed), self.parameters, self.choices, self.model)

    def build(self) -> Problem:
        """The planar or spatial problem from the quasi-static start (nothing is solved)."""
        from cageless.simulation.run import build_problem

        return build_problem(self.scene, self.model, self.parameters)

    def sample_times(self) -> np.ndarray:
        """The trace's sample times (s)."""
        rate = self.choices.sample_rate_hz
        return np.arange(0.0, self.scene.duration_s + 0.5 / rate, 1.0 / rate)

    def _clearance(self) -> dict[str, Any]:
        """The diametral clearance the run used and where it comes from, for the provenance."""
        from cageless.bearing import clearance_note

        g = self.scene.bearing.geometry
        return {"diametral_clearance_m": g.diametral_clearance_m, "note": clearance_note(g)}

    def run(self, out: str | Path | None = None, progress: bool = False,
            config: dict[str, Any] | None = None, inputs: Sequence[str | Path] = ()) -> Trace:
        """Solve, build the trace and (with ``out``) write it atomically; ``config`` adds to its recorded
        configuration, and ``inputs`` (files the run was configured from, such as a ``--config`` TOML) to its
        recorded inputs, each with its hash.

        A solver failure does not raise: :attr:`solution` ``.success`` is False and the trace's ``status``
        says ``"incomplete: <why>"``; samples after the failure are NaN.
        """
        from cageless.simulation.run import to_trace
        from cageless.simulation.solve import solve

        c = self.choices
        begin = time.perf_counter()
        prov = Provenance.start(config={"scene": self.scene.to_dict(), "model": json.loads(self.model.to_json()),
                                        "solver": c.solver_config(), "parameters": self.parameters.to_dict(),
                                        "peak_estimator": peak_estimator(), "clearance": self._clearance(),
                                        **(config or {})}, inputs=inputs)
        pr = self.build()
        t = self.sample_times()
        start = time.perf_counter()
        sol = solve(pr, t, c.method, c.rtol, np.inf if c.max_step is None else c.max_step, max_steps=c.max_steps,
                    force_jump=c.force_jump, chunks=min(50, len(t) - 1), progress=progress)
        wall = time.perf_counter() - start
        provenance = prov.finish().to_dict()
        provenance["solver_stats"] = {"n_steps": sol.n_steps, "n_rejected": sol.n_rejected, "n_rhs": sol.n_rhs,
                                      "n_onset_retries": sol.n_onset_retries,
                                      "n_contact_changes": sol.n_contact_changes,
                                      "n_force_jump_retries": sol.n_force_jump_retries,
                                      "n_stiff_steps": sol.n_stiff_steps, "method": sol.method,
                                      "switch_probes": sol.extra.get("switches", []),
                                      "onset_step_s": pr.onset_step, "wall_s": wall}
        trace = to_trace(self.scene, self.model, pr, sol, c.rtol, wall, provenance)
        trace = dataclasses.replace(trace, simulation=dataclasses.replace(
            trace.simulation, total_wall_s=time.perf_counter() - begin))
        if out is not None:
            write_trace(out, trace)
        self.problem, self.solution, self.trace = pr, sol, trace
        return trace
