"""Compiled contact force laws shared by the models.

Ball-ball normal force: Hertz with hysteresis damping of the Flores type
(Flores, Machado, Silva & Martins, "On the continuous contact force models for
soft materials in multibody dynamics", Mech. Mach. Theory 46 (2011) 1359-1369):

    F = K delta^1.5 (1 + chi * d(delta)/dt / v_in),

where v_in is the approach speed when the contact began. Flores et al. give
chi = 8 (1 - R) / (5 R) in closed form, which rebounds a little below R (0.894
for R = 0.9, 0.256 for R = 0.3). Instead, :func:`damping_factor` calibrates chi
so that a free two-body impact rebounds with exactly R, as the design asks: in
units delta = delta_s x, t = t_s tau with delta_s / t_s = v_in, the impact is
x'' = -x^1.5 (1 + chi x'), x(0) = 0, x'(0) = 1, and the rebound speed depends on
chi alone. The force is never tensile.
"""

from __future__ import annotations

from functools import lru_cache

import numba
import numpy as np
from scipy import optimize
from scipy.integrate import solve_ivp

from cageless.errors import ParameterError

__all__ = ["FASTMATH", "PLASTIC_CHI", "SQUEEZE_CUTOFF", "SQUEEZE_TAPER", "hertz_damped", "hertz_impact_duration",
           "damping_factor", "rebound", "squeeze_film"]


@numba.njit(cache=True, inline="always")
def hertz_damped(delta, delta_dot, v_in, stiffness, chi):  # pragma: no cover - compiled
    """Normal force (N) for overlap ``delta`` (m) > 0 at overlap rate ``delta_dot`` (m/s)."""
    if delta <= 0.0:
        return 0.0
    f = stiffness * delta * np.sqrt(delta)
    if chi > 0.0 and v_in > 0.0:
        f *= 1.0 + chi * delta_dot / v_in
    return max(f, 0.0)


#: Gap (in units of the critical film h_0) at which the ball-ball squeeze film ends: the paper's film acts
#: for h_0 < h < 4/3 h_0 (h floored at h_0 below).
SQUEEZE_CUTOFF = 4.0 / 3.0
#: Half-width (in units of h_0) of the two bands over which :func:`squeeze_film` hands its force over
#: smoothly: to zero around :data:`SQUEEZE_CUTOFF`, and to the Hertz contact around a gap of zero.
SQUEEZE_TAPER = 1.0 / 6.0


@numba.njit(cache=True, inline="always")
def squeeze_film(gap, approach_speed, viscosity, radius, h_film):  # pragma: no cover - compiled
    """Squeeze-film force (N, repulsive) between two balls ``gap`` (m; < 0: overlapping) apart, closing at
    ``approach_speed`` (m/s): the Reynolds squeeze film of two spheres, F = 6 pi eta R^2 (-dh/dt) / h with
    R = ``radius`` (D / 4 for two balls of diameter D) and h floored at ``h_film`` (Delta_r), zero while the
    gap opens.

    The paper's film acts for gaps below 4/3 Delta_r and gives way to the Hertz contact at a gap of zero. Cut
    off there, the force would jump at both ends: from 3/4 of its plateau to zero at 4/3 Delta_r, and from the
    plateau to the Hertz force, which starts at zero, at contact; an error-controlled integrator cuts a step
    that straddles either jump down to nanoseconds. Here the force is handed over smoothly instead, over two
    bands of half-width b = :data:`SQUEEZE_TAPER` h_0, by the cubic w(s) = s^2 (3 - 2 s) (force and slope
    continuous, so C^1 in the gap and along a trajectory), as molecular-dynamics pair styles smooth a force
    to zero at its cut-off (LAMMPS ``lj/smooth``: force and first derivative zero at the outer cut-off):

    * around the cut-off, F falls to zero across 4/3 h_0 -/+ b;
    * around contact, the plateau fades out across -b < gap < b, so it acts on into the first b of overlap,
      as DEM lubrication models keep the film in contact (LIGGGHTS' ``cohesion_model LUBRICATION``: the
      squeeze term with h floored at the minimum separation while the particles overlap) or blend it into the
      contact force near contact (Nijssen, Ottens & Padding, Powder Technol. 2022, "A note on the modelling
      of lubrication forces in unresolved simulations", Eq. 9: a linear blend over the last h_min of gap).

    Both bands are centred on the paper's ends, so the momentum a closing pair exchanges through the film,
    integral F dt = 6 pi eta R^2 integral dh / max(h, h_0) (independent of the approach speed), is kept:
    6 pi eta R^2 (1 + ln 4/3) with the hard ends, 0.12 % less with the bands (the contact band exactly: w is
    antisymmetric about its centre and the plateau constant across it).
    """
    if approach_speed <= 0.0:
        return 0.0
    band = SQUEEZE_TAPER * h_film
    outer = SQUEEZE_CUTOFF * h_film + band
    if gap >= outer or gap <= -band:
        return 0.0
    f = 6.0 * np.pi * viscosity * radius * radius * approach_speed / max(gap, h_film)
    inner = outer - 2.0 * band
    if gap > inner:
        s = (outer - gap) / (2.0 * band)
        f *= s * s * (3.0 - 2.0 * s)
    elif gap < band:
        s = (gap + band) / (2.0 * band)
        f *= s * s * (3.0 - 2.0 * s)
    return f


@numba.njit(cache=True)
def hertz_impact_duration(approach_speed, reduced_mass, stiffness):  # pragma: no cover - compiled
    """Elastic Hertz impact duration (s): 2.943 delta_max / v with delta_max = (5 m* v^2 / (4 K))^(2/5)
    (Johnson, *Contact Mechanics*, 1985, sect. 11.4)."""
    v = max(approach_speed, 1e-9)
    return 2.943 * (5.0 * reduced_mass * v * v / (4.0 * stiffness)) ** 0.4 / v


def rebound(chi: float) -> float:
    """Coefficient of restitution of the dimensionless impact x'' = -x^1.5 (1 + chi x'), x'(0) = 1."""

    def f(_t: float, s: np.ndarray) -> list[float]:
        x, v = s
        return [v, -max(x, 0.0) ** 1.5 * max(1.0 + chi * v, 0.0)]

    def out(_t: float, s: np.ndarray) -> float:
        return s[0]

    out.terminal, out.direction = True, -1  # type: ignore[attr-defined]

    def stop(_t: float, s: np.ndarray) -> float:
        return s[1]  # stuck: the force vanished with the bodies still pressed (fully plastic)

    res = solve_ivp(f, (0.0, 50.0), [1e-12, 1.0], events=out, rtol=1e-11, atol=1e-13, max_step=0.01)
    if res.t_events[0].size:
        return float(-res.y_events[0][0][1])
    return 0.0


#: LLVM fast-math flags of the model right-hand sides: fused multiply-add, reciprocals and signed zeros,
#: but not "nnan"/"ninf", so a non-finite state still propagates to the integrator's check. They change
#: results only at round-off (measured: 5e-7 relative on an acceleration that is the small sum of 100 N
#: contact forces) and cut the spatial right-hand side from 9.2 to ~6 us. "reassoc" is left out: with it,
#: code compiled in a fresh process and the same code loaded from numba's cache gave different round-off
#: (different settled states and traces of one scene), breaking the same-input-same-output rule; without
#: it the two agree bit for bit (tests/simulation/test_determinism.py), at ~4 % on the spatial RHS.
FASTMATH = {"nsz", "arcp", "contract"}

#: Damping factor standing for R = 0. A perfectly plastic impact is the limit chi -> infinity of this
#: law: the clamped force vanishes once the overlap recedes faster than v_in / chi, so the rebound is at
#: most 1 / chi of the approach speed (measured with :func:`rebound`: 0.1 at chi = 10, 0.01 at 100).
#: chi = 1000 keeps the rebound below 0.1 % while the contact stays resolvable (its duration is about
#: (1000 / 0.4)^-0.4, 1/23, of the elastic Hertz time).
PLASTIC_CHI = 1000.0


@lru_cache(maxsize=64)
def damping_factor(restitution: float) -> float:
    """Damping factor chi for which a free impact rebounds with ``restitution`` (0 <= R <= 1).

    R = 0 (perfectly plastic, the lower end of the paper's range 0 <= R < 1) is represented by
    :data:`PLASTIC_CHI`, a rebound below 0.1 % of the approach speed.
    """
    if not 0.0 <= restitution <= 1.0:
        raise ParameterError("restitution", "must lie in [0, 1]", restitution)
    if restitution == 1.0:
        return 0.0
    if restitution <= 1.0 / PLASTIC_CHI:
        return PLASTIC_CHI
    guess = 8.0 * (1.0 - restitution) / (5.0 * restitution)
    hi = guess
    while rebound(hi) > restitution:
        hi *= 2.0
    return float(optimize.brentq(lambda c: rebound(c) - restitution, 0.0, hi, xtol=1e-12, rtol=1e-10))
