"""One entry point over a registry of integrators, like ``scipy.integrate.solve_ivp``.

:func:`solve` runs a :class:`Problem` with the method named in :data:`METHODS`:

* ``"rosw"``: the Rosenbrock-W method ROS34PW2 with its whole loop compiled, linearly implicit in each ball's
  states and the ring's (:mod:`cageless.simulation.integrators.rosw`), with DP5's controls; its step is set by
  accuracy, not by the race damping's stability limit;
* ``"ark4"``: the additive Runge-Kutta IMEX method ARK4(3)6L[2]SA with its whole loop compiled, the race
  normal forces and the radial (and axial) kinematics implicit per ball, everything else explicit
  (:mod:`cageless.simulation.integrators.ark`), with DP5's controls and a looser absolute tolerance on the
  implicit speeds (:data:`ARK_SPEED_ATOL_FACTOR`);
* ``"dp5"``: Dormand-Prince 5(4) with its whole loop compiled (the default); it rejects and retries
  any step longer than ``Problem.onset_step`` in which a contact opens or closes, or across which a
  force jumps by more than the fraction ``force_jump`` (see :func:`solve`), and counts both;
* ``"CVODE"``: SUNDIALS CVODE's variable-order BDF (orders 1-5, Newton iteration) through
  scikit-sundae, on the compiled right-hand side, with the structured Jacobian of
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

import math
import time
import warnings
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Protocol

import numba
import numpy as np
import numpy.typing as npt
from scipy.integrate import BDF, DOP853, LSODA, RK45, Radau

from cageless.errors import ParameterError, suggest
from cageless.simulation.integrators.ark import ark_integrate
from cageless.simulation.integrators.dp5 import STATUS_OK, dp5_integrate
from cageless.simulation.integrators.rosw import JAC_EVERY, LU_RATIO, rosw_integrate
from cageless.simulation.jacobian import JacobianStructure
from cageless.simulation.kernels import implicit_speed_rows, model_gaps, model_post, model_rhs
from cageless.simulation.problem import Problem

__all__ = ["FORCE_JUMP", "Problem", "Solution", "Method", "METHODS", "CvodeSession", "solve", "step_scipy", "step_cvode"]

FloatArray = npt.NDArray[np.float64]
_SCIPY = {"RK45": RK45, "DOP853": DOP853, "LSODA": LSODA, "BDF": BDF, "Radau": Radau}
#: scipy's methods that use a Jacobian; on the compiled path they get the structured one.
_IMPLICIT = ("LSODA", "BDF", "Radau")
#: Default force-jump fraction (see :func:`solve`): a step across which a contact force more than
#: doubles or halves (a change above half its larger value) is retried shorter.
FORCE_JUMP = 0.5
_MESSAGES = {0: "reached the end", 1: "too many steps", 2: "step size underflow", 3: "the state became non-finite"}


@dataclass
class Solution:
    """What a solve returned: samples, status and statistics."""

    t: FloatArray
    y: FloatArray
    status: int
    message: str
    method: str
    n_steps: int = 0
    n_rejected: int = 0
    n_rhs: int = 0
    wall_s: float = 0.0
    n_onset_retries: int = 0
    n_contact_changes: int = 0
    n_force_jump_retries: int = 0
    #: Accepted steps at the edge of the explicit method's stability region (compiled methods only): when
    #: most steps are, the step size is set by stiffness, not accuracy.
    n_stiff_steps: int = 0
    extra: dict[str, Any] = field(default_factory=dict)

    @property
    def success(self) -> bool:
        """True when the integration reached the last requested time."""
        return self.status == STATUS_OK


def _run_compiled(name: str, integrate: Callable[..., int], pr: Problem, t_eval: FloatArray, rtol: float,
                  atol: FloatArray, max_step: float, first_step: float | None, max_steps: int, force_jump: float,
                  n_stats: int, *extra: Any) -> tuple[Solution, FloatArray]:
    """Run a compiled integrator (the signature of dp5_integrate, then ``extra``); its solution and raw stats."""
    out = np.full((len(t_eval), len(pr.y0)), np.nan)
    stats = np.zeros(n_stats)
    floor = np.zeros(len(pr.y0)) if pr.jump_floor is None else pr.jump_floor.astype(np.float64)
    log = pr.log.copy()
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
#: row took the spatial case past 0.01 pp).
ARK_SPEED_ATOL_FACTOR = 10.0


def _ark4(pr: Problem, t_eval: FloatArray, rtol: float, max_step: float, first_step: float | None,
          max_steps: int, force_jump: float) -> Solution:
    """The compiled IMEX method (:mod:`cageless.simulation.integrators.ark`), with the implicit speeds' absolute
    tolerances scaled by :data:`ARK_SPEED_ATOL_FACTOR`."""
    atol = pr.atol.astype(np.float64).copy()
    atol[implicit_speed_rows(pr.model_id, pr.n_balls)] *= ARK_SPEED_ATOL_FACTOR
    sol, _ = _run_compiled("ark4", ark_integrate, pr, t_eval, rtol, atol, max_step, first_step, max_steps,
                               force_jump, 8)
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


def _cvode_status(y: FloatArray, status: int) -> int:
    """Map a CVODE failure flag onto this module's status codes."""
    if not np.all(np.isfinite(y)):
        return 3
    return 1 if status == -1 else 2


#: Share of the predicted time to the next contact change that a CVODE step may cover (see
#: :meth:`CvodeSession.stop_time`); below 1 because the linear prediction misses accelerating approaches.
#: Contact changes inside steps longer than the onset step, and steps, over 5 ms at 3000 rpm (settled) /
#: 10 ms at 1800 rpm from the packed start: no control 16 of 19, 1257 / 9 of 204, 12497 steps; 1.0: 6, 1330
#: / 3, 12597; 0.7: 0, 1357 / 0, 12822; 0.5: 0, 1401 / 0, 12440.
ONSET_APPROACH = 0.7
#: CVODE's Jacobian and linear solver: ``"sparse"``, the structured Jacobian of :mod:`cageless.simulation.jacobian`
#: factorised by SuperLU_MT; ``"structured"``, the same Jacobian in CVODE's dense LU; ``"dense"``, CVODE's own
#: difference quotients (one right-hand side per state) and dense LU. Models without a structure (the test
#: models) always use ``"dense"``.
JACOBIANS = ("sparse", "structured", "dense")
JACOBIAN_DEFAULT = "structured"


def _jacobian_options(pr: Problem, session: CvodeSession, jacobian: str, rtol: float) -> dict[str, Any]:
    """CVODE's ``linsolver``, ``jacfn`` and ``sparsity`` for ``jacobian``."""
    if jacobian not in JACOBIANS:
        raise ParameterError("jacobian", f"must be one of {', '.join(JACOBIANS)}{suggest(jacobian, JACOBIANS)}",
                             jacobian)
    structure = JacobianStructure.for_problem(pr) if jacobian != "dense" else None
    if structure is None:
        return {"linsolver": "dense"}
    evaluate = structure.evaluator(pr, session.log, pr.atol / rtol)
    per_jacobian = structure.rhs_per_jacobian  # counted with the right-hand sides, for the cost model
    n = len(pr.y0)
    full = np.empty((n, n))

    def fill(t: float, y: FloatArray) -> None:
        session.n_jac += 1
        session.n_rhs += per_jacobian
        evaluate(t, y, full)

    if jacobian == "structured":
        def jac_dense(t: float, y: FloatArray, yp: FloatArray, jj: FloatArray) -> None:
            fill(t, y)
            jj[:, :] = full
        return {"linsolver": "dense", "jacfn": jac_dense}
    cols, rows = np.nonzero(structure.pattern.T)  # CSC order: by column, then row

    def jac_sparse(t: float, y: FloatArray, yp: FloatArray, jj: FloatArray) -> None:
        fill(t, y)
        jj[:] = full[rows, cols]
    return {"linsolver": "sparse", "jacfn": jac_sparse, "sparsity": structure.pattern.astype(np.float64)}


@dataclass
class CvodeSession:
    """A CVODE integrator kept between calls, so a run in chunks does not restart it cold each time.

    A cold restart begins again at order 1 from a small step and evaluates a new Jacobian. Over 20 ms in
    50 chunks that cost 8 % more wall time under a 20 kN load and 36 % at the spatial level (500 N + 400 N
    axial) than one uninterrupted call (measured with CVODE's own difference-quotient Jacobian).
    """

    solver: Any
    model_id: int
    params: FloatArray
    log: FloatArray
    #: CVODE's own time and state: the end of its last internal step (at or past the last sample).
    t: float
    state: FloatArray
    n_rhs: int = 0
    #: Jacobians evaluated by the structured routine (CVODE's own difference quotients are not counted here).
    n_jac: int = 0
    #: Onset control (see :func:`step_cvode`): the contact overlaps (:func:`cageless.simulation.kernels.model_gaps`)
    #: at the last three step ends, the length of the step before the last (0 until there is one), and the
    #: predicted time from the last step end to the next contact change.
    gaps: FloatArray | None = None
    gaps_before: FloatArray | None = None
    gaps_older: FloatArray | None = None
    dt_before: float = 0.0
    tau: float = np.inf
    onset_step: float = 0.0
    onset_control: bool = False

    @classmethod
    def start(cls, pr: Problem, rtol: float, max_step: float, first_step: float | None,
              max_steps: int, jacobian: str = JACOBIAN_DEFAULT, onset_control: bool = True) -> CvodeSession:
        """A new integrator at ``pr``'s start; ``jacobian`` is one of :data:`JACOBIANS`; ``onset_control``
        (for a model with contacts and ``pr.onset_step > 0``) stops steps at predicted contact onsets (see
        :func:`step_cvode`)."""
        try:
            from sksundae.cvode import CVODE
        except ImportError as exc:  # pragma: no cover - a declared dependency
            raise ParameterError("method", "CVODE needs scikit-sundae; install it (pip install scikit-sundae) "
                                 "or choose dp5 or LSODA", "CVODE") from exc
        buf = np.empty(len(pr.y0))  # CVODE's y is read-only; a writable copy avoids a second compiled variant
        session = cls(None, pr.model_id, pr.params, pr.log.copy(), float(pr.t0), pr.y0.astype(np.float64))

        def rhs(t: float, y: FloatArray, yp: FloatArray) -> None:
            session.n_rhs += 1
            buf[:] = y
            model_rhs(session.model_id, t, buf, session.params, session.log, yp)

        options = _jacobian_options(pr, session, jacobian, rtol)
        if pr.onset_step > 0 and pr.n_gaps > 0:  # contact changes are counted either way
            session.onset_step, session.onset_control = pr.onset_step, onset_control
            session.gaps = np.empty(pr.n_gaps)
            model_gaps(pr.model_id, session.state, pr.params, session.gaps)
            session.gaps_before = session.gaps.copy()
            session.gaps_older = session.gaps.copy()
        with warnings.catch_warnings():  # sparsity with a jacfn: scikit-sundae notes its own routine is unused
            warnings.filterwarnings("ignore", message="Custom sparse Jacobian approximation")
            session.solver = CVODE(rhs, method="BDF", rtol=rtol, atol=pr.atol.astype(np.float64),
                                   max_step=0.0 if not np.isfinite(max_step) else max_step,
                                   first_step=first_step or 0.0, max_num_steps=max_steps, **options)
        session.solver.init_step(session.t, session.state.copy())
        return session

    def sample(self, t: float) -> FloatArray:
        """The state at ``t``, inside the last internal step (CVODE's interpolant)."""
        return self.state if t == self.t else np.ravel(self.solver.step(float(t)).y)

    def stop_time(self, t_next_sample: float) -> float:
        """Where the next step must end: the next sample, or sooner where a contact is predicted to open or
        close (:func:`_onset_update`). A change predicted at time tau from now ends the step at
        :data:`ONSET_APPROACH` tau, at least ``onset_step`` ahead: the steps close in on the onset, and the
        one that crosses it is at most ``onset_step`` long (DP5 retries such a step at that length)."""
        if not self.onset_control:
            return t_next_sample
        return min(t_next_sample, self.t + max(ONSET_APPROACH * self.tau, self.onset_step))

    def after_step(self, t: float, state: FloatArray) -> bool:
        """Record a step end; True when a contact opened or closed during the step."""
        if self.gaps is None:
            self.t, self.state = t, state
            return False
        self.gaps_older, self.gaps_before, self.gaps = self.gaps_before, self.gaps, self.gaps_older
        changed, self.tau = _onset_update(self.model_id, state, self.params, self.gaps, self.gaps_before,
                                          self.gaps_older, t - self.t, self.dt_before)
        self.dt_before = t - self.t
        self.t, self.state = t, state
        return changed


@numba.njit(cache=True)
def _onset_update(model_id, y, p, gaps, before, older, dt, dt_before):  # pragma: no cover - compiled
    """Fill ``gaps`` with the contact overlaps at ``y``; return whether a contact changed since
    ``before`` (``dt`` earlier) and the earliest time at which an extrapolated overlap changes sign (inf if none).

    Each overlap is extrapolated linearly from the last two step ends and, once there is a third (``older``,
    ``dt_before`` before ``before``), also with its second divided difference: a contact's approach speeds up
    or slows down under the forces on the two bodies (a ball pushed into its neighbour by the race traction),
    which a straight line through the last two points misses. The earlier of the two predicted sign changes
    counts, so the curvature only ever shortens a step."""
    model_gaps(model_id, y, p, gaps)
    changed, tau = False, np.inf
    for i in range(gaps.shape[0]):
        if (gaps[i] > 0.0) != (before[i] > 0.0):
            changed = True
        if dt <= 0.0:
            continue
        rate = (gaps[i] - before[i]) / dt
        if rate != 0.0:
            t_i = -gaps[i] / rate
            if 0.0 < t_i < tau:
                tau = t_i
        if dt_before > 0.0:
            # quadratic through the three step ends: g(s) = g + v s + a s^2 / 2, s from the last end
            acc = 2.0 * (rate - (before[i] - older[i]) / dt_before) / (dt + dt_before)
            v = rate + 0.5 * acc * dt
            t_q = _first_root(gaps[i], v, 0.5 * acc)
            if 0.0 < t_q < tau:
                tau = t_q
    return changed, tau


@numba.njit(cache=True, inline="always")
def _first_root(c0, c1, c2):  # pragma: no cover - compiled
    """The smallest positive root of c0 + c1 s + c2 s^2 (inf if none)."""
    if c2 == 0.0:
        return -c0 / c1 if c1 != 0.0 and -c0 / c1 > 0.0 else np.inf
    disc = c1 * c1 - 4.0 * c2 * c0
    if disc < 0.0:
        return np.inf
    q = -0.5 * (c1 + math.copysign(math.sqrt(disc), c1))  # the stable pair of roots q / c2 and c0 / q
    best = np.inf
    for root in (q / c2, c0 / q if q != 0.0 else np.inf):
        if 0.0 < root < best:
            best = root
    return best


def step_cvode(pr: Problem, t_eval: FloatArray, rtol: float, max_step: float = np.inf,
               first_step: float | None = None, max_steps: int = 50_000_000,
               session: CvodeSession | None = None, jacobian: str = JACOBIAN_DEFAULT,
               onset_control: bool = True) -> Solution:
    """Integrate with SUNDIALS CVODE (BDF) one internal step at a time.

    Each call asks for one step with a stop time: the next sample (so samples are step ends, not
    interpolated) or, with ``onset_control``, sooner where a contact is predicted to open or close
    (:meth:`CvodeSession.stop_time`). CVODE cannot take a step back as DP5 does, so it is stopped ahead
    of an onset instead of retrying across it; the steps that still changed a contact while longer than
    ``pr.onset_step`` (a prediction missed) are counted in ``extra["long_onset_steps"]``, every contact
    change in ``n_contact_changes``. CVODE's own root finding was tried for this and fails on these
    overlaps: at a located root the overlap is exactly zero and stays so at float resolution a few
    ulps of time later, which CVODE rejects ("root found at and very near t"). After every step the
    model's bookkeeping runs on its end state. ``session`` continues an earlier call's integrator (whose
    last sample was ``pr``'s start; ``pr.y0`` and ``pr.log`` are then its own); the solution's
    ``extra["cvode"]`` is the session to continue with.
    """
    start = time.perf_counter()
    if session is None:
        session = CvodeSession.start(pr, rtol, max_step, first_step, max_steps, jacobian, onset_control)
    rhs_before = session.n_rhs
    y = np.full((len(t_eval), len(pr.y0)), np.nan)
    k, steps, changes, long_steps, status, message = 0, 0, 0, 0, STATUS_OK, "reached the end"
    while k < len(t_eval) and t_eval[k] <= session.t:
        y[k] = session.sample(t_eval[k])
        k += 1
    while k < len(t_eval):
        if steps >= max_steps:
            status, message = 1, _MESSAGES[1]
            break
        t_last = session.t
        res = session.solver.step(float(t_eval[-1]), method="onestep", tstop=session.stop_time(float(t_eval[k])))
        # a writable copy: a read-only array would compile a second variant of the bookkeeping
        state, now = np.array(res.y, dtype=np.float64).reshape(-1), float(np.ravel(res.t)[0])
        if not res.success:
            status = _cvode_status(state, int(res.status))
            message = f"CVODE: {res.message}"
            break
        steps += 1
        if session.after_step(now, state):
            changes += 1
            long_steps += now - t_last > session.onset_step * (1.0 + 1e-9)
        model_post(session.model_id, now, state, session.params, session.log)  # accepted-step bookkeeping
        while k < len(t_eval) and t_eval[k] <= now:
            y[k] = state if t_eval[k] == now else session.sample(t_eval[k])
            k += 1
    return Solution(t=t_eval, y=y, status=status, message=message, method="CVODE", n_steps=steps,
                    n_rhs=session.n_rhs - rhs_before, n_contact_changes=changes,
                    wall_s=time.perf_counter() - start,
                    extra={"log": session.log, "cvode": session, "long_onset_steps": long_steps})


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
        Largest step (s).
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
    if chunks is not None:
        from cageless.simulation.auto_switch import solve_chunks

        cap = float(max_step) if np.isfinite(max_step) else None
        return solve_chunks(problem, t, rtol, method, cap, max(1, int(chunks)), progress, int(max_steps),
                            float(force_jump))
    return METHODS[method](problem, t, rtol, float(max_step), first_step, int(max_steps), float(force_jump))
