"""``cageless calibrate``: fit open model parameters to a measured trace or a published peak slip."""

from __future__ import annotations

import argparse
from typing import Any

from cageless.app.cli.common import add_parameter_set_option, finite_float

__all__ = ["register", "run"]

_EXAMPLES = """\
examples:
  cageless calibrate run.trace.h5 --vary cho_n_s_m=2000:8000 -o fitted.toml
  cageless calibrate run.trace.h5 --vary restitution=0.5:0.95 --vary film_thickness_m=1e-7:3.5e-7 --budget 20
  cageless calibrate --speed-rpm 3000 --radial-load-n 500 --target-peak-slip-pct 2.5 --vary cho_n_s_m=0:10000
  cageless simulate --speed-rpm 3000 --radial-load-n 500 --config fitted.toml     use the fitted set
"""


def register(subparsers: Any, parent: argparse.ArgumentParser) -> None:
    """Add the ``calibrate`` subcommand."""
    p = subparsers.add_parser(
        "calibrate", parents=[parent], help="fit open model parameters to a measured slip profile or peak slip",
        description="Fit the --vary parameters, each inside its documented physical range, so that the simulated "
        "slip matches a measured video trace (MAE or RMSE of the mean slip profile over the unloaded zone, "
        "0-180 deg, after the start-up) or a published peak slip at given conditions. One parameter: bounded "
        "Brent; several: a Latin hypercube design then Nelder-Mead with bounds. Each evaluation pools --seeds "
        "simulations (the same seeds every time). Writes a TOML parameter set with the fitted values, ranges, "
        "objective, evaluation table and provenance; pass it to simulate, sweep or report with --config.",
        epilog=_EXAMPLES, formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("trace", nargs="?", help="measured (video) trace file, *.trace.h5")
    p.add_argument("--speed-rpm", type=finite_float, help="without a trace: inner-ring speed (rpm)")
    p.add_argument("--radial-load-n", type=finite_float, help="without a trace: radial load (N)")
    p.add_argument("--axial-load-n", type=finite_float, help="without a trace: axial load (N, default 0)")
    p.add_argument("--target-peak-slip-pct", type=finite_float,
                   help="without a trace: the peak slip (%%) of the mean profile in the unloaded zone to reach")
    p.add_argument("--vary", action="append", default=[], metavar="NAME=LOW:HIGH",
                   help="a parameter to fit and its range (repeatable), e.g. cho_n_s_m=2000:8000")
    p.add_argument("--metric", choices=("mae", "rmse"), default="mae",
                   help="profile error to minimise against a trace (default mae)")
    p.add_argument("--budget", type=int, help="objective evaluations (default 12; 10 per parameter for several)")
    p.add_argument("--seeds", type=int, default=2, help="simulations (seeds 0..K-1) pooled per evaluation (default 2)")
    p.add_argument("--duration", type=finite_float,
                   help="simulated time after the start-up, which is added to it (s; default: the trace's length, at least one cage "
                   "revolution; 0.1 with a target)")
    p.add_argument("--settle", type=finite_float,
                   help="start-up left out (s; default three cage revolutions, at least 0.04)")
    add_parameter_set_option(p)
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE", dest="set_values",
                   help="hold a model parameter at a value (repeatable)")
    p.add_argument("--workers", type=int, default=2, help="local processes (default 2)")
    p.add_argument("--scheduler", help="address of a Dask scheduler to run the simulations on")
    p.add_argument("-o", "--out", help="parameter file to write (default calibration_<rpm>rpm_Fr<N>.toml)")


def _target(args: argparse.Namespace) -> Any:
    from cageless.app.calibrate import target_from_peak, target_from_trace
    from cageless.errors import UsageError

    given = [f for f in ("speed_rpm", "radial_load_n", "axial_load_n") if getattr(args, f) is not None]
    if args.trace:
        if given or args.target_peak_slip_pct is not None:
            raise UsageError("calibrate: with a trace the conditions and the target come from the trace; drop "
                             + ", ".join("--" + g.replace("_", "-") for g in given or ["target_peak_slip_pct"]))
        return target_from_trace(args.trace, args.duration)
    if args.target_peak_slip_pct is None or args.speed_rpm is None or args.radial_load_n is None:
        raise UsageError("calibrate: give a measured trace, or --speed-rpm, --radial-load-n and "
                         "--target-peak-slip-pct (see cageless calibrate --help)")
    return target_from_peak(args.speed_rpm, args.radial_load_n, args.target_peak_slip_pct,
                            args.axial_load_n or 0.0, args.duration if args.duration is not None else 0.1)


def run(args: argparse.Namespace, config: dict[str, Any]) -> int:
    """Calibrate and write the parameter file."""
    from cageless.app.calibrate import (calibrate, calibration_document, default_out_name, parse_bounds,
                                    write_calibration)
    from cageless.app.cli.common import parameter_values
    from cageless.config import bearing_from_config
    from cageless.errors import UsageError

    bearing = bearing_from_config(config)
    bounds = parse_bounds(args.vary, bearing)
    from cageless.simulation.parameters import parse_set_overrides

    clash = [b.name for b in bounds if b.name in parse_set_overrides(args.set_values)]
    if clash:
        raise UsageError(f"calibrate: {', '.join(clash)} is both held (--set) and varied (--vary); drop one")
    varied = {b.name for b in bounds}  # a varied value of a --config file's [parameters] is its start, not fixed
    fixed = {k: v for k, v in parameter_values(args, config).items() if k not in varied}
    if args.workers < 1:
        raise UsageError(f"--workers must be >= 1, got {args.workers}")
    target = _target(args)
    res = calibrate(target, bounds, args.budget, args.seeds, args.metric, args.settle, fixed, bearing, args.workers,
                    args.scheduler, progress=args.progress)
    out = write_calibration(args.out or default_out_name(res), calibration_document(res, config.get("bearing")))
    what = "peak miss" if target.profile is None else args.metric.upper()
    for row in res.evaluations:
        vals = ", ".join(f"{b.name}={row[b.name]:.6g}" for b in bounds)
        result = (f"{what} {row['objective_pp']:.3f} pp  peak {row['peak_slip_pct']:.2f} %  ok" if row["status"] == "ok"
                  else row["status"])
        print(f"{row['index']:3d}  {vals}  {result}")
    fitted = ", ".join(f"{k} = {v:.6g}" for k, v in res.fitted.items())
    print(f"fitted at {target.condition}: {fitted}; {what} {res.objective_pp:.3f} pp after {len(res.evaluations)} "
          f"evaluations x {res.seeds} seeds ({res.method}; {res.wall_s:.0f} s) -> {out}")
    for text in res.warnings:
        print(f"warning: {text}")
    return 0 if all(r["status"] == "ok" for r in res.evaluations) else 1
