"""The spatial model's geometry and energy along a run's samples (numpy, after the solve).

:func:`race_geometry` gives the race contacts' overlaps, contact angles and contact points (the path of the
paper's figure 13), :func:`ring_rotations` the inner ring's rotation, :func:`spatial_energy` the mechanical
energy of the energy balance. The groove geometry is the one of :mod:`cageless.simulation.models.spatial`.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from cageless.simulation.models import base as B
from cageless.simulation.models.spatial_layout import P_FA, P_GAX, P_IR, P_MY, P_RGI, P_RGO, _tilt
from cageless.simulation.problem import Problem

__all__ = ["race_geometry", "ring_rotations", "spatial_energy"]


def race_geometry(problem: Problem,
                  y: npt.NDArray[np.float64]) -> dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """(overlap in m, contact angle in rad, contact point) of the inner and outer race contacts along samples
    y (T, n).

    The contact angle is atan(axial / radial component of the normal), in the frame of the race (the inner
    ring's frame carries its prescribed tilt). The contact point (T, Z, 3: axial x, y, z in m, bearing frame)
    lies on the raceway, the groove radius from its curvature centre along the line through the ball centre:
    its path is the contact trajectory of the paper's figure 13.
    """
    p = problem.params
    z = int(p[B.P_Z])
    b = 5 * z + 6
    r, th, ax = y[:, :z], y[:, z:2 * z], y[:, b:b + z]
    half = 0.5 * p[B.P_D]
    out = {}
    ball = np.stack([ax, r * np.cos(th), r * np.sin(th)], axis=-1)  # (T, Z, 3) in the fixed frame
    for race, rho, rg, centre, frame in (
            ("outer", 0.5 * p[B.P_DO] - p[P_RGO], p[P_RGO], np.zeros((len(y), 1, 3)), np.broadcast_to(np.eye(3), (len(y), 3, 3))),
            ("inner", 0.5 * p[B.P_DI] + p[P_RGI], p[P_RGI],
             np.stack([y[:, b + 4 * z], y[:, 5 * z], y[:, 5 * z + 1]], axis=-1)[:, None, :], ring_rotations(problem, y))):
        q = np.einsum("tzi,tij->tzj", ball - centre, frame)  # R^T (P - C): the ball centre in the race's frame
        rq = np.hypot(q[..., 1], q[..., 2])
        ex, er = q[..., 0], rq - rho
        length = np.hypot(ex, er)
        radial = rho + rg * er / length  # distance of the contact point from the ring's axis
        local = np.stack([rg * ex / length, radial * q[..., 1] / rq, radial * q[..., 2] / rq], axis=-1)
        out[race] = (np.clip(length - (rg - half), 0.0, None), np.arctan2(ex, np.abs(er)),
                     centre + np.einsum("tzj,tij->tzi", local, frame))
    return out


def ring_rotations(problem: Problem, y: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    """The inner ring's rotation matrices R = Rz(beta_z) Ry(beta_y) along samples y (T, 3, 3): the prescribed
    misalignment plus the tilt states."""
    return np.array([_tilt(row, problem.params) for row in y]).reshape(-1, 3, 3)


def spatial_energy(problem: Problem, y: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    """Total mechanical energy (J) along samples y (T, n): kinetic (translation and spin), Hertz, gravity and
    load potentials, the ring's tilt. With the dissipated energy added and the drive's input work taken away it
    is conserved."""
    p = problem.params
    z = int(p[B.P_Z])
    b = 5 * z + 6
    m, m_ring, g, d = p[B.P_M], p[B.P_MR], p[B.P_G] * (p[B.P_F_GRAV] > 0.5), p[B.P_D]
    r, th, rd, thd = y[:, :z], y[:, z:2 * z], y[:, 2 * z:3 * z], y[:, 3 * z:4 * z]
    ax, axd = y[:, b:b + z], y[:, b + z:b + 2 * z]
    spin2 = y[:, 4 * z:5 * z] ** 2 + y[:, b + 2 * z:b + 3 * z] ** 2 + y[:, b + 3 * z:b + 4 * z] ** 2
    cvy, cvz, cvx = y[:, 5 * z + 2], y[:, 5 * z + 3], y[:, b + 4 * z + 1]
    ke = (0.5 * m * np.sum(rd**2 + (r * thd) ** 2 + axd**2, axis=1) + 0.5 * p[B.P_I] * np.sum(spin2, axis=1)
          + 0.5 * m_ring * (cvx**2 + cvy**2 + cvz**2) + 0.5 * p[P_IR] * (y[:, -2] ** 2 + y[:, -1] ** 2))
    pe = m * g * np.sum(r * np.sin(th), axis=1) + (m_ring * g + p[B.P_FR]) * y[:, 5 * z + 1] - p[P_FA] * y[:, b + 4 * z]
    pe -= p[P_MY] * y[:, -4]  # the moment load's work on the tilt beta_y
    pe += p[P_GAX] * (m * np.sum(ax, axis=1) + m_ring * y[:, b + 4 * z])  # gravity along the shaft
    if p[B.P_F_RACE] > 0.5:
        for race, (overlap, _, _) in race_geometry(problem, y).items():
            pe += 0.4 * (p[B.P_KI] if race == "inner" else p[B.P_KO]) * np.sum(overlap**2.5, axis=1)
    if p[B.P_F_BB] > 0.5:
        x, zz = r * np.cos(th), r * np.sin(th)
        gap = np.sqrt((np.roll(x, -1, axis=1) - x) ** 2 + (np.roll(zz, -1, axis=1) - zz) ** 2
                      + (np.roll(ax, -1, axis=1) - ax) ** 2)
        pe += 0.4 * p[B.P_KB] * np.sum(np.clip(d - gap, 0, None) ** 2.5, axis=1)
    return ke + pe
