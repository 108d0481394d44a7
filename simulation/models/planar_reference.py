"""A plain-numpy right-hand side of the planar model, for tests and the benchmark baseline only.

It computes the same forces as :mod:`simulation.models.planar` with vectorised
numpy instead of compiled loops; the tests assert the two agree, and
``benchmarks`` time the compiled path against this one under ``solve_ivp``.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from simulation.models import planar as P

__all__ = ["reference_rhs"]


def reference_rhs(t: float, y: npt.NDArray[np.float64], p: npt.NDArray[np.float64],
                  aux: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    """dy/dt of the planar model (numpy). ``aux`` holds the ball-ball approach speeds, updated in place."""
    z = int(p[P.P_Z])
    d, m, m_ring = p[P.P_D], p[P.P_M], p[P.P_MR]
    g = p[P.P_G] if p[P.P_F_GRAV] > 0.5 else 0.0
    r, th, rd, thd = y[:z], y[z:2 * z], y[2 * z:3 * z], y[3 * z:4 * z]
    cy, cz, cvy, cvz = y[5 * z:5 * z + 4]
    c, s = np.cos(th), np.sin(th)
    fy = np.zeros(z)
    fz = np.full(z, -m * g)
    ring = np.array([0.0, -p[P.P_FR] - m_ring * g])
    power = 0.0
    lub, c_ho = p[P.P_F_LUB] > 0.5, p[P.P_CHO]
    if p[P.P_F_RACE] > 0.5:
        d_o = r + 0.5 * d - 0.5 * p[P.P_DO]
        q = np.where(d_o > 0, p[P.P_KO] * np.clip(d_o, 0, None) ** 1.5, 0.0)
        if lub:
            qd = np.where(d_o > 0, np.maximum(q + c_ho * rd, 0.0), 0.0)
            power += np.sum((qd - q) * rd)
            q = qd
        fy -= q * c
        fz -= q * s
        sx, sz = r * c - cy, r * s - cz
        ln = np.hypot(sx, sz)
        d_i = 0.5 * p[P.P_DI] + 0.5 * d - ln
        nx, nz = sx / ln, sz / ln
        q = np.where(d_i > 0, p[P.P_KI] * np.clip(d_i, 0, None) ** 1.5, 0.0)
        if lub:
            ddot = -((rd * c - r * thd * s - cvy) * nx + (rd * s + r * thd * c - cvz) * nz)
            qd = np.where(d_i > 0, np.maximum(q + c_ho * ddot, 0.0), 0.0)
            power += np.sum((qd - q) * ddot)
            q = qd
        fy += q * nx
        fz += q * nz
        ring -= [np.sum(q * nx), np.sum(q * nz)]
    if p[P.P_F_BB] > 0.5:
        x, zz = r * c, r * s
        vx, vz = rd * c - r * thd * s, rd * s + r * thd * c
        k = np.roll(np.arange(z), -1)
        dx, dz = x[k] - x, zz[k] - zz
        ln = np.hypot(dx, dz)
        delta = d - ln
        nx, nz = dx / ln, dz / ln
        ddot = -((vx[k] - vx) * nx + (vz[k] - vz) * nz)
        touching = delta > 0
        speeds = aux[:z]  # approach speeds (a view: updated in place)
        speeds[~touching] = 0.0
        new = touching & (speeds <= 0)
        speeds[new] = np.maximum(ddot[new], 1e-9)
        chi = p[P.P_CHI]
        el = p[P.P_KB] * np.clip(delta, 0, None) ** 1.5
        f = np.where(touching, np.maximum(el * (1 + (chi * ddot / np.where(speeds > 0, speeds, 1.0) if chi > 0 else 0)),
                                          0), 0.0)
        power += np.sum((f - el) * ddot * touching)
        np.add.at(fy, np.arange(z), -f * nx)
        np.add.at(fz, np.arange(z), -f * nz)
        np.add.at(fy, k, f * nx)
        np.add.at(fz, k, f * nz)
    f_rad, f_tan = fy * c + fz * s, -fy * s + fz * c
    out = np.empty_like(y)
    out[:z], out[z:2 * z] = rd, thd
    out[2 * z:3 * z] = f_rad / m + r * thd**2
    out[3 * z:4 * z] = (f_tan / m - 2 * rd * thd) / r
    out[4 * z:5 * z] = 0.0
    out[5 * z:5 * z + 2] = cvy, cvz
    out[5 * z + 2:5 * z + 4] = ring / m_ring
    out[5 * z + 4] = power
    return out
