"""What a run reports besides the states: contact forces, films, contact angles, positions and spins.

The contact forces, entrainment speeds and films come from the compiled models themselves: at every sample
:func:`kernel_observables` evaluates the model's own race and ball-ball force functions (the ones its
right-hand side calls; :func:`cageless.simulation.models.planar.planar_observe`,
:func:`cageless.simulation.models.spatial.spatial_observe`) and they write what they compute into an output
array, so the trace cannot drift from the forces the solver integrated. Each model has its own compiled
sample loop, so a run compiles the observation code of its own model only. They give:

* ``*_normal``: the elastic (Hertz) part of each contact's normal force, K delta^1.5;
* ``inner_traction``, ``outer_traction``: the race traction on the ball along the rolling direction, the
  tangential law at the contact's own sliding and entrainment speeds on that elastic normal force (the
  right-hand side applies it to the whole normal force, lubricant damping included);
* ``inner_sliding``, ``outer_sliding``: the sliding speed of the ball's surface against the race at the
  contact centre, along the direction of the traction (the speed the traction law was evaluated at);
  ``inner_entrainment``, ``outer_entrainment``: the contact's mean rolling speed u_r;
* ``ball_ball_traction``: the magnitude of the friction between balls j and j+1, likewise;
* ``*_film``: the Hamrock-Dowson central film on the elastic load at the kernel's entrainment speed (NaN
  where a contact is open, or where race traction is off: the race kernels then compute no entrainment),
  from the same compiled formula the film-regime traction uses
  (:func:`cageless.simulation.physics.film_traction.hd_central_film`).

The spatial model's contact angles and points are geometry of the samples
(:func:`cageless.simulation.models.spatial_geometry.race_geometry`). The trace's ``balls``, ``contacts``
and ``inner_ring`` groups.
"""

from __future__ import annotations

import numba
import numpy as np
import numpy.typing as npt

from cageless.simulation.hertz import compliance, hertz_contact, race_curvatures
from cageless.simulation.models import base as B
from cageless.simulation.models import planar as P
from cageless.simulation.models import spatial as S
from cageless.simulation.models.spatial_geometry import race_geometry
from cageless.simulation.problem import Problem
from cageless.simulation.scene import Scene
from cageless.simulation.traction import film_coefficient

__all__ = ["observables", "kernel_observables", "film_coefficients"]


def observables(pr: Problem, t: npt.NDArray[np.float64], y: npt.NDArray[np.float64], scene: Scene,
                film_on: bool) -> dict[str, dict[str, np.ndarray]]:
    """Contact forces (elastic normal part and traction), films, positions and spins along the samples
    (``t``, ``y``); samples with a non-finite state give NaN."""
    p = pr.params
    z = int(p[B.P_Z])
    trac = p[B.P_F_TRAC] > 0.5
    # the films at the oil's viscosity at its temperature, as the race forces use it (the ETA0 slot)
    fields = kernel_observables(pr, t, y, film_coefficients(scene, float(p[B.P_ETA0])) if film_on and trac else None)
    names = ["inner_normal", "outer_normal", "ball_ball_normal"]
    names += ["inner_traction", "outer_traction", "inner_sliding", "outer_sliding", "inner_entrainment",
              "outer_entrainment"] if trac else []
    names += ["inner_film", "outer_film"] if film_on else []
    contacts = {name: fields[:, B.OBSERVABLES.index(name)] for name in names}
    r, om = y[:, :z], y[:, 4 * z:5 * z]
    spatial = pr.model_id == S.MODEL_ID
    axial = y[:, S.SpatialLayout(z).slices()["axial"]] if spatial else np.zeros_like(r)
    spin = np.zeros((len(y), z, 3))
    spin[:, :, 0] = om
    ring = np.column_stack([np.zeros(len(y)), y[:, 5 * z], y[:, 5 * z + 1]])
    tilt = np.zeros((len(y), 2))
    if spatial:
        tilt = y[:, -4:-2] + pr.params[[S.P_TILT_Y, S.P_TILT_Z]]  # about y and z: misalignment plus the free tilt
        sl = S.SpatialLayout(z).slices()
        spin[:, :, 1], spin[:, :, 2] = y[:, sl["spin_y"]], y[:, sl["spin_z"]]
        ring[:, 0] = y[:, sl["ring_axial"]][:, 0]
        for race, (_, angle, point) in race_geometry(pr, y).items():
            contacts[f"{race}_angle"] = angle
            contacts[f"{race}_point"] = point
    if p[B.P_F_BBFRIC] > 0.5:
        contacts["ball_ball_traction"] = fields[:, B.OBS_BB_TRACTION]
    return {
        "balls": {"radius": r, "axial": axial, "spin": spin},
        "contacts": contacts,
        "inner_ring": {"position": ring, "tilt": tilt},
    }


def kernel_observables(pr: Problem, t: npt.NDArray[np.float64], y: npt.NDArray[np.float64],
                       film: tuple[float, float] | None = None) -> npt.NDArray[np.float64]:
    """The fields of :data:`cageless.simulation.models.base.OBSERVABLES` along samples (t, y), as (T, fields, Z),
    written by the model's compiled force functions. ``film`` holds the outer and inner race's film coefficients
    (:func:`film_coefficients`); without it the film fields are NaN. Non-finite states give NaN rows."""
    z = pr.n_balls
    log = pr.log.copy()
    log[:z] = 0.0  # onset speeds are not kept per sample (they enter no field written: the elastic force does)
    out = np.zeros((len(t), B.N_OBS, z))
    c_outer, c_inner = film if film is not None else (np.nan, np.nan)
    loop = {P.MODEL_ID: _observe_planar, S.MODEL_ID: _observe_spatial}.get(pr.model_id)
    if loop is None:  # a model without race contacts: every field 0, the films NaN
        out[:, [B.OBS_OUTER_FILM, B.OBS_INNER_FILM]] = np.nan
    else:
        loop(np.ascontiguousarray(t, dtype=np.float64), np.ascontiguousarray(y, dtype=np.float64), pr.params, log,
             c_outer, c_inner, out)
    out[~np.all(np.isfinite(y), axis=1)] = np.nan
    return out


@numba.njit(cache=True)
def _observe_planar(ts, ys, p, log, c_outer, c_inner, out):  # pragma: no cover - compiled
    """Every sample's observables of the planar model (:func:`cageless.simulation.models.planar.planar_observe`)
    and their films (:func:`_films`)."""
    for i in range(ts.shape[0]):
        P.planar_observe(ts[i], ys[i], p, log, out[i])
        _films(out[i], c_outer, c_inner)


@numba.njit(cache=True)
def _observe_spatial(ts, ys, p, log, c_outer, c_inner, out):  # pragma: no cover - compiled
    """Every sample's observables of the spatial model (:func:`cageless.simulation.models.spatial.spatial_observe`)
    and their films (:func:`_films`)."""
    for i in range(ts.shape[0]):
        S.spatial_observe(ts[i], ys[i], p, log, out[i])
        _films(out[i], c_outer, c_inner)


@numba.njit(cache=True, inline="always")
def _films(row, c_outer, c_inner):  # pragma: no cover - compiled
    """The race films of one sample's observables ``row`` (fields, Z) from the same pass:
    h = c_h max(u_r, 1 um/s)^0.67 Q^-0.067 (NaN where the contact is open)."""
    for j in range(row.shape[1]):
        for f_q, f_u, f_h, c_h in ((B.OBS_OUTER_NORMAL, B.OBS_OUTER_ENTRAIN, B.OBS_OUTER_FILM, c_outer),
                                   (B.OBS_INNER_NORMAL, B.OBS_INNER_ENTRAIN, B.OBS_INNER_FILM, c_inner)):
            q = row[f_q, j]
            row[f_h, j] = c_h * max(row[f_u, j], 1e-6) ** 0.67 * q ** -0.067 if q > 0.0 else np.nan


def film_coefficients(scene: Scene, viscosity_pa_s: float | None = None) -> tuple[float, float]:
    """c_h of the outer and inner race contact in the Hamrock-Dowson central film h = c_h u^0.67 Q^-0.067
    (:func:`cageless.simulation.traction.film_coefficient`, on the compiled formula; SI units), at ``viscosity_pa_s`` (default: the
    lubricant's reference viscosity; a run passes its oil's viscosity at the oil temperature)."""
    b = scene.bearing
    g, lub = b.geometry, b.lubricant
    assert lub is not None
    eta0 = lub.dynamic_viscosity_pa_s if viscosity_pa_s is None else viscosity_pa_s
    eta = compliance(b.material)
    rc = race_curvatures(g)
    d = g.ball_diameter_m
    rx = {"inner": 1.0 / (2.0 / d + 2.0 / g.inner_race_diameter_m), "outer": 1.0 / (2.0 / d - 2.0 / g.outer_race_diameter_m)}
    outer, inner = (film_coefficient(hertz_contact(*rc[race], eta), rx[race], eta0,
                                     lub.pressure_viscosity_coefficient_1_pa, 2.0 / eta) for race in ("outer", "inner"))
    return outer, inner
