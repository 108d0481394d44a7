"""A plain-numpy right-hand side of the planar model, for tests and the benchmark baseline only.

It computes the same forces as :mod:`cageless.simulation.models.planar` with vectorised
numpy instead of compiled loops; the tests assert the two agree, and
``benchmarks`` time the compiled path against this one under ``solve_ivp``.

The geometry, kinematics and assembly are written here again (what the comparison checks); the contact
laws are not: the traction or dry friction (:func:`~cageless.simulation.models.contact_laws.tangential`),
the drag and the churning moment (:func:`~cageless.simulation.models.contact_laws.ball_drag`,
:func:`~cageless.simulation.models.contact_laws.ball_churning`) are the models' own compiled laws mapped
over the arrays, so a law has one copy. The laws themselves are tested against their closed forms and
sources (``tests/validation/test_lubricant_formulas.py``, ``tests/simulation/test_parameters_ensemble.py``).
"""

from __future__ import annotations

import numba
import numpy as np
import numpy.typing as npt

from cageless.simulation.forces import FASTMATH, squeeze_film
from cageless.simulation.models import base as B
from cageless.simulation.models.contact_laws import ball_churning, ball_drag, tangential

__all__ = ["reference_rhs", "tangential_force"]

#: :func:`cageless.simulation.forces.squeeze_film` (its Python source, not the compiled function) over arrays.
_SQUEEZE = np.vectorize(squeeze_film.py_func, otypes=[float])


@numba.njit(cache=True, fastmath=FASTMATH)
def _tangential_map(u_s, u_r, q, p, out):  # pragma: no cover - compiled
    for i in range(out.shape[0]):
        out[i] = tangential(u_s[i], u_r[i], q[i], p)


@numba.njit(cache=True, fastmath=FASTMATH)
def _drag_map(v, om, p, f, m):  # pragma: no cover - compiled
    for i in range(v.shape[0]):
        f[i] = ball_drag(v[i], p)
        m[i] = ball_churning(om[i], p)


def _flat(*arrays: npt.ArrayLike) -> tuple[tuple[int, ...], list[np.ndarray]]:
    """The broadcast shape of ``arrays`` and each as a contiguous float64 vector of that many values."""
    b = np.broadcast_arrays(*(np.asarray(a, dtype=np.float64) for a in arrays))
    return b[0].shape, [np.ascontiguousarray(a).ravel() for a in b]


def tangential_force(u_s: npt.ArrayLike, u_r: npt.ArrayLike, q: npt.ArrayLike, p: np.ndarray) -> np.ndarray:
    """Signed tangential force (N) over arrays: the models' law
    (:func:`~cageless.simulation.models.contact_laws.tangential`: the traction regression, or dry
    Coulomb-Stribeck friction), zero where ``q`` <= 0."""
    shape, (a, b, c) = _flat(u_s, u_r, q)
    out = np.empty(a.size)
    _tangential_map(a, b, c, p, out)
    return out.reshape(shape)


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
    """Drag (N) on the orbital speeds v and churning moments (N m) on the spins om: the models' laws
    (:func:`~cageless.simulation.models.contact_laws.ball_drag`, ``ball_churning``) over the arrays."""
    shape, (a, b) = _flat(v, om)
    f, m = np.empty(a.size), np.empty(a.size)
    _drag_map(a, b, p, f, m)
    return f.reshape(shape), m.reshape(shape)


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
    if p[B.P_F_BBFRIC] > 0.5:
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
