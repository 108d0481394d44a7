"""The planar cageless-bearing model (DESIGN §6, pure radial load on an aligned bearing).

States (n = 5 Z + 5): per ball j the orbital radius r_j, angle theta_j, their
rates, and the spin omega_j about the shaft axis; then the inner-ring centre
(y, z) and its velocity; last, the energy dissipated so far (J), so the energy
balance can be checked. The ring's rotation is prescribed.

In this release the model carries the conservative effects, ball-ball damping
and lubricant damping at the race contacts (C_ho d(delta)/dt, the total normal
force never tensile; default C_ho = 5000 N s/m, the middle of the 2500-7500 N s/m
range of the paper's sensitivity study, Wang et al. 2026 §4): Hertz race contacts (ball to outer groove: delta = r + D/2 - d_o/2;
ball to the displaced inner groove: delta = d_i/2 + D/2 - |P - C|), Hertz
ball-ball contact with restitution-calibrated damping
(:func:`simulation.forces.hertz_damped`), gravity on balls and ring, and the
radial load on the ring (toward -z). The centrifugal force is not an effect: it
comes out of the polar equations, r'' = F_r / m + r theta'^2. Every ball-ball
contact episode is logged after each accepted step (:func:`contact_events`):
its onset, pair, orbital angle at the peak, peak force and duration, classed as
rubbing when it lasts more than :data:`RUBBING_FACTOR` Hertz impact durations at
its approach speed, else as an impact. Race traction,
films and drag are the next slice (their parameter set must be cited first); the
effect flags already gate every term.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba
import numpy as np
import numpy.typing as npt
import pandas as pd

from cageless.bearing import Bearing
from simulation.forces import damping_factor, hertz_damped, hertz_impact_duration
from simulation.hertz import ball_ball_contact, compliance, hertz_contact, race_curvatures
from simulation.problem import Problem

__all__ = [
    "PlanarLayout", "planar_problem", "planar_energy", "packed_start", "contact_events", "DEFAULT_CHO_N_S_M",
    "RUBBING_FACTOR",
]

#: Id of this model in :mod:`simulation.kernels`.
MODEL_ID = 0

# Parameter vector layout.
P_Z, P_D, P_M, P_I, P_MR, P_DI, P_DO, P_KI, P_KO, P_KB, P_CHI, P_G, P_FR, P_WI = range(14)
P_F_RACE, P_F_BB, P_F_GRAV, P_F_LUB, P_CHO = 14, 15, 16, 17, 18
N_PARAMS = 19

#: Lubricant damping coefficient at the race contacts (N s/m): the middle of the paper's 2500-7500 range.
DEFAULT_CHO_N_S_M = 5000.0


@dataclass(frozen=True)
class PlanarLayout:
    """Where each quantity sits in the state vector of ``n_balls`` balls."""

    n_balls: int

    @property
    def size(self) -> int:
        """Number of states, 5 Z + 5."""
        return 5 * self.n_balls + 5

    def slices(self) -> dict[str, slice]:
        """Named slices: r, theta, r_dot, theta_dot, spin, ring (y, z, y', z')."""
        z = self.n_balls
        return {"r": slice(0, z), "theta": slice(z, 2 * z), "r_dot": slice(2 * z, 3 * z),
                "theta_dot": slice(3 * z, 4 * z), "spin": slice(4 * z, 5 * z), "ring": slice(5 * z, 5 * z + 4),
                "dissipated": slice(5 * z + 4, 5 * z + 5)}


@numba.njit(cache=True)
def planar_rhs(t, y, p, aux, dydt):  # pragma: no cover - compiled
    z = int(p[P_Z])
    d, m, inertia, m_ring = p[P_D], p[P_M], p[P_I], p[P_MR]
    ri_race, ro_race = 0.5 * p[P_DI], 0.5 * p[P_DO]
    k_i, k_o, k_b, chi, g, f_r = p[P_KI], p[P_KO], p[P_KB], p[P_CHI], p[P_G], p[P_FR]
    race_on, bb_on, grav_on = p[P_F_RACE] > 0.5, p[P_F_BB] > 0.5, p[P_F_GRAV] > 0.5
    lub_on, c_ho = p[P_F_LUB] > 0.5, p[P_CHO]
    cy, cz, cvy, cvz = y[5 * z], y[5 * z + 1], y[5 * z + 2], y[5 * z + 3]
    power = 0.0  # dissipated power (W)
    fy_ring = 0.0
    fz_ring = -f_r - (m_ring * g if grav_on else 0.0)
    for j in range(z):
        dydt[j] = y[2 * z + j]
        dydt[z + j] = y[3 * z + j]
        dydt[2 * z + j] = 0.0  # force accumulators (Cartesian y, z) held in the acceleration slots for now
        dydt[3 * z + j] = 0.0
        dydt[4 * z + j] = 0.0
    for j in range(z):
        r, th = y[j], y[z + j]
        c, s = np.cos(th), np.sin(th)
        px, pz = r * c, r * s
        fy = 0.0
        fz = -m * g if grav_on else 0.0
        if race_on:
            rd, thd = y[2 * z + j], y[3 * z + j]
            d_o = r + 0.5 * d - ro_race
            if d_o > 0.0:
                q = k_o * d_o**1.5
                if lub_on:
                    q_d = max(q + c_ho * rd, 0.0)  # d(delta_o)/dt = r'; never tensile
                    power += (q_d - q) * rd
                    q = q_d
                fy -= q * c
                fz -= q * s
            sx, sz = px - cy, pz - cz
            ln = np.sqrt(sx * sx + sz * sz)
            d_i = ri_race + 0.5 * d - ln
            if d_i > 0.0:
                nx, nz = sx / ln, sz / ln
                q = k_i * d_i**1.5
                if lub_on:
                    vx = rd * c - r * thd * s - cvy
                    vz = rd * s + r * thd * c - cvz
                    ddot = -(vx * nx + vz * nz)
                    q_d = max(q + c_ho * ddot, 0.0)
                    power += (q_d - q) * ddot
                    q = q_d
                fy += q * nx
                fz += q * nz
                fy_ring -= q * nx
                fz_ring -= q * nz
        dydt[2 * z + j] += fy
        dydt[3 * z + j] += fz
    if bb_on:
        for j in range(z):
            k = j + 1 if j + 1 < z else 0
            rj, tj, rk, tk = y[j], y[z + j], y[k], y[z + k]
            dx = rk * np.cos(tk) - rj * np.cos(tj)
            dz = rk * np.sin(tk) - rj * np.sin(tj)
            ln = np.sqrt(dx * dx + dz * dz)
            delta = d - ln
            if delta <= 0.0:
                aux[j] = 0.0
                continue
            nx, nz = dx / ln, dz / ln
            vjx = y[2 * z + j] * np.cos(tj) - rj * y[3 * z + j] * np.sin(tj)
            vjz = y[2 * z + j] * np.sin(tj) + rj * y[3 * z + j] * np.cos(tj)
            vkx = y[2 * z + k] * np.cos(tk) - rk * y[3 * z + k] * np.sin(tk)
            vkz = y[2 * z + k] * np.sin(tk) + rk * y[3 * z + k] * np.cos(tk)
            delta_dot = -((vkx - vjx) * nx + (vkz - vjz) * nz)
            if aux[j] <= 0.0:
                aux[j] = max(delta_dot, 1e-9)
            f = hertz_damped(delta, delta_dot, aux[j], k_b, chi)
            power += (f - k_b * delta**1.5) * delta_dot
            dydt[2 * z + j] -= f * nx
            dydt[3 * z + j] -= f * nz
            dydt[2 * z + k] += f * nx
            dydt[3 * z + k] += f * nz
    for j in range(z):
        r, th = y[j], y[z + j]
        c, s = np.cos(th), np.sin(th)
        fy, fz = dydt[2 * z + j], dydt[3 * z + j]
        f_rad = fy * c + fz * s
        f_tan = -fy * s + fz * c
        rd, thd = y[2 * z + j], y[3 * z + j]
        dydt[2 * z + j] = f_rad / m + r * thd * thd
        dydt[3 * z + j] = (f_tan / m - 2.0 * rd * thd) / r
        dydt[4 * z + j] = 0.0 / inertia  # spin torques come with traction (next slice)
    dydt[5 * z] = cvy
    dydt[5 * z + 1] = cvz
    dydt[5 * z + 2] = fy_ring / m_ring
    dydt[5 * z + 3] = fz_ring / m_ring
    dydt[5 * z + 4] = power


# Auxiliary array layout: per pair j (between ball j and j+1):
#   aux[j]           approach speed recorded at contact onset (used by the damping term)
#   aux[Z + 4j + 0]  onset time (NaN when apart)
#   aux[Z + 4j + 1]  peak force so far
#   aux[Z + 4j + 2]  orbital angle of the pair's midpoint at the peak
#   aux[Z + 4j + 3]  approach speed at onset (kept for classification)
# then the event count and EVENT_FIELDS values per logged episode.
EVENT_FIELDS = 6  # time, pair, angle, peak_force, duration, kind (0 impact, 1 rubbing)
#: An episode longer than this many Hertz impact durations (at its approach speed) is rubbing.
RUBBING_FACTOR = 3.0


def aux_size(n_balls: int, capacity: int) -> int:
    """Length of the auxiliary array for ``capacity`` logged contact episodes."""
    return 5 * n_balls + 1 + EVENT_FIELDS * capacity


@numba.njit(cache=True)
def planar_post(t, y, p, aux):  # pragma: no cover - compiled
    z = int(p[P_Z])
    if p[P_F_BB] < 0.5:
        return
    d, k_b, m = p[P_D], p[P_KB], p[P_M]
    base = 5 * z + 1
    cap = (aux.shape[0] - base) // EVENT_FIELDS
    for j in range(z):
        k = j + 1 if j + 1 < z else 0
        rj, tj, rk, tk = y[j], y[z + j], y[k], y[z + k]
        dx = rk * np.cos(tk) - rj * np.cos(tj)
        dz = rk * np.sin(tk) - rj * np.sin(tj)
        delta = d - np.sqrt(dx * dx + dz * dz)
        slot = z + 4 * j
        if delta > 0.0:
            f = k_b * delta**1.5
            if np.isnan(aux[slot]):
                aux[slot] = t
                aux[slot + 1] = 0.0
                aux[slot + 3] = aux[j]
            if f > aux[slot + 1]:
                aux[slot + 1] = f
                aux[slot + 2] = 0.5 * (tj + tk + (2.0 * np.pi if k == 0 else 0.0))
        elif not np.isnan(aux[slot]):
            n = int(aux[base - 1])
            if n < cap:
                e = base + EVENT_FIELDS * n
                duration = t - aux[slot]
                t_hertz = hertz_impact_duration(aux[slot + 3], 0.5 * m, k_b)
                aux[e] = aux[slot]
                aux[e + 1] = j
                aux[e + 2] = aux[slot + 2] % (2.0 * np.pi)
                aux[e + 3] = aux[slot + 1]
                aux[e + 4] = duration
                aux[e + 5] = 1.0 if duration > RUBBING_FACTOR * t_hertz else 0.0
            aux[base - 1] = n + 1
            aux[slot] = np.nan


def _params(bearing: Bearing, radial_load_n: float, restitution: float, gravity_m_s2: float, inner_speed: float,
            effects: dict[str, bool], cho_n_s_m: float) -> npt.NDArray[np.float64]:
    g, mat, masses = bearing.geometry, bearing.material, bearing.masses
    eta = compliance(mat)
    rc = race_curvatures(g)
    p = np.zeros(N_PARAMS)
    p[P_Z], p[P_D], p[P_M] = g.n_balls, g.ball_diameter_m, masses.ball_mass_kg
    p[P_I] = 0.1 * masses.ball_mass_kg * g.ball_diameter_m**2
    p[P_MR] = masses.ring_translational_mass_kg
    p[P_DI], p[P_DO] = g.inner_race_diameter_m, g.outer_race_diameter_m
    p[P_KI] = hertz_contact(*rc["inner"], eta).stiffness
    p[P_KO] = hertz_contact(*rc["outer"], eta).stiffness
    p[P_KB] = ball_ball_contact(g, mat).stiffness
    p[P_CHI] = damping_factor(restitution)
    p[P_G], p[P_FR], p[P_WI] = gravity_m_s2, radial_load_n, inner_speed
    p[P_F_RACE] = float(effects.get("race_contact", True))
    p[P_F_BB] = float(effects.get("ball_ball_contact", True))
    p[P_F_GRAV] = float(effects.get("gravity", True))
    p[P_F_LUB] = float(effects.get("lubricant_damping", bearing.lubricant is not None))
    p[P_CHO] = cho_n_s_m
    return p


def planar_problem(bearing: Bearing, theta0: npt.ArrayLike, radius0: npt.ArrayLike, ring0: tuple[float, float],
                   radial_load_n: float, restitution: float = 0.8, gravity_m_s2: float = 9.81,
                   inner_speed_rad_s: float = 0.0, effects: dict[str, bool] | None = None,
                   atol_scale: float = 1.0, cho_n_s_m: float = DEFAULT_CHO_N_S_M,
                   theta_dot0: npt.ArrayLike | None = None, event_capacity: int = 10_000) -> Problem:
    """The planar model from a given state (balls at rest), as a :class:`~simulation.solve.Problem`.

    The absolute tolerances (0.1 nm on positions, 0.1 um/s on speeds) are multiplied by ``atol_scale``;
    contact overlaps are micrometres, so energy-level checks want a smaller scale.
    """
    g = bearing.geometry
    lay = PlanarLayout(g.n_balls)
    sl = lay.slices()
    y0 = np.zeros(lay.size)
    y0[sl["theta"]] = theta0
    y0[sl["r"]] = radius0
    y0[5 * g.n_balls:5 * g.n_balls + 2] = ring0
    if theta_dot0 is not None:
        y0[sl["theta_dot"]] = theta_dot0
    atol = np.empty(lay.size)
    atol[sl["r"]] = 1e-10
    atol[sl["theta"]] = 1e-10 / (0.5 * g.pitch_diameter_m)
    atol[sl["r_dot"]] = 1e-7
    atol[sl["theta_dot"]] = 1e-7 / (0.5 * g.pitch_diameter_m)
    atol[sl["spin"]] = 1e-6
    atol[sl["ring"]] = [1e-10, 1e-10, 1e-7, 1e-7]
    atol[sl["dissipated"]] = 1e-9
    atol *= atol_scale
    p = _params(bearing, radial_load_n, restitution, gravity_m_s2, inner_speed_rad_s, effects or {}, cho_n_s_m)
    aux = np.zeros(aux_size(g.n_balls, event_capacity))
    aux[g.n_balls:5 * g.n_balls] = np.nan  # no contact episode open
    aux[g.n_balls + 1:5 * g.n_balls:4] = 0.0
    aux[g.n_balls + 2:5 * g.n_balls:4] = 0.0
    aux[g.n_balls + 3:5 * g.n_balls:4] = 0.0
    return Problem(model_id=MODEL_ID, params=p, aux=aux, y0=y0, t0=0.0, atol=atol, name="planar cageless bearing")


def contact_events(problem: Problem, aux: npt.NDArray[np.float64], t_end: float) -> pd.DataFrame:
    """The ball-ball contact episodes as the trace's event table (DESIGN §4, ``EVENT_COLUMNS``).

    Episodes still open at ``t_end`` are closed there (their duration is a lower bound). If more
    episodes happened than the capacity, the table holds the first ones and ``attrs["dropped"]``
    counts the rest.
    """
    p = problem.params
    z = int(p[P_Z])
    base = 5 * z + 1
    n = int(aux[base - 1])
    cap = (aux.shape[0] - base) // EVENT_FIELDS
    rows = aux[base:base + EVENT_FIELDS * min(n, cap)].reshape(-1, EVENT_FIELDS)
    still_open = []
    for j in range(z):
        slot = z + 4 * j
        if not np.isnan(aux[slot]):
            t_hertz = hertz_impact_duration(aux[slot + 3], 0.5 * p[P_M], p[P_KB])
            duration = t_end - aux[slot]
            still_open.append([aux[slot], j, aux[slot + 2] % (2 * np.pi), aux[slot + 1], duration,
                               float(duration > RUBBING_FACTOR * t_hertz)])
    if still_open:
        rows = np.vstack([rows, np.array(still_open)])
    table = pd.DataFrame({
        "time": rows[:, 0], "pair": rows[:, 1].astype(np.int64), "angle": rows[:, 2], "peak_force": rows[:, 3],
        "duration": rows[:, 4], "kind": np.where(rows[:, 5] > 0.5, "rubbing", "impact").astype(object),
    })
    table.attrs["dropped"] = max(0, n - cap)
    return table


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


def packed_start(bearing: Bearing, seed: int = 0, spread: float = 0.05) -> npt.NDArray[np.float64]:
    """Ball angles packed around the loaded zone (270 deg) with the one free gap at the top.

    Adjacent balls start ``spread`` of the free space apart (seeded), so nothing overlaps.
    """
    g = bearing.geometry
    z = g.n_balls
    phi = 2 * math.asin(g.ball_diameter_m / g.pitch_diameter_m)
    free = 2 * math.pi - z * phi
    extra = np.random.default_rng(seed).dirichlet(np.ones(z - 1)) * free * spread
    gaps = phi + extra
    span = gaps.sum()
    return 1.5 * math.pi - 0.5 * span + np.concatenate([[0.0], np.cumsum(gaps)])

