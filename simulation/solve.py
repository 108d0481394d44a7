"""One entry point over a registry of integrators, like ``scipy.integrate.solve_ivp``.

:func:`solve` runs a :class:`Problem` with the method named in :data:`METHODS`:

* ``"rosw"``: the Rosenbrock-W method ROS34PW2 with its whole loop compiled, linearly implicit in each ball's
  states and the ring's (:mod:`cageless.simulation.integrators.rosw`), with DP5's controls; its step is set by
  accuracy, not by the race damping's stability limit;
* ``"ark4"``: the additive Runge-Kutta IMEX method ARK4(3)6L[2]SA with its whole loop compiled, the race
  normal forces and the radial (and axial) kinematics implicit per ball, everything else explicit
  (:mod:`cageless.simulation.integrators.ark`), with DP5's controls, a tighter rtol (:data:`ARK_RTOL_FACTOR`)
  and a looser absolute tolerance on the implicit speeds (:data:`ARK_SPEED_ATOL_FACTOR`);
* ``"dp5"``: Dormand-Prince 5(4) with its whole loop compiled (the default); it rejects and retries
  any step longer than ``Problem.onset_step`` in which a contact opens or closes, or across which a
  force jumps by more than the fraction ``force_jump`` (see :func:`solve`), and counts both;
* ``"CVODE"``: SUNDIALS CVODE's variable-order BDF (orders 1-5, Newton iteration) through
  scikit-sundae (:mod:`cageless.simulation.integrators.cvode`), on the compiled right-hand side, with the structured Jacobian of
  :mod:`cageless.simulation.jacobian` (see :data:`JACOBIANS`): the stiff backend the automatic switch of
  :mod:`cageless.simulation.auto_switch` goes to. Its loop is compiled C, so a step costs the right-hand-side calls
  plus 17 us (planar) to 30 us (spatial) of Python and dense linear algebra;
* ``"RK45"``, ``"DOP853"``, ``"LSODA"``, ``"BDF"``, ``"Radau"``: scipy's ``solve_ivp`` steppers on the
  same compiled right-hand side, as references; the implicit ones get the structured Jacobian too;
* ``"auto"``: compiled DP5 switching to CVODE or ``ark4`` where that pays (:mod:`cageless.simulation.auto_switch`).

CVODE and scipy's steppers are stepped one accepted step at a time here, so the accepted-step
bookkeeping (contact episodes) runs after every step as it does in the compiled loop. They cannot
take a step back. CVODE is stopped ahead of predicted contact changes instead (see
:func:`step_cvode`); scipy's steppers, kept as references, have neither the onset nor the force-jump
control, and for every one of them the force-jump control is left to the error control and
``max_step``. Their rejected steps are not counted (scikit-sundae and scipy do not expose them).

It returns a :class:`Solution` carrying the status, a message, and the solver
statistics; a failure is a result with ``success = False``, never an exception.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any, Protocol

import numpy as np
import numpy.typing as npt
from scipy.integrate import BDF, DOP853, LSODA, RK45, Radau

from cageless.errors import ParameterError, suggest
from cageless.simulation.integrators.ark import SESSION_ROWS, SESSION_SLOTS, ark_integrate
# the CVODE backend and the solution type live in their own modules; re-exported here, where they always were
from cageless.simulation.integrators.cvode import (JACOBIAN_DEFAULT, JACOBIANS, ONSET_APPROACH, CvodeSession,
                                                   _first_root, _onset_update, step_cvode)  # noqa: F401
from cageless.simulation.integrators.dp5 import STATUS_OK, _hermite, dp5_integrate
from cageless.simulation.integrators.rosw import JAC_EVERY, LU_RATIO, rosw_integrate
from cageless.simulation.jacobian import JacobianStructure
from cageless.simulation.kernels import SPATIAL, implicit_speed_rows, model_post, model_rhs, ring_rows
from cageless.simulation.problem import Problem
from cageless.simulation.solution import MESSAGES as _MESSAGES
from cageless.simulation.solution import FloatArray, Solution

__all__ = ["FORCE_JUMP", "Problem", "Solution", "Method", "METHODS", "CvodeSession", "ArkSession", "solve",
           "step_scipy", "step_cvode", "step_ark", "JACOBIANS", "JACOBIAN_DEFAULT", "ONSET_APPROACH"]

_SCIPY = {"RK45": RK45, "DOP853": DOP853, "LSODA": LSODA, "BDF": BDF, "Radau": Radau}
#: scipy's methods that use a Jacobian; on the compiled path they get the structured one.
_IMPLICIT = ("LSODA", "BDF", "Radau")
#: Default force-jump fraction (see :func:`solve`): a step across which a contact force more than
#: doubles or halves (a change above half its larger value) is retried shorter.
FORCE_JUMP = 0.5


def _run_compiled(name: str, integrate: Callable[..., int], pr: Problem, t_eval: FloatArray, rtol: float,
                  atol: FloatArray, max_step: float, first_step: float | None, max_steps: int, force_jump: float,
                  n_stats: int, *extra: Any, log: FloatArray | None = None) -> tuple[Solution, FloatArray]:
    """Run a compiled integrator (the signature of dp5_integrate, then ``extra``); its solution and raw stats.
    ``log``: the contact log to update in place (a session's); default a copy of the problem's."""
    out = np.full((len(t_eval), len(pr.y0)), np.nan)
    stats = np.zeros(n_stats)
    floor = np.zeros(len(pr.y0)) if pr.jump_floor is None else pr.jump_floor.astype(np.float64)
    log = pr.log.copy() if log is None else log
    h0 = first_step or min(max_step, 1e-3 * max(t_eval[-1] - pr.t0, 1e-12))
    t0 = time.perf_counter()
    status = integrate(pr.model_id, pr.params, log, pr.y0.astype(np.float64), float(pr.t0), t_eval, float(rtol),
                       atol, float(h0), float(max_step), int(max_steps), out, stats,
                       float(pr.onset_step), floor, float(force_jump if pr.jump_floor is not None else 0.0), *extra)
    sol = Solution(t=t_eval, y=out, status=int(status), message=_MESSAGES[int(status)], method=name,
                   n_steps=int(stats[0]), n_rejected=int(stats[1]), n_rhs=int(stats[2]),
                   wall_s=time.perf_counter() - t0, n_onset_retries=int(stats[4]),
                   n_contact_changes=int(stats[5]), n_force_jump_retries=int(stats[6]),
                   extra={"log": log, "last_h": float(stats[3])})
    return sol, stats


def _compiled(name: str, integrate: Callable[..., int]) -> Callable[..., Solution]:
    """A registry entry for an integrator whose whole loop is compiled (same signature as dp5_integrate)."""
    def run(pr: Problem, t_eval: FloatArray, rtol: float, max_step: float, first_step: float | None,
            max_steps: int, force_jump: float) -> Solution:
        sol, stats = _run_compiled(name, integrate, pr, t_eval, rtol, pr.atol.astype(np.float64), max_step,
                                   first_step, max_steps, force_jump, 8)
        sol.n_stiff_steps = int(stats[7])
        return sol

    return run


def _rosw_blocks(pr: Problem, ring_implicit: bool = True,
                 ring_coupling: bool = True) -> tuple[npt.NDArray[np.int64], ...]:
    """The blocks the Rosenbrock-W method treats implicitly, from the problem's Jacobian structure
    (:class:`~cageless.simulation.jacobian.JacobianStructure`): each ball's states (grouped by colour), the
    ring's states (explicit with ``ring_implicit`` False), the rows every ball reaches (none with
    ``ring_coupling`` False: W then keeps the balls' blocks and the ring's own block, without their coupling),
    and the rest explicit. A model without a structure is one dense block."""
    structure = JacobianStructure.for_problem(pr)
    n = len(pr.y0)
    none = np.zeros(0, dtype=np.int64)
    if structure is None:
        return (np.arange(n, dtype=np.int64).reshape(n, 1), np.zeros((1, 1), dtype=np.int64),
                np.zeros((0, 1), dtype=np.int64), none, none)
    ring = structure.other_cols.reshape(-1, 1).astype(np.int64)
    if not ring_implicit:
        ring = ring[:0]
    explicit = np.setdiff1d(np.arange(n), np.concatenate([structure.ball_cols.ravel(), ring.ravel()]))
    ring_rows = structure.ring_rows.astype(np.int64) if ring_coupling else none
    return (structure.ball_cols.astype(np.int64), structure.groups.astype(np.int64), ring, explicit.astype(np.int64),
            ring_rows)


#: The Rosenbrock-W method's absolute tolerances: the problem's times this factor times rtol / 1e-6, so one rtol
#: moves both. Its steps are set by its error test, and at the problem's own atol (which the explicit DP5 runs
#: far below, held by stability) that test admits 0.036 pp of slip error over 5 ms at 3000 rpm, 500 N
#: (planar, from a settled state); at this factor, with the error filter (see
#: :data:`cageless.simulation.integrators.rosw.FILTER_ERROR`), 0.036 pp at rtol 1e-6, 2.5e-3 pp at 1e-7, 2.2e-4 pp
#: at 1e-8 (benchmarks/solver_speed.py); on today's physics without the filter 2.3e-3 pp at 1e-6, 9.6e-4 pp at
#: 3e-7, 4.5e-4 pp at 1e-7.
ROSW_ATOL_FACTOR = 1e-2


#: ark4's absolute tolerance on the speeds it integrates implicitly
#: (:func:`cageless.simulation.kernels.implicit_speed_rows`) as a factor on the problem's: their filtered error
#: estimate sets its steps, though the L-stable implicit table damps the error itself (docs/imex.md: planar
#: 3000 rpm, 500 N, 1639 -> 1273 right-hand sides per 5 ms at x10, slip error 0.0019 -> 0.0026 pp; x10 on every
#: row took the spatial case past 0.01 pp). x30 with :data:`ARK_RTOL_FACTOR`: see there.
ARK_SPEED_ATOL_FACTOR = 30.0
#: ark4 runs its error test at this factor times the caller's rtol, so that rtol 1e-6 keeps the slip within
#: 0.01 pp of the tight reference (DP5, rtol 1e-10, 0.25 us cap) as DP5 at 1e-6 does. The slip error of ark4
#: at the caller's rtol came from the ball-ball impacts of the unloaded zone (their timing), which the RMS norm
#: over all states weighs little: 0.017 pp over the settled 20 ms planar window at 3000 rpm, 500 N (764 steps).
#: Measured with :data:`ARK_SPEED_ATOL_FACTOR` (settled 3000 rpm windows, slip error pp / right-hand sides,
#: planar 5 ms, planar 20 ms, spatial 500 N + 400 N 5 ms, 20 ms): factor 1 and x10 0.0020 / 1147, 0.0171 / 5119,
#: 0.0032 / 1003, 0.0043 / 3061; 0.3 and x30 0.0016 / 1177, 0.0124 / 5227 (x10), 0.0010 / 931, 0.0020 / 2953;
#: **0.2 and x30** 0.0012 / 1201, 0.0046 / 5257, 0.0023 / 937, 0.0009 / 3007; 0.1 and x10 0.0011 / 1285,
#: 0.0047 / 5623, 0.0007 / 937, 0.0008 / 2995; 0.1 and x30 0.0008 / 1249, 0.0054 / 5527, 0.0020 / 925,
#: 0.0005 / 3031. The 20 ms windows from other settled states (35 and 40 ms after the start) do not rank
#: them: there every setting, DP5 at rtol 1e-8 and CVODE too, is 0.05-0.9 pp off the reference by 18 ms, where
#: an impact falls a sample apart (docs/imex.md).
ARK_RTOL_FACTOR = 0.2
#: ark4's step cap (s) on a problem with contacts when the caller gives none (``auto`` gives it the same: its
#: default for ark4; a problem without contacts runs uncapped, its steps set by the error test). Uncapped, its
#: steps grow past the ball-ball impacts' timing: over the settled 20 ms planar window at 3000 rpm, 500 N it was
#: 0.0156 pp off the tight reference (DP5, rtol 1e-10, 0.25 us cap) in 738 steps, past the 0.01 pp that DP5 at
#: rtol 1e-6 keeps, and 0.0031 pp in 796 steps with this cap (docs/imex.md, the eighth step).
ARK_MAX_STEP_S = 5e-5


def _ark_jump_floor(pr: Problem) -> Problem:
    """``pr`` as ark4 runs it: without the force-jump test on the rows every ball reaches (the ring's
    accelerations, :func:`cageless.simulation.kernels.ring_rows`).

    The ring's acceleration is the sum of every ball's race forces and the load, a small difference of large
    forces; a contact force that jumps shows on its ball's own rows, which keep the test. With no radial load
    (500 N axial only, spatial) that sum is about 1 N against ~100 N per ball, changes sign within ark4's
    10-20 us steps, and the test (a change above half its larger value plus 1 N) refused 156 of 351 steps over
    2-6 ms (92 on the ring's axial, 64 on its radial accelerations) with no force jumping: without it 19 of 267
    (all at contact changes), 3151 -> 1717 right-hand sides, slip error 0.00028 -> 0.00031 pp and the ring's
    position within 1e-11 m of DP5 at rtol 1e-10 either way. DP5 keeps the test on every row: its 1 us steps do
    not see the ring's force change sign. The spatial level only: the planar ark4 was measured and pinned with the
    test on (settled at 3000 rpm, 500 N it makes no difference: 174 steps, 1147 right-hand sides either way)."""
    rows = ring_rows(pr.model_id, pr.n_balls)
    if pr.jump_floor is None or not rows or pr.model_id != SPATIAL:
        return pr
    floor = pr.jump_floor.astype(np.float64).copy()
    floor[rows] = 0.0
    return replace(pr, jump_floor=floor)


@dataclass
class ArkSession:
    """``ark4`` kept between the output chunks of one run, as :class:`CvodeSession` keeps CVODE: the state, the
    step the controller proposes, its error history, the contact signature and a contact change located ahead
    (:func:`cageless.simulation.integrators.ark.ark_integrate`'s ``state`` and ``rows``), and the contact log.

    Its steps are bounded by the run's end (``t_stop``), not by a chunk's last sample: a chunk returns after the
    step that crosses its last sample, and the next chunk's first samples come from that step's interpolant, so
    a run in chunks takes the same steps as one solve (bit for bit). Before this, every 0.1 ms chunk of ``auto``
    restarted ark4 with a step clipped to the chunk's end, no error history and a fresh right-hand side: 202
    steps where one solve takes 174 over 5 ms settled at 3000 rpm, 500 N (planar), and 4.33 CPU s per
    simulated s against 2.58.
    """

    problem: Problem
    atol: FloatArray
    t_stop: float
    state: FloatArray
    rows: FloatArray
    log: FloatArray
    calls: int = 0

    @classmethod
    def start(cls, pr: Problem, t_stop: float) -> ArkSession:
        """A session from ``pr``'s start that may step up to ``t_stop`` (s), the run's end."""
        atol = pr.atol.astype(np.float64).copy()
        atol[implicit_speed_rows(pr.model_id, pr.n_balls)] *= ARK_SPEED_ATOL_FACTOR
        return cls(_ark_jump_floor(pr), atol, float(t_stop), np.zeros(SESSION_SLOTS),
                   np.zeros((SESSION_ROWS, len(pr.y0))), pr.log.copy())

    @property
    def t(self) -> float:
        """Where the integrator is (s): past the last sample written by up to one step."""
        return float(self.state[1]) if self.state[0] > 0 else float(self.problem.t0)

    def samples(self, t_eval: FloatArray) -> FloatArray:
        """The states at ``t_eval`` (s, at or before :attr:`t`), from the last step's interpolant."""
        out = np.empty((len(t_eval), self.rows.shape[1]))
        for i, ts in enumerate(t_eval):
            if self.state[8] > 0 and ts > self.state[7]:
                _hermite(float(self.state[7]), float(self.state[8]), self.rows[3], self.rows[0], self.rows[4],
                         self.rows[1], float(ts), out[i])
            else:
                out[i] = self.rows[0]
        return out

    def handover(self, pr: Problem) -> Problem:
        """``pr`` from where the integrator is (its time, state and contact log), for another method to go on."""
        return replace(pr, y0=self.rows[0].copy(), t0=self.t, log=self.log.copy())


def step_ark(pr: Problem, t_eval: FloatArray, rtol: float, max_step: float, max_steps: int = 50_000_000,
             force_jump: float = FORCE_JUMP, first_step: float | None = None, session: ArkSession | None = None,
             t_stop: float | None = None) -> Solution:
    """``ark4`` over ``t_eval`` in a session (:class:`ArkSession`; a new one from ``pr``'s start, stepping up to
    ``t_stop``, default the last sample), returned in ``extra["ark4"]`` for the next chunk. With a session,
    ``pr``, ``first_step`` and ``t_stop`` are not used; without, the first step is by default 1e-3 of the span to
    ``t_stop``, as one solve's over it. The error test runs at :data:`ARK_RTOL_FACTOR` times ``rtol``."""
    if session is None:
        session = ArkSession.start(pr, float(t_eval[-1]) if t_stop is None else t_stop)
        first_step = first_step or min(max_step, 1e-3 * max(session.t_stop - pr.t0, 1e-12))  # as one solve's
    sol, _ = _run_compiled("ark4", ark_integrate, session.problem, t_eval, rtol * ARK_RTOL_FACTOR, session.atol,
                           max_step, first_step, max_steps, force_jump, 8, session.t_stop, session.state, session.rows,
                           log=session.log)
    session.calls += 1
    sol.extra["ark4"] = session
    return sol


def _ark4(pr: Problem, t_eval: FloatArray, rtol: float, max_step: float, first_step: float | None,
          max_steps: int, force_jump: float) -> Solution:
    """The compiled IMEX method (:mod:`cageless.simulation.integrators.ark`), with the implicit speeds' absolute
    tolerances scaled by :data:`ARK_SPEED_ATOL_FACTOR`, rtol by :data:`ARK_RTOL_FACTOR`, no force-jump test on
    the ring's rows (:func:`_ark_jump_floor`) and, on a problem with contacts (an onset step), its steps capped at
    :data:`ARK_MAX_STEP_S` when ``max_step`` is infinite, in one call."""
    max_step = ARK_MAX_STEP_S if pr.onset_step > 0 and not np.isfinite(max_step) else max_step
    sol = step_ark(pr, t_eval, rtol, max_step, max_steps, force_jump, first_step)
    del sol.extra["ark4"]
    return sol


def _rosw(pr: Problem, t_eval: FloatArray, rtol: float, max_step: float, first_step: float | None,
          max_steps: int, force_jump: float, jac_every: int = JAC_EVERY, lu_ratio: float = LU_RATIO,
          ring_implicit: bool = True, ring_coupling: bool = True) -> Solution:
    """The compiled Rosenbrock-W method (:mod:`cageless.simulation.integrators.rosw`), with absolute tolerances
    scaled by :data:`ROSW_ATOL_FACTOR` and rtol."""
    atol = pr.atol.astype(np.float64) * (ROSW_ATOL_FACTOR * rtol / 1e-6)
    sol, stats = _run_compiled("rosw", rosw_integrate, pr, t_eval, rtol, atol, max_step, first_step, max_steps,
                               force_jump, 10, _rosw_blocks(pr, ring_implicit, ring_coupling), int(jac_every), float(lu_ratio))
    sol.extra["n_jacobians"] = int(stats[8])
    sol.extra["n_factorisations"] = int(stats[9])
    return sol


def _scipy_steps(solver: Any, pr: Problem, t_eval: FloatArray, log: FloatArray,
                 max_steps: int) -> tuple[FloatArray, int, int, str]:
    """:func:`step_scipy`'s loop: step ``solver`` to the last sampling time, running the model's accepted-step
    bookkeeping after each step and sampling its dense output; returns the samples, steps, status and message."""
    y = np.full((len(t_eval), len(pr.y0)), np.nan)
    k, steps, status, message = 0, 0, STATUS_OK, "reached the end"
    while k < len(t_eval) and t_eval[k] <= pr.t0:
        y[k] = pr.y0
        k += 1
    while k < len(t_eval):
        if steps >= max_steps:
            status, message = 1, _MESSAGES[1]
            break
        msg = solver.step()
        if solver.status == "failed":
            status, message = 3, str(msg)
            break
        steps += 1
        model_post(pr.model_id, solver.t, solver.y, pr.params, log)  # accepted-step bookkeeping
        if k < len(t_eval) and (t_eval[k] <= solver.t or solver.status == "finished"):
            dense = solver.dense_output()
            while k < len(t_eval) and (t_eval[k] <= solver.t or solver.status == "finished"):
                y[k] = dense(t_eval[k])
                k += 1
    return y, steps, status, message


def step_scipy(pr: Problem, t_eval: FloatArray, method: str, rtol: float, max_step: float = np.inf,
               first_step: float | None = None, max_steps: int = 50_000_000,
               fun: Callable[[float, FloatArray, FloatArray], FloatArray] | None = None) -> Solution:
    """Step one of scipy's ``solve_ivp`` steppers, running the model's accepted-step bookkeeping after each step.

    ``fun(t, y, log)`` replaces the compiled right-hand side (the benchmarks pass the numpy reference).
    """
    log = pr.log.copy()
    buf = np.empty(len(pr.y0))
    count = [0]

    def compiled(t: float, y: FloatArray, log: FloatArray) -> FloatArray:
        model_rhs(pr.model_id, t, y, pr.params, log, buf)
        return buf.copy()

    rhs = fun or compiled

    def counted(t: float, y: FloatArray) -> FloatArray:
        count[0] += 1
        return rhs(t, y, log)

    kw: dict[str, Any] = {"max_step": max_step}
    if first_step:
        kw["first_step"] = first_step
    structure = JacobianStructure.for_problem(pr) if fun is None and method in _IMPLICIT else None
    if structure is not None:  # the compiled path gets the structured Jacobian (its sparsity)
        evaluate, jac = structure.evaluator(pr, log, pr.atol / rtol), np.empty((len(pr.y0), len(pr.y0)))

        def jacobian(t: float, y: FloatArray) -> FloatArray:
            count[0] += structure.rhs_per_jacobian
            evaluate(t, y, jac)
            return jac.copy()
        kw["jac"] = jacobian
    start = time.perf_counter()
    solver = _SCIPY[method](counted, pr.t0, pr.y0.astype(np.float64), float(t_eval[-1]), rtol=rtol, atol=pr.atol,
                            **kw)
    y, steps, status, message = _scipy_steps(solver, pr, t_eval, log, max_steps)
    return Solution(t=t_eval, y=y, status=status, message=message, method=method, n_steps=steps, n_rhs=count[0],
                    wall_s=time.perf_counter() - start, extra={"log": log})


def _scipy(method: str) -> Callable[..., Solution]:
    def run(pr: Problem, t_eval: FloatArray, rtol: float, max_step: float, first_step: float | None,
            max_steps: int, force_jump: float) -> Solution:
        return step_scipy(pr, t_eval, method, rtol, max_step, first_step, max_steps)

    return run


def _auto(pr: Problem, t_eval: FloatArray, rtol: float, max_step: float, first_step: float | None,
          max_steps: int, force_jump: float) -> Solution:
    """The automatic switch (:mod:`cageless.simulation.auto_switch`): compiled DP5, then CVODE where that pays, in up to
    50 chunks. An infinite ``max_step`` gives each method its default cap; ``first_step`` is not used."""
    from cageless.simulation.auto_switch import solve_chunks

    cap = max_step if np.isfinite(max_step) else None
    start = t_eval if t_eval[0] == pr.t0 else np.concatenate([[pr.t0], t_eval])
    sol = solve_chunks(pr, start, rtol, "auto", cap, min(50, len(start) - 1), False, max_steps, force_jump)
    if start is not t_eval:
        sol.t, sol.y = t_eval, sol.y[1:]
    return sol


class Method(Protocol):
    """What every entry of :data:`METHODS` is: a function from a problem and its sample times to a
    :class:`Solution` (the arguments of :func:`solve`, checked there). A method sees the right-hand side, the
    contact hooks and the Jacobian structure through :mod:`cageless.simulation.kernels` and
    :mod:`cageless.simulation.jacobian`, never the model's parameter layout."""

    def __call__(self, pr: Problem, t_eval: FloatArray, rtol: float, max_step: float, first_step: float | None,
                 max_steps: int, force_jump: float) -> Solution: ...


METHODS: dict[str, Method] = {
    "dp5": _compiled("dp5", dp5_integrate),
    "rosw": _rosw,
    "ark4": _ark4,
    "CVODE": lambda pr, t, rtol, max_step, first_step, max_steps, force_jump: step_cvode(pr, t, rtol, max_step,
                                                                                       first_step, max_steps),
    **{m: _scipy(m) for m in ("RK45", "DOP853", "LSODA", "BDF", "Radau")},
    "auto": _auto,
}


def solve(problem: Problem, t_eval: npt.ArrayLike, method: str = "dp5", rtol: float = 1e-6,
          max_step: float = np.inf, first_step: float | None = None, max_steps: int = 50_000_000,
          force_jump: float = FORCE_JUMP, chunks: int | None = None, progress: bool = False) -> Solution:
    """Integrate ``problem`` and sample it at ``t_eval``.

    Parameters
    ----------
    problem
        The initial-value problem.
    t_eval
        Increasing sample times (s), the first at or after ``problem.t0``.
    method
        A key of :data:`METHODS`.
    rtol
        Relative tolerance; the absolute tolerances are the problem's, per state.
    max_step
        Largest step (s); ``"ark4"`` caps an infinite one at :data:`ARK_MAX_STEP_S` on problems with contacts.
    first_step
        First trial step (s); default 1e-3 of the span, at most ``max_step``.
    max_steps
        Bound on accepted plus rejected steps.
    force_jump
        Compiled methods reject a step longer than ``problem.onset_step`` across which an acceleration
        flagged by ``problem.jump_floor`` changes by more than this fraction of its size (plus its
        floor), and retry it at half the length, so a force that rises steeply inside a contact is
        resolved even when the error estimate passes (the role of the contact-force-change trigger of
        Gupta's GSTIFF integrator, paper §2.6). 0 turns it off.
    chunks
        Cut the run at sample times into about this many pieces
        (:func:`cageless.simulation.auto_switch.solve_chunks`): ``"auto"`` re-decides its method between them
        and ``progress`` shows a bar of the simulated time; an infinite ``max_step`` then gives each method its
        default cap. None: one piece (``"auto"`` always runs in up to 50).
    progress
        With ``chunks``: show the progress bar (and the compile notice of a first run).

    Raises
    ------
    ParameterError
        For an unknown method (with a suggestion) or bad tolerances or times, before anything runs.
    """
    t = _checked_times(problem, t_eval, method, rtol, max_step, force_jump)
    if chunks is not None:
        from cageless.simulation.auto_switch import solve_chunks

        cap = float(max_step) if np.isfinite(max_step) else None
        return solve_chunks(problem, t, rtol, method, cap, max(1, int(chunks)), progress, int(max_steps),
                            float(force_jump))
    return METHODS[method](problem, t, rtol, float(max_step), first_step, int(max_steps), float(force_jump))


def _checked_times(problem: Problem, t_eval: npt.ArrayLike, method: str, rtol: float, max_step: float,
                   force_jump: float) -> FloatArray:
    """:func:`solve`'s arguments checked before anything runs; the sample times as an array.

    Raises
    ------
    ParameterError
        For an unknown method (with a suggestion) or bad tolerances, times or absolute tolerances.
    """
    if method not in METHODS:
        raise ParameterError("method", "is not a solver" + (suggest(method, METHODS) or f"; use one of {list(METHODS)}"),
                             method)
    if not (0 < rtol < 1):
        raise ParameterError("rtol", "must lie in (0, 1)", rtol)
    if not (0 <= force_jump < np.inf):
        raise ParameterError("force_jump", "must be a fraction >= 0 (0 turns the force-jump control off)", force_jump)
    if not (max_step > 0):
        raise ParameterError("max_step", "must be > 0", max_step)
    t = np.asarray(t_eval, dtype=np.float64)
    if t.ndim != 1 or len(t) == 0 or t[0] < problem.t0 or np.any(np.diff(t) <= 0):
        raise ParameterError("t_eval", f"must be increasing times >= t0 = {problem.t0}")
    if problem.atol.shape != problem.y0.shape or np.any(problem.atol <= 0):
        raise ParameterError("atol", "must be positive, one per state")
    return t
