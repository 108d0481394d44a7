"""A plain-numpy right-hand side of the planar model, for tests and the benchmark baseline only.

It computes the same forces as :mod:`cageless.simulation.models.planar` with vectorised
numpy instead of compiled loops; the tests assert the two agree, and
``benchmarks`` time the compiled path against this one under ``solve_ivp``.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

from cageless.simulation.forces import squeeze_film
from cageless.simulation.models import base as B

__all__ = ["reference_rhs", "tangential_force"]

#: :func:`cageless.simulation.forces.squeeze_film` (its Python source, not the compiled function) over arrays.
_SQUEEZE = np.vectorize(squeeze_film.py_func, otypes=[float])


def tangential_force(u_s: np.ndarray, u_r: np.ndarray, q: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Signed tangential force (N): the traction regression, or dry Coulomb-Stribeck friction."""
    if p[B.P_DRY] > 0.5:
        mu_c, mu_s = p[B.P_MU_DRY], p[B.P_MU_STATIC]
        mu = mu_c + (mu_s - mu_c) * np.exp(-(u_s / p[B.P_V_STRIBECK]) ** 2)
        return np.where(q > 0, mu * q * np.tanh(u_s / p[B.P_V_REG]), 0.0)
    sr = np.abs(u_s) / np.maximum(np.abs(u_r), p[B.P_U_FLOOR])
    mu = (p[B.P_TA] + p[B.P_TB] * sr) * np.exp(-p[B.P_TC] * sr) + p[B.P_TD]
    return np.where((q > 0) & (u_s != 0), np.sign(u_s) * mu * q, 0.0)


def reference_rhs(t: float, y: npt.NDArray[np.float64], p: npt.NDArray[np.float64],
                  log: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
    """dy/dt of the planar model (numpy). ``log`` holds the ball-ball approach speeds recorded at onset."""
    z = int(p[B.P_Z])
    m, m_ring = p[B.P_M], p[B.P_MR]
    g = p[B.P_G] if p[B.P_F_GRAV] > 0.5 else 0.0
    w_i = p[B.P_WI] * (min(t / p[B.P_RAMP], 1.0) if p[B.P_RAMP] > 0 else 1.0)
    r, th, rd, thd = y[:z], y[z:2 * z], y[2 * z:3 * z], y[3 * z:4 * z]
    cvy, cvz = y[5 * z + 2:5 * z + 4]
    c, s = np.cos(th), np.sin(th)
    fy = np.zeros(z)
    fz = np.full(z, -m * g)
    torque = np.zeros(z)
    ring = np.array([0.0, -p[B.P_FR] - m_ring * g])
    power, power_in = _races(y, p, w_i, c, s, fy, fz, torque, ring) if p[B.P_F_RACE] > 0.5 else (0.0, 0.0)
    if p[B.P_F_BB] > 0.5:
        power += _pairs(y, p, log, fy, fz, torque)
    f_rad, f_tan = fy * c + fz * s, -fy * s + fz * c
    if p[B.P_F_DRAG] > 0.5:
        v, om = r * thd, y[4 * z:5 * z]
        f_d, m_c = _drag(v, om, p)
        f_tan = f_tan + f_d
        torque = torque + m_c
        power -= np.sum(f_d * v + m_c * om)
    out = np.empty_like(y)
    out[:z], out[z:2 * z] = rd, thd
    out[2 * z:3 * z] = f_rad / m + r * thd**2
    out[3 * z:4 * z] = (f_tan / m - 2 * rd * thd) / r
    out[4 * z:5 * z] = torque / p[B.P_I]
    out[5 * z:5 * z + 2] = cvy, cvz
    out[5 * z + 2:5 * z + 4] = ring / m_ring
    out[5 * z + 4] = power_in
    out[5 * z + 5] = power
    return out


def _races(y: np.ndarray, p: np.ndarray, w_i: float, c: np.ndarray, s: np.ndarray, fy: np.ndarray, fz: np.ndarray,
           torque: np.ndarray, ring: np.ndarray) -> tuple[float, float]:
    """The race contacts' forces into fy, fz, torque and ring (in place); returns the dissipated and the input
    power."""
    z = int(p[B.P_Z])
    half = 0.5 * p[B.P_D]
    trac = p[B.P_F_TRAC] > 0.5
    r, rd, thd, om = y[:z], y[2 * z:3 * z], y[3 * z:4 * z], y[4 * z:5 * z]
    cy, cz, cvy, cvz = y[5 * z:5 * z + 4]
    power, power_in = 0.0, 0.0
    lub, c_ho = p[B.P_F_LUB] > 0.5, p[B.P_CHO]
    d_o = r + half - 0.5 * p[B.P_DO]
    q = np.where(d_o > 0, p[B.P_KO] * np.clip(d_o, 0, None) ** 1.5, 0.0)
    if lub:
        qd = np.where(d_o > 0, np.maximum(q + c_ho * rd, 0.0), 0.0)
        power += np.sum((qd - q) * rd)
        q = qd
    f_t = np.zeros(z)
    if trac:
        u = r * thd + half * om
        f_t = -tangential_force(u, 0.5 * np.abs(u - p[B.P_DO] * thd), q, p)
        power -= np.sum(f_t * u)
        torque += half * f_t
    fy += -q * c - f_t * s
    fz += -q * s + f_t * c
    sx, sz = r * c - cy, r * s - cz
    ln = np.hypot(sx, sz)
    d_i = 0.5 * p[B.P_DI] + half - ln
    nx, nz = sx / ln, sz / ln
    vx, vz = rd * c - r * thd * s - cvy, rd * s + r * thd * c - cvz
    q = np.where(d_i > 0, p[B.P_KI] * np.clip(d_i, 0, None) ** 1.5, 0.0)
    if lub:
        ddot = -(vx * nx + vz * nz)
        qd = np.where(d_i > 0, np.maximum(q + c_ho * ddot, 0.0), 0.0)
        power += np.sum((qd - q) * ddot)
        q = qd
    f_t = np.zeros(z)
    if trac:
        r_i = 0.5 * p[B.P_DI]
        vt = -vx * nz + vz * nx
        u = vt - half * om - w_i * r_i
        f_t = -tangential_force(u, 0.5 * np.abs(vt * (1 - 2 * r_i / ln) - half * om + w_i * r_i), q, p)
        power -= np.sum(f_t * u)
        power_in += np.sum(w_i * r_i * f_t)
        torque -= half * f_t
    gy, gz = q * nx - f_t * nz, q * nz + f_t * nx
    fy += gy
    fz += gz
    ring -= [np.sum(gy), np.sum(gz)]
    return power, power_in


def _drag(v: np.ndarray, om: np.ndarray, p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Drag (N) on the orbital speeds v and churning moments (N m) on the spins om, vectorised."""
    d, rho, mu = p[B.P_D], p[B.P_RHO_MIX], p[B.P_MU_MIX]
    if p[B.P_CD] > 0:
        f = -0.125 * np.pi * p[B.P_CD] * rho * d * d * v * np.abs(v)
    else:
        re = rho * np.abs(v) * d / mu
        cd = np.maximum(24.0 / np.maximum(re, 1e-300) * (1.0 + 0.15 * re ** 0.687), 0.44)
        f = -np.sign(v) * 0.125 * np.pi * cd * rho * d * d * v * v
    w, r = np.abs(om), 0.5 * d
    m = -np.sign(om) * (8.0 * np.pi * mu * r ** 3 * w + 3.225 * np.sqrt(rho * mu) * r ** 4 * w ** 1.5)
    return f, m


def _pairs(y: np.ndarray, p: np.ndarray, log: np.ndarray, fy: np.ndarray, fz: np.ndarray,
           torque: np.ndarray) -> float:
    """Ball-ball Hertz, friction and squeeze film into fy, fz, torque (in place); returns dissipated power."""
    z = int(p[B.P_Z])
    d = p[B.P_D]
    r, th, rd, thd, om = y[:z], y[z:2 * z], y[2 * z:3 * z], y[3 * z:4 * z], y[4 * z:5 * z]
    c, s = np.cos(th), np.sin(th)
    x, zz = r * c, r * s
    vx, vz = rd * c - r * thd * s, rd * s + r * thd * c
    k = np.roll(np.arange(z), -1)
    dx, dz = x[k] - x, zz[k] - zz
    ln = np.hypot(dx, dz)
    delta = d - ln
    nx, nz = dx / ln, dz / ln
    ddot = -((vx[k] - vx) * nx + (vz[k] - vz) * nz)
    touching = delta > 0
    # recorded onset speed, else the current one; floored (ModelParameters.min_approach_speed_m_s)
    speeds = np.maximum(np.where(log[:z] > 0, log[:z], ddot), p[B.P_V_IN_MIN])
    chi = p[B.P_CHI]
    el = p[B.P_KB] * np.clip(delta, 0, None) ** 1.5
    f = np.where(touching, np.maximum(el * (1 + (chi * ddot / np.where(speeds > 0, speeds, 1.0) if chi > 0 else 0)),
                                      0), 0.0)
    power = np.sum((f - el) * ddot * touching)
    ft = np.zeros(z)
    if p[B.P_F_TRAC] > 0.5:
        u = (vx - vx[k]) * -nz + (vz - vz[k]) * nx + 0.5 * d * (om + om[k])
        ft = np.where(touching, -tangential_force(u, 0.25 * d * np.abs(om - om[k]), f, p), 0.0)
        power -= np.sum(ft * u)
        torque += 0.5 * d * ft
        np.add.at(torque, k, 0.5 * d * ft)
    film = np.zeros(z)
    if p[B.P_F_BBFILM] > 0.5:
        # the one squeeze-film law of the compiled models, run as plain Python on each pair
        film = _SQUEEZE(-delta, ddot, p[B.P_ETA0], 0.25 * d, p[B.P_H0])
        power += np.sum(film * ddot)
    on_k_y = (f + film) * nx + ft * nz
    on_k_z = (f + film) * nz - ft * nx
    np.add.at(fy, np.arange(z), -on_k_y)
    np.add.at(fz, np.arange(z), -on_k_z)
    np.add.at(fy, k, on_k_y)
    np.add.at(fz, k, on_k_z)
    return float(power)
