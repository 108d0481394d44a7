"""``cageless sweep``: a scene over a parameter grid and seeds (table and plot of peak slip)."""

from __future__ import annotations

import argparse
import sys
from typing import Any

from cageless.app.cli.common import add_bearing_options, add_parameter_set_option, finite_float, scene_bearing

__all__ = ["register", "run"]

_EXAMPLES = """\
examples:
  cageless sweep --speed-rpm 1800 --radial-load-n 500 --vary lubricant.viscosity=0.02:0.06:5 --seeds 4
  cageless sweep --radial-load-n 500 --vary speed_rpm=1800,3000,6000 --vary cho_n_s_m=2500,7500 -o sweep
  cageless sweep --speed-rpm 1800 --vary film_thickness_m=1e-7:3.5e-7:6 --scheduler tcp://10.0.0.5:8786
  cageless sweep --speed-rpm 1800 --vary film_thickness_m=1e-7,3.5e-7 --effect ehl_film=off     a fixed film
  cageless sweep --speed-rpm 3000 --clearance-um 32 --vary geometry.ball_diameter_m=8e-3,9.525e-3
"""


def register(subparsers: Any, parent: argparse.ArgumentParser) -> None:
    """Add the ``sweep`` subcommand."""
    p = subparsers.add_parser(
        "sweep", parents=[parent], help="a scene over a parameter grid and seeds: peak slip table and plot",
        description="Rerun a scene over every combination of the --vary values and --seeds seeds, and write "
        "OUT/runs.csv (one row per run), OUT/summary.csv (mean and seed spread of the peak slip in the unloaded "
        "zone per grid point) and OUT/peak_slip.png. Runs locally on both cores or on a Dask cluster.",
        epilog=_EXAMPLES, formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--speed-rpm", type=finite_float, default=1800.0, help="inner-ring speed (rpm, default 1800)")
    p.add_argument("--radial-load-n", type=finite_float, default=500.0, help="radial load (N, default 500)")
    p.add_argument("--axial-load-n", type=finite_float, default=0.0, help="axial load (N, default 0)")
    p.add_argument("--vary", action="append", default=[], metavar="NAME=SPEC",
                   help="a parameter and its values: start:stop:count or v1,v2,... (repeatable)")
    p.add_argument("--seeds", type=int, default=1, help="seeds per grid point (default 1)")
    p.add_argument("--duration", type=finite_float, default=0.1, help="simulated time after the start-up, which is added to it (s, default 0.1)")
    p.add_argument("--settle", type=finite_float,
                   help="start-up left out (s; default three cage revolutions at each point, at least 0.04)")
    add_bearing_options(p)
    add_parameter_set_option(p)
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE", dest="set_values",
                   help="fixed model-parameter changes for every run")
    p.add_argument("--effect", action="append", default=[], metavar="NAME=on|off",
                   help="switch an effect on or off for every run (forced; repeatable), e.g. ehl_film=off")
    p.add_argument("--workers", type=int, default=2, help="local processes (default 2)")
    p.add_argument("--scheduler", help="address of a Dask scheduler")
    p.add_argument("-o", "--out", default="sweep", help="output folder (default ./sweep)")


def run(args: argparse.Namespace, config: dict[str, Any]) -> int:
    """Run the sweep and print the summary."""
    from cageless.errors import UsageError
    from cageless.simulation.sweep import parse_vary, run_sweep, summarise, write_sweep
    from cageless.app.calibrate import describe_calibration
    from cageless.app.cli.common import parameter_values

    if args.seeds < 1:
        raise UsageError(f"--seeds must be >= 1, got {args.seeds}")
    from cageless.outputs import check_output_dir
    from cageless.validate import check_options

    check_options(args, ("speed_rpm", "radial_load_n", "axial_load_n", "duration", "settle", "workers",
                         "clearance_um"), force=False)
    check_output_dir(args.out, "-o")
    bearing = scene_bearing(args, config)  # --config's [bearing.*], --dry and --clearance-um, as simulate takes them
    vary = parse_vary(args.vary, bearing)
    fixed = parameter_values(args, config)  # [parameters] of --config, then --set
    from cageless.simulation.effects import parse_effect_overrides

    runs = run_sweep(vary, args.seeds, args.speed_rpm, args.radial_load_n, args.axial_load_n, args.duration,
                     args.settle, fixed, bearing, args.workers, args.scheduler, progress=args.progress,
                     effects=parse_effect_overrides(args.effect))
    paths = write_sweep(runs, list(vary), args.out)
    note = describe_calibration(config.get("calibration"))
    if note:
        print(f"parameters: {note}")
    print(summarise(runs, list(vary)).to_string(index=False, float_format=lambda v: f"{v:.4g}"))
    failed = runs[runs.status != "ok"]
    for _, r in failed.iterrows():
        print(f"FAILED seed {r.seed}: {r.message}", file=sys.stderr)
    print(f"runs -> {paths['runs']}; summary -> {paths['summary']}; plot -> {paths['plot']}")
    return 1 if len(failed) else 0
