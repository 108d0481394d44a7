"""One scene over a parameter grid and seeds, locally or on Dask (``cageless sweep``).

This is the paper's lubrication sensitivity study (§4: viscosity, film thickness and damping varied
at 1800 rpm). Each grid point runs ``seeds`` simulations; the result is the peak of the mean slip
profile in the unloaded zone after the start-up, per run, and its mean and seed spread
per point. A parameter name is a scene quantity (``speed_rpm``, ``radial_load_n``, ``axial_load_n``),
an open model parameter (``cho_n_s_m``, ``film_thickness_m``, ...) or a dotted bearing field
(``lubricant.dynamic_viscosity_pa_s``; ``lubricant.viscosity`` is accepted for it; ``geometry.diametral_clearance_m``
moves the races apart about the pitch circle).
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from cageless.atomic import atomic_write_text
from cageless.outputs import versioned_csv
from cageless.bearing import CLEARANCE_NAME, Bearing, default_bearing
from cageless.errors import ParameterError, suggest

__all__ = ["parse_vary", "sweep_grid", "run_sweep", "simulate_point", "sweep_base", "summarise", "plot_sweep", "SCENE_NAMES", "ALIASES"]

SCENE_NAMES = ("speed_rpm", "radial_load_n", "axial_load_n")
ALIASES = {"lubricant.viscosity": "lubricant.dynamic_viscosity_pa_s"}


def _values(name: str, spec: str) -> list[float]:
    try:
        if ":" in spec:
            lo, hi, n = spec.split(":")
            if int(n) < 1 or float(n) != int(n):
                raise ValueError
            vals = np.linspace(float(lo), float(hi), int(n)).tolist()
        else:
            vals = [float(v) for v in spec.split(",") if v.strip()]
    except ValueError:
        raise ParameterError("--vary", f"{name}={spec!r}: write start:stop:count (e.g. 0.02:0.06:5) or a list "
                             "(e.g. 1800,3000,6000)") from None
    if not vals or not all(math.isfinite(v) for v in vals):
        raise ParameterError("--vary", f"{name}={spec!r}: needs finite numbers")
    return vals


def parse_vary(items: Sequence[str], bearing: Bearing | None = None) -> dict[str, list[float]]:
    """``NAME=start:stop:count`` or ``NAME=v1,v2`` items into {canonical name: values}; names are checked."""
    from cageless.simulation.parameters import BUILT_IN_NAMES

    bearing = bearing or default_bearing()
    model = list(BUILT_IN_NAMES)
    dotted = [f"{s}.{k}" for s, d in bearing.to_dict().items() if isinstance(d, dict) for k in d]
    known = [*SCENE_NAMES, *model, *dotted, CLEARANCE_NAME, *ALIASES]
    out: dict[str, list[float]] = {}
    for item in items:
        name, sep, spec = item.partition("=")
        name = name.strip()
        if not sep:
            raise ParameterError("--vary", f"expects NAME=VALUES, got {item!r}")
        if name not in known:
            raise ParameterError("--vary", f"{name!r} is not a sweepable parameter" + suggest(name, known))
        out[ALIASES.get(name, name)] = _values(name, spec)
    if not out:
        raise ParameterError("--vary", "give at least one --vary NAME=VALUES")
    return out


def sweep_grid(vary: Mapping[str, Sequence[float]], seeds: int) -> list[dict[str, Any]]:
    """Every combination of the varied values, times seeds 0..seeds-1."""
    names = list(vary)
    return [{**dict(zip(names, combo, strict=True)), "seed": s}
            for combo in itertools.product(*(vary[n] for n in names)) for s in range(seeds)]


def simulate_point(point: Mapping[str, Any], base: Mapping[str, Any]) -> tuple[Any, Any, float, str]:
    """Run one grid point: ``(trace, solution, settle_s, error)``.

    ``point`` holds the varied values (scene quantities, model parameters, dotted bearing fields) and
    ``seed``; ``base`` the fixed ones (see :func:`run_sweep`). On a refused scene or parameter set the
    trace and solution are None and ``error`` says why. Used by the sweep and by the calibration.
    """
    from cageless.conditions import OperatingConditions
    from cageless.errors import CagelessError
    from cageless.kinematics import startup_duration
    from cageless.simulation.parameters import ModelParameters
    from cageless.simulation.scene import Scene
    from cageless.simulation.simulation import Choices, Simulation

    scene_kw = {n: point.get(n, base[n]) for n in SCENE_NAMES}
    model = {k: v for k, v in point.items() if k not in SCENE_NAMES and "." not in k and k != "seed"}
    dotted = {k: v for k, v in point.items() if "." in k}
    settle = float("nan")
    try:
        bearing = Bearing.from_dict(base["bearing"]).with_overrides(dotted)
        g = bearing.geometry
        settle = base["settle_s"] if base["settle_s"] is not None else startup_duration(
            scene_kw["speed_rpm"], g.ball_diameter_m, g.pitch_diameter_m)
        scene = Scene(conditions=OperatingConditions(**scene_kw), bearing=bearing,
                      duration_s=settle + base["duration_s"], seed=int(point["seed"]))
        choices = Choices(effects=dict(base.get("effects") or {}), force=bool(base.get("effects")))
        sim = Simulation(scene, ModelParameters().with_overrides({**base["parameters"], **model}), choices)
        trace = sim.run(config={"command": base.get("command", "sweep")})
    except CagelessError as exc:
        return None, None, settle, str(exc)
    return trace, sim.solution, settle, ""


def _run_point(point: dict[str, Any], base: dict[str, Any]) -> dict[str, Any]:
    from cageless.simulation.run import peak_unloaded_slip

    trace, sol, settle, error = simulate_point(point, base)
    if trace is None:
        return {**point, "peak_slip_pct": float("nan"), "status": "failed", "message": error, "wall_s": 0.0}
    ok = sol.success
    peak = peak_unloaded_slip(trace, settle_s=settle) if ok else float("nan")
    return {**point, "peak_slip_pct": 100 * peak, "status": "ok" if ok else "failed",
            "message": "" if ok else trace.status, "wall_s": trace.simulation.wall_s}


def sweep_base(speed_rpm: float, radial_load_n: float = 0.0, axial_load_n: float = 0.0, duration_s: float = 0.1,
               settle_s: float | None = None, parameters: Mapping[str, float] | None = None,
               bearing: Bearing | None = None, command: str = "sweep",
               effects: Mapping[str, bool] | None = None) -> dict[str, Any]:
    """The fixed part of every grid point (plain values, so it travels to worker processes and Dask);
    ``effects`` are effect overrides (name -> on), applied as forced."""
    return {"speed_rpm": speed_rpm, "radial_load_n": radial_load_n, "axial_load_n": axial_load_n,
            "duration_s": duration_s, "settle_s": settle_s, "parameters": dict(parameters or {}),
            "bearing": (bearing or default_bearing()).to_dict(), "command": command, "effects": dict(effects or {})}


def run_sweep(vary: Mapping[str, Sequence[float]], seeds: int, speed_rpm: float, radial_load_n: float = 0.0,
              axial_load_n: float = 0.0, duration_s: float = 0.1, settle_s: float | None = None,
              parameters: Mapping[str, float] | None = None, bearing: Bearing | None = None, workers: int = 2,
              scheduler: str | None = None, progress: bool = True,
              effects: Mapping[str, bool] | None = None) -> pd.DataFrame:
    """Run the grid and return one row per run (the varied values, seed, peak slip in %, status)."""
    from cageless.parallel import gather, job_pool

    base = sweep_base(speed_rpm, radial_load_n, axial_load_n, duration_s, settle_s, parameters, bearing,
                      effects=effects)
    points = sweep_grid(vary, seeds)
    with job_pool(workers, scheduler) as pool:
        rows = gather([pool.submit(_run_point, p, base) for p in points], "sweep runs", progress)
    return pd.DataFrame(rows)


def summarise(runs: pd.DataFrame, names: Sequence[str]) -> pd.DataFrame:
    """Mean, seed spread (population std over the seeds; NaN from one run, which shows no spread) and count
    of the peak slip per grid point."""
    ok = runs[runs.status == "ok"]
    g = ok.groupby(list(names), sort=True)["peak_slip_pct"]
    count = g.count()
    return pd.DataFrame({"peak_slip_mean_pct": g.mean(), "peak_slip_std_pct": g.std(ddof=0).where(count > 1),
                         "runs": count}).reset_index()


def plot_sweep(summary: pd.DataFrame, names: Sequence[str], path: str | Path) -> None:
    """One panel per varied parameter: peak slip (mean, seed spread) against it."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    with matplotlib.rc_context({"font.size": 8}):
        fig, axes = plt.subplots(1, len(names), figsize=(3.4 * len(names), 2.8), squeeze=False)
        for ax, name in zip(axes[0], names, strict=True):
            others = [n for n in names if n != name]
            groups = summary.groupby(others) if others else [((), summary)]
            for key, part in groups:
                part = part.sort_values(name)
                label = ", ".join(f"{o}={v:g}" for o, v in zip(others, np.atleast_1d(key), strict=False)) or None
                ax.errorbar(part[name], part.peak_slip_mean_pct, yerr=part.peak_slip_std_pct, marker="o",
                            capsize=2, label=label)
            ax.set(xlabel=name, ylabel="peak slip, unloaded zone (%)\nmean, bars: spread over seeds")
            if others:
                ax.legend(fontsize=6)
            ax.grid(True, alpha=0.3)
        fig.tight_layout()
        fig.savefig(path, dpi=120)
        plt.close(fig)


def write_sweep(runs: pd.DataFrame, names: Sequence[str], out: str | Path) -> dict[str, Path]:
    """Write ``runs.csv``, ``summary.csv`` and ``peak_slip.png`` into ``out``."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    summary = summarise(runs, names)
    atomic_write_text(out / "runs.csv", versioned_csv(runs, "%.6g"))
    atomic_write_text(out / "summary.csv", versioned_csv(summary, "%.6g"))
    if len(summary):
        plot_sweep(summary, names, out / "peak_slip.png")
    return {"runs": out / "runs.csv", "summary": out / "summary.csv", "plot": out / "peak_slip.png"}
