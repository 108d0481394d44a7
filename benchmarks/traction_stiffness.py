"""How stiff the regime traction law is: its largest slope dF/du_s against today's traction curve's.

    python benchmarks/traction_stiffness.py [--roughness-um 0.1] [--u-min 0.01]

The slope of a tangential force law at zero sliding is what sets the stiffness it adds to the ball equations:
an explicit step must stay below ~ m / (dF/du_s). For the paper's bearing (Table 1) at 500 N and three speeds,
three representative contacts are taken at pure rolling: the most loaded inner and outer contacts (Stribeck's
Q_max ~ 5 F_r / Z, as in Harris & Kotzalas, Essential Concepts, ch. 7), and an outer
contact in the unloaded zone carrying only the centrifugal force m (d_m / 2) omega_c^2. For each, the table
gives the Hamrock-Dowson film, Lambda = h_min / sigma, the effective viscosity (Roelands at the mean Hertz
pressure), and the slope at u_s = 0 of

* today's curve, ``simulation.traction.regression_traction``: mu'(0) Q / max(u_r, u_floor);
* the regime law (``simulation.physics.film_traction``) with the floor u_min ("new"), with no floor (the
  physical limiting-shear-stress slope), and with the floor but Barus instead of Roelands for eta_e (the
  stiff case: Barus viscosity at contact pressure is orders of magnitude higher).

The ratio column divides the floored slope by today's, both computed in this run. No timing is involved.

``--cost`` measures what the law costs in the models, with the ``film_traction`` effect on against off
(the traction curve), everything else at the defaults, same run, interleaved, best of N:

* the right-hand side alone, at a state of the running bearing (after 20 ms at 3000 rpm, 500 N), planar and
  spatial (400 N axial, 5 strips);
* a short planar run (``--run-ms``, default 30 ms, 3000 rpm, 500 N): its accepted steps, right-hand side
  calls and wall time, which show the stiffness the law adds (an explicit method's steps) or not.

    python benchmarks/traction_stiffness.py --cost [--run-ms 30]
"""

from __future__ import annotations

import argparse
import math

from cageless.bearing import default_bearing
from cageless.kinematics import theoretical_cage_speed
from cageless.simulation.hertz import compliance, hertz_contact, race_curvatures
from cageless.simulation.parameters import ModelParameters
from cageless.simulation.physics import film_traction as ft
from cageless.simulation.physics.viscosity import barus, roelands


def _today_slope(q: float, u_r: float, par: ModelParameters) -> float:
    a, b, c, d = par.traction_coefficients
    # mu(s) = (A + B s) e^{-C s} + D, A = -D: mu'(0) = B - A C = B + C D
    return (b + c * d) * q / max(u_r, par.min_entrainment_m_s)


def rows(sigma: float, u_min: float) -> list[tuple]:
    """One row per (speed, contact)."""
    bearing = default_bearing()
    g, mat, lub = bearing.geometry, bearing.material, bearing.lubricant
    par = ModelParameters()
    e_red = mat.youngs_modulus_pa / (1 - mat.poisson_ratio**2)
    rc = race_curvatures(g)
    eta_c = compliance(mat)
    dd, dm = g.ball_diameter_m, g.pitch_diameter_m
    rx = {"inner": 0.5 * dd * (dm - dd) / dm, "outer": 0.5 * dd * (dm + dd) / dm}
    out = []
    for rpm in (1800.0, 3000.0, 6000.0):
        w_i = rpm * math.pi / 30
        w_c = theoretical_cage_speed(g, w_i)
        u_in = (w_i - w_c) * 0.5 * g.inner_race_diameter_m  # pure rolling: both surfaces at this speed
        u_out = w_c * 0.5 * g.outer_race_diameter_m
        q_max = 5.0 * 500.0 / g.n_balls
        q_cf = bearing.masses.ball_mass_kg * 0.5 * dm * w_c**2
        for label, race, q, u in (("inner, Q_max", "inner", q_max, u_in), ("outer, Q_max", "outer", q_max, u_out),
                                  ("outer, unloaded", "outer", q_cf, u_out)):
            hc = hertz_contact(*rc[race], eta_c)
            a, b = hc.semi_axes(q)
            area = math.pi * a * b
            h_c = ft.hd_central_film(lub.dynamic_viscosity_pa_s, lub.pressure_viscosity_coefficient_1_pa, e_red, u, q,
                                     rx[race], hc.kappa)
            h_m = ft.hd_minimum_film(lub.dynamic_viscosity_pa_s, lub.pressure_viscosity_coefficient_1_pa, e_red, u, q,
                                     rx[race], hc.kappa)
            eta_e = roelands(lub.dynamic_viscosity_pa_s, lub.pressure_viscosity_coefficient_1_pa, q / area)
            args = (q, area, h_m, h_c, sigma, eta_e, par.limiting_shear_coefficient)
            tail = (par.boundary_friction_coefficient, par.boundary_slip_speed_m_s, ft.LAMBDA_BOUNDARY,
                    ft.LAMBDA_FULL)
            floored = ft.film_traction_slope(*args, u_min, *tail)
            physical = ft.film_traction_slope(*args, 1e-300, *tail)
            eta_b = barus(lub.dynamic_viscosity_pa_s, lub.pressure_viscosity_coefficient_1_pa, q / area)
            stiff = ft.film_traction_slope(*args[:5], eta_b, args[6], u_min, *tail)
            today = _today_slope(q, u, par)
            out.append((rpm, label, q, u, h_c * 1e6, h_m / sigma, eta_e, today, floored, physical, stiff,
                        floored / today))
    return out


def _problems():
    """(label, problem with film_traction on, problem with it off, state of the running bearing)."""

    import numpy as np

    from cageless.conditions import OperatingConditions
    from cageless.simulation.scene import Scene
    from cageless.simulation.simulation import Choices, Simulation
    from cageless.simulation.solve import solve

    out = []
    for label, cond in (("planar", OperatingConditions(3000.0, 500.0)),
                        ("spatial, 5 strips", OperatingConditions(3000.0, 500.0, 400.0))):
        scene = Scene(conditions=cond)
        on = Simulation(scene, ModelParameters()).build()
        off = Simulation(scene, ModelParameters(), Choices(effects={"film_traction": False}, force=True)).build()
        sol = solve(on, np.array([0.0, 0.02]), rtol=1e-6)
        out.append((label, on, off, sol.y[-1]))
    return out


def cost(run_ms: float, repeats: int = 5, calls: int = 2000) -> None:
    """Print the right-hand side's and a short run's cost with the regime law on and off (same run)."""
    import time

    from cageless.conditions import OperatingConditions
    from cageless.simulation.scene import Scene
    from cageless.simulation.simulation import Choices, Simulation

    print("| model | RHS on (us) | RHS off (us) | ratio on/off |\n|---|---|---|---|")
    for label, on, off, y in _problems():
        best = {"on": math.inf, "off": math.inf}
        for _ in range(repeats):
            for key, pr in (("on", on), ("off", off)):
                pr.rhs(0.02, y)  # compiled, warm
                t0 = time.perf_counter()
                for _ in range(calls):
                    pr.rhs(0.02, y, pr.log)
                best[key] = min(best[key], (time.perf_counter() - t0) / calls)
        print(f"| {label} | {best['on'] * 1e6:.1f} | {best['off'] * 1e6:.1f} | {best['on'] / best['off']:.2f} |")
    scene = Scene(conditions=OperatingConditions(3000.0, 500.0), duration_s=run_ms * 1e-3)
    rows = {}
    for _ in range(2):
        for key, eff in (("on", {}), ("off", {"film_traction": False})):
            t0 = time.perf_counter()
            sim = Simulation(scene, choices=Choices(effects=eff, force=True))
            sim.run()
            wall = time.perf_counter() - t0
            old = rows.get(key)
            rows[key] = (sim.solution.n_steps, sim.solution.n_rhs, min(wall, old[2]) if old else wall)
    print(f"\n{run_ms:g} ms planar run at 3000 rpm, 500 N (best of 2 walls, interleaved)\n")
    print("| film_traction | steps | RHS calls | wall (s) |\n|---|---|---|---|")
    for key in ("on", "off"):
        print(f"| {key} | {rows[key][0]} | {rows[key][1]} | {rows[key][2]:.1f} |")
    print(f"\nratio on/off: steps {rows['on'][0] / rows['off'][0]:.2f}, "
          f"RHS calls {rows['on'][1] / rows['off'][1]:.2f}, "
          f"wall {rows['on'][2] / rows['off'][2]:.2f}")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--roughness-um", type=float, default=ModelParameters().surface_roughness_m * 1e6,
                    help="composite rms roughness sigma (um)")
    ap.add_argument("--u-min", type=float, default=ft.DEFAULT_MIN_SLIP_SPEED_M_S, help="floor u_min (m/s)")
    ap.add_argument("--cost", action="store_true", help="time the right-hand side and a short run, law on/off")
    ap.add_argument("--run-ms", type=float, default=30.0, help="length of the timed run with --cost (ms)")
    args = ap.parse_args()
    if args.cost:
        cost(args.run_ms)
        return
    par = ModelParameters()
    print(f"sigma = {args.roughness_um:g} um, u_min = {args.u_min:g} m/s, Lambda_LSS = "
          f"{par.limiting_shear_coefficient:g}, mu_b = {par.boundary_friction_coefficient:g}, v_reg = "
          f"{par.boundary_slip_speed_m_s:g} m/s; slopes in N s/m\n")
    print("| rpm | contact | Q (N) | u (m/s) | h_c (um) | Lambda | eta_e (Pa s) | today | new | "
          "new, no floor | new, Barus eta_e | ratio new/today |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for r in rows(args.roughness_um * 1e-6, args.u_min):
        print(f"| {r[0]:g} | {r[1]} | {r[2]:.3g} | {r[3]:.2f} | {r[4]:.3f} | {r[5]:.2f} | {r[6]:.3g} | {r[7]:.3g} | "
              f"{r[8]:.3g} | {r[9]:.3g} | {r[10]:.3g} | {r[11]:.3g} |")


if __name__ == "__main__":
    main()
