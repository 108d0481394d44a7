"""The initial-value problem the integrators solve.

A problem names its model by :data:`model_id` (see :mod:`cageless.simulation.kernels`):
the compiled integrator calls the model's right-hand side by a static switch,
not through a function argument, so numba can cache the compiled loop on disk
and a fresh process does not recompile it.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt

if TYPE_CHECKING:
    from cageless.simulation.layout import ParameterLayout

__all__ = ["Problem"]

FloatArray = npt.NDArray[np.float64]


@dataclass(frozen=True)
class Problem:
    """An initial-value problem: model, parameters, contact log, start, absolute tolerances.

    ``log`` is the model's contact log, a float array the kernels update after each accepted step (per-pair
    onset speeds and open contact episodes, then the logged episodes; see
    :func:`cageless.simulation.models.planar.log_size`) with a scratch tail for the right-hand side.
    """

    model_id: int
    params: FloatArray
    log: FloatArray
    y0: FloatArray
    t0: float
    atol: FloatArray
    name: str = "problem"
    #: Steps longer than this (s) in which a contact opens or closes are rejected and retried shorter
    #: (0: no contact-onset control). See :func:`cageless.simulation.kernels.model_signature`.
    onset_step: float = 0.0
    #: Per-component floor (units of dy/dt) of the force-jump test; > 0 marks the accelerations that are
    #: checked (None: no force-jump control). The floor is the acceleration a 1 N force gives the body, so
    #: changes of forces well below 1 N never count as jumps. See :func:`cageless.simulation.solve.solve`.
    jump_floor: FloatArray | None = None
    #: Names of the slots of ``params`` (None for the test models, whose few parameters are positional).
    layout: ParameterLayout | None = None
    #: Effects of the table that are on (:data:`cageless.simulation.effects.EFFECTS`), for the solvers' choices.
    effects: frozenset[str] = field(default_factory=frozenset)
    #: Balls of a bearing model (0 for the test models).
    n_balls: int = 0
    #: Contact overlaps the model reports (:func:`cageless.simulation.kernels.model_gaps`; 0: none).
    n_gaps: int = 0

    def parameter(self, name: str) -> float:
        """The value of the parameter slot ``name`` (see :mod:`cageless.simulation.layout`)."""
        if self.layout is None:
            raise KeyError(f"{self.name} has no named parameter slots")
        return self.layout.value(self.params, name)

    def rhs(self, t: float, y: FloatArray, log: FloatArray | None = None) -> FloatArray:
        """dy/dt at (t, y), evaluated by the compiled kernel (``log`` defaults to a copy of the problem's)."""
        from cageless.simulation.kernels import model_rhs

        out = np.empty_like(np.asarray(y, dtype=np.float64))
        model_rhs(self.model_id, float(t), np.asarray(y, dtype=np.float64), self.params,
                  self.log.copy() if log is None else log, out)
        return out
