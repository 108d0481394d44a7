"""Slip error of the solvers by a statistic that chaos does not scramble: long-run means (issue 18's accuracy bar).

    nice -n 10 python benchmarks/ark_accuracy_means.py [--case planar] [--settle 0.15] [--revolutions 10]
                                                        [--rate 10000] [--candidates ark4,ark4-7,auto,dp5]
                                                        [--check-reference] [--bar 0.01] [--json out.json]

The ball ring is chaotic (``benchmarks/ark_accuracy_states.py``): two accurate solutions from one state part within
a few milliseconds, so the largest pointwise difference measures the chaos, not the integrator. What a report
takes from a run are long-run averages: the mean slip and the mean slip profile over the orbital angle, whose
unloaded-zone peak is the headline (:func:`cageless.profiles.unloaded_zone_peak`). For such averages an
integrator's error is a bias, which shrinks with the tolerance, and the run's length adds a sampling error,
which shrinks as one over its square root; this measures both (docs/imex.md, the twelfth step).

From the state ``--settle`` seconds after the start (:func:`cageless.simulation.bench._settled_problem`; 0.15 s is
the 3000 rpm start-up that ``compare`` and ``report`` leave out: :func:`cageless.kinematics.startup_duration`), each
candidate and the tight reference (DP5, rtol 1e-10, 0.25 us cap: :func:`solver_speed.measure`, which also times
them) run ``--revolutions`` pure-rolling cage revolutions sampled at ``--rate`` Hz, in batches of about the square
root of that many revolutions (:func:`batch_revolutions`).
For each candidate the statistic is the difference from the reference of (1) the mean slip over all balls and
samples and (2) the unloaded-zone peak of the mean slip profile (1 deg bins, smoothed as the reports smooth it),
both in percentage points. Its standard error is the delete-one-batch jackknife over the batches, the two runs'
batches paired (Kuensch 1989; for the mean slip it equals the batch-means error). The decision is Schuirmann's two
one-sided tests at 5 %: the bar is **met** when the 90 % t interval of the difference (B - 1 degrees of freedom)
lies within +-``--bar``, **missed** when it lies wholly outside, and **not decidable** otherwise (the run is too
short for the bar). With ``--check-reference`` the reference is compared the same way with DP5 at rtol 1e-11 and a
0.125 us cap: its difference shows the statistic's noise floor between two solutions of negligible bias.
"""

from __future__ import annotations

import argparse
import json
import logging
import math
import sys
import time
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
from scipy import stats

from cageless.atomic import atomic_write_text
from cageless.profiles import PEAK_SMOOTHING_DEG, angle_profile, peak_of_mean
from cageless.simulation.bench import _settled_problem
from cageless.simulation.solve import solve
from ark_accuracy_states import CASES  # the sibling scripts (on sys.path)
from solver_speed import CANDIDATES, _run, measure

log = logging.getLogger("ark_accuracy_means")

#: Orbital-angle bin of the slip profile (deg), as ``simulate``'s reports bin it.
BIN_DEG = 1.0


def batch_sums(y: np.ndarray, t: np.ndarray, z: int, cage: float, edges: np.ndarray) -> dict[str, np.ndarray]:
    """Per batch (``edges``, s): the sum and count of the slip (pp) over all balls and samples, and per 1 deg
    orbital-angle bin.

    Parameters
    ----------
    y : numpy.ndarray
        A solution's samples, shape (T, n); the orbital angles are columns z:2z and speeds 3z:4z.
    t : numpy.ndarray
        The sample times (s).
    z : int
        Number of balls.
    cage : float
        The pure-rolling cage speed (rad/s).
    edges : numpy.ndarray
        Batch edges (s), B + 1 of them; a sample at an inner edge belongs to the later batch.

    Returns
    -------
    dict
        ``total``, ``count``: shape (B,); ``bin_total``, ``bin_count``: shape (B, bins).
    """
    slip = 100.0 * (1.0 - y[:, 3 * z:4 * z] / cage)
    which = np.clip(np.searchsorted(edges, t, side="right") - 1, 0, len(edges) - 2)
    n_bins = int(round(360.0 / BIN_DEG))
    out = {"total": [], "count": [], "bin_total": [], "bin_count": []}
    for b in range(len(edges) - 1):
        rows = which == b
        prof = angle_profile(y[rows, z:2 * z], slip[rows], BIN_DEG)
        count = prof["count"].to_numpy(dtype=np.float64)
        out["total"].append(np.nansum(slip[rows]))
        out["count"].append(np.isfinite(slip[rows]).sum())
        out["bin_total"].append(np.where(count > 0, prof["mean"].to_numpy() * count, 0.0))
        out["bin_count"].append(count)
    assert all(len(v) == len(edges) - 1 for v in out.values()) and n_bins == len(out["bin_count"][0])
    return {k: np.asarray(v, dtype=np.float64) for k, v in out.items()}


def _statistics(sums: dict[str, np.ndarray], keep: np.ndarray) -> np.ndarray:
    """The mean slip and the unloaded-zone peak of the mean profile (pp) over the batches ``keep`` (bool mask)."""
    mean = sums["total"][keep].sum() / sums["count"][keep].sum()
    with np.errstate(invalid="ignore", divide="ignore"):
        profile = sums["bin_total"][keep].sum(axis=0) / sums["bin_count"][keep].sum(axis=0)
    return np.array([mean, peak_of_mean(profile, BIN_DEG, PEAK_SMOOTHING_DEG)])


def regroup(sums: dict[str, np.ndarray], size: int) -> dict[str, np.ndarray]:
    """:func:`batch_sums` of one revolution each summed over ``size`` consecutive revolutions (a remainder at the end
    joins the last batch)."""
    n = len(sums["total"])
    which = np.minimum(np.arange(n) // size, max(n // size, 1) - 1)
    return {k: np.stack([v[which == i].sum(axis=0) for i in range(which[-1] + 1)]) for k, v in sums.items()}


def batch_revolutions(revolutions: int) -> int:
    """Revolutions per batch: the square root of their number, rounded down (Flegal & Jones, Ann. Statist. 38
    (2010) 1034: batches of about n^(1/2) make the batch-means variance consistent), one below four."""
    return 1 if revolutions < 4 else math.isqrt(revolutions)


def paired_difference(a: dict[str, np.ndarray], b: dict[str, np.ndarray], size: int = 1) -> dict[str, Any]:
    """The statistics of ``a`` minus those of ``b`` (both :func:`batch_sums` over the same revolutions), with the
    delete-one-batch jackknife standard error over batches of ``size`` revolutions.

    Parameters
    ----------
    a, b : dict
        :func:`batch_sums` of two solutions.
    size : int
        Revolutions per batch (:func:`regroup`).

    Returns
    -------
    dict
        ``a``, ``b``: the statistics [mean slip, unloaded-zone peak] (pp); ``diff``, ``se``: their difference and its
        jackknife standard error; ``batches``: their number.
    """
    a, b = regroup(a, size), regroup(b, size)
    n = len(a["total"])
    every = np.ones(n, dtype=bool)
    sa, sb = _statistics(a, every), _statistics(b, every)
    leave = np.array([_statistics(a, np.arange(n) != i) - _statistics(b, np.arange(n) != i) for i in range(n)])
    se = np.sqrt((n - 1) / n * ((leave - leave.mean(axis=0)) ** 2).sum(axis=0))
    return {"a": sa, "b": sb, "diff": sa - sb, "se": se, "batches": n}


def decide(diff: float, se: float, batches: int, bar: float, alpha: float = 0.05) -> tuple[str, float, float]:
    """Schuirmann's two one-sided tests: ``"met"`` when the 1 - 2 ``alpha`` t interval of ``diff`` (``batches`` - 1
    degrees of freedom) lies within +-``bar``, ``"missed"`` when it lies wholly outside, else ``"not decidable"``;
    with the interval's ends."""
    half = stats.t.ppf(1.0 - alpha, batches - 1) * se
    lo, hi = diff - half, diff + half
    if -bar < lo and hi < bar:
        return "met", lo, hi
    if lo > bar or hi < -bar:
        return "missed", lo, hi
    return "not decidable", lo, hi


def segmented(pr: Any, cage: float, key: str, revolutions: int, segment: int, rate: float) -> dict[str, Any]:
    """One candidate over ``revolutions`` cage revolutions, solved ``segment`` revolutions at a time (each from the
    last one's end state and contact log, so memory stays flat), with its per-revolution :func:`batch_sums`.

    Parameters
    ----------
    pr : Problem
        The settled problem.
    cage : float
        The pure-rolling cage speed (rad/s).
    key : str
        A key of ``solver_speed.CANDIDATES``.
    revolutions, segment : int
        Revolutions in all and per solve (``revolutions`` a whole multiple of ``segment``).
    rate : float
        Samples per second.

    Returns
    -------
    dict
        ``sums`` (:func:`batch_sums` over all revolutions), ``cpu_s_per_sim_s`` (the solves' CPU time, this
        process's), ``steps``, ``ok``, ``method``, ``end`` (the problem from the last state).
    """
    if revolutions % segment:
        raise SystemExit(f"--revolutions ({revolutions}) must be a whole multiple of --segment ({segment})")
    span = segment * 2.0 * math.pi / cage
    t = np.linspace(0.0, span, int(round(span * rate)) + 1)
    edges = np.linspace(0.0, span, segment + 1)
    parts, cpu, steps, ok = [], 0.0, 0, True
    for _ in range(revolutions // segment):
        start = time.process_time()
        sol = _run(pr, t, *CANDIDATES[key][1:])
        cpu += time.process_time() - start
        steps, ok = steps + sol.n_steps, ok and bool(sol.success)
        parts.append(batch_sums(sol.y[:-1], t[:-1], pr.n_balls, cage, edges))  # the end sample starts the next
        pr = replace(pr, y0=sol.y[-1].copy(), log=sol.extra["log"], t0=0.0)
    sums = {k: np.concatenate([p[k] for p in parts]) for k in parts[0]}
    return {"sums": sums, "cpu_s_per_sim_s": cpu / (revolutions * span / segment), "steps": steps, "ok": ok,
            "method": sol.method, "end": pr}


def settled_start(case: str, settle: float, advance: int, key: str) -> tuple[Any, float]:
    """The problem ``settle`` seconds after the start (:func:`cageless.simulation.bench._settled_problem`), then
    ``advance`` cage revolutions further by the candidate ``key`` (10 at a time), and the cage speed (rad/s)."""
    pr, cage = _settled_problem(3000, 500, settle, **CASES[case])
    if advance:
        pr = segmented(pr, cage, key, advance, math.gcd(advance, 10), 1e3)["end"]
    return pr, cage


def run_long(case: str, settle: float, advance: int, revolutions: int, segment: int, rate: float, keys: list[str],
             reference: str, bar: float) -> list[dict[str, Any]]:
    """:func:`run` with a candidate as the reference (``reference``, a ``solver_speed.CANDIDATES`` key), each run
    :func:`segmented`: for runs long enough to resolve the bar, where the tight reference would cost too much."""
    pr, cage = settled_start(case, settle, advance, reference)
    for key in [*keys, reference]:  # compile untimed
        _run(pr, np.array([0.0, 1e-6]), *CANDIDATES[key][1:])
    runs = {key: segmented(pr, cage, key, revolutions, segment, rate) for key in dict.fromkeys([*keys, reference])}
    log.info("solved: %s", ", ".join(f"{k} {r['cpu_s_per_sim_s']:.2f} CPU s/s" for k, r in runs.items()))
    return [_entry(case, {"solver": f"{CANDIDATES[key][0]} vs {reference}", "steps": runs[key]["steps"],
                          "cpu_s_per_sim_s": runs[key]["cpu_s_per_sim_s"], "slip_error_pp": math.nan,
                          "method": runs[key]["method"]},
                   runs[key]["sums"], runs[reference]["sums"], settle, revolutions * 2.0 * math.pi / cage, bar)
            for key in keys]


def _entry(case: str, row: dict[str, Any], a: dict[str, np.ndarray], b: dict[str, np.ndarray], settle: float,
           span: float, bar: float) -> dict[str, Any]:
    """One table row: the candidate's ``row`` (solver, method, CPU, steps, pointwise error) and per statistic the
    :func:`paired_difference` of its sums ``a`` and the reference's ``b`` over batches of
    :func:`batch_revolutions`, with the :func:`decide` verdict; ``se_one_revolution``: the error over one-revolution
    batches (below the batches' error when revolutions are correlated); ``per_revolution``: each revolution's mean
    slip (pp) in both runs."""
    revolutions = len(a["total"])
    size = batch_revolutions(revolutions)
    d, one = paired_difference(a, b, size), paired_difference(a, b, 1)
    entry = {"case": case, "solver": row["solver"], "method": row.get("method", ""),
             "cpu_s_per_sim_s": row["cpu_s_per_sim_s"], "steps": row["steps"], "pointwise_pp": row["slip_error_pp"],
             "settle_s": settle, "revolutions": revolutions, "batch_revolutions": size, "span_s": span,
             "per_revolution": [(a["total"] / a["count"]).tolist(), (b["total"] / b["count"]).tolist()]}
    for j, name in enumerate(("mean", "peak")):
        verdict, lo, hi = decide(float(d["diff"][j]), float(d["se"][j]), d["batches"], bar)
        entry[name] = {"value": float(d["a"][j]), "reference": float(d["b"][j]), "diff": float(d["diff"][j]),
                       "se": float(d["se"][j]), "se_one_revolution": float(one["se"][j]), "lo": lo, "hi": hi,
                       "verdict": verdict}
    return entry


def run(case: str, settle: float, advance: int, revolutions: int, rate: float, keys: list[str],
        check_reference: bool, bar: float) -> list[dict[str, Any]]:
    """Each candidate's statistics against the reference's over ``revolutions`` cage revolutions (see the module text).

    Returns
    -------
    list of dict
        One row per candidate (and, with ``check_reference``, one for the reference against the tighter one): the
        label, CPU s per simulated s, steps, the pointwise slip error (pp), and per statistic the candidate's and
        reference's values, the difference, its standard error, the TOST interval and the decision.
    """
    pr, cage = settled_start(case, settle, advance, "ark4-8")
    period = 2.0 * math.pi / cage
    span = revolutions * period
    t = np.linspace(0.0, span, int(round(span * rate)) + 1)
    edges = np.linspace(0.0, span, revolutions + 1)
    for key in keys:  # compile untimed
        _run(pr, t[:2] * 1e-3, *CANDIDATES[key][1:])
    keep: dict[str, Any] = {}
    rows = measure(case, pr, cage, t, 1, keys, keep)
    log.info("solved: %s", ", ".join(f"{r['solver']} {r['cpu_s_per_sim_s']:.2f} CPU s/s" for r in rows))
    z = pr.n_balls
    ref = batch_sums(keep["reference"].y, t, z, cage, edges)
    pairs = [(r, batch_sums(keep[r["solver"]].y, t, z, cage, edges)) for r in rows]
    if check_reference:
        tighter = solve(pr, t, rtol=1e-11, max_step=1.25e-7)
        pairs.append(({"solver": "reference (DP5 1e-10, 0.25 us) vs DP5 1e-11, 0.125 us", "cpu_s_per_sim_s": math.nan,
                       "steps": keep["reference"].n_steps, "slip_error_pp": math.nan}, ref))
        ref_for_last = batch_sums(tighter.y, t, z, cage, edges)
    last = len(pairs) - 1
    return [_entry(case, row, sums, ref_for_last if check_reference and i == last else ref, settle, span, bar)
            for i, (row, sums) in enumerate(pairs)]


def format_table(rows: list[dict[str, Any]], bar: float) -> str:
    """One line per candidate: both statistics' difference +- SE, the 90 % interval and the verdict, CPU s/s."""
    lines = [f"| solver | mean slip (pp) | diff +- SE | 90 % interval | vs {bar:g} pp | peak slip (pp) | diff +- SE | "
             "90 % interval | verdict | pointwise max (pp) | CPU s / sim s | ratio | steps |", "|---" * 13 + "|"]
    base = rows[0]["cpu_s_per_sim_s"]
    for r in rows:
        cells = []
        for name in ("mean", "peak"):
            s = r[name]
            cells.append(f"{s['value']:.4f} | {s['diff']:+.4f} +- {s['se']:.4f} | [{s['lo']:+.4f}, {s['hi']:+.4f}] | "
                         f"{s['verdict']}")
        lines.append(f"| {r['solver']} | " + " | ".join(cells) + f" | {r['pointwise_pp']:.2g} | "
                     f"{r['cpu_s_per_sim_s']:.2f} | {r['cpu_s_per_sim_s'] / base:.2f} | {r['steps']} |")
    return "\n".join(lines)


def main() -> None:
    """The command line (see the module text)."""
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--case", choices=sorted(CASES), default="planar")
    ap.add_argument("--settle", type=float, default=0.15, help="simulated seconds from the start to the first sample")
    ap.add_argument("--advance", type=int, default=0,
                    help="cage revolutions from --settle to the first sample, by ark4 at rtol 1e-8 (or the candidate "
                         "--reference); the mean slip relaxes for about 100 (docs/imex.md, the twelfth step)")
    ap.add_argument("--revolutions", type=int, default=10, help="pure-rolling cage revolutions measured")
    ap.add_argument("--rate", type=float, default=10_000.0, help="samples per second (simulate's default)")
    ap.add_argument("--candidates", default="ark4,ark4-7,auto,dp5",
                    help="keys of solver_speed.CANDIDATES; the first is the base of the ratios")
    ap.add_argument("--check-reference", action="store_true",
                    help="also the reference against DP5 at rtol 1e-11 and a 0.125 us cap")
    ap.add_argument("--bar", type=float, default=0.01, help="the slip error bar (pp)")
    ap.add_argument("--reference", default="tight",
                    help="'tight' (DP5, rtol 1e-10, 0.25 us cap), or a key of solver_speed.CANDIDATES: each run is "
                         "then solved --segment revolutions at a time")
    ap.add_argument("--segment", type=int, default=10, help="with a candidate --reference: revolutions per solve")
    ap.add_argument("--json", type=Path)
    args = ap.parse_args()
    logging.basicConfig(level=logging.INFO, format="%(message)s", stream=sys.stderr)
    keys = args.candidates.split(",")
    if args.reference == "tight":
        rows = run(args.case, args.settle, args.advance, args.revolutions, args.rate, keys, args.check_reference,
                   args.bar)
    else:
        rows = run_long(args.case, args.settle, args.advance, args.revolutions, args.segment, args.rate, keys,
                        args.reference, args.bar)
    print(f"{args.case}, {args.revolutions} cage revolutions ({rows[0]['span_s']:.3f} s) from {args.settle:g} s and "
          f"{args.advance} revolutions\n")
    print(format_table(rows, args.bar))
    if args.json:
        atomic_write_text(args.json, json.dumps(rows, indent=1, default=str))


if __name__ == "__main__":
    main()
