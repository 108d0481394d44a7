"""The spatial model's race geometry along a run's samples (numpy, after the solve).

:func:`race_geometry` gives the race contacts' overlaps, contact angles and contact points (the path of the
paper's figure 13), :func:`ring_rotations` the inner ring's rotation. The groove geometry is the one of
:mod:`cageless.simulation.models.spatial`.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from cageless.simulation.models import base as B
from cageless.simulation.models.spatial_layout import P_RGI, P_RGO, _tilt
from cageless.simulation.problem import Problem

__all__ = ["race_geometry", "ring_rotations"]


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
