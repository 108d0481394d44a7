"""``cageless simulate``: the scene, the model it calls for, and the run.

``--explain`` prints the model level and effects with their reasons. A run
writes a ``cageless-trace/1`` simulation file and prints a summary. This release
runs the planar level (pure radial load on an aligned bearing); a scene that
needs the spatial level is refused with the flags that force it. ``--set``
changes an open model parameter (:class:`cageless.simulation.parameters.ModelParameters`),
``--ensemble N`` runs seeds 0..N-1 on both cores.
"""

from __future__ import annotations

import argparse
import math
import re
from typing import Any

from cageless.app.cli.common import add_bearing_options, add_parameter_set_option, finite_float, scene_bearing
from cageless.config import bearing_from_config

__all__ = ["register", "run"]

_EXAMPLES = """\
examples:
  cageless simulate --speed-rpm 3000 --radial-load-n 500 --explain
  cageless simulate --speed-rpm 3000 --radial-load-n 500 --axial-load-n 400 --explain
  cageless simulate --speed-rpm 1800 --radial-load-n 500 --oil-air-density 20 --explain
  cageless simulate --speed-rpm 3000 --axial-load-n 300 --level planar --force --explain
  cageless simulate --speed-rpm 6000 --radial-load-n 500 --duration 0.1
  cageless simulate --speed-rpm 1800 --radial-load-n 500 --set cho_n_s_m=2500 --ensemble 4
"""


def register(subparsers: Any, parent: argparse.ArgumentParser) -> None:
    """Add the ``simulate`` subcommand."""
    p = subparsers.add_parser(
        "simulate", parents=[parent],
        help="simulate the bearing for a scene (--explain: the model and effects it calls for, and why)",
        description="Build the scene (speed, loads, lubricant, orientation), decide the model level and "
        "the effects it calls for, each with its reason, and simulate it into a trace. --explain prints the "
        "choice without solving.",
        epilog=_EXAMPLES, formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    _add_scene_arguments(p)
    p.add_argument("--seed", type=int, default=0, help="seed that perturbs the initial gaps (default 0)")
    p.add_argument("--level", help="force the model level: planar or spatial (default: the scene's; --explain "
                   "says which and why)")
    p.add_argument("--effect", action="append", default=[], metavar="NAME=on|off",
                   help="force an effect on or off (repeatable; --explain lists the effects)")
    p.add_argument("--force", action="store_true", help="allow forced choices that contradict the scene, and "
                   "numbers outside their plausible ranges")
    p.add_argument("--overwrite", action="store_true", help="allow -o to replace a file that is not a cageless trace")
    p.add_argument("--explain", action="store_true", help="print the level and effects with reasons; do not solve")
    p.add_argument("--json", action="store_true", help="with --explain: print JSON")
    _add_solver_arguments(p)
    add_parameter_set_option(p)
    p.add_argument("--set", action="append", default=[], metavar="NAME=VALUE", dest="set_values",
                   help="change an open model parameter, e.g. --set cho_n_s_m=2500 (repeatable; "
                   "simulation/parameters.py lists them with their sources)")
    p.add_argument("--speed-ramp", type=finite_float, default=0.0,
                   help="time for the ring to reach its speed from rest (s, default 0: at speed from the start)")
    p.add_argument("--ensemble", type=int, default=1, metavar="N",
                   help="run seeds 0..N-1 (N traces, both cores; default 1)")
    p.add_argument("--scheduler", help="with --ensemble: address of a Dask scheduler to run the seeds on")
    p.add_argument("--sample-rate", type=finite_float, default=10_000.0, help="samples per second (default 10000)")
    p.add_argument("-o", "--out", help="trace file to write (default sim_<rpm>rpm_Fr<N>.trace.h5, with _Fa<N> "
                   "under an axial load)")


def _add_scene_arguments(p: argparse.ArgumentParser) -> None:
    """``simulate``'s options that describe the scene: speed, loads, gravity, orientation, lubricant."""
    p.add_argument("--speed-rpm", type=finite_float, required=True, help="inner-ring speed (rpm)")
    p.add_argument("--radial-load-n", type=finite_float, default=0.0, help="radial load (N, default 0)")
    p.add_argument("--axial-load-n", type=finite_float, default=0.0, help="axial load (N, default 0)")
    p.add_argument("--duration", type=finite_float, default=None,
                   help="total simulated time, start-up included (s; default: the start-up that compare and report "
                   "leave out, three cage revolutions, then one more revolution: 0.2 s at 3000 rpm)")
    p.add_argument("--gravity", type=finite_float, default=9.81, help="gravity (m/s^2, default 9.81; 0 for none)")
    p.add_argument("--orientation", choices=("horizontal", "vertical"), default="horizontal",
                   help="shaft orientation (default horizontal; vertical puts gravity along the shaft)")
    p.add_argument("--misalignment-rad", type=finite_float, default=0.0,
                   help="prescribed inner-ring tilt about y (rad, default 0); the ring tilts further under the "
                   "contacts")
    p.add_argument("--moment-load-nm", type=finite_float, default=0.0,
                   help="moment load on the inner ring about y (N m, default 0); selects the spatial level")
    p.add_argument("--oil-air-density", type=finite_float, help="oil-air mixture density (kg/m^3; default 42.4, 5 %% oil by volume, in a lubricated scene; 0 turns drag off)")
    add_bearing_options(p)


def _add_solver_arguments(p: argparse.ArgumentParser) -> None:
    """``simulate``'s options that choose the integrator and its accuracy."""
    p.add_argument("--solver", default="auto", help="integrator: auto (default: compiled dp5, switching to CVODE "
                   "(BDF) or ark4 when stiffness makes that cheaper and ark4 refuses under 10 %% of its steps), "
                   "dp5, ark4 (compiled IMEX, the race normal forces "
                   "implicit), rosw, CVODE, RK45, DOP853, LSODA, BDF, Radau")
    p.add_argument("--rtol", type=finite_float, default=1e-6, help="relative tolerance (default 1e-6)")
    p.add_argument("--max-step", type=finite_float, default=None,
                   help="largest step (s; default 2e-6, and 5e-6 for CVODE, also after an automatic switch, "
                   "1e-5 for rosw, 5e-5 for ark4)")
    p.add_argument("--restitution", type=finite_float,
                   help="ball-ball coefficient of restitution R, 0 <= R <= 1, 0 perfectly plastic (same as --set "
                   "restitution=R)")

def run(args: argparse.Namespace, config: dict[str, Any]) -> int:
    """Build the scene, choose the model, and explain it."""
    from cageless.conditions import OperatingConditions
    from cageless.simulation.effects import parse_effect_overrides
    from cageless.simulation.scene import Scene

    bearing = bearing_from_config(config)
    _default_duration(args, bearing)
    _validate(args, bearing)
    bearing = scene_bearing(args, config)
    scene = Scene(conditions=OperatingConditions(args.speed_rpm, args.radial_load_n, args.axial_load_n),
                  bearing=bearing, gravity_m_s2=args.gravity, orientation=args.orientation,
                  misalignment_rad=args.misalignment_rad, moment_load_nm=args.moment_load_nm,
                  oil_air_density_kg_m3=args.oil_air_density,
                  duration_s=args.duration, speed_ramp_s=args.speed_ramp, seed=args.seed)
    from cageless.simulation.simulation import Choices, Simulation

    choices = Choices(level=args.level, effects=parse_effect_overrides(args.effect), force=args.force,
                      method=args.solver, rtol=args.rtol, max_step=args.max_step, sample_rate_hz=args.sample_rate)
    if args.explain:
        _parameters(args, config)  # the same checks of --parameter-set, --config and --set as a run
        choice = Simulation(scene, choices=choices).model  # the choice alone: nothing is built or compiled
        print(choice.to_json() if args.json else
              f"{choice.explain()}\n{_parameter_line(args, config)}\nbearing: {_bearing_line(scene.bearing)}")
        return 0
    return _run(args, scene, choices, config)


_CHECKED = ("speed_rpm", "radial_load_n", "axial_load_n", "duration", "gravity", "misalignment_rad", "moment_load_nm",
            "oil_air_density", "clearance_um", "seed", "rtol", "max_step", "restitution", "speed_ramp", "ensemble",
            "sample_rate")


def _default_duration(args: argparse.Namespace, bearing: Any) -> None:
    """Without ``--duration``: the start-up that ``compare`` leaves out plus one cage revolution, so that a
    default run can be compared (a shorter run holds no settled slip)."""
    import math

    from cageless.kinematics import startup_duration

    args.duration_default = args.duration is None
    if args.duration is not None or not (math.isfinite(args.speed_rpm) and args.speed_rpm > 0):
        return
    geometry = bearing.geometry
    startup = startup_duration(args.speed_rpm, geometry.ball_diameter_m, geometry.pitch_diameter_m)
    revolution = startup_duration(args.speed_rpm, geometry.ball_diameter_m, geometry.pitch_diameter_m,
                                  revolutions=1.0, minimum_s=0.0)
    args.duration = float(f"{startup + revolution:.3g}")


def _validate(args: argparse.Namespace, bearing: Any) -> None:
    """Every number in its range and the output path usable, before any work."""
    from cageless.outputs import check_output_file
    from cageless.validate import check_options, check_output_size

    check_options(args, _CHECKED)
    if args.explain:
        return
    check_output_size(args.duration, args.sample_rate, bearing.geometry.n_balls)
    if args.out:
        check_output_file(args.out, "-o", overwrite=args.overwrite)
    elif args.ensemble == 1:
        check_output_file(_default_out(args), "the default output",
                          overwrite=args.overwrite)


def _default_out(args: argparse.Namespace) -> str:
    """``sim_<rpm>rpm_Fr<N>.trace.h5``, with ``_Fa<N>`` under an axial load (so scenes that differ only in it
    do not replace each other's trace)."""
    axial = f"_Fa{args.axial_load_n:g}" if args.axial_load_n else ""
    return f"sim_{args.speed_rpm:g}rpm_Fr{args.radial_load_n:g}{axial}.trace.h5"


def _bearing_line(bearing: Any) -> str:
    """The bearing's name and its diametral clearance with the clearance's source."""
    from cageless.bearing import clearance_note

    return f"{bearing.name}, {clearance_note(bearing.geometry)}"


def _parameter_line(args: argparse.Namespace, config: dict[str, Any]) -> str:
    """One line naming the parameter set a run starts from and what changes it."""
    from cageless.simulation.parameter_sets import DEFAULT_SET

    name = args.parameter_set or DEFAULT_SET
    changes = [*config.get("parameters", {}), *(s.split("=", 1)[0] for s in args.set_values)]
    tail = f", changed by --config/--set: {', '.join(changes)}" if changes else ""
    return f"parameters: set '{name}'{tail}"


def _parameters(args: argparse.Namespace, config: dict[str, Any]) -> Any:
    from cageless.app.cli.common import parameter_values
    from cageless.simulation.parameters import ModelParameters

    values = parameter_values(args, config)  # [parameters] of --config, then --set
    if args.restitution is not None:
        values["restitution"] = args.restitution
    return ModelParameters().with_overrides(values)


def _run(args: argparse.Namespace, scene: Any, choices: Any, config: dict[str, Any]) -> int:
    from cageless.errors import UsageError
    from cageless.simulation.simulation import Simulation

    par = _parameters(args, config)  # validated before anything compiles
    sim = Simulation(scene, par, choices)  # the model choice, checked against the scene
    choice = sim.model
    if args.ensemble < 1:
        raise UsageError(f"--ensemble must be >= 1, got {args.ensemble}")
    out = args.out or _default_out(args)
    from cageless.app.calibrate import describe_calibration

    from cageless.simulation.parameter_sets import DEFAULT_SET

    note = describe_calibration(config.get("calibration"))
    line = _parameter_line(args, config)
    config = {"command": "simulate", "parameter_set": args.parameter_set or DEFAULT_SET, "set": args.set_values,
              **({"calibration": note} if note else {})}
    if args.scheduler and args.ensemble == 1:
        raise UsageError("--scheduler runs an ensemble on a Dask cluster: give --ensemble N as well")
    print(f"parameters: {note}" if note else line)
    if getattr(args, "duration_default", False):
        print(f"duration: {args.duration:g} s (the start-up that compare leaves out, then one cage revolution; "
              "--duration changes it)")
    inputs = [args.config] if args.config else []  # its hash joins the trace's inputs, beside its values
    if not args.quiet and not args.progress:  # with the bar, the run says it (standard error not a terminal)
        from cageless.app.lab import say_if_compiling

        say_if_compiling("simulation")
    if args.ensemble == 1:
        trace = sim.run(out=out, progress=args.progress, config=config, inputs=inputs)
        print(f"effects: {', '.join(choice.active)}")
        print(_summary_line(trace, sim.solution, out))
        return 0 if sim.solution.success else 1
    from cageless.simulation.ensemble import run_ensemble

    rows = run_ensemble(sim, args.ensemble, out, progress=args.progress, scheduler=args.scheduler, config=config,
                        inputs=inputs)
    print(f"effects: {', '.join(choice.active)}")
    for row in rows:
        print(f"seed {row['seed']}: {row['summary']}")
    return 0 if all(r["success"] for r in rows) else 1


def _summary_line(trace: Any, sol: Any, out: str) -> str:
    from cageless.profiles import PEAK_SMOOTHING_DEG
    from cageless.simulation.run import settled_peak_slip

    ev = trace.events
    peak, startup = settled_peak_slip(trace)
    if not math.isnan(peak):
        slip = (f"peak slip in the unloaded zone after {1e3 * startup:.0f} ms: {100 * peak:.2f}% "
                f"(mean profile smoothed over {PEAK_SMOOTHING_DEG:g} deg)")
    else:  # a start-up transient's peak is not a slip anyone should quote
        slip = (f"no settled slip: the run is within the {1e3 * startup:.0f} ms start-up that compare and report "
                f"leave out (simulate at least --duration {startup + 0.1:.2g})")
    # the compiled methods count their own rejections; CVODE and scipy's do not report theirs
    compiled_only = not re.search(r"CVODE|RK45|DOP853|LSODA|BDF|Radau", sol.method)
    by, uncounted = ("", "") if compiled_only else (" by DP5", "; CVODE's and scipy's own rejections are not counted")
    return (f"{trace.status} ({sol.method}): {sol.n_steps} steps, {sol.n_rejected} rejected{by} "
            f"({sol.n_onset_retries} at contact onsets, {sol.n_force_jump_retries} at force jumps; "
            f"{sol.n_contact_changes} contact changes; {sol.n_stiff_steps} at the stability edge){uncounted}, "
            f"{sol.n_rhs} RHS calls, "
            f"{trace.simulation.wall_s:.2f} s wall in the solver ({trace.simulation.total_wall_s:.2f} s in all) for "
            f"{trace.time[-1]:g} s simulated; contact episodes "
            f"{len(ev)} ({int((ev.kind == 'impact').sum())} impacts); {slip} -> {out}")
