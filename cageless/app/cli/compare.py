"""``cageless compare VIDEO_TRACE SIM_TRACE``: one Table-2 row, optionally the figures."""

from __future__ import annotations

import argparse
import logging
from pathlib import Path
from typing import Any

from cageless.app.cli.common import finite_float

__all__ = ["register", "run"]

log = logging.getLogger(__name__)

_EXAMPLES = """\
examples:
  cageless compare out/traces/clip_3000rpm.trace.h5 sim_3000rpm_Fr500.trace.h5
  cageless compare measured.trace.h5 simulated.trace.h5 --figures figs/ --align-ball 3
  cageless compare measured.trace.h5 simulated.trace.h5 --slip-reference loaded-zone
"""


def register(subparsers: Any, parent: argparse.ArgumentParser) -> None:
    """Add the ``compare`` subcommand."""
    p = subparsers.add_parser(
        "compare", parents=[parent], help="compare a measured and a simulated trace (one Table-2 row)",
        description="Align a video trace and a simulation trace as slip and speed profiles against orbital "
        "angle and print the Table-2-style row: theoretical and experimental slip, MAE, RMSE, maximum error.",
        epilog=_EXAMPLES, formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("video_trace", help="trace of a video (source = video; given the other way round, the two "
                   "are swapped with a warning)")
    p.add_argument("sim_trace", help="trace of a simulation (source = simulation)")
    p.add_argument("--bin-deg", type=finite_float, default=1.0, help="angle bin width (deg, default 1)")
    p.add_argument("--settle", type=finite_float,
                   help="simulated start-up left out of the simulation's profile (s; default three cage "
                   "revolutions, at least 0.04)")
    p.add_argument("--slip-reference", choices=("cage", "loaded-zone"), default="cage",
                   help="what slip is referred to: the pure-rolling cage speed of the stated speed (default, the "
                   "paper's definition) or each trace's own loaded-zone speed, which removes a flat bias from a "
                   "stated speed, scale or clearance slightly off")
    p.add_argument("--force", action="store_true", help="compare traces of different conditions or bearings")
    p.add_argument("--align-ball", type=int,
                   help="also align this ball's speed in time (cross-correlation; balls are numbered 0..Z-1, "
                   "counter-clockwise)")
    p.add_argument("--figures", help="write the speed, slip, contact and ring figures (SVG) to this folder")


def run(args: argparse.Namespace, config: dict[str, Any]) -> int:
    """Compare and print."""
    from cageless.atomic import atomic_write_text
    from cageless.errors import UsageError
    from cageless.trace import read_trace
    from cageless.comparison.align import align_time
    from cageless.comparison.compare import compare
    from cageless.comparison.report import describe_condition, figures
    from cageless.comparison.table import table_frame, to_markdown

    from cageless.outputs import check_output_dir
    from cageless.validate import check_options

    check_options(args, ("bin_deg", "settle"), force=False)
    if args.figures:
        check_output_dir(args.figures, "--figures")
    measured, simulated = read_trace(args.video_trace), read_trace(args.sim_trace)
    video_path = args.video_trace
    if measured.source == "simulation" and simulated.source == "video":  # given the other way round: the traces say
        log.warning("%s is the simulation and %s the video trace: compared as video %s against simulation %s",
                    args.video_trace, args.sim_trace, args.sim_trace, args.video_trace)
        measured, simulated, video_path = simulated, measured, args.sim_trace
    if measured.source != "video" or simulated.source != "simulation":
        raise UsageError(f"give a video trace and a simulation trace (got a {measured.source} trace, "
                         f"{args.video_trace}, and a {simulated.source} trace, {args.sim_trace}).")
    c = compare(measured, simulated, args.bin_deg, args.settle, args.force, label=Path(video_path).name,
                slip_reference=args.slip_reference)
    print(to_markdown(table_frame([c.row])), end="")
    if args.slip_reference != "cage":
        print(f"Note: {c.row.message}")
    if args.align_ball is not None:
        a = align_time(measured, simulated, args.align_ball)
        print(f"time alignment of ball {a.ball}: measured(t) ~ simulated(t {a.lag_s:+.6f} s), "
              f"correlation {a.correlation:.3f}")
    if args.figures:
        d = describe_condition(c.row.label, c, measured, simulated)
        folder = Path(args.figures)
        folder.mkdir(parents=True, exist_ok=True)
        for name, fn in (("speed", figures.speed_figure), ("slip", figures.slip_figure),
                         ("contacts", figures.contact_polar_figure), ("ring", figures.ring_figure)):
            atomic_write_text(folder / f"{name}.svg", fn(d))
        print(f"figures -> {folder}")
    return 0
