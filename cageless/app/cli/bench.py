"""``cageless bench``: what accuracy costs in time (prints tables; not tests)."""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

__all__ = ["register", "run"]

_EXAMPLES = """\
examples:
  cageless bench tracking                       render 2400 full-size frames once, then measure
  cageless bench tracking --frames 600 --json bench.json
  cageless bench accuracy --plot work_precision.png   simulator: error against wall time per solver/tolerance
  cageless bench effects --speed-rpm 1800                each optional effect removed in turn: change and saving
"""


def register(subparsers: Any, parent: argparse.ArgumentParser) -> None:
    """Add the ``bench`` subcommand."""
    p = subparsers.add_parser(
        "bench", parents=[parent], help="accuracy-versus-time studies (tables)",
        description="Measure what accuracy costs in time. 'tracking': end-to-end frames/s on full-size "
        "footage, detector and smoothing-window trade-offs, trackpy on the same frames, peak memory. "
        "'accuracy': the simulator's work-precision table (solvers x tolerances against a tight reference) "
        "and what model fidelity costs (planar against spatial, strip counts). 'effects': each optional effect "
        "removed in turn, with the change in slip and the time saved.",
        epilog=_EXAMPLES, formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("study", choices=("tracking", "accuracy", "effects"), help="which study to run")
    p.add_argument("--speed-rpm", type=float, default=1800.0, help="effects: scene speed (rpm, default 1800)")
    p.add_argument("--radial-load-n", type=float, default=500.0, help="effects: radial load (default 500 N)")
    p.add_argument("--axial-load-n", type=float, default=0.0, help="effects: axial load (default 0 N)")
    p.add_argument("--window", type=float, default=0.005, help="accuracy: simulated window (s, default 0.005)")
    p.add_argument("--plot", help="accuracy: write the work-precision diagram to this image")
    p.add_argument("--dir", default="bench_footage",
                   help="tracking: where rendered footage is kept (default ./bench_footage)")
    p.add_argument("--frames", type=int, default=2400,
                   help="tracking: frames of full-size footage (default 2400, 4.9 GB)")
    p.add_argument("--repeats", type=int, default=3,
                   help="tracking and accuracy: timing repeats, best taken (default 3)")
    p.add_argument("--json", help="also write the results as JSON")


def run(args: argparse.Namespace, config: dict[str, Any]) -> int:
    """Run the study and print its tables."""
    if args.study == "effects":
        from cageless.simulation.bench import effects_study, format_effects

        result = effects_study(args.speed_rpm, args.radial_load_n, args.axial_load_n)
        print(format_effects(result))
    elif args.study == "accuracy":
        from cageless.simulation.bench import accuracy_study, format_accuracy, format_models, model_study, plot_accuracy

        result = accuracy_study(window_s=args.window, repeats=args.repeats)
        print(format_accuracy(result))
        models = model_study(window_s=args.window, repeats=args.repeats)
        print()
        print(format_models(models))
        result["models"] = models
        if args.plot:
            plot_accuracy(result, args.plot)
    else:
        from cageless.tracking.bench import format_tables, run_benchmark

        folder = Path(args.dir)
        folder.mkdir(parents=True, exist_ok=True)
        result = run_benchmark(folder, args.frames, args.repeats)
        print(format_tables(result))
    if args.json:
        from cageless.atomic import atomic_write_text

        atomic_write_text(args.json, json.dumps(result, indent=1))
    return 0
