"""The contact log of the ball-bearing models: ball-ball contact episodes, kept by the compiled code.

The log is a float array (``Problem.log``) that the integrator hands to the model's kernels: the approach
speed each ball-ball contact closed at (the damping term reads it), the episode that is open at each pair,
then the episodes logged so far. :func:`planar_post` updates it after every accepted step (both the planar
and the spatial model, whose first 5 Z + 6 states are laid out alike); :func:`contact_events` turns it into
the trace's event table. Its last 2 Z values are the right-hand side's scratch (cos and sin of every ball's
angle).
"""

from __future__ import annotations

import numba
import numpy as np
import numpy.typing as npt
import pandas as pd

from cageless.simulation.forces import hertz_impact_duration
from cageless.simulation.models.base import P_D, P_F_BB, P_KB, P_M, P_Z
from cageless.simulation.problem import Problem

__all__ = ["EVENT_FIELDS", "RUBBING_FACTOR", "ONSET_RESOLUTION", "log_size", "empty_log", "planar_post",
           "contact_events"]


# The contact log (a float array, ``Problem.log``): per pair j (between ball j and j+1):
#   log[j]           approach speed recorded at contact onset (used by the damping term)
#   log[Z + 4j + 0]  onset time (NaN when apart)
#   log[Z + 4j + 1]  peak force so far
#   log[Z + 4j + 2]  orbital angle of the pair's midpoint at the peak
#   log[Z + 4j + 3]  approach speed at onset (kept for classification)
# then the event count and EVENT_FIELDS values per logged episode.
EVENT_FIELDS = 6  # time, pair, angle, peak_force, duration, kind (0 impact, 1 rubbing)
#: An episode longer than this many Hertz impact durations (at its approach speed) is rubbing.
RUBBING_FACTOR = 3.0
#: Contact onsets are resolved to this fraction of the Hertz impact duration at 1 m/s approach.
ONSET_RESOLUTION = 20.0


def log_size(n_balls: int, capacity: int) -> int:
    """Length of the contact log for ``capacity`` logged contact episodes."""
    return 5 * n_balls + 1 + EVENT_FIELDS * capacity + 2 * n_balls  # last 2 Z: the RHS's trig scratch


def empty_log(n_balls: int, capacity: int) -> npt.NDArray[np.float64]:
    """A contact log with no episode open and none logged, for ``capacity`` episodes."""
    log = np.zeros(log_size(n_balls, capacity))
    log[n_balls:5 * n_balls] = np.nan  # no contact episode open
    log[n_balls + 1:5 * n_balls:4] = 0.0
    log[n_balls + 2:5 * n_balls:4] = 0.0
    log[n_balls + 3:5 * n_balls:4] = 0.0
    return log


@numba.njit(cache=True)
def planar_post(t, y, p, log):  # pragma: no cover - compiled
    z = int(p[P_Z])
    if p[P_F_BB] < 0.5:
        return
    d, k_b, m = p[P_D], p[P_KB], p[P_M]
    base = 5 * z + 1
    cap = (log.shape[0] - base - 2 * z) // EVENT_FIELDS
    spatial = y.shape[0] > 5 * z + 6
    for j in range(z):
        k = j + 1 if j + 1 < z else 0
        rj, tj, rk, tk = y[j], y[z + j], y[k], y[z + k]
        dx = rk * np.cos(tk) - rj * np.cos(tj)
        dz = rk * np.sin(tk) - rj * np.sin(tj)
        da = dva = 0.0
        if spatial:  # the spatial model appends axial positions and rates (simulation.models.spatial)
            da, dva = y[5 * z + 6 + k] - y[5 * z + 6 + j], y[6 * z + 6 + k] - y[6 * z + 6 + j]
        ln = np.sqrt(dx * dx + dz * dz + da * da)
        delta = d - ln
        slot = z + 4 * j
        if delta > 0.0 and log[j] <= 0.0:
            vx = y[2 * z + k] * np.cos(tk) - rk * y[3 * z + k] * np.sin(tk) - (
                y[2 * z + j] * np.cos(tj) - rj * y[3 * z + j] * np.sin(tj))
            vz = y[2 * z + k] * np.sin(tk) + rk * y[3 * z + k] * np.cos(tk) - (
                y[2 * z + j] * np.sin(tj) + rj * y[3 * z + j] * np.cos(tj))
            log[j] = max(-(vx * dx + vz * dz + dva * da) / ln, 1e-9)
        elif delta <= 0.0:
            log[j] = 0.0
        if delta > 0.0:
            f = k_b * delta**1.5
            if np.isnan(log[slot]):
                log[slot] = t
                log[slot + 1] = 0.0
                log[slot + 3] = log[j]
            if f > log[slot + 1]:
                log[slot + 1] = f
                log[slot + 2] = 0.5 * (tj + tk + (2.0 * np.pi if k == 0 else 0.0))
        elif not np.isnan(log[slot]):
            n = int(log[base - 1])
            if n < cap:
                e = base + EVENT_FIELDS * n
                duration = t - log[slot]
                t_hertz = hertz_impact_duration(log[slot + 3], 0.5 * m, k_b)
                log[e] = log[slot]
                log[e + 1] = j
                log[e + 2] = log[slot + 2] % (2.0 * np.pi)
                log[e + 3] = log[slot + 1]
                log[e + 4] = duration
                log[e + 5] = 1.0 if duration > RUBBING_FACTOR * t_hertz else 0.0
            log[base - 1] = n + 1
            log[slot] = np.nan


def contact_events(problem: Problem, log: npt.NDArray[np.float64], t_end: float) -> pd.DataFrame:
    """The ball-ball contact episodes as the trace's event table (``EVENT_COLUMNS``).

    Episodes still open at ``t_end`` are closed there (their duration is a lower bound). If more
    episodes happened than the capacity, the table holds the first ones and ``attrs["dropped"]``
    counts the rest.
    """
    p = problem.params
    z = int(p[P_Z])
    base = 5 * z + 1
    n = int(log[base - 1])
    cap = (log.shape[0] - base - 2 * z) // EVENT_FIELDS
    rows = log[base:base + EVENT_FIELDS * min(n, cap)].reshape(-1, EVENT_FIELDS)
    still_open = []
    for j in range(z):
        slot = z + 4 * j
        if not np.isnan(log[slot]):
            t_hertz = hertz_impact_duration(log[slot + 3], 0.5 * p[P_M], p[P_KB])
            duration = t_end - log[slot]
            still_open.append([log[slot], j, log[slot + 2] % (2 * np.pi), log[slot + 1], duration,
                               float(duration > RUBBING_FACTOR * t_hertz)])
    if still_open:
        rows = np.vstack([rows, np.array(still_open)])
    table = pd.DataFrame({
        "time": rows[:, 0], "pair": rows[:, 1].astype(np.int64), "angle": rows[:, 2], "peak_force": rows[:, 3],
        "duration": rows[:, 4], "kind": np.where(rows[:, 5] > 0.5, "rubbing", "impact").astype(object),
    })
    table.attrs["dropped"] = max(0, n - cap)
    return table
