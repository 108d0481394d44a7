"""Contact laws the bearing models share, reading their parameters from the named slots.

:func:`tangential` is the friction law of every sliding contact (race and ball-ball, planar and
spatial): the lubricated traction curve, or dry Coulomb-Stribeck friction when the ``dry_friction``
effect is on (:mod:`cageless.simulation.traction` holds the formulas). :data:`race_extra` adds the registered extra
race-contact laws (:mod:`cageless.simulation.models.race_laws`).
"""

from __future__ import annotations

import numba

from cageless.simulation.models import race_laws
import math

from cageless.simulation.models.base import (LAYOUT, P_CD, P_D, P_MU_MIX, P_RHO_MIX, P_DRY, P_MU_DRY, P_MU_STATIC, P_TA, P_TB, P_TC, P_TD, P_U_FLOOR, P_V_REG,
                                    P_V_STRIBECK)
from cageless.simulation.physics.drag import churning_moment, drag_force
from cageless.simulation.traction import dry_friction, regression_traction

__all__ = ["tangential", "race_extra", "RACE_LAWS", "ball_drag", "ball_churning"]


@numba.njit(cache=True, inline="always")
def tangential(u_s, u_r, q, p):  # pragma: no cover - compiled
    """Signed tangential force (N) at a contact sliding at u_s: lubricated traction, or dry friction."""
    if p[P_DRY] > 0.5:
        return dry_friction(u_s, q, p[P_MU_DRY], p[P_V_REG], p[P_MU_STATIC], p[P_V_STRIBECK])
    return regression_traction(u_s, u_r, q, p[P_TA], p[P_TB], p[P_TC], p[P_TD], p[P_U_FLOOR])


@numba.njit(cache=True, inline="always")
def ball_drag(v, p):  # pragma: no cover - compiled
    """Signed drag (N) on a ball moving at ``v`` (m/s) through the oil-air mixture: the Schiller-Naumann law
    (:func:`cageless.simulation.physics.drag.drag_force`), or 1/2 C_D rho A v|v| with a fixed C_D when the slot CD > 0."""
    if p[P_CD] > 0.0:
        return -0.125 * math.pi * p[P_CD] * p[P_RHO_MIX] * p[P_D] * p[P_D] * v * abs(v)
    return drag_force(v, p[P_D], p[P_RHO_MIX], p[P_MU_MIX])


@numba.njit(cache=True, inline="always")
def ball_churning(omega, p):  # pragma: no cover - compiled
    """Signed churning moment (N m) against a spin of magnitude ``omega`` (rad/s)
    (:func:`cageless.simulation.physics.drag.churning_moment`)."""
    return churning_moment(omega, p[P_D], p[P_RHO_MIX], p[P_MU_MIX])


#: The registered extra race-contact laws (:mod:`cageless.simulation.models.race_laws`), summed under their flags, and
#: whether there are any (a compile-time constant: with none, the race contacts compile without them).
race_extra = race_laws.compose(LAYOUT)
RACE_LAWS = race_laws.freeze()
