"""The paper's damped normal force evaluated strip by strip: what it does to one ball, by hand.

Source: Wang, Zhao, Wang, Jin, Appl. Sci. 2026, 16, 9284, sec. 2.2 (reference/paper.txt lines 68-80):

* the contact-point velocity v_b^c = omega_b x r_x^bc + v_b with r_x^bc = (x, y, ...) a point of the contact
  ellipse (line 69-70);
* "F_bn^k = +-K delta_k + C_ho v_rb3^c", v_rb3^c "the normal component of the initial contact-point sliding
  velocity" v_rb^c = v_r^c - v_b^c (lines 72-73);
* "The contact ellipse is sectioned into m narrow strips in the x_c direction", each strip's friction
  mu_k F_bn^k (lines 74-75); F_n = sum_k F_bn^k (line 78); the moment sums only the strips' tangential forces
  (line 80).

The text leaves open where on a strip the velocity is taken. Two readings:

* **A (across the rolling direction).** x_c along the major axis, as r_x^bc's third component (built on the
  groove radius R_delta and the long semi-axis a, line 70) and "Y_c ... the rolling element movement direction"
  (line 51) say; the strip's point at y = 0. The rolling rotation is about x_c, so omega_b x r_x^bc has no
  normal component there: every strip sees the approach speed d(delta)/dt, and the strip sum is the lumped
  damper C_ho d(delta)/dt (with C_ho split over the strips) -- the simulator's default model.
* **B (along the rolling direction; the hypothesis).** x_c along the minor axis, as "the X_c axis is the short
  half-axis" (line 51) and T_x = F sin(theta_f) with theta_f taken from the major axis (line 75) say. Then the
  relative normal velocity of the two surfaces at a strip x ahead of the centre is d(delta)/dt + u x / R_x
  (u the entraining speed, R_x the contact's radius along the rolling direction): material is compressed at
  the inlet and relaxes at the outlet. C_ho spread over the ellipse by area, strip k gets
  F_k = max(w_k Q_H + c_k (d(delta)/dt + u x_k / R_x), 0), w_k its share of the Hertz load (line load
  proportional to 1 - (x/b)^2), c_k = C_ho times its share of the area (chord proportional to sqrt(1 - (x/b)^2)),
  and the clip because a strip cannot pull (the paper does not write the clip; without it the u x_k / R_x terms
  cancel in pairs and reading B is reading A).

This script evaluates both at the paper's bearing, 1800 rpm, 500 N, C_ho = 2500 and 7500 N s/m, d(delta)/dt = 0,
for the unloaded outer contact (the centrifugal load) and the most loaded outer and inner ones (Stribeck,
5 F_r / Z): the strips' forces, their sum F_n, the friction the strips can carry mu_peak F_n (mu_peak of the
default traction curve) and its moment about the ball centre (D/2) mu_peak F_n (line 80: the normal forces add
no moment). Two cases for the approach:

* **held**: delta at the Hertz approach of the load, as if the ball could not move (a quasi-static solution
  that leaves the damping out of the load balance, then adds it);
* **free**: delta solved so that sum_k F_k = the load, as a dynamic model does (the ball moves until its radial
  forces balance on average).

    python benchmarks/paper_strip_damping.py             # well under a second, no simulation
    python benchmarks/paper_strip_damping.py --strips 21
"""

from __future__ import annotations

import argparse
import math
import sys
from dataclasses import dataclass

import numpy as np
from scipy import optimize

CHO_N_S_M = (2500.0, 7500.0)  # the paper's range (sec. 4, line 176)


def strip_shares(m: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Strip centres xi_k (in units of the semi-axis b along the rolling direction), their Hertz-load shares w_k
    and area shares s_k, for ``m`` strips of equal width over [-1, 1].

    The Hertz pressure's line load along the minor axis is (3 Q / 4 b)(1 - xi^2), the ellipse's chord
    2 a sqrt(1 - xi^2): w_k = (3/4)[xi - xi^3/3] and s_k = (1/pi)[xi sqrt(1 - xi^2) + asin xi] between the
    strip's edges; each sums to 1.
    """
    edges = np.linspace(-1.0, 1.0, m + 1)
    w_int = 0.75 * (edges - edges ** 3 / 3.0)
    s_int = (edges * np.sqrt(1.0 - edges ** 2) + np.arcsin(edges)) / math.pi
    return 0.5 * (edges[1:] + edges[:-1]), np.diff(w_int), np.diff(s_int)


def strip_forces(q_h: float, b: float, r_x: float, u: float, cho: float, delta_dot: float, m: int,
                 clip: bool = True) -> np.ndarray:
    """Reading B's strip forces F_k (N): Hertz load ``q_h`` (N) of semi-axis ``b`` (m) along the rolling
    direction, contact radius ``r_x`` (m), entraining speed ``u`` (m/s), damping ``cho`` (N s/m), approach
    speed ``delta_dot`` (m/s), ``m`` strips, no tension when ``clip``."""
    xi, w, s = strip_shares(m)
    f = w * q_h + cho * s * (delta_dot + abs(u) * xi * b / r_x)
    return np.maximum(f, 0.0) if clip else f


@dataclass(frozen=True)
class Contact:
    """One race contact at its load: Hertz stiffness K (N/m^1.5), b per cube root of load (m/N^(1/3)), R_x (m)."""

    label: str
    load_n: float
    stiffness: float
    b_coeff: float
    r_x: float


def contacts(speed_rpm: float, radial_load_n: float) -> tuple[list[Contact], float, float]:
    """The unloaded outer contact and the most loaded outer and inner ones; the entraining speed of pure rolling
    u = (d_m / 4)(1 - gamma^2) w_i (Harris & Kotzalas, *Rolling Bearing Analysis*, 5th ed., vol. 1, ch. 8); the
    ball diameter."""
    from cageless.bearing import default_bearing
    from cageless.simulation.hertz import compliance, hertz_contact, race_curvatures

    brg = default_bearing()
    g = brg.geometry
    d, dm = g.ball_diameter_m, g.pitch_diameter_m
    w_i = speed_rpm * 2.0 * math.pi / 60.0
    w_c = 0.5 * w_i * (1.0 - d / dm)
    u = 0.25 * dm * (1.0 - (d / dm) ** 2) * w_i
    curv, eta = race_curvatures(g), compliance(brg.material)
    out = []
    for race, label, q in (("outer", "unloaded outer", brg.masses.ball_mass_kg * 0.5 * dm * w_c * w_c),
                           ("outer", "most loaded outer", 5.0 * radial_load_n / g.n_balls),
                           ("inner", "most loaded inner", 5.0 * radial_load_n / g.n_balls)):
        hc = hertz_contact(*curv[race], eta)
        r_x = 0.5 * d * (dm + (d if race == "outer" else -d)) / dm
        out.append(Contact(label, q, hc.stiffness, hc.b_coeff, r_x))
    return out, u, d


def evaluate(c: Contact, u: float, cho: float, m: int, free: bool, clip: bool = True) -> dict[str, float]:
    """Reading B at contact ``c``: the approach, Hertz load, leading-edge damping C_ho u b / R_x, the strips'
    sum F_n, and the largest strip force, with the approach held at the Hertz one or ``free``."""
    def at(delta: float) -> tuple[float, float, np.ndarray]:
        q_h = c.stiffness * delta ** 1.5
        b = c.b_coeff * q_h ** (1.0 / 3.0)
        return q_h, b, strip_forces(q_h, b, c.r_x, u, cho, 0.0, m, clip)

    delta_h = (c.load_n / c.stiffness) ** (2.0 / 3.0)
    delta = delta_h
    if free:
        delta = optimize.brentq(lambda d: at(d)[2].sum() - c.load_n, 1e-9 * delta_h, delta_h, xtol=1e-16,
                                rtol=1e-13)
    q_h, b, f = at(delta)
    return {"delta_ratio": delta / delta_h, "q_h": q_h, "edge": cho * abs(u) * b / c.r_x, "f_n": f.sum(),
            "f_max": f.max(), "strips_loaded": int((f > 0.0).sum())}


def approach_speed(c: Contact, u: float, cho: float, m: int, delta: float) -> float:
    """The approach speed d(delta)/dt (m/s, < 0 while the ball lifts off) at which reading B's clipped strips
    carry exactly the load at approach ``delta``: the over-damped ball, its inertia neglected (m_b / C_ho is
    0.5-1.4 us against the milliseconds it settles over)."""
    q_h = c.stiffness * delta ** 1.5
    b = c.b_coeff * q_h ** (1.0 / 3.0)
    excess = strip_forces(q_h, b, c.r_x, u, cho, 0.0, m).sum() - c.load_n
    if excess <= 0.0:
        return 0.0
    lo = -excess / cho * 1e3
    return optimize.brentq(lambda v: strip_forces(q_h, b, c.r_x, u, cho, v, m).sum() - c.load_n, lo, 0.0,
                           xtol=1e-18, rtol=1e-12)


def settling_time(c: Contact, u: float, cho: float, m: int, within: float = 0.05) -> float:
    """Time (s) the over-damped ball takes from the Hertz approach of its load to within ``within`` (relative)
    of the approach at which the clipped strips carry the load: t = int d(delta) / |d(delta)/dt|."""
    free = evaluate(c, u, cho, m, free=True)["delta_ratio"]
    delta_h = (c.load_n / c.stiffness) ** (2.0 / 3.0)
    grid = np.geomspace(delta_h, (1.0 + within) * free * delta_h, 400)
    rate = np.array([-approach_speed(c, u, cho, m, d) for d in grid])
    return float(np.trapezoid(1.0 / rate[::-1], grid[::-1]))


def traction_peak() -> float:
    """The default traction curve's peak coefficient (the regression's, ``traction_peak_coefficient``)."""
    from cageless.simulation.parameters import ModelParameters

    return ModelParameters().traction_peak_coefficient


def table(speed_rpm: float, radial_load_n: float, m: int) -> str:
    """Both readings at each contact and C_ho, as a markdown table."""
    cs, u, d = contacts(speed_rpm, radial_load_n)
    mu = traction_peak()
    out = [f"u = {u:.3f} m/s, mu_peak = {mu:g}, m = {m} strips, d(delta)/dt = 0", "",
           "| contact | Q (N) | C_ho (N s/m) | C_ho u b/R_x (N) | reading | approach | delta/delta_H | F_n (N) | "
           "F_n/Q | mu_peak F_n (N) | moment (D/2) mu_peak F_n (mN m) | strips in compression |",
           "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for c in cs:
        for cho in CHO_N_S_M:
            for reading, approach, free, clip in (("A (= lumped)", "held", False, False),
                                                 ("B, no clip", "held", False, False),
                                                 ("B, clipped", "held", False, True),
                                                 ("B, clipped", "free", True, True)):
                r = evaluate(c, u if reading.startswith("B") else 0.0, cho, m, free, clip)
                edge = cho * u * c.b_coeff * c.load_n ** (1.0 / 3.0) / c.r_x
                out.append(f"| {c.label} | {c.load_n:.3g} | {cho:g} | {edge:.3g} | "
                           f"{reading} | {approach} | {r['delta_ratio']:.3g} | {r['f_n']:.4g} | "
                           f"{r['f_n'] / c.load_n:.3g} | {mu * r['f_n']:.3g} | {0.5 * d * mu * r['f_n'] * 1e3:.3g} | "
                           f"{r['strips_loaded']}/{m} |")
    from cageless.bearing import default_bearing

    g = default_bearing().geometry
    w_c = 0.5 * (speed_rpm * 2.0 * math.pi / 60.0) * (1.0 - g.ball_diameter_m / g.pitch_diameter_m)
    out += ["", f"Unloaded outer contact, reading B clipped, ball free: time from the Hertz approach to within 5 % of "
            f"the approach where the strips carry the load, against half an orbit ({math.pi / w_c * 1e3:.1f} ms)"]
    for cho in CHO_N_S_M:
        out.append(f"- C_ho = {cho:g} N s/m: {settling_time(cs[0], u, cho, m) * 1e6:.3g} us")
    return "\n".join(out)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--speed-rpm", type=float, default=1800.0)
    ap.add_argument("--radial-load-n", type=float, default=500.0)
    ap.add_argument("--strips", type=int, default=5, help="strips across the ellipse (the spatial model's default)")
    args = ap.parse_args(argv)
    sys.stdout.write(f"The paper's per-strip damped normal force at {args.speed_rpm:g} rpm, {args.radial_load_n:g} N"
                     f"\n\n{table(args.speed_rpm, args.radial_load_n, args.strips)}\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
