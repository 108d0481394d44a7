"""The parameter layout the ball-bearing models share, generated from the effects table.

The planar model's slots are its body (ball count and size, masses, race diameters, the load and the
drive) followed by every effect's flag and parameter slots (:func:`cageless.simulation.effects.parameter_slots`);
the spatial model extends them (:data:`cageless.simulation.models.spatial.LAYOUT`). The ``P_*`` constants are
the slot positions, module-level integers that numba compiles in as literals; only the models and
their physics modules (:mod:`cageless.simulation.models.contact_laws`) use them.
"""

from __future__ import annotations

import numba

from cageless.simulation.effects import parameter_slots
from cageless.simulation.layout import ParameterLayout

__all__ = ["BODY_SLOTS", "LAYOUT", "OBSERVABLES", "N_OBS", "signature_add"]

#: The model body: ball count Z, ball diameter D, ball mass M and spin inertia I, the ring's translational
#: mass MR, the race diameters DI and DO, the radial load FR, the ring speed WI and its ramp time RAMP.
BODY_SLOTS = ("Z", "D", "M", "I", "MR", "DI", "DO", "FR", "WI", "RAMP")
LAYOUT = ParameterLayout(parameter_slots(BODY_SLOTS))

P_Z, P_D, P_M, P_I, P_MR, P_DI, P_DO, P_FR, P_WI, P_RAMP = LAYOUT.slots(*BODY_SLOTS)
P_F_RACE, P_KI, P_KO = LAYOUT.slots("F_RACE", "KI", "KO")
P_F_LUB, P_CHO = LAYOUT.slots("F_LUB", "CHO")
P_F_TRAC, P_TA, P_TB, P_TC, P_TD, P_U_FLOOR = LAYOUT.slots("F_TRAC", "TA", "TB", "TC", "TD", "U_FLOOR")
(P_F_FILM,) = LAYOUT.slots("F_FILM")
(P_F_ROLL,) = LAYOUT.slots("F_ROLL")
P_RC_I, P_RH_I, P_LT_FILM_I, P_LT_FIX_I = LAYOUT.slots("RC_I", "RH_I", "LT_FILM_I", "LT_FIX_I")
P_RC_O, P_RH_O, P_LT_FILM_O, P_LT_FIX_O = LAYOUT.slots("RC_O", "RH_O", "LT_FILM_O", "LT_FIX_O")
P_F_BB, P_KB, P_CHI, P_V_IN_MIN = LAYOUT.slots("F_BB", "KB", "CHI", "V_IN_MIN")
P_F_BBFRIC = LAYOUT.index("F_BBFRIC")
P_F_BBFILM, P_ETA0, P_H0 = LAYOUT.slots("F_BBFILM", "ETA0", "H0")
P_F_GRAV, P_G = LAYOUT.slots("F_GRAV", "G")
P_F_DRAG, P_CD, P_RHO_MIX, P_MU_MIX = LAYOUT.slots("F_DRAG", "CD", "RHO_MIX", "MU_MIX")
P_DRY, P_MU_DRY, P_V_REG, P_MU_STATIC, P_V_STRIBECK = LAYOUT.slots("DRY", "MU_DRY", "V_REG", "MU_STATIC",
                                                                   "V_STRIBECK")
N_PARAMS = len(LAYOUT)

#: What the models' observation pass (``planar_observe``, ``spatial_observe``) writes per ball j, in this order:
#: the elastic (Hertz) part of the outer and inner race normal forces (N), the race traction the tangential
#: law gives (N, on the ball along the rolling direction), the race contacts' entrainment speeds u_r (m/s),
#: the elastic normal force and the friction magnitude between balls j and j+1 (N), then the race films (m),
#: filled from the same pass by :func:`cageless.simulation.models.observables.kernel_observables`, and the
#: sliding speed of the ball's surface against the outer and inner race at the contact centre, along the
#: direction the traction is given in (m/s: the speed the traction law was evaluated at, so the traction
#: opposes it).
OBSERVABLES = ("outer_normal", "inner_normal", "outer_traction", "inner_traction", "outer_entrainment",
               "inner_entrainment", "ball_ball_normal", "ball_ball_traction", "outer_film", "inner_film",
               "outer_sliding", "inner_sliding")
(OBS_OUTER_NORMAL, OBS_INNER_NORMAL, OBS_OUTER_TRACTION, OBS_INNER_TRACTION, OBS_OUTER_ENTRAIN, OBS_INNER_ENTRAIN,
 OBS_BB_NORMAL, OBS_BB_TRACTION, OBS_OUTER_FILM, OBS_INNER_FILM, OBS_OUTER_SLIDE, OBS_INNER_SLIDE) = range(
    len(OBSERVABLES))
N_OBS = len(OBSERVABLES)


@numba.njit(cache=True, inline="always")
def signature_add(sig, j, z, outer, inner, pair):  # pragma: no cover - compiled
    """Ball j's closed contacts added to a contact signature: (index + 1) of each closed contact, the outer race
    contacts indexed 0..Z-1, the inner Z..2Z-1, the pairs (j, j+1) 2Z..3Z-1 (both models' ``*_signature``)."""
    if outer > 0.0:
        sig += 1.0 + j
    if inner > 0.0:
        sig += 1.0 + z + j
    if pair > 0.0:
        sig += 1.0 + 2 * z + j
    return sig
