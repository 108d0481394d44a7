"""The ``strip_damping`` effect: the paper's strip formulation of the race damping, opt-in, planar model.

For reproducing the paper, not the default physics. Wang, Zhao, Wang, Jin, Appl. Sci. 2026, 16, 9284, sec. 2.2
(reference/paper.txt lines 68-80) write the damped normal force strip by strip, F_bn^k = K delta_k + C_ho v_n
(line 72), with the contact-point velocity v_b^c = omega_b x r_x^bc + v_b at the points r_x^bc = (x, y, ...)
of the contact ellipse (lines 69-70), the ellipse "sectioned into m narrow strips in the x_c direction" (line
74), the X_c axis its "short half-axis" (line 51), F_n = sum_k F_bn^k (line 78) and each strip's friction
mu_k F_bn^k (line 75). Read with the strips along the rolling direction (the minor axis), the two surfaces'
relative normal speed at a strip x ahead of the centre is d(delta)/dt + u x / R_x, u the entraining speed and R_x
the contact's radius along the rolling direction: the inlet is compressed, the outlet relaxes. Here:

* :data:`STRIPS` strips of equal width over the minor axis [-b, b], b = SB delta^(1/2) (the Hertz semi-axis,
  b = b* Q^(1/3) with Q = K delta^1.5), centres xi_k b;
* strip k carries F_k = max(w_k Q + C_ho s_k (d(delta)/dt + |u| xi_k b / R_x), 0): w_k its share of the Hertz
  load (line load proportional to 1 - xi^2), s_k its share of the area (chord proportional to sqrt(1 - xi^2)),
  so that a uniform approach speed gives the lumped damper C_ho d(delta)/dt, and no strip pulls (the paper
  does not write this clip; without it the u x / R_x terms cancel in pairs and nothing changes);
* the sum F_n replaces the lumped max(Q + C_ho d(delta)/dt, 0) of the ``lubricant_damping`` effect at both race
  contacts, along the contact normal through the ball centre (the paper's moments sum only the strips'
  tangential forces, line 80), and the traction acts on it as on the lumped force;
* its power (F_n - Q) d(delta)/dt is booked as the damper's, so the energy balance closes (the force can do
  positive work: it depends on the rolling speed, not on d(delta)/dt alone).

``benchmarks/paper_strip_damping.py`` evaluates the same law by hand (and tests/validation checks it against
closed forms). With the ball free to move, as here, the approach settles where the strips carry the ball's
radial load, so the normal force, and the friction on it, stay the load's.
"""

from __future__ import annotations

import math

import numba
import numpy as np

from cageless.simulation.forces import FASTMATH
from cageless.simulation.models.base import LAYOUT, P_CHO

__all__ = ["STRIPS", "strip_shares", "strip_normal", "strip_slots"]

#: Strips across the minor axis (the spatial model's default strip count).
STRIPS = 5

P_F_STRIP, P_SB_I, P_SB_O, P_SRX_I, P_SRX_O = LAYOUT.slots("F_STRIP", "SB_I", "SB_O", "SRX_I", "SRX_O")


def strip_shares(m: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Centres xi_k (units of b), Hertz-load shares w_k = (3/4)[xi - xi^3/3] and area shares
    s_k = (1/pi)[xi sqrt(1 - xi^2) + asin xi] (between each strip's edges) of ``m`` equal strips over [-1, 1]."""
    edges = np.linspace(-1.0, 1.0, m + 1)
    w_int = 0.75 * (edges - edges ** 3 / 3.0)
    s_int = (edges * np.sqrt(1.0 - edges ** 2) + np.arcsin(edges)) / math.pi
    return 0.5 * (edges[1:] + edges[:-1]), np.diff(w_int), np.diff(s_int)


_XI, _W, _S = (tuple(float(v) for v in a) for a in strip_shares(STRIPS))


@numba.njit(cache=True, fastmath=FASTMATH, inline="always")
def strip_normal(q, delta, delta_dot, u_e, inner, p):  # pragma: no cover - compiled
    """The strips' normal force (N) at a race contact of Hertz force ``q`` (N) and approach ``delta`` (m) closing
    at ``delta_dot`` (m/s), entraining speed ``u_e`` (m/s); ``inner`` picks the race's constants."""
    if inner:
        sb, rx = p[P_SB_I], p[P_SRX_I]
    else:
        sb, rx = p[P_SB_O], p[P_SRX_O]
    cho = p[P_CHO]
    edge = abs(u_e) * sb * math.sqrt(delta) / rx  # u b / R_x
    f = 0.0
    for k in range(STRIPS):
        f += max(_W[k] * q + cho * _S[k] * (delta_dot + _XI[k] * edge), 0.0)
    return f


def strip_slots(bearing) -> dict[str, float]:  # type: ignore[no-untyped-def]
    """The ``strip_damping`` slots for ``bearing``, per race (suffix _I, _O): SB = b* K^(1/3), so that the Hertz
    semi-axis along the rolling direction is b = SB delta^(1/2), and SRX = R_x = (D/2)(d_m -+ D)/d_m."""
    from cageless.simulation.hertz import compliance, hertz_contact, race_curvatures

    g = bearing.geometry
    d, dm = g.ball_diameter_m, g.pitch_diameter_m
    rc, eta = race_curvatures(g), compliance(bearing.material)
    out = {}
    for tag, race, r_x in (("I", "inner", 0.5 * d * (dm - d) / dm), ("O", "outer", 0.5 * d * (dm + d) / dm)):
        hc = hertz_contact(*rc[race], eta)
        out.update({f"SB_{tag}": hc.b_coeff * hc.stiffness ** (1.0 / 3.0), f"SRX_{tag}": r_x})
    return out
