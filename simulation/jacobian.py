"""The structured finite-difference Jacobian of the bearing models, for the implicit backend.

An implicit BDF step solves a Newton system with the matrix I - gamma J, J = df/dy. CVODE's
default difference-quotient Jacobian perturbs one state at a time: one right-hand side per state
(76 at the planar level, 138 at the spatial level), and those evaluations were 58 % and 70 % of all
right-hand sides of a CVODE run. The bearing's Jacobian is sparse with a known structure:

* ball j's states reach only the rows of balls j - 1, j and j + 1 (ball-ball contacts join
  neighbours only), plus the rows of the inner ring's accelerations (every ball presses on the ring)
  and of the two energy counters (the input and dissipated power sum over every contact);
* the ring's states (position, axial position, tilt, their rates) reach every row;
* the energy counters (input work, dissipated energy) reach no row.

So J is a cyclic block-tridiagonal band with a dense border, an "arrowhead": no ordering makes it
banded, but it is sparse. Its columns are estimated in groups (Curtis, Powell & Reid, "On the
estimation of sparse Jacobian matrices", J. Inst. Math. Appl. 13 (1974) 117-119): balls at least
three apart round the ring share no ball row, so one right-hand side with the same state of every
ball of one colour perturbed gives all their ball rows at once. The ring and counter rows are sums
over the balls and contacts, so each perturbed ball's own share of them is evaluated separately
(:func:`cageless.simulation.kernels.model_ring_share`: its race contacts, its drag and the two ball-ball
contacts it takes part in, a fraction of a right-hand side): with balls of one colour three apart,
no contact joins two perturbed balls, so the change of a ball's share is the change of the sum.
Fourteen balls need four colours: 5 x 4 + 4 = 24 right-hand sides per planar Jacobian instead of 76,
and 9 x 4 + 10 = 46 instead of 138 at the spatial level.

The counter rows matter although nothing depends on the counters: left zero, the Newton iteration
updated the counters one iteration behind the states, and under steep dry friction at the spatial
level the energy balance drifted by 1.4e-5 of the input work against 4.3e-6 with full rows (10 ms).
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np
import numpy.typing as npt

from cageless.simulation.kernels import PLANAR, SPATIAL, model_rhs, model_ring_share
from cageless.simulation.models import planar, spatial
from cageless.simulation.problem import Problem

__all__ = ["JacobianStructure", "ball_colours", "dense_fd_jacobian", "grouped_fd"]

IntArray = npt.NDArray[np.int64]
FloatArray = npt.NDArray[np.float64]

_SRUR = float(np.sqrt(np.finfo(float).eps))


def ball_colours(n_balls: int) -> IntArray:
    """A colouring of the ball ring in which balls of one colour are at least three apart round the ring.

    Blocks 0 1 2 and 0 1 2 3 laid end to end keep that distance across every block boundary and across
    the ring's closure, so ``n_balls = 3 a + 4 b`` needs at most four colours (fourteen balls: 4).
    Rings that cannot be split so (fewer than six balls, other than three or four) give every ball its
    own colour.
    """
    if n_balls < 1:
        raise ValueError(f"n_balls must be positive, got {n_balls}")
    for fours in range(n_balls // 4 + 1):
        rest = n_balls - 4 * fours
        if rest % 3 == 0:
            colours = [c for _ in range(fours) for c in range(4)] + [c for _ in range(rest // 3) for c in range(3)]
            return np.array(colours, dtype=np.int64)
    return np.arange(n_balls, dtype=np.int64)


@numba.njit(cache=True)
def grouped_fd(model_id, t, y, p, log, f0, ball_cols, groups, ring_rows, ring_cols, floor, y_work, f1, share0,
               share1, dense, jac, jb, js, g):  # pragma: no cover - compiled
    """The grouped difference quotients at (t, y), f0 = f(t, y), written in one of two layouts; returns the
    right-hand sides used (one per (field, colour) and one per ring state; f0 and the shares not counted).

    The increment of state i is sqrt(eps) max(|y_i|, floor_i), as in CVODE's difference quotients.
    Columns of ball j (``ball_cols[:, j]``) reach the rows of balls j - 1, j, j + 1 and, through ball j's own
    share (:func:`cageless.simulation.kernels.model_ring_share`), the ``ring_rows``; the ring's columns
    (``ring_cols[:, 0]``) are estimated one at a time and reach every row.

    ``dense``: into ``jac`` (n x n; entries outside the structure are left as they are). Otherwise the
    Rosenbrock-W method's blocks (:mod:`cageless.simulation.integrators.rosw`): ``jb[j, 0, r, f]`` = d f[ball_cols[r,
    j]] / d y[ball_cols[f, j]], and with three balls or more ``jb[j, 1]`` and ``jb[j, 2]``, the same against the
    states of balls j - 1 and j + 1; ``js[j, q, f]`` = d f[ring_rows[q]] / d y[ball_cols[f, j]];
    ``g[c, i]`` = d f[i] / d y[ring_cols[c, 0]]. The unused layout's arrays may be any size.
    """
    n, n_fields, z, n_ring = y.shape[0], ball_cols.shape[0], ball_cols.shape[1], ring_rows.shape[0]
    for i in range(n):
        y_work[i] = y[i]
    if n_ring > 0:
        for j in range(z):
            model_ring_share(model_id, t, y, p, log, j, share0[j])
    for f in range(n_fields):
        for c in range(groups.shape[0]):
            for m in range(groups.shape[1]):
                j = groups[c, m]
                if j < 0:
                    break
                col = ball_cols[f, j]
                y_work[col] = y[col] + _SRUR * max(abs(y[col]), floor[col])
            model_rhs(model_id, t, y_work, p, log, f1)
            for m in range(groups.shape[1]):
                j = groups[c, m]
                if j < 0:
                    break
                col = ball_cols[f, j]
                h = y_work[col] - y[col]  # the increment as stored, so the quotient is exact in it
                _ball_columns(ball_cols, f0, f1, j, f, h, dense, jac, jb)
                if n_ring > 0:
                    _ring_share_rows(model_id, t, y_work, p, log, j, f, col, h, ring_rows, share0, share1,
                                     dense, jac, js)
                y_work[col] = y[col]
    _ring_columns(model_id, t, y, p, log, f0, ring_cols, floor, y_work, f1, dense, jac, g)
    return n_fields * groups.shape[0] + ring_cols.shape[0]


@numba.njit(cache=True, inline="always")
def _ring_share_rows(model_id, t, y_work, p, log, j, f, col, h, ring_rows, share0, share1, dense, jac,
                     js):  # pragma: no cover - compiled
    """Field f of ball j's column in the ring rows, from the change of ball j's own share (see :func:`grouped_fd`)."""
    model_ring_share(model_id, t, y_work, p, log, j, share1)
    for q in range(ring_rows.shape[0]):
        d = (share1[q] - share0[j, q]) / h
        if dense:
            jac[ring_rows[q], col] = d
        else:
            js[j, q, f] = d


@numba.njit(cache=True, inline="always")
def _ring_columns(model_id, t, y, p, log, f0, ring_cols, floor, y_work, f1, dense, jac,
                  g):  # pragma: no cover - compiled
    """The ring's columns, one right-hand side each, in every row (see :func:`grouped_fd`)."""
    n = y.shape[0]
    for c in range(ring_cols.shape[0]):
        col = ring_cols[c, 0]
        y_work[col] = y[col] + _SRUR * max(abs(y[col]), floor[col])
        h = y_work[col] - y[col]
        model_rhs(model_id, t, y_work, p, log, f1)
        for i in range(n):
            d = (f1[i] - f0[i]) / h
            if dense:
                jac[i, col] = d
            else:
                g[c, i] = d
        y_work[col] = y[col]


@numba.njit(cache=True, inline="always")
def _ball_columns(ball_cols, f0, f1, j, f, h, dense, jac, jb):  # pragma: no cover - compiled
    """Field f of ball j's column: the rows of balls j - 1, j and j + 1 (see :func:`grouped_fd`)."""
    n_fields, z = ball_cols.shape[0], ball_cols.shape[1]
    col = ball_cols[f, j]
    if dense:
        for dj in (-1, 0, 1):
            jj = (j + dj + z) % z
            for ff in range(n_fields):
                row = ball_cols[ff, jj]
                jac[row, col] = (f1[row] - f0[row]) / h
        return
    for r in range(n_fields):
        jb[j, 0, r, f] = (f1[ball_cols[r, j]] - f0[ball_cols[r, j]]) / h
    if z >= 3:  # the neighbours' rows: ball j is the lower neighbour of j + 1, the upper of j - 1
        up, down = (j + 1) % z, (j - 1 + z) % z
        for r in range(n_fields):
            jb[up, 1, r, f] = (f1[ball_cols[r, up]] - f0[ball_cols[r, up]]) / h
            jb[down, 2, r, f] = (f1[ball_cols[r, down]] - f0[ball_cols[r, down]]) / h


@numba.njit(cache=True)
def _structured_fd(model_id, t, y, p, log, ball_cols, groups, ring_rows, ring_cols, floor, jac,
                   y_work, f0, f1, share0, share1, unused):  # pragma: no cover - compiled
    """Fill ``jac`` (n x n, dense storage) with the grouped difference quotients (zero outside the structure)."""
    jac[:, :] = 0.0
    model_rhs(model_id, t, y, p, log, f0)
    grouped_fd(model_id, t, y, p, log, f0, ball_cols, groups, ring_rows, ring_cols, floor, y_work, f1, share0,
               share1, True, jac, unused[0], unused[1], unused[2])


@dataclass(frozen=True)
class JacobianStructure:
    """Where the nonzeros of a bearing model's Jacobian can be, and how to estimate them in groups."""

    #: State index of field f of ball j, (fields, Z).
    ball_cols: IntArray
    #: Balls of each colour, (colours, largest class), padded with -1.
    groups: IntArray
    #: Rows every ball reaches (the ring's accelerations, the energy counters), in the order of the model's
    #: ring share.
    ring_rows: IntArray
    #: Columns estimated one at a time (the ring's states).
    other_cols: IntArray
    #: Structural nonzeros, (n, n) boolean.
    pattern: npt.NDArray[np.bool_]

    @classmethod
    def for_problem(cls, problem: Problem) -> JacobianStructure | None:
        """The structure of ``problem``'s model, or None for a model without one (the test models)."""
        if problem.model_id not in (PLANAR, SPATIAL):
            return None
        z = problem.n_balls
        n = len(problem.y0)
        # the models own their state layouts
        fields, ring_rows, other, counters = (planar.planar_state_blocks(z) if problem.model_id == PLANAR
                                              else spatial.spatial_state_blocks(z, n))
        ball_cols = np.array(fields, dtype=np.int64)
        if sorted(ball_cols.ravel().tolist() + other + counters) != list(range(n)):
            raise ValueError(f"the state layout of model {problem.model_id} does not match its Jacobian structure")
        colours = ball_colours(z)
        members = [np.flatnonzero(colours == c) for c in range(colours.max() + 1)]
        groups = np.full((len(members), max(len(m) for m in members)), -1, dtype=np.int64)
        for c, m in enumerate(members):
            groups[c, :len(m)] = m
        pattern = np.zeros((n, n), dtype=bool)
        for j in range(z):
            rows = ball_cols[:, [(j - 1) % z, j, (j + 1) % z]].ravel()
            pattern[np.ix_(np.concatenate([rows, ring_rows]), ball_cols[:, j])] = True
        pattern[:, other] = True
        pattern[np.arange(n), np.arange(n)] = True  # the diagonal is always stored (I - gamma J)
        return cls(ball_cols, groups, np.array(ring_rows, dtype=np.int64), np.array(other, dtype=np.int64),
                   pattern)

    @property
    def rhs_per_jacobian(self) -> int:
        """Right-hand sides per Jacobian: one per (field, colour), one per ring state, one at the base point."""
        return self.ball_cols.shape[0] * self.groups.shape[0] + len(self.other_cols) + 1

    def evaluator(self, problem: Problem, log: FloatArray, floor: FloatArray):  # noqa: ANN201 - a closure
        """A function ``(t, y, jac)`` filling ``jac`` (n x n) for ``problem`` with this structure.

        ``floor`` (per state) sets the smallest perturbation scale: the increment of state i is
        sqrt(eps) max(|y_i|, floor_i), as in CVODE's own difference quotients.
        """
        n = len(problem.y0)
        g = len(self.ring_rows)
        work = [np.empty(n) for _ in range(4)]  # y copy (CVODE's y is read-only), perturbed y, f0, f1
        share0, share1 = np.empty((self.ball_cols.shape[1], g)), np.empty(g)
        floor = np.ascontiguousarray(floor, dtype=np.float64)
        ring_cols = np.ascontiguousarray(self.other_cols.reshape(-1, 1))
        unused = (np.zeros((1, 1, 1, 1)), np.zeros((1, 1, 1)), np.zeros((1, 1)))  # the block layout's arrays

        def evaluate(t: float, y: FloatArray, jac: FloatArray) -> None:
            work[3][:] = y
            _structured_fd(problem.model_id, float(t), work[3], problem.params, log, self.ball_cols, self.groups,
                           self.ring_rows, ring_cols, floor, jac, work[0], work[1], work[2], share0, share1, unused)

        return evaluate


def dense_fd_jacobian(problem: Problem, t: float, y: FloatArray, floor: FloatArray) -> FloatArray:
    """The plain one-state-at-a-time difference-quotient Jacobian (the reference in the tests)."""
    f0 = problem.rhs(t, y)
    n = len(y)
    jac = np.empty((n, n))
    for col in range(n):
        yp = y.copy()
        yp[col] = y[col] + _SRUR * max(abs(y[col]), floor[col])
        jac[:, col] = (problem.rhs(t, yp) - f0) / (yp[col] - y[col])
    return jac
