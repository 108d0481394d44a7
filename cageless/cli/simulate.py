"""``cageless simulate``: the scene, the model it calls for, and (in a later release) the run.

This release decides and explains the model (``--explain``); the solver lands
with the rest of the simulator issue, and until then running without
``--explain`` says so and exits with the usage code.
"""

from __future__ import annotations

import argparse
from typing import Any

from cageless.cli.common import finite_float
from cageless.config import bearing_from_config
from cageless.errors import UsageError

__all__ = ["register", "run"]

_EXAMPLES = """\
examples:
  cageless simulate --speed-rpm 3000 --radial-load-n 500 --explain
  cageless simulate --speed-rpm 3000 --radial-load-n 500 --axial-load-n 400 --explain
  cageless simulate --speed-rpm 1800 --radial-load-n 500 --effect drag=on --oil-air-density 5 --explain
  cageless simulate --speed-rpm 3000 --axial-load-n 300 --level planar --force --explain
"""


def register(subparsers: Any, parent: argparse.ArgumentParser) -> None:
    """Add the ``simulate`` subcommand."""
    p = subparsers.add_parser(
        "simulate", parents=[parent], help="decide (and explain) the bearing model a scene calls for",
        description="Build the scene (speed, loads, lubricant, orientation) and decide the model level and "
        "the effects it calls for, each with its reason. --explain prints them without solving.",
        epilog=_EXAMPLES, formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--speed-rpm", type=finite_float, required=True, help="inner-ring speed (rpm)")
    p.add_argument("--radial-load-n", type=finite_float, default=0.0, help="radial load (N, default 0)")
    p.add_argument("--axial-load-n", type=finite_float, default=0.0, help="axial load (N, default 0)")
    p.add_argument("--duration", type=finite_float, default=0.05, help="simulated time (s, default 0.05)")
    p.add_argument("--gravity", type=finite_float, default=9.81, help="gravity (m/s^2, default 9.81; 0 for none)")
    p.add_argument("--orientation", choices=("horizontal", "vertical"), default="horizontal", help="shaft orientation")
    p.add_argument("--misalignment-rad", type=finite_float, default=0.0, help="inner-ring tilt (rad)")
    p.add_argument("--oil-air-density", type=finite_float, help="oil-air mixture density (kg/m^3); enables drag")
    p.add_argument("--dry", action="store_true", help="no lubricant")
    p.add_argument("--seed", type=int, default=0, help="perturbs the initial gaps")
    p.add_argument("--level", help="force the model level: planar or spatial")
    p.add_argument("--effect", action="append", default=[], metavar="NAME=on|off", help="force an effect")
    p.add_argument("--force", action="store_true", help="allow forced choices that contradict the scene")
    p.add_argument("--explain", action="store_true", help="print the level and effects with reasons; do not solve")
    p.add_argument("--json", action="store_true", help="with --explain: print JSON")


def run(args: argparse.Namespace, config: dict[str, Any]) -> int:
    """Build the scene, choose the model, and explain it."""
    import dataclasses

    from cageless.conditions import OperatingConditions
    from simulation.effects import choose_model, parse_effect_overrides
    from simulation.scene import Scene

    bearing = bearing_from_config(config)
    if args.dry:
        bearing = dataclasses.replace(bearing, lubricant=None)
    scene = Scene(conditions=OperatingConditions(args.speed_rpm, args.radial_load_n, args.axial_load_n),
                  bearing=bearing, gravity_m_s2=args.gravity, orientation=args.orientation,
                  misalignment_rad=args.misalignment_rad, oil_air_density_kg_m3=args.oil_air_density,
                  duration_s=args.duration, seed=args.seed)
    choice = choose_model(scene, args.level, parse_effect_overrides(args.effect), args.force)
    if not args.explain:
        raise UsageError("the solver is not in this release yet; run with --explain to see the model the scene "
                         "calls for.")
    print(choice.to_json() if args.json else choice.explain())
    return 0
