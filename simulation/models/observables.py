"""What a run reports besides the states: contact forces, films, contact angles, positions and spins.

Computed along the samples from the states with the models' named parameter slots (the plain-numpy
traction law of :mod:`cageless.simulation.models.planar_reference`); the trace's ``balls``, ``contacts`` and
``inner_ring`` groups.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from cageless.simulation.hertz import compliance, hertz_contact, race_curvatures
from cageless.simulation.models import base as B
from cageless.simulation.models import spatial as S
from cageless.simulation.models.planar_reference import tangential_force
from cageless.simulation.models.regime import P_F_FTRAC, race_tangential_array
from cageless.simulation.problem import Problem
from cageless.simulation.scene import Scene
from cageless.simulation.traction import film_coefficient

__all__ = ["observables", "films"]


def observables(pr: Problem, y: npt.NDArray[np.float64], scene: Scene,
                 film_on: bool) -> dict[str, dict[str, np.ndarray]]:
    """Contact forces (elastic normal part and traction), films, positions and spins along the samples."""
    p = pr.params
    z = int(p[B.P_Z])
    d, half = p[B.P_D], 0.5 * p[B.P_D]
    r, th, rd, thd, om = (y[:, i * z:(i + 1) * z] for i in range(5))
    cy, cz, cvy, cvz = (y[:, 5 * z + i][:, None] for i in range(4))
    w_i = p[B.P_WI]
    outer = p[B.P_KO] * np.clip(r + half - 0.5 * p[B.P_DO], 0, None) ** 1.5
    sx, sz = r * np.cos(th) - cy, r * np.sin(th) - cz
    ln = np.hypot(sx, sz)
    inner = p[B.P_KI] * np.clip(0.5 * p[B.P_DI] + half - ln, 0, None) ** 1.5
    spatial = pr.model_id == S.MODEL_ID
    axial, axial_dot = ((y[:, S.SpatialLayout(z).slices()[k]] for k in ("axial", "axial_dot")) if spatial
                        else (np.zeros_like(r), np.zeros_like(r)))
    bb = p[B.P_KB] * np.clip(d - _centre_gap(r, th, axial), 0, None) ** 1.5
    u_o = r * thd + half * om
    ur_o = 0.5 * np.abs(u_o - p[B.P_DO] * thd)
    vt = (rd * np.sin(th) + r * thd * np.cos(th) - cvz) * sx / ln - (rd * np.cos(th) - r * thd * np.sin(th) - cvy) * sz / ln
    r_i = 0.5 * p[B.P_DI]
    u_i = vt - half * om - w_i * r_i
    ur_i = 0.5 * np.abs(vt * (1 - 2 * r_i / ln) - half * om + w_i * r_i)
    contacts = {"inner_normal": inner, "outer_normal": outer, "ball_ball_normal": bb}
    if p[B.P_F_TRAC] > 0.5 and p[P_F_FTRAC] > 0.5:  # traction by film regime (models/regime.py)
        contacts["inner_traction"] = -race_tangential_array(u_i, ur_i, inner, True, p)
        contacts["outer_traction"] = -race_tangential_array(u_o, ur_o, outer, False, p)
    elif p[B.P_F_TRAC] > 0.5:
        contacts["inner_traction"] = -tangential_force(u_i, ur_i, inner, p)
        contacts["outer_traction"] = -tangential_force(u_o, ur_o, outer, p)
    if film_on:
        contacts.update(films(scene, inner, outer, ur_i, ur_o))
    spin = np.zeros((len(y), z, 3))
    spin[:, :, 0] = om
    ring = np.column_stack([np.zeros(len(y)), cy[:, 0], cz[:, 0]])
    tilt = np.zeros((len(y), 2))
    if spatial:
        tilt = y[:, -4:-2] + pr.params[[S.P_TILT_Y, S.P_TILT_Z]]  # about y and z: misalignment plus the free tilt
        sl = S.SpatialLayout(z).slices()
        spin[:, :, 1], spin[:, :, 2] = y[:, sl["spin_y"]], y[:, sl["spin_z"]]
        ring[:, 0] = y[:, sl["ring_axial"]][:, 0]
        for race, (overlap, angle, point) in S.race_geometry(pr, y).items():
            k_n = p[B.P_KI] if race == "inner" else p[B.P_KO]
            contacts[f"{race}_normal"] = k_n * overlap**1.5
            contacts[f"{race}_angle"] = angle
            contacts[f"{race}_point"] = point
    if p[B.P_F_TRAC] > 0.5:
        contacts["ball_ball_traction"] = _ball_ball_traction(p, r, th, rd, thd, axial, axial_dot, spin, bb)
    return {
        "balls": {"radius": r, "axial": axial, "spin": spin},
        "contacts": contacts,
        "inner_ring": {"position": ring, "tilt": tilt},
    }


def _centre_gap(r: np.ndarray, th: np.ndarray, axial: np.ndarray) -> np.ndarray:
    """Distance (m) between the centres of ball j and ball j+1 (T, Z)."""
    pos = np.stack([axial, r * np.cos(th), r * np.sin(th)], axis=-1)
    return np.linalg.norm(np.roll(pos, -1, axis=1) - pos, axis=-1)


def _ball_ball_traction(p: np.ndarray, r: np.ndarray, th: np.ndarray, rd: np.ndarray, thd: np.ndarray,
                        axial: np.ndarray, axial_dot: np.ndarray, spin: np.ndarray, normal: np.ndarray) -> np.ndarray:
    """Magnitude (N) of the friction between ball j and ball j+1 (T, Z), from the sliding of their surfaces
    along the contact plane, as in the models' pair forces (elastic normal force; 0 where apart)."""
    z = r.shape[1]
    half = 0.5 * p[B.P_D]
    pos = np.stack([axial, r * np.cos(th), r * np.sin(th)], axis=-1)
    vel = np.stack([axial_dot, rd * np.cos(th) - r * thd * np.sin(th), rd * np.sin(th) + r * thd * np.cos(th)], -1)
    k = np.roll(np.arange(z), -1)
    n = pos[:, k] - pos
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    u = vel - vel[:, k] + np.cross(spin + spin[:, k], half * n)  # surface of j against j+1
    u -= np.sum(u * n, axis=-1, keepdims=True) * n
    u_s = np.linalg.norm(u, axis=-1)
    u_r = 0.5 * half * np.linalg.norm(np.cross(spin - spin[:, k], n), axis=-1)
    return np.abs(tangential_force(u_s, u_r, normal, p))


def films(scene: Scene, inner: np.ndarray, outer: np.ndarray, ur_i: np.ndarray,
           ur_o: np.ndarray) -> dict[str, np.ndarray]:
    """Hamrock-Dowson central film (m) at the race contacts (NaN where a contact is open)."""
    b = scene.bearing
    g, lub = b.geometry, b.lubricant
    assert lub is not None
    eta = compliance(b.material)
    rc = race_curvatures(g)
    d = g.ball_diameter_m
    rx = {"inner": 1.0 / (2.0 / d + 2.0 / g.inner_race_diameter_m), "outer": 1.0 / (2.0 / d - 2.0 / g.outer_race_diameter_m)}
    out = {}
    for race, q, u in (("inner", inner, ur_i), ("outer", outer, ur_o)):
        c_h = film_coefficient(hertz_contact(*rc[race], eta), rx[race], lub.dynamic_viscosity_pa_s,
                               lub.pressure_viscosity_coefficient_1_pa, 2.0 / eta)
        with np.errstate(divide="ignore", invalid="ignore"):
            out[f"{race}_film"] = np.where(q > 0, c_h * np.maximum(u, 1e-6) ** 0.67 * q ** -0.067, np.nan)
    return out
