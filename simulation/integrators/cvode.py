"""SUNDIALS CVODE's variable-order BDF as a backend of :func:`cageless.simulation.solve.solve`, stepped one internal
step at a time (:func:`step_cvode`) so that the contact bookkeeping runs after every accepted step, and stopped
ahead of predicted contact changes (it cannot take a step back as the compiled methods do).

Through scikit-sundae, on the compiled right-hand side, with the structured Jacobian of
:mod:`cageless.simulation.jacobian` (see :data:`JACOBIANS`); a :class:`CvodeSession` keeps the integrator between
the chunks of a long run. Its rejected steps are not counted (scikit-sundae does not expose them).
"""

from __future__ import annotations

import math
import time
import warnings
from dataclasses import dataclass
from typing import Any

import numba
import numpy as np

from cageless.errors import ParameterError, suggest
from cageless.simulation.integrators.dp5 import ONSET_TOL, STATUS_OK
from cageless.simulation.jacobian import JacobianStructure
from cageless.simulation.kernels import model_gaps, model_post, model_rhs
from cageless.simulation.problem import Problem
from cageless.simulation.solution import MESSAGES as _MESSAGES
from cageless.simulation.solution import FloatArray, Solution

__all__ = ["ONSET_APPROACH", "JACOBIANS", "JACOBIAN_DEFAULT", "CvodeSession", "step_cvode"]


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
            long_steps += now - t_last > session.onset_step * (1.0 + ONSET_TOL)
        model_post(session.model_id, now, state, session.params, session.log)  # accepted-step bookkeeping
        while k < len(t_eval) and t_eval[k] <= now:
            y[k] = state if t_eval[k] == now else session.sample(t_eval[k])
            k += 1
    return Solution(t=t_eval, y=y, status=status, message=message, method="CVODE", n_steps=steps,
                    n_rhs=session.n_rhs - rhs_before, n_contact_changes=changes,
                    wall_s=time.perf_counter() - start,
                    extra={"log": session.log, "cvode": session, "long_onset_steps": long_steps})

