"""What a solve returns (:class:`Solution`), apart from :mod:`cageless.simulation.solve` so that the backends in
:mod:`cageless.simulation.integrators` can build one without importing the registry."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

from cageless.simulation.integrators.dp5 import STATUS_OK

__all__ = ["FloatArray", "MESSAGES", "Solution"]

FloatArray = npt.NDArray[np.float64]
#: The message of each status code of the compiled integrators (:mod:`cageless.simulation.integrators.dp5`).
MESSAGES = {0: "reached the end", 1: "too many steps", 2: "step size underflow", 3: "the state became non-finite"}


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
