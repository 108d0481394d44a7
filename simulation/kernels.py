"""The registry of compiled model kernels: a static switch on the model id.

The integrator calls :func:`model_rhs` and :func:`model_post`; each branch is a
direct call to a module-level compiled function, which numba can inline and
cache. Add a model by giving it an id here.
"""

from __future__ import annotations

import numba

from cageless.simulation.models import (implicit_normal, implicit_normal_spatial, planar, spatial, textbook,
                                        two_balls)

__all__ = ["PLANAR", "SPATIAL", "TWO_BALLS", "OSCILLATOR", "RICCATI", "DAMPED", "model_rhs", "model_post",
           "model_signature", "model_ring_share", "model_gaps", "model_implicit", "model_stage", "model_filter_error",
           "implicit_speed_rows", "ring_rows"]

PLANAR, TWO_BALLS, SPATIAL = planar.MODEL_ID, two_balls.MODEL_ID, spatial.MODEL_ID
OSCILLATOR, RICCATI, DAMPED = textbook.OSCILLATOR, textbook.RICCATI, textbook.DAMPED


@numba.njit(cache=True)
def model_rhs(model_id, t, y, p, log, dydt):  # pragma: no cover - compiled
    """dy/dt of model ``model_id`` into ``dydt``."""
    if model_id == PLANAR:
        planar.planar_rhs(t, y, p, log, dydt)
    elif model_id == SPATIAL:
        spatial.spatial_rhs(t, y, p, log, dydt)
    elif model_id == TWO_BALLS:
        two_balls.two_ball_rhs(t, y, p, log, dydt)
    elif model_id == OSCILLATOR:
        textbook.oscillator_rhs(t, y, p, log, dydt)
    elif model_id == DAMPED:
        textbook.damped_rhs(t, y, p, log, dydt)
    else:
        textbook.riccati_rhs(t, y, p, log, dydt)


@numba.njit(cache=True)
def model_post(model_id, t, y, p, log):  # pragma: no cover - compiled
    """Bookkeeping after an accepted step (contact episodes)."""
    if model_id == PLANAR or model_id == SPATIAL:
        planar.planar_post(t, y, p, log)
    elif model_id == TWO_BALLS:
        two_balls.two_ball_post(t, y, p, log)


@numba.njit(cache=True)
def model_signature(model_id, y, p):  # pragma: no cover - compiled
    """A number that changes whenever a contact opens or closes (0 for models without contacts)."""
    if model_id == PLANAR:
        return planar.planar_signature(y, p)
    if model_id == SPATIAL:
        return spatial.spatial_signature(y, p)
    return 0.0


@numba.njit(cache=True)
def model_gaps(model_id, y, p, out):  # pragma: no cover - compiled
    """Every contact's overlap (m, > 0 closed) for the ball-bearing models (3 Z values; see
    :func:`cageless.simulation.models.planar.planar_gaps`)."""
    if model_id == PLANAR:
        planar.planar_gaps(y, p, out)
    elif model_id == SPATIAL:
        spatial.spatial_gaps(y, p, out)


@numba.njit(cache=True)
def model_ring_share(model_id, t, y, p, log, j, out):  # pragma: no cover - compiled
    """Ball j's additive share of the rows every ball reaches (the ring's accelerations), for the structured
    Jacobian of :mod:`cageless.simulation.jacobian`. Only the ball-bearing models have one."""
    if model_id == PLANAR:
        planar.planar_ring_share(t, y, p, log, j, out)
    elif model_id == SPATIAL:
        spatial.spatial_ring_share(t, y, p, log, j, out)


@numba.njit(cache=True)
def model_implicit(model_id, t, y, p, hg, k_i, work):  # pragma: no cover - compiled
    """The implicit part f_I of the model's IMEX split into ``k_i`` (the race contacts' normal forces and the
    balls' radial and axial kinematics, per ball: :mod:`cageless.simulation.models.implicit_normal`,
    :mod:`cageless.simulation.models.implicit_normal_spatial`); with ``hg > 0`` the stage equation
    y = y_Z + hg f_I(y) is solved first, in place on ``y`` (the predictor y_Z on entry). ``work`` (12) is scratch.
    A model without a split has f_I = 0 (every term explicit)."""
    if model_id == PLANAR:
        implicit_normal.planar_implicit_normal(y, p, hg, k_i)
    elif model_id == SPATIAL:
        implicit_normal_spatial.spatial_implicit_normal(y, p, hg, k_i)
    elif model_id == DAMPED:
        textbook.damped_implicit(y, p, hg, k_i)
    else:
        for i in range(k_i.shape[0]):
            k_i[i] = 0.0


@numba.njit(cache=True)
def model_stage(model_id, t, y, p, log, hg, k_i, dydt, work):  # pragma: no cover - compiled
    """One stage of the IMEX method: :func:`model_implicit` with ``hg`` (y solved in place, f_I(y) into ``k_i``),
    then :func:`model_rhs` at the solved y into ``dydt``; the planar model computes its angles' cos and sin once
    for both (:func:`cageless.simulation.models.implicit_normal.planar_stage`), the others call the two."""
    if model_id == PLANAR:
        implicit_normal.planar_stage(t, y, p, log, hg, k_i, dydt)
    else:
        model_implicit(model_id, t, y, p, hg, k_i, work)
        model_rhs(model_id, t, y, p, log, dydt)


def implicit_speed_rows(model_id: int, n_balls: int) -> list[int]:
    """The state rows of the speeds that :func:`model_implicit` integrates implicitly with the race normal
    forces: each ball's radial speed r' (planar), and its axial speed x' (spatial); none for other models."""
    z = n_balls
    if model_id == PLANAR:
        return list(range(2 * z, 3 * z))
    if model_id == SPATIAL:
        return list(range(2 * z, 3 * z)) + list(range(6 * z + 6, 7 * z + 6))
    return []


def ring_rows(model_id: int, n_balls: int) -> list[int]:
    """The state rows every ball reaches (the ring's accelerations and the energy counters; see
    :attr:`cageless.simulation.jacobian.JacobianStructure.ring_rows`); none for models without a ring."""
    if model_id == PLANAR:
        return planar.planar_ring_rows(n_balls)
    if model_id == SPATIAL:
        return spatial.spatial_ring_rows(n_balls)
    return []


@numba.njit(cache=True)
def model_filter_error(model_id, y, p, hg, e):  # pragma: no cover - compiled
    """Filter an IMEX error estimate ``e`` in place through the implicit part's stiffness at ``y``,
    (I - hg J_I)^-1 e, where the model has such a filter (the planar model's race normal forces:
    :func:`cageless.simulation.models.implicit_normal.planar_filter_error`); unchanged otherwise."""
    if model_id == PLANAR:
        implicit_normal.planar_filter_error(y, p, hg, e)
    elif model_id == SPATIAL:
        implicit_normal_spatial.spatial_filter_error(y, p, hg, e)
