"""Fit open model parameters to a measured slip profile or a target peak slip (``cageless calibrate``).

This module is the app layer, like :mod:`cageless.app.lab`: it alone joins the simulation (one run per
seed per evaluation, through :func:`cageless.simulation.sweep.simulate_point`) and the comparison metrics.

Objective
    With a video trace: the MAE (or RMSE) in percentage points between the measured mean slip
    profile and the simulated one, over the 1 deg bins of the unloaded zone (0-180 deg) where both
    have data; the simulated profile pools every seed's samples after the start-up. With a target:
    the absolute miss, in pp, of the peak of that pooled profile in the unloaded zone (the paper's
    "theoretical slip rate", as in ``cageless sweep`` and the report's table).

Method
    The objective is noisy (the ball ring is chaotic; the seeds 0..K-1 are the same at every
    evaluation, common random numbers, so the noise is frozen but rough) and each evaluation costs K
    simulations, so the budget is small. One parameter: bounded Brent
    (:func:`scipy.optimize.minimize_scalar`, ``method="bounded"``), one evaluation at a time with its
    seeds in parallel. Several: a Latin hypercube design (:class:`scipy.stats.qmc.LatinHypercube`) of
    half the budget, evaluated in parallel, then Nelder-Mead with bounds started from the best d+1
    design points for the rest. Either way the result is the best evaluation in the table.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from datetime import datetime, timezone
from pathlib import Path
from typing import Any

import numpy as np
from tqdm.auto import tqdm

from cageless import __version__
from cageless.bearing import Bearing, default_bearing
from cageless.errors import CagelessError, ParameterError, TraceFormatError, UsageError, suggest
from cageless.profiles import UNLOADED_ZONE_DEG, peak_estimator, peak_of_mean

__all__ = ["Target", "Bound", "CalibrationResult", "parse_bounds", "target_from_trace", "target_from_peak",
           "calibrate", "describe_calibration", "fit_warnings", "UNLOADED_ZONE_DEG", "PENALTY_PP"]

#: The objective of an evaluation whose runs failed (pp): larger than any real miss.
PENALTY_PP = 100.0
_BIN_DEG = 1.0
_ALIASES = {"lubricant.viscosity": "lubricant.dynamic_viscosity_pa_s"}


@dataclass(frozen=True)
class Target:
    """What a calibration fits: a measured zone profile, or a peak slip, at one condition."""

    speed_rpm: float
    radial_load_n: float
    axial_load_n: float
    duration_s: float
    profile: np.ndarray | None = None  # mean slip (fraction) per 1 deg bin, 0..360 deg
    peak_slip_pct: float | None = None
    identity: dict[str, Any] = field(default_factory=dict)

    @property
    def condition(self) -> str:
        """The condition in words."""
        return f"{self.speed_rpm:g} rpm, {self.radial_load_n:g} N radial, {self.axial_load_n:g} N axial"


@dataclass(frozen=True)
class Bound:
    """One varied parameter and its range."""

    name: str
    low: float
    high: float


def _known_names(bearing: Bearing) -> list[str]:
    from cageless.simulation.parameters import BUILT_IN_NAMES

    model = list(BUILT_IN_NAMES)
    dotted = [f"{s}.{k}" for s, d in bearing.to_dict().items() if isinstance(d, dict) for k in d]
    return [*model, *dotted, *_ALIASES]


def parse_bounds(items: Sequence[str], bearing: Bearing | None = None) -> list[Bound]:
    """``NAME=LOW:HIGH`` items into bounds, each checked against the parameter's documented range.

    Raises
    ------
    ParameterError
        For a malformed item, an unknown name (with a suggestion), a parameter without a documented
        range, LOW >= HIGH, or a range outside the documented one (named with its source).
    """
    from cageless.simulation.ranges import DOCUMENTED_RANGES

    known = _known_names(bearing or default_bearing())
    out: list[Bound] = []
    for item in items:
        name, sep, spec = item.partition("=")
        name = name.strip()
        if not sep:
            raise ParameterError("--vary", f"expects NAME=LOW:HIGH, got {item!r} (e.g. --vary cho_n_s_m=2000:8000)")
        if name not in known:
            raise ParameterError("--vary", f"{name!r} is not a model parameter" + (
                suggest(name, known) or f"; calibratable: {', '.join(DOCUMENTED_RANGES)}"))
        canon = _ALIASES.get(name, name)
        if canon not in DOCUMENTED_RANGES:
            raise ParameterError("--vary", f"{name!r} has no documented physical range and is not calibrated; "
                                 f"calibratable: {', '.join(DOCUMENTED_RANGES)}")
        try:
            lo_text, hi_text = spec.split(":")
            lo, hi = float(lo_text), float(hi_text)
        except ValueError:
            raise ParameterError("--vary", f"{name}={spec!r}: write LOW:HIGH (e.g. {name}=2000:8000)") from None
        if not (math.isfinite(lo) and math.isfinite(hi)):
            raise ParameterError("--vary", f"{name}={spec!r}: LOW and HIGH must be finite")
        if lo >= hi:
            raise ParameterError("--vary", f"{name}={spec!r}: LOW must be below HIGH")
        doc = DOCUMENTED_RANGES[canon]
        if lo < doc.low or hi > doc.high:
            raise ParameterError("--vary", f"{name}={spec!r} leaves the documented range {doc.low:g}..{doc.high:g} "
                                 f"({doc.source}); narrow it")
        if any(b.name == canon for b in out):
            raise ParameterError("--vary", f"{name} is given twice")
        out.append(Bound(canon, lo, hi))
    if not out:
        raise ParameterError("--vary", "give at least one --vary NAME=LOW:HIGH")
    return out


def target_from_trace(path: str | Path, duration_s: float | None = None) -> Target:
    """The measured zone profile of a video trace and its conditions.

    ``duration_s`` is the simulated time after the start-up (default: the trace's length, at least
    one pure-rolling cage revolution).

    Raises
    ------
    UsageError
        When the file is not a readable trace, is not a video trace, or has no data in the unloaded zone.
    """
    from cageless.provenance import sha256_file
    from cageless.trace import read_trace
    from cageless.comparison.align import profiles

    try:
        trace = read_trace(path)
    except TraceFormatError as exc:
        raise UsageError(str(exc)) from None
    if trace.source != "video":
        raise UsageError(f"{path}: is a {trace.source} trace; calibrate against a measured (video) trace, "
                         "or give --target-peak-slip-pct with the conditions instead.")
    prof = profiles(trace, _BIN_DEG).slip
    if not _zone(prof["mean"].to_numpy()).any():
        raise UsageError(f"{path}: no valid samples in the unloaded zone (0-180 deg); nothing to fit.")
    omega_i = trace.speed_rpm * math.pi / 30.0
    cage = 0.5 * omega_i * (1.0 - trace.ball_diameter_m / trace.pitch_diameter_m)  # pure rolling, alpha = 0
    length = float(trace.time[-1] - trace.time[0])
    duration = duration_s if duration_s is not None else max(length, 2 * math.pi / cage)
    return Target(trace.speed_rpm, trace.radial_load_n, trace.axial_load_n, duration,
                  profile=prof["mean"].to_numpy(),
                  identity={"trace_file": str(Path(path).resolve()), "trace_sha256": sha256_file(path),
                            "trace_duration_s": length})


def target_from_peak(speed_rpm: float, radial_load_n: float, peak_slip_pct: float, axial_load_n: float = 0.0,
                     duration_s: float = 0.1) -> Target:
    """A published peak slip (pp) at a condition."""
    if not (math.isfinite(peak_slip_pct) and -100 < peak_slip_pct < 100):
        raise ParameterError("--target-peak-slip-pct", "must be a slip in percent, between -100 and 100",
                             peak_slip_pct)
    return Target(speed_rpm, radial_load_n, axial_load_n, duration_s, peak_slip_pct=peak_slip_pct,
                  identity={"target_peak_slip_pct": peak_slip_pct})


def _zone(values: np.ndarray) -> np.ndarray:
    centres = (np.arange(values.size) + 0.5) * _BIN_DEG
    lo, hi = UNLOADED_ZONE_DEG
    return (centres > lo) & (centres < hi) & np.isfinite(values)


def _evaluate_seed(point: dict[str, Any], base: dict[str, Any]) -> dict[str, Any]:
    """One simulation of an evaluation: the per-bin slip sums and counts after the start-up (a worker job)."""
    from cageless.profiles import angle_profile
    from cageless.simulation.sweep import simulate_point

    trace, sol, settle, error = simulate_point(point, base)
    if trace is None or not sol.success:
        return {"ok": False, "message": error or trace.status}
    keep = (trace.time >= settle)[:, None] & trace.valid
    prof = angle_profile(trace.angle, trace.slip, _BIN_DEG, valid=keep)
    count = prof["count"].to_numpy().astype(float)
    return {"ok": True, "sum": np.nan_to_num(prof["mean"].to_numpy()) * count, "count": count,
            "wall_s": trace.simulation.wall_s}


def _miss(target: Target, mean: np.ndarray, metric: str) -> tuple[float, float]:
    """(objective in pp, peak of ``mean`` in the zone in %)."""
    from cageless.comparison.metrics import profile_errors

    zone = _zone(mean)
    peak = 100 * peak_of_mean(mean, _BIN_DEG)
    if target.profile is None:
        return abs(peak - float(target.peak_slip_pct)), peak
    both = zone & _zone(target.profile)
    if not both.any():
        return PENALTY_PP, peak
    err = profile_errors(target.profile[both], mean[both])
    return (err.rmse_pp if metric == "rmse" else err.mae_pp), peak


@dataclass
class CalibrationResult:
    """A finished calibration: the best values, the objective there and every evaluation."""

    fitted: dict[str, float]
    objective_pp: float
    evaluations: list[dict[str, Any]]
    method: str
    budget: int
    seeds: int
    metric: str
    target: Target
    bounds: list[Bound]
    settle_s: float | None
    fixed: dict[str, Any]
    wall_s: float = 0.0

    @property
    def warnings(self) -> list[str]:
        """Why the fitted values may not be determined by the target (empty when they are)."""
        return fit_warnings(self)


class _Budget(Exception):
    """The evaluation budget is spent."""


class _Objective:
    """Evaluations on the pool, each the pooled profile of K seeds; a table of every one."""

    def __init__(self, target: Target, bounds: list[Bound], base: dict[str, Any], seeds: int, metric: str,
                 pool: Any, budget: int, bar: Any) -> None:
        self.target, self.bounds, self.base, self.seeds, self.metric = target, bounds, base, seeds, metric
        self.pool, self.budget, self.bar = pool, budget, bar
        self.table: list[dict[str, Any]] = []

    def values(self, u: Sequence[float]) -> dict[str, float]:
        """Unit-cube coordinates -> parameter values."""
        return {b.name: b.low + float(np.clip(x, 0.0, 1.0)) * (b.high - b.low) for b, x in zip(self.bounds, u,
                                                                                                   strict=True)}

    def batch(self, us: Sequence[Sequence[float]]) -> list[float]:
        """Evaluate several points at once (all their seeds in parallel)."""
        us = list(us)[: self.budget - len(self.table)]
        if not us:
            raise _Budget
        futures = [[self.pool.submit(_evaluate_seed, {**self.values(u), "seed": s}, self.base)
                    for s in range(self.seeds)] for u in us]
        return [self._record(self.values(u), [f.result() for f in fs]) for u, fs in zip(us, futures, strict=True)]

    def __call__(self, u: Sequence[float] | float) -> float:
        return self.batch([np.atleast_1d(u)])[0]

    def _record(self, values: dict[str, float], runs: list[dict[str, Any]]) -> float:
        good = [r for r in runs if r["ok"]]
        row: dict[str, Any] = {"index": len(self.table), **values, "runs_ok": len(good)}
        if len(good) < len(runs):
            row.update(objective_pp=PENALTY_PP, peak_slip_pct=float("nan"), seed_spread_pp=float("nan"),
                       status="failed: " + next(r["message"] for r in runs if not r["ok"]))
        else:
            total, count = sum(r["sum"] for r in good), sum(r["count"] for r in good)
            with np.errstate(invalid="ignore", divide="ignore"):
                obj, peak = _miss(self.target, total / count, self.metric)
                per_seed = [_miss(self.target, r["sum"] / r["count"], self.metric)[0] for r in good]
            row.update(objective_pp=obj, peak_slip_pct=peak,
                       seed_spread_pp=float(np.std(per_seed, ddof=1)) if len(per_seed) > 1 else float("nan"),
                       status="ok")
        self.table.append(row)
        self.bar.update(1)
        return float(row["objective_pp"])


def _search(f: _Objective, d: int, budget: int) -> str:
    from scipy.optimize import minimize, minimize_scalar
    from scipy.stats import qmc

    try:
        if d == 1:
            minimize_scalar(lambda u: f([u]), bounds=(0.0, 1.0), method="bounded",
                            options={"maxiter": budget, "xatol": 1e-3})
            return "bounded Brent (scipy.optimize.minimize_scalar), unit-scaled"
        n0 = max(d + 1, budget // 2)
        design = qmc.LatinHypercube(d=d, seed=0).random(n0)
        f.batch(design)
        ranked = sorted(range(len(f.table)), key=lambda i: f.table[i]["objective_pp"])
        start = np.array([[(f.table[i][b.name] - b.low) / (b.high - b.low) for b in f.bounds]
                          for i in ranked[: d + 1]])
        simplex = start if np.linalg.matrix_rank(start[1:] - start[0]) == d else None
        minimize(lambda u: f(u), start[0], method="Nelder-Mead", bounds=[(0.0, 1.0)] * d,
                 options={"maxfev": budget - len(f.table), "initial_simplex": simplex, "xatol": 1e-3,
                          "fatol": 1e-3})
        return (f"Latin hypercube design of {n0} points (scipy.stats.qmc, seed 0), then Nelder-Mead with bounds "
                "(scipy.optimize.minimize) from the best d+1 design points, unit-scaled")
    except _Budget:
        return "bounded Brent (scipy.optimize.minimize_scalar), unit-scaled" if d == 1 else (
            f"Latin hypercube design of {max(d + 1, budget // 2)} points (scipy.stats.qmc, seed 0), then "
            "Nelder-Mead with bounds (scipy.optimize.minimize), unit-scaled")


def _check_range_ends(bounds: list[Bound], fixed: Mapping[str, Any]) -> None:
    """Both ends of every varied model parameter must make a valid parameter set with the held values (a rule
    between two parameters, such as peak above sliding traction, can refuse part of a documented range)."""
    from cageless.simulation.parameters import ModelParameters

    for b in bounds:
        if "." in b.name:
            continue
        for value in (b.low, b.high):
            try:
                ModelParameters().with_overrides({**fixed, b.name: value})
            except ParameterError as exc:
                other = exc.parameter.removeprefix("parameters.")
                shown = "" if exc.value is None or other == b.name else f"={exc.value}"
                raise UsageError(f"--vary {b.name}={b.low:g}:{b.high:g}: at {value:g}, {other}{shown} {exc.rule}. "
                                 "Narrow the range, or set the other parameter with --set.") from None


def calibrate(target: Target, bounds: list[Bound], budget: int | None = None, seeds: int = 2, metric: str = "mae",
              settle_s: float | None = None, fixed: Mapping[str, Any] | None = None, bearing: Bearing | None = None,
              workers: int = 2, scheduler: str | None = None, progress: bool = True) -> CalibrationResult:
    """Fit ``bounds`` to ``target``; see the module docstring for the objective and the method.

    ``budget`` is the number of evaluations (default 12 for one parameter, 10 per parameter for
    several), each ``seeds`` simulations of ``target.duration_s`` after the start-up ``settle_s``
    (default three cage revolutions, at least 40 ms). ``fixed`` are model parameters held at the given
    values. Locally the simulations run on ``workers`` processes; ``scheduler`` sends them to Dask.
    """
    import time

    from cageless.parallel import job_pool
    from cageless.simulation.parameters import ModelParameters
    from cageless.simulation.sweep import sweep_base

    d = len(bounds)
    budget = budget if budget is not None else (12 if d == 1 else 10 * d)
    if budget < (3 if d == 1 else 2 * d + 1):
        raise UsageError(f"--budget {budget} is too small for {d} parameter(s): give at least "
                         f"{3 if d == 1 else 2 * d + 1}")
    if seeds < 1:
        raise UsageError(f"--seeds must be >= 1, got {seeds}")
    if metric not in ("mae", "rmse"):
        raise UsageError(f"--metric must be mae or rmse, got {metric!r}")
    fixed = dict(fixed or {})
    model_fixed = {k: v for k, v in fixed.items() if "." not in k}
    ModelParameters().with_overrides(model_fixed)  # checked before any work starts
    _check_range_ends(bounds, model_fixed)
    bearing = bearing or default_bearing()
    base = sweep_base(target.speed_rpm, target.radial_load_n, target.axial_load_n, target.duration_s, settle_s,
                      model_fixed, bearing, command="calibrate")
    start = time.perf_counter()
    with job_pool(min(workers, seeds * (1 if d == 1 else budget)), scheduler) as pool, \
            tqdm(total=budget, desc="calibration evaluations", disable=not progress, leave=False) as bar:
        f = _Objective(target, bounds, base, seeds, metric, pool, budget, bar)
        method = _search(f, d, budget)
    ok = [r for r in f.table if r["status"] == "ok"]
    if not ok:
        raise CagelessError("every calibration run failed: " + f.table[0]["status"].removeprefix("failed: "))
    best = min(ok, key=lambda r: r["objective_pp"])
    return CalibrationResult(fitted={b.name: best[b.name] for b in bounds}, objective_pp=best["objective_pp"],
                             evaluations=f.table, method=method, budget=budget, seeds=seeds, metric=metric,
                             target=target, bounds=bounds, settle_s=settle_s, fixed=fixed,
                             wall_s=time.perf_counter() - start)


#: A fitted value closer to a bound than this share of its range is reported as at the edge.
EDGE_SHARE = 0.02


def fit_warnings(result: CalibrationResult) -> list[str]:
    """Say where a calibration does not determine its parameters.

    Checks on the evaluation table: several parameters against one number (a peak-slip target); a fitted
    value at the edge of its range; one seed per evaluation (noise unknown); an objective whose whole spread
    over the evaluations is within the largest seed-to-seed spread (the target does not see the parameter);
    and other evaluations, far from the fitted values, that fit as well within that spread.
    """
    out: list[str] = []
    ok = [r for r in result.evaluations if r["status"] == "ok"]
    if result.target.profile is None and len(result.bounds) > 1:
        out.append(f"a peak slip is one number: it cannot determine {len(result.bounds)} parameters; "
                   "vary one, or fit a measured trace's profile")
    for b in result.bounds:
        share = (result.fitted[b.name] - b.low) / (b.high - b.low)
        if min(share, 1.0 - share) < EDGE_SHARE:
            out.append(f"{b.name} = {result.fitted[b.name]:.6g} is at the edge of its range {b.low:g}:{b.high:g}; "
                       "the best value may lie outside it")
    if result.seeds == 1:
        out.append("one seed per evaluation: the objective's seed-to-seed noise is unknown; --seeds 2 or more "
                   "shows whether the fit is determined")
    spreads = [r["seed_spread_pp"] for r in ok if np.isfinite(r["seed_spread_pp"])]
    spread = max(spreads) if spreads and result.seeds > 1 else 0.0  # the noise an evaluation can carry
    objectives = np.array([r["objective_pp"] for r in ok])
    if len(ok) > 2 and np.isfinite(spread) and np.ptp(objectives) <= spread:
        out.append(f"the objective changes by {np.ptp(objectives):.3f} pp over the evaluations, within the "
                   f"seeds' spread ({spread:.3f} pp): this target does not determine the parameters")
    elif len(ok) > 2 and np.isfinite(spread) and spread > 0:
        near = [r for r in ok if r["objective_pp"] <= result.objective_pp + spread]
        for b in result.bounds:
            lo, hi = min(r[b.name] for r in near), max(r[b.name] for r in near)
            if hi - lo > 0.25 * (b.high - b.low):
                out.append(f"{b.name} from {lo:.6g} to {hi:.6g} fits as well (within the seeds' spread of "
                           f"{spread:.3f} pp)")
    return out


def describe_calibration(table: Mapping[str, Any] | None) -> str | None:
    """One line for a ``[calibration]`` table of a parameter file: what was fitted, to which condition."""
    if not table:
        return None
    fitted = ", ".join(f"{k} = {v:.6g}" for k, v in dict(table.get("fitted", {})).items())
    if "target_peak_slip_pct" in table:
        what = f"target peak slip {table['target_peak_slip_pct']:g} %"
    else:
        what = f"trace {Path(str(table.get('trace_file', '?'))).name} (sha256 {str(table.get('trace_sha256', ''))[:12]})"
    return (f"calibration ({fitted}) fitted at {table.get('condition', '?')} to {what}; "
            f"{str(table.get('metric', '')).upper()} {table.get('objective_pp', float('nan')):.3g} pp after "
            f"{table.get('evaluations_used', '?')} evaluations x {table.get('seeds', '?')} seeds, "
            f"cageless {table.get('software_version', '?')}, {table.get('created_utc', '?')}")


def default_out_name(result: CalibrationResult) -> str:
    """``calibration_<rpm>rpm_Fr<N>.toml``."""
    t = result.target
    return f"calibration_{t.speed_rpm:g}rpm_Fr{t.radial_load_n:g}.toml"


def calibration_document(result: CalibrationResult, bearing_section: Mapping[str, Any] | None = None) -> dict[str, Any]:
    """The parameter file as nested tables: ``[parameters]``, ``[bearing.*]`` and ``[calibration]``."""
    t = result.target
    params = {k: v for k, v in result.fixed.items() if "." not in k and v is not None}
    bearing: dict[str, Any] = {k: dict(v) if isinstance(v, Mapping) else v for k, v in (bearing_section or {}).items()}
    for name, value in {**{k: v for k, v in result.fixed.items() if "." in k}, **result.fitted}.items():
        if "." in name:
            part, key = name.split(".", 1)
            bearing.setdefault(part, {})[key] = value
        else:
            params[name] = value
    cal: dict[str, Any] = {
        "software_version": __version__,
        "created_utc": datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
        "condition": t.condition, "speed_rpm": t.speed_rpm, "radial_load_n": t.radial_load_n,
        "axial_load_n": t.axial_load_n, **t.identity,
        "metric": result.metric if t.profile is not None else "peak miss",
        "peak_estimator": peak_estimator(),
        "objective_pp": result.objective_pp, "method": result.method, "budget": result.budget,
        "evaluations_used": len(result.evaluations), "seeds": result.seeds,
        "seed_values": list(range(result.seeds)), "simulated_s_after_startup": t.duration_s,
        "startup_s": "three cage revolutions, at least 0.04 s" if result.settle_s is None else result.settle_s,
        "wall_s": round(result.wall_s, 2),
        "fitted": dict(result.fitted),
        "warnings": result.warnings,
        "ranges": {b.name: [b.low, b.high] for b in result.bounds},
        "evaluations": [{k: v for k, v in r.items()} for r in result.evaluations],
    }
    doc: dict[str, Any] = {"parameters": params}
    if bearing:
        doc["bearing"] = bearing
    doc["calibration"] = cal
    return doc


def write_calibration(path: str | Path, doc: Mapping[str, Any]) -> Path:
    """Write the parameter file atomically (TOML)."""
    from cageless.atomic import atomic_write_text
    from cageless.app.tomlwrite import dumps

    header = ("# cageless parameter set from `cageless calibrate`. Use it with --config FILE.toml in\n"
              "# cageless simulate, sweep or report; --set on the command line wins over [parameters].\n")
    atomic_write_text(path, header + dumps(doc))
    return Path(path)

