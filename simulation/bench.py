"""What simulator accuracy costs in time: a work-precision study (``cageless bench accuracy``).

One scene (3000 rpm, 500 N, every effect of a lubricated scene) is run past its
start-up; from that state, each candidate integrates the same window, and its
error is measured against a tight-tolerance reference run in the same process:

* the compiled Dormand-Prince loop across tolerances (rtol 1e-4 ... 1e-8);
* the compiled Rosenbrock-W method (``rosw``, :mod:`cageless.simulation.integrators.rosw`) across tolerances, at its
  10 us cap;
* the compiled IMEX method (``ark4``, :mod:`cageless.simulation.integrators.ark`) across tolerances, at its
  50 us cap;
* SUNDIALS CVODE (BDF) across tolerances and step caps (2, 5, 20 us), and at its default settings
  with each Jacobian of :data:`cageless.simulation.solve.JACOBIANS` and without its onset control;
* scipy's LSODA, BDF and DOP853 on the same compiled right-hand side;
* scipy's LSODA on the plain-numpy right-hand side (the "numpy" baseline).

CVODE and scipy's steppers run one accepted step at a time (:func:`cageless.simulation.solve.step_cvode`,
:func:`cageless.simulation.solve.step_scipy`), so the contact bookkeeping after each accepted step is the same
for every candidate.

The ball ring is chaotic, so the window is kept at a few milliseconds (two
correct runs part after that). Error: the largest difference in slip over all balls and samples, in
percentage points, and the RMS ball-position difference along the orbit (um).
Times are wall seconds per simulated second, the best of the repeats with the candidates
interleaved (every candidate once per round); the ratio column divides by dp5 at rtol 1e-6 and the
speed-up column divides the automatic switch's time (``auto`` as ``simulate`` runs it, the first row) by
the row's, both measured in the same run, since absolute times on a shared 2-core machine are noisy.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

import numpy as np
import numpy.typing as npt

from cageless.conditions import OperatingConditions
from cageless.kinematics import theoretical_cage_speed
from cageless.simulation.auto_switch import RTOL_FACTOR
from cageless.simulation.effects import choose_model, removable_effects
from cageless.simulation.models.planar_reference import reference_rhs
from cageless.simulation.problem import Problem

from cageless.simulation.parameters import ModelParameters
from cageless.simulation.scene import Scene
from cageless.simulation.simulation import Choices, Simulation
from cageless.simulation.solve import solve, step_cvode, step_scipy

__all__ = ["accuracy_study", "format_accuracy", "plot_accuracy", "model_study", "format_models", "effects_study",
           "format_effects", "fastest_modes"]

#: (method, rtol, max_step in s). The step cap is an accuracy knob of its own for the implicit CVODE,
#: whose steps are otherwise set by accuracy alone: the default 2 us keeps ~15 steps inside a ball-ball
#: impact (29 us), the longer caps show what resolving contacts by error control alone buys and costs.
#: CVODE at rtol 3e-8 and 5 us is how ``simulate`` runs it at rtol 1e-6 (simulation.auto_switch.RTOL_FACTOR).
CANDIDATES: tuple[tuple[str, float, float], ...] = (
    ("dp5", 1e-4, 2e-6), ("dp5", 1e-5, 2e-6), ("dp5", 1e-6, 2e-6), ("dp5", 1e-7, 2e-6), ("dp5", 1e-8, 2e-6),
    ("CVODE", 1e-6, 2e-6), ("CVODE", 1e-6, 5e-6), ("CVODE", 1e-7, 5e-6), ("CVODE", 3e-8, 5e-6),
    ("CVODE", 1e-6, 2e-5),
    ("LSODA", 1e-6, 2e-6), ("BDF", 1e-6, 2e-6), ("DOP853", 1e-6, 2e-6),
    ("rosw", 1e-6, 1e-5), ("rosw", 1e-7, 1e-5), ("rosw", 1e-8, 1e-5),
    ("ark4", 1e-5, 5e-5), ("ark4", 1e-6, 5e-5), ("ark4", 1e-7, 5e-5),
)
#: CVODE as ``simulate`` runs it (rtol 3e-8, 5 us) with one setting changed: the other Jacobians of
#: :data:`cageless.simulation.solve.JACOBIANS` (the rows above use the structured one: what it saves, and what
#: SuperLU_MT's sparse factorisation costs at this size), and without the onset control (what stopping
#: ahead of contact changes costs). Variant names are keys of :data:`_VARIANT_LABELS`.
CVODE_VARIANTS: tuple[tuple[str, float, float, str], ...] = (
    ("CVODE", 3e-8, 5e-6, "dense"), ("CVODE", 3e-8, 5e-6, "sparse"), ("CVODE", 3e-8, 5e-6, "no onset control"),
)
_VARIANT_LABELS = {"dense": "CVODE's own Jacobian", "sparse": "structured Jacobian, sparse LU",
                   "no onset control": "no onset control"}


def _settled_problem(rpm: float, load_n: float, settle_s: float, axial_n: float = 0.0, level: str | None = None,
                     strips: int = 5) -> tuple[Problem, float]:
    scene = Scene(conditions=OperatingConditions(rpm, load_n, axial_n))
    pr = Simulation(scene, ModelParameters(strips=strips), Choices(level=level)).build()
    sol = solve(pr, np.array([settle_s]), rtol=1e-8, max_step=1e-6)
    y0 = sol.y[-1].copy()
    z = scene.bearing.geometry.n_balls
    y0[5 * z + 4:5 * z + 6] = 0.0  # restart the work and dissipation counters (same slots in both layouts)
    cage = theoretical_cage_speed(scene.bearing.geometry, scene.conditions.speed_rad_s)
    return replace(pr, y0=y0, log=sol.extra["log"], t0=0.0), cage


def _errors(y: npt.NDArray[np.float64], ref: npt.NDArray[np.float64], z: int, cage: float,
            radius: float) -> tuple[float, float]:
    slip_pp = 100 * np.nanmax(np.abs(y[:, 3 * z:4 * z] - ref[:, 3 * z:4 * z])) / cage
    pos_um = 1e6 * radius * float(np.sqrt(np.nanmean((y[-1, z:2 * z] - ref[-1, z:2 * z]) ** 2)))
    return float(slip_pp), pos_um


#: The automatic switch as ``simulate`` runs it (each method's own cap and rtol factor): the row every other is
#: compared with (the "speed-up vs auto" column).
AUTO: tuple[str, float, float, str] = ("auto", 1e-6, np.inf, "default")


def _candidate_run(pr: Problem, t: npt.NDArray[np.float64], method: str, rtol: float, cap: float,
                   variant: str | None) -> Any:
    """One candidate of :func:`accuracy_study` (a :data:`CANDIDATES` row, a :data:`CVODE_VARIANTS` row or
    :data:`AUTO`)."""
    if variant is None or variant == "default":
        return solve(pr, t, method=method, rtol=rtol, max_step=cap)
    if variant == "no onset control":
        return step_cvode(pr, t, rtol, max_step=cap, onset_control=False)
    return step_cvode(pr, t, rtol, max_step=cap, jacobian=variant)


def _interleaved(runs: list[Any], repeats: int) -> list[tuple[Any, float]]:
    """Each ``run()``'s last result and shortest wall time, the runs interleaved (every run once per round,
    ``repeats`` rounds), so that a busy spell of the shared machine slows every candidate alike."""
    results: list[Any] = [None] * len(runs)
    best = [np.inf] * len(runs)
    for _ in range(max(1, repeats)):
        for i, run in enumerate(runs):
            results[i] = run()
            best[i] = min(best[i], results[i].wall_s)
    return list(zip(results, best, strict=True))


def _best_wall(run: Any, repeats: int) -> tuple[Any, float]:
    """The result of ``run()`` and its shortest wall time over ``repeats`` runs (the machine's noise only
    ever adds time)."""
    sol = run()
    best = sol.wall_s
    for _ in range(repeats - 1):
        best = min(best, run().wall_s)
    return sol, best


#: The plain-numpy baseline's row (:mod:`~cageless.simulation.models.planar_reference` has neither the rolling
#: losses nor the regime traction).
NUMPY_ROW = "LSODA (numpy RHS; rolling losses and film traction off in it and its reference)"
#: The effects the plain-numpy right-hand side leaves out, with their flags.
_NOT_IN_NUMPY = {"rolling_losses": "F_ROLL", "film_traction": "F_FTRAC"}


def _numpy_physics(pr: Problem) -> Problem:
    """``pr`` with the effects off that the plain-numpy right-hand side does not compute: measured against the
    full model its error was those effects (1.45 pp of slip over 1 ms), not the integrator's. With them off the
    two right-hand sides agree to 3e-6 relative at the settled state (up to 2,400 with them on)."""
    from cageless.simulation.models.base import LAYOUT

    params = pr.params.copy()
    for flag in _NOT_IN_NUMPY.values():
        params[LAYOUT.index(flag)] = 0.0
    return replace(pr, params=params, effects=pr.effects - set(_NOT_IN_NUMPY))


def _numpy_lsoda(pr: Problem, t: npt.NDArray[np.float64], rtol: float) -> Any:
    return step_scipy(pr, t, "LSODA", rtol, max_step=2e-6, fun=lambda tt, yy, log: reference_rhs(tt, yy, pr.params, log))


def accuracy_study(rpm: float = 3000.0, load_n: float = 500.0, window_s: float = 0.005, settle_s: float = 0.03,
                   numpy_window_s: float = 0.0005, repeats: int = 1) -> dict[str, Any]:
    """Run every candidate over the same window and return rows of error and cost.

    Each candidate's wall time is the best of ``repeats`` runs (the machine's noise only adds time), after
    every candidate has run once untimed over the first output interval, which compiles what it needs.

    The plain-numpy baseline runs over ``numpy_window_s`` only (it is ~100x slower); its error is
    measured against the reference over that shorter window.
    """
    pr, cage = _settled_problem(rpm, load_n, settle_s)
    z = pr.n_balls
    radius = float(np.mean(pr.y0[:z]))
    t = np.linspace(0.0, window_s, 51)
    ref = solve(pr, t, rtol=1e-10, max_step=2.5e-7)
    rows = []
    setups = [AUTO] + [(*c, None) for c in CANDIDATES] + list(CVODE_VARIANTS)
    for c in setups:  # compile every method untimed first: on a cold cache minutes would count against one row
        _candidate_run(pr, t[:2], *c)
    runs = [lambda c=c: _candidate_run(pr, t, *c) for c in setups]
    for (method, rtol, cap, variant), (sol, wall) in zip(setups, _interleaved(runs, repeats), strict=True):
        slip_pp, pos_um = _errors(sol.y, ref.y, z, cage, radius)
        rows.append({"solver": f"{method} (compiled RHS)", "rtol": rtol, "max_step": cap, "ok": sol.success,
                     "wall_s_per_sim_s": wall / window_s, "slip_error_pp": slip_pp, "position_error_um": pos_um,
                     "steps": sol.n_steps, "rhs_calls": sol.n_rhs, "variant": variant, "method": sol.method})
    tn = np.linspace(0.0, numpy_window_s, 6)
    pr_np = _numpy_physics(pr)  # what the numpy RHS computes, for it and its reference
    sol_np, wall = _best_wall(lambda: _numpy_lsoda(pr_np, tn, 1e-6), repeats)
    y_np = sol_np.y
    ref_short = solve(pr_np, tn, rtol=1e-10, max_step=2.5e-7)
    slip_pp, pos_um = _errors(y_np, ref_short.y, z, cage, radius)
    rows.append({"solver": NUMPY_ROW, "rtol": 1e-6, "max_step": 2e-6, "ok": True,
                 "wall_s_per_sim_s": wall / numpy_window_s, "slip_error_pp": slip_pp, "position_error_um": pos_um, "steps": 0, "rhs_calls": 0})
    base = next(r for r in rows if r["solver"].startswith("dp5") and r["rtol"] == 1e-6)["wall_s_per_sim_s"]
    auto = rows[0]["wall_s_per_sim_s"]
    for r in rows:
        r["label"] = f"{r['solver']}, cap {1e6 * r['max_step']:g} us" if r["max_step"] != 2e-6 else r["solver"]
        if r.get("variant") == "default":  # with the path the switch took, e.g. "dp5 -> ark4 at 0.0001 s"
            r["label"] = f"auto (as simulate runs it: {r['method'].removeprefix('auto: ')})"
        elif r.get("variant"):
            r["label"] += f", {_VARIANT_LABELS[r['variant']]}"
        r["time_ratio"] = r["wall_s_per_sim_s"] / base
        r["speedup_vs_auto"] = auto / r["wall_s_per_sim_s"]
    return {"scene": {"speed_rpm": rpm, "radial_load_n": load_n, "window_s": window_s, "settle_s": settle_s},
            "reference": {"method": "dp5", "rtol": 1e-10, "max_step": 2.5e-7, "wall_s": ref.wall_s}, "rows": rows}


def _cost_table(title: str, first: tuple[str, str], rows: list[dict[str, Any]], cells: Any) -> str:
    """A Markdown cost table: two leading columns, then wall time, its ratio and the two errors."""
    vs_auto = all("speedup_vs_auto" in r for r in rows)
    extra = (" speed-up vs auto |", "---|") if vs_auto else ("", "")
    lines = [title, "", f"| {first[0]} | {first[1]} | wall s / sim s | ratio |{extra[0]} slip error (pp) | "
             "position error (um) |", f"|---|---|---|---|{extra[1]}---|---|"]
    for r in rows:
        a, b = cells(r)
        flag = "" if r["ok"] else " (failed)"
        speedup = f" {r['speedup_vs_auto']:.2f} |" if vs_auto else ""
        lines.append(f"| {a}{flag} | {b} | {r['wall_s_per_sim_s']:.1f} | {r['time_ratio']:.2f} |{speedup} "
                     f"{r['slip_error_pp']:.3g} | {r['position_error_um']:.3g} |")
    return "\n".join(lines)


def format_accuracy(result: dict[str, Any]) -> str:
    """The study as a Markdown table (ratio: to dp5 at rtol 1e-6; speed-up: auto's time over the row's, same run)."""
    sc = result["scene"]
    title = (f"Work-precision, {sc['speed_rpm']:g} rpm, {sc['radial_load_n']:g} N, {1e3 * sc['window_s']:g} ms window "
             f"after {1e3 * sc['settle_s']:g} ms (reference: dp5 rtol 1e-10; ratio: to dp5 rtol 1e-6)")
    return _cost_table(title + "; step cap 2 us unless given", ("solver", "rtol"), result["rows"],
                       lambda r: (r.get("label", r["solver"]), f"{r['rtol']:g}"))


#: Floor of the plotted slip error (pp): an error below it is drawn on it.
PLOT_ERROR_FLOOR_PP = 1e-6


def plot_accuracy(result: dict[str, Any], path: str) -> None:
    """Write the work-precision diagram (error against wall time) as an image."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    with matplotlib.rc_context():
        fig = accuracy_figure(result)
        fig.savefig(path, dpi=120, bbox_inches="tight")
        plt.close(fig)


def accuracy_figure(result: dict[str, Any]) -> Any:
    """The work-precision diagram as a matplotlib figure: one series per solver, each with its own colour and
    marker pair, and the legend beside the axes, where it hides no point."""
    import itertools

    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(9.5, 4.2))
    colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    styles = zip(itertools.cycle(colours), itertools.cycle("osD^v<>p*hX"), strict=False)
    for solver, (colour, marker) in zip(dict.fromkeys(r.get("label", r["solver"]) for r in result["rows"]), styles):
        rows = [r for r in result["rows"] if r.get("label", r["solver"]) == solver]
        ax.loglog([r["wall_s_per_sim_s"] for r in rows],
                  [max(r["slip_error_pp"], PLOT_ERROR_FLOOR_PP) for r in rows], "-", marker=marker, color=colour,
                  label=solver)
    ax.set_xlabel("wall seconds per simulated second")
    ax.set_ylabel(f"largest slip error (pp; floor {PLOT_ERROR_FLOOR_PP:g})")
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0.0)
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    return fig


def model_study(window_s: float = 0.005, settle_s: float = 0.03, repeats: int = 1) -> dict[str, Any]:
    """What model fidelity costs: planar against spatial, and the strip count m of the spatial model.

    * Pure radial load (3000 rpm, 500 N), where the planar model is exact: planar and spatial (m = 1, 5)
      against a planar rtol 1e-10 reference.
    * Combined load (3000 rpm, 500 N radial, 400 N axial), where only the spatial model applies: m = 1, 5,
      11, 21 against a spatial m = 21, rtol 1e-9 reference; and m = 5 under CVODE as ``simulate`` runs it
      (rtol x 0.03) with a 2 us cap and with its default 5 us cap.

    All at rtol 1e-6 from the same settled state, with DP5 unless named; wall seconds per simulated
    second (the best of ``repeats`` runs: this shared machine's noise only ever adds time) and the ratio to
    the planar run measured in the same process.
    """
    t = np.linspace(0.0, window_s, 51)
    rows = []
    for scene_name, axial, level, ref_strips, cases in (
            ("pure radial", 0.0, "planar", 1, (("planar", 1, "dp5", 2e-6), ("spatial", 1, "dp5", 2e-6),
                                               ("spatial", 5, "dp5", 2e-6))),
            ("500 N + 400 N axial", 400.0, "spatial", 21, (
                ("spatial", 1, "dp5", 2e-6), ("spatial", 5, "dp5", 2e-6), ("spatial", 11, "dp5", 2e-6),
                ("spatial", 21, "dp5", 2e-6), ("spatial", 5, "CVODE", 2e-6), ("spatial", 5, "CVODE", 5e-6)))):
        # CVODE rows run as simulate runs them at rtol 1e-6 (rtol x 0.03, see simulation.auto_switch.RTOL_FACTOR)
        base, cage = _settled_problem(3000.0, 500.0, settle_s, axial, level, ref_strips)
        ref = solve(base, t, rtol=1e-9 if axial else 1e-10, max_step=5e-7)
        scene = Scene(conditions=OperatingConditions(3000.0, 500.0, axial))
        for lvl, m, method, cap in cases:
            pr = Simulation(scene, ModelParameters(strips=m), Choices(level=lvl, force=True)).build()
            n = len(pr.y0)  # the planar state is the first 5 Z + 6 entries of the spatial one
            y0 = np.concatenate([base.y0, np.zeros(max(0, n - len(base.y0)))])[:n]
            pr = replace(pr, y0=y0, log=base.log.copy())
            rtol = 1e-6 * RTOL_FACTOR.get(method, 1.0)
            solve(pr, t[:2], method=method, rtol=rtol, max_step=cap)  # compiles what this row needs, untimed
            sol, wall = _best_wall(lambda pr=pr, method=method, cap=cap, rtol=rtol: solve(
                pr, t, method=method, rtol=rtol, max_step=cap), repeats)
            z = pr.n_balls
            slip_pp, pos_um = _errors(sol.y[:, :5 * z + 6], ref.y[:, :5 * z + 6], z, cage, float(np.mean(pr.y0[:z])))
            label = lvl if lvl == "planar" else f"spatial, m = {m}"
            if method != "dp5":
                label += f", {method} (rtol {rtol:g}, cap {1e6 * cap:g} us)"
            rows.append({"scene": scene_name, "model": label, "method": method, "max_step": cap,
                         "wall_s_per_sim_s": wall / window_s, "slip_error_pp": slip_pp,
                         "position_error_um": pos_um, "ok": sol.success})
    base_time = rows[0]["wall_s_per_sim_s"]
    for r in rows:
        r["time_ratio"] = r["wall_s_per_sim_s"] / base_time
    return {"window_s": window_s, "settle_s": settle_s, "rows": rows}


def format_models(result: dict[str, Any]) -> str:
    """The model-fidelity study as a Markdown table (ratio: to the planar run)."""
    title = (f"Model fidelity against cost, 3000 rpm, {1e3 * result['window_s']:g} ms window after "
             f"{1e3 * result['settle_s']:g} ms, rtol 1e-6 (ratio: to the planar model)")
    return _cost_table(title, ("scene", "model"), result["rows"], lambda r: (r["scene"], r["model"]))


def effects_study(rpm: float = 1800.0, radial_load_n: float = 500.0, axial_load_n: float = 0.0,
                  duration_s: float = 0.15, settle_s: float | None = None) -> dict[str, Any]:
    """Run a scene with every effect it calls for, then with each removable one that is on removed in turn
    (:func:`cageless.simulation.effects.removable_effects`; removing an effect also switches off those that act
    only on it).

    Each run lasts ``settle_s`` (default: the start-up of :func:`cageless.kinematics.startup_duration`)
    plus ``duration_s``, and its statistics come from the part after the start-up.

    Each row gives the peak slip in the unloaded zone and how far the slip profile moved (RMS over the
    1-degree bins, percentage points) against the full model, with the wall time and its saving. An effect
    that is off for the scene (e.g. drag without an oil-air mixture) is listed as not applicable.

    The full model runs twice and only the second run is timed: the first compiles whatever the scene's
    solvers need (minutes after an install), which would otherwise count against the full model and show
    every removal as a saving of 90 % and more. The effects are flags read at run time, so the removals run
    the same compiled code. Both runs give the same trace (determinism).
    """
    from cageless.profiles import angle_profile
    from cageless.simulation.run import peak_unloaded_slip

    from cageless.bearing import default_bearing
    from cageless.kinematics import startup_duration

    g = default_bearing().geometry
    settle_s = startup_duration(rpm, g.ball_diameter_m, g.pitch_diameter_m) if settle_s is None else settle_s
    scene = Scene(conditions=OperatingConditions(rpm, radial_load_n, axial_load_n), duration_s=settle_s + duration_s)
    full = choose_model(scene)

    def run(choice: Any) -> tuple[Any, float]:
        trace = Simulation(scene, model=choice).run()
        return trace, trace.simulation.wall_s

    def profile(trace: Any) -> npt.NDArray[np.float64]:
        keep = (trace.time >= settle_s)[:, None] & trace.valid
        return angle_profile(trace.angle, trace.slip, 1.0, valid=keep)["mean"].to_numpy()

    run(full)  # compiles what the scene needs; not timed
    ref, ref_wall = run(full)
    ref_profile = profile(ref)
    rows = [{"removed": "(none: full model)", "peak_slip_pct": 100 * peak_unloaded_slip(ref, settle_s),
             "profile_change_pp": 0.0, "wall_s": ref_wall, "saving_pct": 0.0}]
    on = {e.name for e in full.effects if e.on}
    for name in removable_effects():
        if name not in on:
            rows.append({"removed": name, "peak_slip_pct": float("nan"), "profile_change_pp": float("nan"),
                         "wall_s": float("nan"), "saving_pct": float("nan"), "note": "off for this scene"})
            continue
        trace, wall = run(choose_model(scene, level=full.level, effects={name: False}, force=True))
        d = 100 * (profile(trace) - ref_profile)
        rows.append({"removed": name, "peak_slip_pct": 100 * peak_unloaded_slip(trace, settle_s),
                     "profile_change_pp": float(np.sqrt(np.nanmean(d**2))), "wall_s": wall,
                     "saving_pct": 100 * (1 - wall / ref_wall)})
    return {"scene": {"speed_rpm": rpm, "radial_load_n": radial_load_n, "axial_load_n": axial_load_n,
                      "duration_s": duration_s, "settle_s": settle_s, "level": full.level}, "rows": rows}


def format_effects(result: dict[str, Any]) -> str:
    """The ablation study as a Markdown table."""
    sc = result["scene"]
    lines = [f"Effect ablation, {sc['speed_rpm']:g} rpm, {sc['radial_load_n']:g} N radial, {sc['axial_load_n']:g} N "
             f"axial ({sc['level']}): {1e3 * sc['duration_s']:.0f} ms simulated after a start-up of "
             f"{1e3 * sc['settle_s']:.0f} ms, which the profiles leave out", "",
             "| effect removed | peak slip (%) | profile change, RMS (pp) | wall (s) | saving |",
             "|---|---|---|---|---|"]
    for r in result["rows"]:
        if r.get("note"):
            lines.append(f"| {r['removed']} | {r['note']} | | | |")
            continue
        lines.append(f"| {r['removed']} | {r['peak_slip_pct']:.2f} | {r['profile_change_pp']:.2f} | {r['wall_s']:.1f} | "
                     f"{r['saving_pct']:.0f} % |")
    return "\n".join(lines)


def fastest_modes(pr: Problem, count: int = 2) -> dict[str, list[complex]]:
    """The ``count`` largest eigenvalues (1/s) of the Jacobian of f and of f - f_I at the problem's start
    (central differences, steps 1e-2 of each state's absolute tolerance): what limits an explicit step, and
    what ``ark4``'s implicit part (:func:`~cageless.simulation.kernels.model_implicit`) leaves to the explicit
    one."""
    from cageless.simulation.kernels import model_implicit, model_rhs

    n = pr.y0.size
    log_ = pr.log.copy()
    work = np.zeros(12)

    def full(y: np.ndarray) -> np.ndarray:
        out = np.empty(n)
        model_rhs(pr.model_id, 0.0, y, pr.params, log_, out)
        return out

    def explicit(y: np.ndarray) -> np.ndarray:
        k_i = np.empty(n)
        model_implicit(pr.model_id, 0.0, y.copy(), pr.params, 0.0, k_i, work)
        return full(y) - k_i

    result = {}
    for name, fun in (("f", full), ("f - f_I", explicit)):
        jac = np.empty((n, n))
        for i in range(n):
            e = max(1e-7 * abs(pr.y0[i]), 1e-2 * pr.atol[i])
            up, down = pr.y0.copy(), pr.y0.copy()
            up[i] += e
            down[i] -= e
            jac[:, i] = (fun(up) - fun(down)) / (2 * e)
        ev = np.linalg.eigvals(jac)
        result[name] = list(ev[np.argsort(-np.abs(ev))[:count]])
    return result
