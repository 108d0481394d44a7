"""``cageless report LAB_FOLDER -o OUT``: track, simulate, compare, and write one HTML report."""

from __future__ import annotations

import argparse
import sys
from typing import Any

from cageless.app.cli.common import add_parameter_set_option, add_track_fit_option, finite_float

__all__ = ["register", "run"]

_EXAMPLES = """\
examples:
  cageless report sample_data/lab -o report
  cageless report lab -o out --duration 0.2 --set cho_n_s_m=2500
  cageless report sample_data/lab -o quick --revolutions 2     a quick look (2 cage revolutions simulated)
  cageless report lab -o out --config fitted.toml     parameters from `cageless calibrate`
  cageless report lab -o out --scheduler tcp://10.0.0.5:8786     the same workflow on a Dask cluster
"""


def register(subparsers: Any, parent: argparse.ArgumentParser) -> None:
    """Add the ``report`` subcommand."""
    p = subparsers.add_parser(
        "report", parents=[parent], help="lab folder -> traces, simulations, slip table and report.html",
        description="For a lab folder: track every video, simulate each distinct condition once, compare, and "
        "write OUT/report.html and OUT/slip_table.csv (also .md, .tex, .html). Unchanged work is skipped on a "
        "re-run. A video or simulation that fails is a failed row in the report; the rest completes (exit 1).",
        epilog=_EXAMPLES, formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("lab", help="lab folder (videos with their conditions)")
    p.add_argument("-o", "--out", default="report", help="output folder (default ./report)")
    p.add_argument("--duration", type=finite_float,
                   help="simulated time after the start-up, which is added to it (s; default: the longest video, at least --revolutions "
                   "cage revolutions)")
    p.add_argument("--revolutions", type=finite_float, default=20.0,
                   help="cage revolutions simulated after the start-up, at least (default 20: every 1 deg bin "
                   "filled by every ball many times, dozens of Poincare points); --duration overrides it")
    p.add_argument("--settle", type=finite_float,
                   help="simulated start-up left out of the comparison (s; default three cage revolutions, "
                   "at least 0.04)")
    p.add_argument("--slip-reference", choices=("cage", "loaded-zone"), default="cage",
                   help="what slip is referred to: the pure-rolling cage speed of the stated speed (default) or "
                   "each trace's own loaded-zone speed (removes a flat bias from scale or clearance)")
    add_parameter_set_option(p)
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE", dest="set_values",
                   help="change an open model parameter (see `cageless simulate --help`)")
    p.add_argument("--rtol", type=finite_float, default=1e-6, help="simulation tolerance (default 1e-6)")
    p.add_argument("--workers", type=int, default=2, help="local processes (default 2)")
    p.add_argument("--scheduler", help="address of a Dask scheduler to run the jobs on")
    p.add_argument("--force", action="store_true", help="compare even when a trace's conditions differ, and accept "
                   "numbers and conditions outside their plausible ranges")
    p.add_argument("--n-balls", type=int, metavar="N",
                   help="ball count the videos show, when it differs from the bearing's (default: the bearing's)")
    p.add_argument("--window", type=int, metavar="FRAMES",
                   help="Savitzky-Golay speed window of the tracking, in frames, odd, >= 3 (default 21); a shorter "
                   "one tracks shorter clips, with noisier speeds")
    add_track_fit_option(p, None)
    p.add_argument("--allow-truncated", action="store_true",
                   help="track the complete frames of a cut-off .cine instead of failing its row")


def run(args: argparse.Namespace, config: dict[str, Any]) -> int:
    """Run the workflow and print where the report is."""
    from cageless.conditions import find_videos, nested_videos_hint
    from cageless.config import bearing_from_config
    from cageless.errors import CagelessError
    from cageless.app.lab import LabOptions, run_lab
    from cageless.comparison.compare import QC_FAILED
    from cageless.app.calibrate import describe_calibration
    from cageless.app.cli.common import check_n_balls, check_window, failed_line, parameter_values
    from cageless.simulation.parameter_sets import DEFAULT_SET

    from cageless.app.lab import CACHE_NAME, REPORT_PRODUCTS
    from cageless.outputs import check_output_dir, check_products
    from cageless.validate import check_options

    check_n_balls(args.n_balls, config)
    check_window(args.window)
    values = parameter_values(args, config)  # [parameters] of --config, then --set; before any work starts
    check_options(args, ("duration", "settle", "revolutions", "rtol", "workers", "window"))
    check_output_dir(args.out, "-o")
    check_products(args.out, REPORT_PRODUCTS, CACHE_NAME)
    note = describe_calibration(config.get("calibration"))
    options = LabOptions(duration_s=args.duration, settle_s=args.settle, revolutions=args.revolutions,
                         rtol=args.rtol, workers=args.workers,
                         scheduler=args.scheduler, force=args.force, parameters=values, calibration=note,
                         n_balls=args.n_balls, allow_truncated=args.allow_truncated, window=args.window,
                         track_fit=args.track_fit,
                         slip_reference=args.slip_reference,
                         parameter_set=args.parameter_set or DEFAULT_SET)
    if not find_videos(args.lab):  # find_videos names a missing folder; say so before any output
        raise CagelessError(f"{args.lab}: no videos found. A lab folder holds videos (cine, avi/mp4/mkv or image "
                            "folders) with their conditions." + nested_videos_hint(args.lab))
    print(f"parameters: {note}" if note else f"parameters: set '{options.parameter_set}'")
    res = run_lab(args.lab, args.out, options, bearing_from_config(config), progress=not args.quiet,
                  bars=args.progress)
    failed = []
    for row in sorted(res.rows, key=lambda r: (r.status == "failed", r.speed_rpm, r.radial_load_n, r.label)):
        if row.status == "failed":
            failed.append(row.label)
            if args.quiet:  # else each failure was printed with its reason as it happened
                print(failed_line(row.label, row.message), file=sys.stderr)
        else:
            print(f"{row.label}: {row.speed_rpm:g} r/min, {row.radial_load_n:g} N: theoretical slip "
                  f"{row.theoretical_slip_pct:.2f} ± {row.theoretical_slip_se_pp:.2f} %, experimental "
                  f"{row.experimental_slip_pct:.2f} ± {row.experimental_slip_se_pp:.2f} %, MAE {row.mae_pp:.2f} pp"
                  + (f" ({row.status}: {row.message})" if row.status == QC_FAILED else ""))
    if failed and not args.quiet:
        print(f"failed: {', '.join(failed)} (the reasons are above and in the report)", file=sys.stderr)
    timing = ", ".join(f"{k} {v:.1f} s" for k, v in res.timings.items())
    print(f"report -> {res.report}; table -> {res.table} ({timing}; {res.skipped} jobs unchanged and skipped)")
    return 1 if res.n_failed else 0
