"""Can the race damping C_ho reach the unloaded-zone slip through viscoelastic rolling resistance?

A lumped normal damper C_ho d(delta)/dt does no work in steady rolling: the approach delta is constant. A
real damped contact that rolls is compressed at its leading edge and relaxes at its trailing edge, so the
damping shifts the pressure centroid forward by x_bar and resists rolling with the moment Q x_bar (Johnson,
*Contact Mechanics*, 1985, sec. 9.2-9.4; Greenwood, Minshall & Tabor, Proc. R. Soc. A 259 (1961) 480). This
script sizes that term for the paper's bearing and C_ho range, with the C_ho spread over the contact as a
Kelvin-Voigt elastic (Winkler) foundation that carries no tension (:func:`winkler_kv_rolling`), and compares
its power with the hydrodynamic rolling loss that sets the slip now (Chiu 1974, the ``rolling_losses`` effect).

Model (our derivation, checked against its two closed-form limits in tests/validation):

* foundation: pressure p = k'' w + c'' dw/dt on the ellipse's area, w the local compression; the ball's
  profile is the paraboloid w = delta - x^2 / (2 R_x) - y^2 / (2 R_y), x along the rolling direction;
* the profile's radii are chosen so that at the Hertz approach delta_H the contact is the Hertz ellipse
  (R_x = b^2 / (2 delta_H), b the semi-axis along the rolling direction, R_y = a^2 / (2 delta_H)), and
  k'' = 2 Q / (pi a b delta_H) gives the Hertz load Q statically; c'' = C_ho / (pi a b): a uniform approach
  rate delta' then meets the lumped force C_ho delta';
* rolling at speed V, material enters the contact undeformed at x = +b_y, is compressed while dw/dt =
  V x / R_x > 0 and unloads behind the centre; the contact ends where p = 0, at
  x_t = L - sqrt(L^2 + b_y^2), L = c'' V / k'' (the relaxation length), on every strip y;
* the approach delta is solved so that the integrated pressure is the load Q; x_bar = M / Q.

Limits: for L << b (slow rolling, De = L / b << 1) M = C_ho V delta / 2, a rolling-friction coefficient
x_bar / (D/2) growing linearly with C_ho V (the low-speed law of viscoelastic rolling: Brilliantov & Poeschel,
Europhys. Lett. 42 (1998) 511, valid when the relaxation time is short against the contact's transit time);
for L >> b the contact shrinks to its leading half and x_bar -> (3 pi / 16) b_eff, which no longer grows with
C_ho (the decrease at high speed of Brilliantov & Poeschel, Eur. Phys. J. B 12 (1999) 299, for a cylinder).

    python benchmarks/cho_rolling_resistance.py            # a second: closed forms only, no simulation
"""

from __future__ import annotations

import argparse
import math
import sys

import numpy as np
from scipy import optimize

CHO_N_S_M = (0.0, 2500.0, 5000.0, 7500.0)  # the paper's range (Wang et al. 2026, sec. 4) and no damping
_GAUSS = np.polynomial.legendre.leggauss(64)


def _strip(delta_y: float, r_x: float, k2: float, c2: float, v: float) -> tuple[float, float]:
    """Line load (N/m) and its moment about x = 0 (N) of one strip of the no-tension Kelvin-Voigt foundation."""
    if delta_y <= 0.0:
        return 0.0, 0.0
    a = math.sqrt(2.0 * r_x * delta_y)
    lam = c2 * v / k2
    x_t = lam - math.hypot(lam, a)  # trailing edge, p(x_t) = 0
    el_f = k2 * (delta_y * (a - x_t) - (a ** 3 - x_t ** 3) / (6.0 * r_x))
    dm_f = c2 * v * (a * a - x_t * x_t) / (2.0 * r_x)
    el_m = k2 * (delta_y * (a * a - x_t * x_t) / 2.0 - (a ** 4 - x_t ** 4) / (8.0 * r_x))
    dm_m = c2 * v * (a ** 3 - x_t ** 3) / (3.0 * r_x)
    return el_f + dm_f, el_m + dm_m


def winkler_kv_load(delta: float, r_x: float, r_y: float, k2: float, c2: float, v: float) -> tuple[float, float]:
    """Load Q (N) and rolling-resistance moment M (N m) of the rolling no-tension Kelvin-Voigt foundation.

    ``delta`` approach (m), ``r_x``/``r_y`` profile radii along/across the rolling direction (m), ``k2``
    stiffness (Pa/m) and ``c2`` damping (Pa s/m) per unit area, ``v`` rolling speed (m/s).
    """
    if delta <= 0.0:
        return 0.0, 0.0
    half = math.sqrt(2.0 * r_y * delta)
    s, wts = _GAUSS
    f = m = 0.0
    for si, wi in zip(s, wts, strict=True):
        y = half * si
        fy, my = _strip(delta - y * y / (2.0 * r_y), r_x, k2, c2, v)
        f += wi * fy * half
        m += wi * my * half
    return f, m


def winkler_kv_rolling(load_n: float, a_m: float, b_m: float, delta_h_m: float, cho_n_s_m: float,
                       v_m_s: float) -> dict[str, float]:
    """The rolling no-tension Kelvin-Voigt contact carrying ``load_n`` whose static contact is the Hertz ellipse
    of semi-axes ``a_m`` (across) and ``b_m`` (along the rolling direction) at the Hertz approach
    ``delta_h_m``, with the lumped damping ``cho_n_s_m`` spread over it, rolling at ``v_m_s``.

    Returns delta (m), M (N m), x_bar = M / Q (m), the relaxation length L = C_ho V delta_H / (2 Q) (m),
    De = L / b, the contact's semi-axis along the rolling direction b_eff (m) and the dissipated power
    P = int p dw/dt dA = M V / R_x (W), R_x = b^2 / (2 delta_H) the profile's radius.
    """
    delta_h = delta_h_m
    r_x, r_y = b_m * b_m / (2.0 * delta_h), a_m * a_m / (2.0 * delta_h)
    k2 = 2.0 * load_n / (math.pi * a_m * b_m * delta_h)
    c2 = cho_n_s_m / (math.pi * a_m * b_m)
    delta = optimize.brentq(lambda d: winkler_kv_load(d, r_x, r_y, k2, c2, v_m_s)[0] - load_n,
                            1e-6 * delta_h, 2.0 * delta_h, xtol=1e-14 * delta_h, rtol=1e-12)
    _, m = winkler_kv_load(delta, r_x, r_y, k2, c2, v_m_s)
    lam = c2 * v_m_s / k2
    return {"delta": delta, "moment": m, "x_bar": m / load_n, "relax_len": lam, "de": lam / b_m,
            "b_eff": math.sqrt(2.0 * r_x * delta), "power": m * v_m_s / r_x}


def contact_rows(speed_rpm: float = 1800.0, radial_load_n: float = 500.0,
                 cho_values: tuple[float, ...] = CHO_N_S_M) -> list[dict[str, float | str]]:
    """The damped-rolling term at the unloaded outer contact and the most loaded ones, for each C_ho.

    Loads: the unloaded outer contact carries the centrifugal force m (d_m / 2) w_c^2; the most loaded ones
    Q_max = 5 F_r / Z (Stribeck). Rolling speed: the entraining speed of pure rolling,
    u = (d_m / 4)(1 - gamma^2) w_i (Harris & Kotzalas, *Rolling Bearing Analysis*, 5th ed., vol. 1, ch. 8).
    The hydrodynamic loss beside it is the ``rolling_losses`` effect's at the default parameters: the ball loses
    2 |F_R| u (Chiu 1974; :mod:`cageless.simulation.physics.rolling_force`), with the Hamrock-Dowson central film.
    """
    from cageless.bearing import default_bearing
    from cageless.simulation.hertz import compliance, hertz_contact, race_curvatures
    from cageless.simulation.parameters import ModelParameters
    from cageless.simulation.physics.film_traction import hd_central_film
    from cageless.simulation.physics.rolling_force import chiu_rolling_forces

    b = default_bearing()
    g, mat, lub = b.geometry, b.material, b.lubricant
    par = ModelParameters()
    d, dm = g.ball_diameter_m, g.pitch_diameter_m
    gamma = d / dm
    w_i = speed_rpm * 2.0 * math.pi / 60.0
    w_c = 0.5 * w_i * (1.0 - gamma)
    u = 0.25 * dm * (1.0 - gamma * gamma) * w_i
    e_red = mat.youngs_modulus_pa / (1.0 - mat.poisson_ratio ** 2)
    curv, eta_c = race_curvatures(g), compliance(mat)
    rows = []
    for race, label, q in (("outer", "unloaded outer", b.masses.ball_mass_kg * 0.5 * dm * w_c * w_c),
                           ("outer", "most loaded outer", 5.0 * radial_load_n / g.n_balls),
                           ("inner", "most loaded inner", 5.0 * radial_load_n / g.n_balls)):
        hc = hertz_contact(*curv[race], eta_c)
        a, bb = hc.semi_axes(q)
        r_x = 0.5 * d * (dm + (d if race == "outer" else -d)) / dm
        f = g.outer_curvature_factor if race == "outer" else g.inner_curvature_factor
        r_y = f * d / (2.0 * f - 1.0)
        h = hd_central_film(lub.dynamic_viscosity_pa_s, lub.pressure_viscosity_coefficient_1_pa, e_red, u, q, r_x,
                            hc.kappa)
        f_r = chiu_rolling_forces(lub.dynamic_viscosity_pa_s, u, 0.0, h, r_x, r_y, par.meniscus_distance_m, d)[0]
        p_chiu = 2.0 * abs(f_r) * u
        k_lin = 1.5 * hc.stiffness ** (2.0 / 3.0) * q ** (1.0 / 3.0)
        for cho in cho_values:
            r = winkler_kv_rolling(q, a, bb, hc.deflection(q), cho, u)
            p_h = r["power"]
            rows.append({"contact": label, "load_n": q, "u_m_s": u, "b_um": bb * 1e6, "cho": cho,
                         "tau_ms": cho / k_lin * 1e3, "de": r["de"], "x_bar_um": r["x_bar"] * 1e6,
                         "mu_roll": r["x_bar"] / (0.5 * d),
                         "mu_linear": cho * u * r["delta"] / 2.0 / q / (0.5 * d) if cho else 0.0,
                         "p_h_mw": p_h * 1e3, "p_chiu_mw": p_chiu * 1e3})
    return rows


def bearing_torque(cho_n_s_m: float, speed_rpm: float = 1800.0, radial_load_n: float = 500.0) -> float:
    """The drive torque (N m) the damped rolling term alone would take from the inner ring: the dissipated power
    of both race contacts of every loaded ball over w_i.

    Loads: zero clearance, one ball under the load line, Q = Q_max cos^1.5 psi over |psi| < 90 deg, Q_max from
    F_r = sum Q cos psi (Stribeck; Harris & Kotzalas, vol. 1, ch. 7); rolling speed as in :func:`contact_rows`.
    """
    from cageless.bearing import default_bearing
    from cageless.simulation.hertz import compliance, hertz_contact, race_curvatures

    b = default_bearing()
    g = b.geometry
    d, dm = g.ball_diameter_m, g.pitch_diameter_m
    w_i = speed_rpm * 2.0 * math.pi / 60.0
    u = 0.25 * dm * (1.0 - (d / dm) ** 2) * w_i
    psi = 2.0 * math.pi * np.arange(g.n_balls) / g.n_balls
    shape = np.where(np.cos(psi) > 0.0, np.clip(np.cos(psi), 0.0, None) ** 1.5, 0.0)
    q_max = radial_load_n / float(np.sum(shape * np.cos(psi)))
    curv, eta_c = race_curvatures(g), compliance(b.material)
    power = 0.0
    for race in ("inner", "outer"):
        hc = hertz_contact(*curv[race], eta_c)
        for q in q_max * shape[shape > 0.0]:
            a, bb = hc.semi_axes(q)
            power += winkler_kv_rolling(q, a, bb, hc.deflection(q), cho_n_s_m, u)["power"] if cho_n_s_m else 0.0
    return power / w_i


#: The catalogue friction coefficient of an open deep-groove ball bearing (SKF, *Rolling bearings* catalogue,
#: "Estimating the frictional moment": M = 0.5 mu P d, d the bore), used with d < d_m as an upper bound.
SKF_MU_DEEP_GROOVE = 0.0015


def format_rows(rows: list[dict[str, float | str]]) -> str:
    """The rows as a markdown table."""
    out = ["| contact | Q (N) | u (m/s) | b (um) | C_ho (N s/m) | tau = C_ho/k (ms) | De = L/b | x_bar (um) | "
           "x_bar/(D/2) | low-De law x_bar/(D/2) | P_hyst (mW) | P_Chiu (mW) | P_hyst/P_Chiu |",
           "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        out.append(f"| {r['contact']} | {r['load_n']:.3g} | {r['u_m_s']:.3g} | {r['b_um']:.3g} | {r['cho']:g} | "
                   f"{r['tau_ms']:.3g} | {r['de']:.3g} | {r['x_bar_um']:.3g} | {r['mu_roll']:.2e} | "
                   f"{r['mu_linear']:.2e} | {r['p_h_mw']:.3g} | {r['p_chiu_mw']:.3g} | "
                   f"{r['p_h_mw'] / r['p_chiu_mw']:.3f} |")
    return "\n".join(out)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--speed-rpm", type=float, default=1800.0)
    ap.add_argument("--radial-load-n", type=float, default=500.0)
    args = ap.parse_args(argv)
    rows = contact_rows(args.speed_rpm, args.radial_load_n)
    sys.stdout.write(f"Damped (Kelvin-Voigt, no tension) rolling resistance at {args.speed_rpm:g} rpm, "
                     f"{args.radial_load_n:g} N, over the paper's C_ho range\n\n{format_rows(rows)}\n")
    from cageless.bearing import default_bearing

    bound = 0.5 * SKF_MU_DEEP_GROOVE * args.radial_load_n * default_bearing().geometry.pitch_diameter_m
    out = ["| C_ho (N s/m) | drive torque of the damped rolling term (N m) | / catalogue bound |", "|---|---|---|"]
    for cho in CHO_N_S_M[1:]:
        t = bearing_torque(cho, args.speed_rpm, args.radial_load_n)
        out.append(f"| {cho:g} | {t:.3g} | {t / bound:.1f} |")
    scan = tuple(float(c) for c in np.geomspace(10.0, 10000.0, 13))
    unl = [r for r in contact_rows(args.speed_rpm, args.radial_load_n, scan) if r["contact"] == "unloaded outer"]
    best = max(unl, key=lambda r: r["p_h_mw"])
    sys.stdout.write(f"\nAny C_ho (10-10000 N s/m, 13 values): the unloaded outer contact's damped-rolling loss is "
                     f"largest at C_ho = {best['cho']:.3g} N s/m (De = {best['de']:.2f}): {best['p_h_mw']:.3g} mW, "
                     f"{best['p_h_mw'] / best['p_chiu_mw']:.1%} of the Chiu loss\n")
    for c in (25.0, 50.0, 100.0):
        t = bearing_torque(c, args.speed_rpm, args.radial_load_n)
        sys.stdout.write(f"C_ho = {c:g} N s/m: drive torque {t:.3g} N m\n")
    sys.stdout.write(f"\nBearing friction torque: catalogue bound 0.5 mu F_r d_m = {bound:.3g} N m "
                     f"(mu = {SKF_MU_DEEP_GROOVE}, SKF)\n\n" + "\n".join(out) + "\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
