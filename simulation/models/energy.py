"""The mechanical energy of the ball-bearing models along a run's samples (numpy, after the solve).

With the dissipated energy added and the drive's input work taken away it is conserved: the energy balance
of :func:`cageless.simulation.run.energy_balance`.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from cageless.simulation.models import base as B
from cageless.simulation.models.base import (P_D, P_DI, P_DO, P_F_BB, P_F_GRAV, P_F_RACE, P_FR, P_G, P_I, P_KB,
                                             P_KI, P_KO, P_M, P_MR, P_Z)
from cageless.simulation.models.spatial_geometry import race_geometry
from cageless.simulation.models.spatial_layout import P_FA, P_GAX, P_IR, P_MY
from cageless.simulation.problem import Problem

__all__ = ["planar_energy", "spatial_energy"]


def planar_energy(problem: Problem, y: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    """Total mechanical energy (J) along samples y (T, n): kinetic + Hertz + gravity + load potential.

    Conserved when every active force is conservative; with damping on, this plus the dissipated
    energy (the last state) is conserved.
    """
    p = problem.params
    z = int(p[P_Z])
    d, m, m_ring, g, f_r = p[P_D], p[P_M], p[P_MR], p[P_G], p[P_FR]
    r, th, rd, thd = y[:, :z], y[:, z:2 * z], y[:, 2 * z:3 * z], y[:, 3 * z:4 * z]
    cy, cz, cvy, cvz = (y[:, 5 * z + i] for i in range(4))
    ke = 0.5 * m * np.sum(rd**2 + (r * thd) ** 2, axis=1) + 0.5 * m_ring * (cvy**2 + cvz**2)
    ke += 0.5 * p[P_I] * np.sum(y[:, 4 * z:5 * z] ** 2, axis=1)
    pe = m * g * np.sum(r * np.sin(th), axis=1) * (p[P_F_GRAV] > 0.5) + (m_ring * g * (p[P_F_GRAV] > 0.5) + f_r) * cz
    if p[P_F_RACE] > 0.5:
        d_o = np.clip(r + 0.5 * d - 0.5 * p[P_DO], 0, None)
        ln = np.hypot(r * np.cos(th) - cy[:, None], r * np.sin(th) - cz[:, None])
        d_i = np.clip(0.5 * p[P_DI] + 0.5 * d - ln, 0, None)
        pe += 0.4 * (p[P_KO] * np.sum(d_o**2.5, axis=1) + p[P_KI] * np.sum(d_i**2.5, axis=1))
    if p[P_F_BB] > 0.5:
        x, zz = r * np.cos(th), r * np.sin(th)
        gap = np.hypot(np.roll(x, -1, axis=1) - x, np.roll(zz, -1, axis=1) - zz)
        pe += 0.4 * p[P_KB] * np.sum(np.clip(d - gap, 0, None) ** 2.5, axis=1)
    return ke + pe


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
    if p[B.P_F_GRAV] > 0.5:  # gravity along the shaft
        pe += p[P_GAX] * (m * np.sum(ax, axis=1) + m_ring * y[:, b + 4 * z])
    if p[B.P_F_RACE] > 0.5:
        for race, (overlap, _, _) in race_geometry(problem, y).items():
            pe += 0.4 * (p[B.P_KI] if race == "inner" else p[B.P_KO]) * np.sum(overlap**2.5, axis=1)
    if p[B.P_F_BB] > 0.5:
        x, zz = r * np.cos(th), r * np.sin(th)
        gap = np.sqrt((np.roll(x, -1, axis=1) - x) ** 2 + (np.roll(zz, -1, axis=1) - zz) ** 2
                      + (np.roll(ax, -1, axis=1) - ax) ** 2)
        pe += 0.4 * p[B.P_KB] * np.sum(np.clip(d - gap, 0, None) ** 2.5, axis=1)
    return ke + pe
