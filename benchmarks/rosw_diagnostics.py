"""Why the compiled Rosenbrock-W method (``rosw``) pays or does not: where its steps and its time go.

    python benchmarks/rosw_diagnostics.py [--window 0.005] [--level planar|spatial] [--rtol 1e-7]
                                          [--jac-every 20] [--json out.json]

From the settled 3000 rpm, 500 N state (as ``cageless bench accuracy``), one window is integrated by an
instrumented copy of the method's loop, built here from the method's own compiled pieces
(:mod:`cageless.simulation.integrators.rosw`: the same step, controls and bookkeeping, so the same steps as
``solve(method="rosw")``). It records every attempted step and prints

* the histogram of accepted step lengths;
* why steps were rejected or shortened: error-test rejections, contact-onset retries (at ``onset_step``),
  force-jump halvings, non-finite states;
* how often W was evaluated and why: its age (every ``jac_every`` steps), a contact that opened or closed
  in the last step (by kind: outer race, inner race, ball-ball), two rejections in a row;
* the cost split: right-hand sides, Jacobian difference quotients (their right-hand sides), block LU
  (``_prepare``), block solves, and the rest (loop, controls, dense output, bookkeeping), from per-call
  times measured in the same process, multiplied by the counts, against the run's time.

Times are the process's CPU time (``time.process_time``), steadier than wall time on a shared machine; they
are still noisy there (the per-call times are measured separately from the run, so the split's rest can
come out negative).

The instrumented loop lives here, not in the method: the method's hot loop keeps no counters beyond its
statistics.
"""

from __future__ import annotations

import argparse
import json
import logging
import time
from pathlib import Path
from typing import Any

import numba
import numpy as np

from cageless.atomic import atomic_write_text
from cageless.simulation.bench import _settled_problem
from cageless.simulation.integrators import rosw as rw
from cageless.simulation.kernels import model_gaps, model_rhs, model_signature
from cageless.simulation.solve import ROSW_ATOL_FACTOR, _rosw_blocks

log = logging.getLogger("rosw_diagnostics")

# outcome of an attempt
ACCEPT, REJECT_ERROR, RETRY_ONSET, RETRY_JUMP, NONFINITE = 0, 1, 2, 3, 4
# why W was evaluated before an attempt
W_NONE, W_AGE, W_CONTACT, W_REJECT = 0, 1, 2, 3


@numba.njit(cache=False)
def _traced(model_id, p, log_, y0, t0, t_end, rtol, atol, h0, h_max, max_att, h_onset, jump_floor, force_jump, st,
            jac_every, lu_ratio, rec, kinds, n_gaps, counts):  # pragma: no cover - compiled
    """The loop of :func:`rw.rosw_integrate` (no samples) recording per attempt: t, h, err, outcome, W reason.
    ``kinds`` counts the contacts that changed in accepted steps by gap index."""
    vec, u, wk = rw._workspace(y0.shape[0], st[0], st[2], st[4])
    y, k1, k7, ynew = vec[0], vec[1], vec[2], vec[5]
    cnt = np.zeros(8, dtype=np.int64)
    lu_at = np.zeros(1)
    t_out = np.array([t_end])
    out = np.zeros((1, y0.shape[0]))
    rw._start(model_id, t0, y0, p, log_, t_out, out, atol, rtol, vec)
    t, h, age = t0, h0, jac_every
    reason = W_AGE
    sig = model_signature(model_id, y, p)
    g0 = np.zeros(n_gaps)
    g1 = np.zeros(n_gaps)
    rejected = False
    n = 0
    while t < t_end and n < max_att:
        h = min(h, h_max, t_end - t)
        fresh = 0 < jac_every <= age
        err = rw._step(model_id, t, h, p, log_, atol, rtol, vec, u, st, wk, fresh, cnt, lu_at, lu_ratio)
        rec[n, 0], rec[n, 1], rec[n, 2], rec[n, 4] = t, h, err, reason if fresh else W_NONE
        if fresh:
            age = 0
        if not err <= 1.0:
            rec[n, 3] = REJECT_ERROR if np.isfinite(err) else NONFINITE
            n += 1
            if rejected and age > 0:
                age, reason = jac_every, W_REJECT
            rejected = True
            h *= max(0.2, 0.9 * err ** (-1.0 / 3.0)) if np.isfinite(err) else 0.25
            continue
        model_rhs(model_id, t + h, ynew, p, log_, k7)
        grow = 1.0 if rejected else 5.0
        rejected = False
        verdict, sig = rw._controls(model_id, ynew, p, sig, h, h_onset, k1, k7, jump_floor, force_jump)
        if verdict == 1 or verdict == 2:
            rec[n, 3] = RETRY_ONSET if verdict == 1 else RETRY_JUMP
            n += 1
            h = h_onset if verdict == 1 else max(0.5 * h, h_onset)
            continue
        rec[n, 3] = ACCEPT
        n += 1
        if verdict == 3:
            model_gaps(model_id, y, p, g0)
            model_gaps(model_id, ynew, p, g1)
            for i in range(n_gaps):
                if (g0[i] > 0.0) != (g1[i] > 0.0):
                    kinds[i] += 1
            age, reason = jac_every, W_CONTACT
        else:
            age += 1
            if age >= jac_every:
                reason = W_AGE
        rw._accept(model_id, t, h, y, ynew, k1, k7, p, log_, t_out, out, 0)
        t += h
        h *= min(grow, max(0.2, 0.9 * max(err, 1e-10) ** (-1.0 / 3.0)))
    counts[:] = cnt
    return n


@numba.njit(cache=False)
def _time_pieces(model_id, t, y, p, log_, atol, rtol, st, h, reps, out):  # pragma: no cover - compiled
    """Mean wall time (s) of one right-hand side, one W evaluation, one block LU and one block solve."""
    vec, u, wk = rw._workspace(y.shape[0], st[0], st[2], st[4])
    rw._start(model_id, t, y, p, log_, np.array([t + 1.0]), np.zeros((1, y.shape[0])), atol, rtol, vec)
    f = np.zeros(y.shape[0])
    with numba.objmode(a="f8"):
        a = time.process_time()
    for _ in range(reps):
        model_rhs(model_id, t, vec[0], p, log_, f)
    with numba.objmode(b="f8"):
        b = time.process_time()
    out[0] = (b - a) / reps
    n_rhs = 0
    for _ in range(reps // 20 + 1):
        n_rhs = rw._jacobian(model_id, t, vec[0], p, log_, vec[1], st, wk, vec[7], vec[8], vec[9])
    with numba.objmode(c="f8"):
        c = time.process_time()
    out[1] = (c - b) / (reps // 20 + 1)
    out[5] = n_rhs
    for _ in range(reps):
        rw._prepare(st, wk, 1.0 / (h * rw.GAMMA))
    with numba.objmode(d="f8"):
        d = time.process_time()
    out[2] = (d - c) / reps
    for _ in range(reps):
        vec[4, :] = vec[1]
        rw._solve(st, wk, h * rw.GAMMA, vec[4], vec[6])
    with numba.objmode(e="f8"):
        e = time.process_time()
    out[3] = (e - d) / reps


def diagnose(level: str, window: float, rtol: float, jac_every: int, lu_ratio: float = rw.LU_RATIO,
             trace: Path | None = None) -> dict[str, Any]:
    """Run the instrumented loop over ``window`` and return the numbers (see the module text)."""
    pr, _ = _settled_problem(3000, 500, 0.03, axial_n=400 if level == "spatial" else 0.0, level=level, strips=5)
    atol = pr.atol.astype(np.float64) * (ROSW_ATOL_FACTOR * rtol / 1e-6)
    st = _rosw_blocks(pr)
    floor = pr.jump_floor.astype(np.float64)
    from cageless.simulation.auto_switch import default_max_step
    from cageless.simulation.solve import FORCE_JUMP
    cap = default_max_step("rosw")
    z = pr.n_balls
    n_gaps = pr.n_gaps
    max_att = 2_000_000
    results = {}
    for attempt in range(2):  # the first call compiles
        rec = np.zeros((max_att, 5))
        kinds = np.zeros(n_gaps, dtype=np.int64)
        counts = np.zeros(8, dtype=np.int64)
        logc = pr.log.copy()
        start = time.process_time()
        n = _traced(pr.model_id, pr.params, logc, pr.y0.astype(np.float64), 0.0, window, rtol, atol, window * 1e-3,
                    cap, max_att, float(pr.onset_step), floor, FORCE_JUMP, st, jac_every, lu_ratio, rec, kinds, n_gaps,
                    counts)
        results = {"wall": time.process_time() - start, "rec": rec[:n].copy(), "kinds": kinds, "n_lu": int(counts[7])}
    rec, wall = results["rec"], results["wall"]
    pieces = np.zeros(6)
    acc = rec[:, 3] == ACCEPT
    h_med = float(np.median(rec[acc, 1]))
    _time_pieces(pr.model_id, 0.0, pr.y0.astype(np.float64), pr.params, pr.log.copy(), atol, rtol, st, h_med, 20, pieces)
    _time_pieces(pr.model_id, 0.0, pr.y0.astype(np.float64), pr.params, pr.log.copy(), atol, rtol, st, h_med, 2000,
                 pieces)
    t_rhs, t_jac, t_lu, t_solve, jac_rhs = pieces[[0, 1, 2, 3, 5]]
    n_att = len(rec)
    n_acc = int(acc.sum())
    n_w = int((rec[:, 4] != W_NONE).sum())
    outcomes = {name: int((rec[:, 3] == code).sum()) for name, code in
                (("accepted", ACCEPT), ("error rejections", REJECT_ERROR), ("onset retries", RETRY_ONSET),
                 ("force-jump retries", RETRY_JUMP), ("non-finite", NONFINITE))}
    w_reasons = {name: int((rec[:, 4] == code).sum()) for name, code in
                 (("age", W_AGE), ("contact change", W_CONTACT), ("two rejections", W_REJECT))}
    kinds = results["kinds"]
    changes = {"outer race": int(kinds[:z].sum()), "inner race": int(kinds[z:2 * z].sum()),
               "ball-ball": int(kinds[2 * z:].sum())}
    # right-hand sides: 3 per attempt + 1 per error-passed attempt (its end) + the Jacobians' own
    n_end = n_att - outcomes["error rejections"] - outcomes["non-finite"]
    n_rhs_stage = 3 * n_att + n_end
    solves_per_attempt = 4 + int(rw.FILTER_ERROR)
    cost = {"right-hand sides (stages, step ends)": n_rhs_stage * t_rhs,
            "W evaluations (difference quotients)": n_w * t_jac,
            "block LU": results["n_lu"] * t_lu,
            "block solves": n_att * solves_per_attempt * t_solve}
    cost["rest (loop, controls, dense output, bookkeeping)"] = wall - sum(cost.values())
    edges = np.array([0, 0.25, 0.5, 1, 2, 3, 4, 5, 6, 8, 10.001]) * 1e-6
    hist, _ = np.histogram(rec[acc, 1], bins=edges)
    if trace is not None:
        np.save(trace, rec)
    return {"level": level, "window_s": window, "rtol": rtol, "jac_every": jac_every, "wall_s": wall,
            "wall_s_per_sim_s": wall / window, "attempts": n_att, "factorisations": results["n_lu"],
            "lu_ratio": lu_ratio, "accepted": n_acc,
            "onset_step_us": pr.onset_step * 1e6, "median_h_us": h_med * 1e6,
            "mean_h_us": float(rec[acc, 1].mean() * 1e6), "outcomes": outcomes, "w_evaluations": n_w,
            "w_reasons": w_reasons, "contact_changes": changes,
            "per_call_us": {"rhs": t_rhs * 1e6, "W": t_jac * 1e6, "W rhs": int(jac_rhs), "LU": t_lu * 1e6,
                            "solve": t_solve * 1e6},
            "cost_s": cost, "h_hist_us": {f"{a * 1e6:g}-{b * 1e6:.3g}": int(c)
                                          for a, b, c in zip(edges[:-1], edges[1:], hist, strict=True)}}


def format_report(d: dict[str, Any]) -> str:
    """The numbers as text tables."""
    lines = [f"rosw, {d['level']}, 3000 rpm, 500 N, {d['window_s'] * 1e3:g} ms, rtol {d['rtol']:g}, "
             f"jac_every {d['jac_every']}, lu_ratio {d['lu_ratio']:g}: {d['wall_s_per_sim_s']:.2f} CPU s / sim s",
             f"attempts {d['attempts']}, accepted {d['accepted']}, mean h {d['mean_h_us']:.2f} us, "
             f"median h {d['median_h_us']:.2f} us, onset step {d['onset_step_us']:.2f} us",
             "outcomes: " + ", ".join(f"{k} {v}" for k, v in d["outcomes"].items()),
             f"factorisations {d['factorisations']}, W evaluations {d['w_evaluations']}: " + ", ".join(f"{k} {v}" for k, v in d["w_reasons"].items()),
             "contact changes in accepted steps: " + ", ".join(f"{k} {v}" for k, v in d["contact_changes"].items()),
             "per call (us): " + ", ".join(f"{k} {v:.3g}" for k, v in d["per_call_us"].items()),
             "accepted step lengths (us): " + ", ".join(f"{k}: {v}" for k, v in d["h_hist_us"].items()),
             "| cost | CPU s | share |", "|---|---|---|"]
    for k, v in d["cost_s"].items():
        lines.append(f"| {k} | {v:.3f} | {100 * v / d['wall_s']:.0f} % |")
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--window", type=float, default=0.005)
    ap.add_argument("--level", default="planar", choices=("planar", "spatial"))
    ap.add_argument("--rtol", type=float, default=1e-7)
    ap.add_argument("--jac-every", type=int, default=rw.JAC_EVERY)
    ap.add_argument("--lu-ratio", type=float, default=rw.LU_RATIO)
    ap.add_argument("--json", type=Path)
    ap.add_argument("--trace", type=Path, help="save every attempt (t, h, err, outcome, W reason) as .npy")
    args = ap.parse_args()
    logging.basicConfig(level=logging.INFO, format="%(message)s")
    d = diagnose(args.level, args.window, args.rtol, args.jac_every, args.lu_ratio, args.trace)
    print(format_report(d))
    if args.json:
        atomic_write_text(args.json, json.dumps(d, indent=1))


if __name__ == "__main__":
    main()
