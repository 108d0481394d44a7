"""The paper's lubricant sensitivity study at 1800 rpm, 500 N, run through ``cageless sweep``'s code.

Source: Wang, Zhao, Wang, Jin, Appl. Sci. 2026, 16, 9284, §4 (discussion of Table 2): varying each parameter
alone, the paper's predicted 1800 rpm slip falls from about 24.5 % to 15.9 % over viscosity 0.02-0.06 Pa s,
from 24.8 % to 17.0 % over film thickness 0.1-0.35 um, and from 24.4 % to 16.8 % over the lubricant damping
C_ho 2500-7500 N s/m: a fall of 30-35 % each as the parameter grows.

The last row is not the paper's: the oil temperature at 20 and 60 degC (the viscosity falls by
exp(-0.027 x 40) = 0.34 with the paper's temperature-viscosity coefficient) shows the temperature reaching the
slip through the film, the traction and the rolling losses.

Each row is the sweep of one parameter at its two ends (the equivalent command is printed with it), the rest at
the default parameter set. The film thickness h_0 is swept twice: with the Hamrock-Dowson film on (the
default, where h_0 is only the critical film of the ball-ball squeeze film) and with the fixed film h_0 in the
race contacts (``--effect ehl_film=off``), which is how the paper's model uses it.

The "+-" beside each change is its standard error from the seed spread: sqrt(s_lo^2 / n + s_hi^2 / n) / mean_lo,
with s the standard deviation of the per-seed peak slips at each end and n the seeds. At 1800 rpm the ring of
balls is chaotic and one seed's peak spreads by about 1 pp, so a change smaller than twice its standard error
is not resolved.

    python benchmarks/lubricant_sensitivity.py               # 2 seeds, 0.1 s each: about 10 min, 2 loaded cores
    python benchmarks/lubricant_sensitivity.py --seeds 1 --duration 0.05
    python benchmarks/lubricant_sensitivity.py --rows cho_n_s_m film_thickness_m --seeds 4 --duration 0.2
    python benchmarks/lubricant_sensitivity.py --rows cho_n_s_m --effect strip_damping=on   # the paper's strips

``--effect NAME=on|off`` (repeatable) applies to every row, on top of the row's own effects, as in
``cageless sweep --effect``.
"""

from __future__ import annotations

import argparse
import sys
import time

#: name, low, high, effects, the paper's (slip at low, slip at high) in % (None: not in the paper's study).
STUDY = (
    ("lubricant.viscosity", 0.02, 0.06, {}, (24.5, 15.9)),
    ("film_thickness_m", 0.1e-6, 0.35e-6, {}, (24.8, 17.0)),
    ("film_thickness_m", 0.1e-6, 0.35e-6, {"ehl_film": False}, (24.8, 17.0)),
    ("cho_n_s_m", 2500.0, 7500.0, {}, (24.4, 16.8)),
    ("oil_temperature_c", 20.0, 60.0, {}, None),
)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--seeds", type=int, default=2)
    ap.add_argument("--duration", type=float, default=0.1)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--speed-rpm", type=float, default=1800.0)
    ap.add_argument("--rows", nargs="*", default=None, help="only the rows of these parameters (default: all)")
    ap.add_argument("--effect", action="append", default=[], metavar="NAME=on|off",
                    help="an effect override for every row (repeatable)")
    ap.add_argument("--values", nargs="*", type=float, default=None,
                    help="the values to sweep between the row's ends (default: its two ends)")
    args = ap.parse_args(argv)
    from cageless.errors import UsageError
    from cageless.simulation.effects import parse_effect_overrides

    try:
        extra = parse_effect_overrides(args.effect)
    except UsageError as exc:
        ap.error(str(exc))
    known = {row[0] for row in STUDY}
    if args.rows and not set(args.rows) <= known:
        ap.error(f"--rows: unknown {sorted(set(args.rows) - known)}; the rows are {sorted(known)}")
    from cageless.simulation.sweep import parse_vary, run_sweep, summarise

    out = ["| parameter | low -> high | peak slip (%) low -> high | change (relative) +- its standard error | "
           "paper (%) | paper change |", "|---|---|---|---|---|---|"]
    start = time.perf_counter()
    for name, lo, hi, effects, paper_pct in STUDY:
        if args.rows and name not in args.rows:
            continue
        effects = {**effects, **extra}
        values = sorted({lo, hi, *(args.values or ())})
        vary = parse_vary([f"{name}=" + ",".join(f"{v:g}" for v in values)])
        runs = run_sweep(vary, args.seeds, args.speed_rpm, 500.0, duration_s=args.duration, workers=args.workers,
                         progress=False, effects=effects)
        summ = summarise(runs, list(vary)).reset_index(drop=True)
        s_lo, s_hi = summ.peak_slip_mean_pct.iloc[0], summ.peak_slip_mean_pct.iloc[-1]
        n_lo, n_hi = summ.runs.iloc[0], summ.runs.iloc[-1]
        # the std of summarise is the population one (ddof 0); the standard error wants the sample one
        sd_lo, sd_hi = (summ.peak_slip_std_pct.iloc[i] * (n / max(n - 1, 1)) ** 0.5
                        for i, n in ((0, n_lo), (-1, n_hi)))
        se = (sd_lo ** 2 / n_lo + sd_hi ** 2 / n_hi) ** 0.5 / s_lo
        label = name + "".join(f" ({k} {'on' if v else 'off'})" for k, v in effects.items())
        paper = "— | —" if paper_pct is None else \
            f"{paper_pct[0]} -> {paper_pct[1]} | {(paper_pct[1] - paper_pct[0]) / paper_pct[0]:+.0%}"
        out.append(f"| {label} | {lo:g} -> {hi:g} | {s_lo:.2f} -> {s_hi:.2f} | {(s_hi - s_lo) / s_lo:+.0%} +- {se:.0%} | "
                   f"{paper} |")
        if len(summ) > 2:
            out.append("|  | all values | " + " -> ".join(f"{v:.2f}" for v in summ.peak_slip_mean_pct) + " |  |  |  |")
        cmd = (f"cageless sweep --speed-rpm {args.speed_rpm:g} --radial-load-n 500 --vary {name}="
               + ",".join(f"{v:g}" for v in values) + " "
               f"--seeds {args.seeds} --duration {args.duration:g}"
               + "".join(f" --effect {k}={'on' if v else 'off'}" for k, v in effects.items()))
        sys.stderr.write(cmd + "\n")
    sys.stdout.write(f"Lubricant sensitivity at {args.speed_rpm:g} rpm, 500 N ({args.seeds} seed(s) x "
                     f"{args.duration:g} s after the start-up)\n\n" + "\n".join(out) + "\n")
    sys.stdout.write(f"(wall {time.perf_counter() - start:.0f} s)\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
