"""``cageless sample``: render a synthetic lab folder (videos, conditions, ground truth)."""

from __future__ import annotations

import argparse
from typing import Any

from cageless.cli.common import finite_float
from cageless.config import bearing_from_config

__all__ = ["register", "run"]

_EXAMPLES = """\
examples:
  cageless sample my_lab                         the small three-condition sample (as in sample_data/lab)
  cageless sample big --preset full --workers 2  full-size 1280x800, 10 kfps 12-bit cines
  cageless sample my_lab --revolutions 1 --seed 7
"""


def register(subparsers: Any, parent: argparse.ArgumentParser) -> None:
    """Add the ``sample`` subcommand."""
    p = subparsers.add_parser(
        "sample", parents=[parent], help="render synthetic bearing videos with known ground truth",
        description="Render a lab folder of synthetic end-face videos of the bearing (three conditions: 1800, "
        "3000 and 6000 rpm at 500 N), with their conditions and ground truth (<clip>.truth.csv/.json).",
        epilog=_EXAMPLES, formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("out", metavar="DIR", help="folder to write")
    p.add_argument("--preset", choices=("lab", "full"), default="lab",
                   help="lab: 320x200 px, small (default); full: 1280x800 px camera footage")
    p.add_argument("--seed", type=int, default=2026, help="random seed (default 2026, the bundled sample's)")
    p.add_argument("--revolutions", type=finite_float, default=None,
                   help="orbits each ball travels per clip (default 0.34 lab, 0.1 full)")
    p.add_argument("--workers", type=int, default=1, help="processes rendering frames (default 1)")


def run(args: argparse.Namespace, config: dict[str, Any]) -> int:
    """Render the folder and print one line per clip; return the exit code."""
    from tracking.synthetic.lab import make_lab

    geometry = bearing_from_config(config).geometry
    results = make_lab(args.out, preset=args.preset, seed=args.seed, revolutions=args.revolutions,
                       geometry=geometry, workers=max(1, args.workers), progress=not args.quiet)
    for res in results:
        print(f"{res['video']}: {res['n_frames']} frames, truth in {res['truth_csv'].name}")
    return 0
