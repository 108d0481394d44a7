"""Shared pieces of the command-line interface: parser, common options, logging."""

from __future__ import annotations

import argparse
from pathlib import Path
import logging
import math
import os
import re
from collections.abc import Sequence
from typing import Any, NoReturn

from cageless.errors import CagelessError, UsageError, suggest

__all__ = [
    "ArgumentParser", "common_options", "apply_config_defaults", "config_path_of", "setup_logging", "finite_float", "parameter_values",
]


class ArgumentParser(argparse.ArgumentParser):
    """An argparse parser that raises :class:`UsageError` instead of exiting.

    This keeps :func:`cageless.app.cli.main` testable in-process and lets the error
    carry a suggestion for a misspelled subcommand or option.
    """

    def error(self, message: str) -> NoReturn:  # noqa: D401 - argparse API
        m = re.search(r"argument (\S+): invalid choice: '([^']*)' \(choose from (.*)\)", message)
        if m:
            arg, given = m.group(1), m.group(2)
            choices = re.findall(r"'([^']*)'", m.group(3)) or [c.strip() for c in m.group(3).split(",")]
            hint = suggest(given, choices) or f" Choose from: {', '.join(choices)}."
            what = "unknown command" if arg == "COMMAND" else f"{arg}: invalid choice"
            message = f"{what} '{given}'.{hint}"
        raise UsageError(f"{self.prog}: {message}\nRun '{self.prog} --help' for usage.")


def finite_float(text: str) -> float:
    """argparse type: a finite float (refuses 'nan' and 'inf' with a clear message)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a number, got {text!r}") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"must be a finite number, got {text!r}")
    return value


def track_fit_value(text: str) -> int | str:
    """argparse type for ``--track-fit``: ``auto``, 1 (no track fit) or an odd number of frames >= 5."""
    if text.strip().lower() == "auto":
        return "auto"
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be 'auto' or an odd number of frames, got {text!r}") from None
    if value != 1 and (value < 5 or value % 2 == 0):
        raise argparse.ArgumentTypeError(f"must be 'auto', 1 (no track fit) or an odd number of frames >= 5, "
                                         f"got {value}")
    return value


def add_track_fit_option(parser: argparse.ArgumentParser, default: str | None) -> None:
    """Add ``--track-fit`` (each ball's angle smoothing window) to a subcommand that tracks videos."""
    parser.add_argument("--track-fit", type=track_fit_value, default=default, metavar="auto|FRAMES",
                        help="frames of the robust local quadratic each ball's angle is read from: 'auto' (default) "
                        "picks 7-41 frames per clip by cross-validation; a number fixes it (odd, >= 5; 1: raw "
                        "angles). Longer windows cut noise but blur sharp speed changes at impacts")


def common_options() -> ArgumentParser:
    """Return a parent parser with the options every subcommand has."""
    parent = ArgumentParser(add_help=False)
    group = parent.add_argument_group("common options")
    group.add_argument("--config", metavar="FILE.toml", help="read defaults and bearing overrides from a TOML file")
    group.add_argument("-q", "--quiet", action="store_true", help="no progress bars, warnings and errors only")
    group.add_argument("-v", "--verbose", action="count", default=0, help="more log output (-vv for debug)")
    return parent


def add_bearing_options(parser: argparse.ArgumentParser) -> None:
    """Add the bearing overrides of a command that simulates a scene (simulate, sweep): ``--clearance-um`` and
    ``--dry``, applied by :func:`scene_bearing` on top of ``--config``'s ``[bearing.*]`` tables."""
    parser.add_argument("--clearance-um", type=finite_float,
                        help="diametral clearance (um), races moved apart symmetrically (default: the bearing's, 0 "
                        "for the paper's; ISO 5753-1 C4 for this size is 23-41 um)")
    parser.add_argument("--dry", action="store_true", help="no lubricant")


def scene_bearing(args: argparse.Namespace, config: dict[str, Any]) -> Any:
    """The bearing a simulating command runs: the configured one (``--config``'s ``[bearing.*]``), dry with
    ``--dry``, with ``--clearance-um``'s clearance (:meth:`cageless.bearing.Bearing.with_overrides`, so its name
    records the change)."""
    import dataclasses

    from cageless.bearing import CLEARANCE_NAME, derived_name
    from cageless.config import bearing_from_config

    bearing = bearing_from_config(config)
    if args.dry and bearing.lubricant is not None:
        bearing = dataclasses.replace(bearing, lubricant=None, name=derived_name(bearing.name, {"lubricant": "none"}))
    if args.clearance_um is not None:
        bearing = bearing.with_overrides({CLEARANCE_NAME: 1e-6 * args.clearance_um})
    return bearing


def add_parameter_set_option(parser: ArgumentParser) -> None:
    """Add ``--parameter-set`` to a command that simulates (simulate, sweep, report, calibrate)."""
    parser.add_argument("--parameter-set", metavar="NAME",
                        help="named model parameter set to start from: paper-table2 (default; calibrated at 3000 rpm, "
                        "500 N against the paper's measured slip) or representative (the earlier, uncalibrated values)")


def config_path_of(argv: Sequence[str]) -> str | None:
    """The value of ``--config`` in ``argv`` (``--config F`` or ``--config=F``), if given."""
    for i, word in enumerate(argv):
        if word == "--config" and i + 1 < len(argv):
            return argv[i + 1]
        if word.startswith("--config="):
            return word.split("=", 1)[1]
    return None


def apply_config_defaults(parser: argparse.ArgumentParser, command: str, path: str | None) -> dict[str, Any]:
    """Make the ``[command]`` table of the ``--config`` file ``path`` the defaults of ``command``'s options,
    before the command line is parsed (so a file entry also satisfies a required option; the command line
    wins). Returns the whole configuration (empty without ``--config``).
    """
    if not path:
        return {}
    from cageless.config import load_config  # imported here: ``--version``/``--help`` do not need it

    config = load_config(path)
    _check_config_tables(config, path)
    table = config.get(command, {})
    sub = parser._subparsers._group_actions[0].choices[command]  # type: ignore[union-attr]
    actions = {a.dest: a for a in sub._actions if a.dest not in ("help", "config")}
    defaults = {}
    for key, value in table.items():
        dest = key.replace("-", "_")
        if dest not in actions:
            raise UsageError(f"--config {path}: [{command}] has unknown option '{key}'." + suggest(dest, actions))
        defaults[dest] = _config_value(actions[dest], value, f"--config {path}: [{command}] {key}")
        actions[dest].required = False  # the file gives it
    sub.set_defaults(**defaults)
    return config


#: Top-level tables of a configuration file besides one per command.
CONFIG_TABLES = ("bearing", "parameters", "calibration")


def _check_config_tables(config: dict[str, Any], path: str) -> None:
    """Refuse an unknown top-level table or key (a misspelt ``[reprot]`` would otherwise be ignored) and a
    ``[bearing]`` table that does not make a bearing, naming the file."""
    from cageless.app.cli import SUBCOMMANDS
    from cageless.config import bearing_from_config

    known = (*SUBCOMMANDS, *CONFIG_TABLES)
    for key, value in config.items():
        if key not in known:
            what = "table" if isinstance(value, dict) else "key"
            raise UsageError(f"--config {path}: unknown {what} '{key}' (a file holds [bearing.*], [parameters], "
                             f"[calibration] and one table per command)." + suggest(key, known))
        if key in SUBCOMMANDS and not isinstance(value, dict):
            raise UsageError(f"--config {path}: '{key}' must be a table ([{key}]).")
    try:
        bearing_from_config(config)
    except CagelessError as exc:
        raise UsageError(f"--config {path}: {exc}") from None


def _config_value(action: argparse.Action, value: Any, where: str) -> Any:
    """A ``--config`` entry checked and converted as its command-line option would be, its error naming the file
    and the entry (argparse would blame the command-line option the user never typed)."""
    if isinstance(action, argparse._StoreConstAction | argparse._StoreTrueAction | argparse._StoreFalseAction):
        if not isinstance(value, bool):
            raise UsageError(f"{where} = {value!r}: must be true or false.")
        return value
    if isinstance(action, argparse._AppendAction):
        if not isinstance(value, list):
            raise UsageError(f"{where} = {value!r}: must be a list, e.g. [\"a\", \"b\"].")
        return [_config_value(argparse.Action([], action.dest, type=action.type, choices=action.choices), v, where)
                for v in value]
    if value is None or isinstance(value, bool | dict | list):
        raise UsageError(f"{where} = {value!r}: must be a single value.")
    if action.type is not None:
        try:
            value = action.type(value if isinstance(value, str) else str(value))
        except (argparse.ArgumentTypeError, TypeError, ValueError) as exc:
            raise UsageError(f"{where} = {value!r}: {str(exc).rstrip('.') or 'invalid value'}.") from None
    if action.choices is not None and value not in action.choices:
        raise UsageError(f"{where} = {value!r}: must be one of {', '.join(map(str, action.choices))}.")
    return value


def setup_logging(quiet: bool, verbose: int) -> None:
    """Configure the root logger for the CLI."""
    level = logging.WARNING if quiet or verbose == 0 else (logging.INFO if verbose == 1 else logging.DEBUG)
    logging.basicConfig(level=level, format="%(levelname)s: %(message)s", force=True)


def parameter_values(args: argparse.Namespace, config: dict[str, Any]) -> dict[str, Any]:
    """The model-parameter changes of a run: the named ``--parameter-set``, then the ``[parameters]`` table of
    ``--config`` (e.g. a file written by ``cageless calibrate``), then ``--set`` on the command line, which wins. Checked by name
    and value; a bad file entry names the file."""
    from cageless.errors import CagelessError, ParameterError
    from cageless.simulation.parameters import ModelParameters, parse_set_overrides

    table = config.get("parameters", {})
    if not isinstance(table, dict) or any(isinstance(v, bool) or not isinstance(v, int | float)
                                          for v in table.values()):
        raise UsageError(f"--config {args.config}: [parameters] must hold name = number entries "
                         "(e.g. cho_n_s_m = 2500)")
    try:
        ModelParameters().with_overrides(table)
    except CagelessError as exc:
        raise UsageError(f"--config {args.config}: [parameters]: {exc}") from None
    named = getattr(args, "parameter_set", None)
    if named is not None:
        from cageless.simulation.parameter_sets import set_values

        named = set_values(named)
    given = parse_set_overrides(getattr(args, "set_values", []))
    values = {**(named or {}), **table, **given}
    try:
        ModelParameters().with_overrides(values)
    except ParameterError as exc:
        raise UsageError(_parameter_error_text(exc, given, table, args)) from None
    return values


def _parameter_error_text(exc: Any, given: dict[str, Any], table: dict[str, Any], args: argparse.Namespace) -> str:
    """A model-parameter error named by where the user gave the value: ``--set``, the ``--config`` file, or
    the parameter set; a rule between two parameters names the one given and the one to give as well."""
    if not exc.parameter.startswith("parameters."):
        return str(exc)
    name = exc.parameter.removeprefix("parameters.")
    shown = "" if exc.value is None else f"={exc.value:g}" if isinstance(exc.value, float) else f"={exc.value}"
    if name in given:
        return f"--set {name}{shown}: {exc.rule}. {exc.hint}".rstrip()
    if name in table:
        return f"--config {args.config}: [parameters] {name}{shown}: {exc.rule}. {exc.hint}".rstrip()
    other = next((n for n in given if n in exc.rule), None)
    if other is not None:
        return (f"--set {other}={given[other]}: {name}{shown} {exc.rule}; set {name} as well "
                f"(--set {name}=...).")
    named = getattr(args, "parameter_set", None)
    source = f"--parameter-set {named}" if named else "the default parameter set"
    return f"{source}: {name}{shown}: {exc.rule}. {exc.hint}".rstrip()


def check_window(window: int | None) -> None:
    """Refuse a ``--window`` (the Savitzky-Golay speed window, frames) that is even or below 3; ``None``: not given."""
    if window is not None and (window < 3 or window % 2 == 0):
        raise UsageError(f"--window {window}: must be an odd number of frames >= 3.")


def check_n_balls(n_balls: int | None, config: dict[str, Any]) -> None:
    """Refuse a ``--n-balls`` below 3 or above what fits on the configured bearing's pitch circle.

    Raises
    ------
    UsageError
        Naming the option, the limit and why.
    """
    if n_balls is None:
        return
    if n_balls < 3:
        raise UsageError(f"--n-balls {n_balls}: must be a whole number >= 3.")
    from cageless.config import bearing_from_config

    g = bearing_from_config(config).geometry
    if n_balls > g.max_ball_count:
        raise UsageError(f"--n-balls {n_balls}: at most {g.max_ball_count} balls of {g.ball_diameter_m * 1e3:.4g} mm "
                         f"fit on the bearing's {g.pitch_diameter_m * 1e3:.4g} mm pitch circle. Give the count the "
                         "videos show, or describe their bearing (n_balls, ball_diameter_mm, pitch_diameter_mm in a "
                         "sidecar or --config).")


def failed_line(video: Path | str, why: object, shown: Path | str | None = None) -> str:
    """``FAILED <video>: <why>``, naming the video once even when the message starts with its file name or a
    path to it (an absolute one may hold spaces); ``shown`` is how the video is named on the line (default:
    as given)."""
    text = str(why)
    head = f"{Path(video).name}: "
    cut = text.find(head)
    # the name, or a path to it: absolute (spaces and all), or relative without spaces (not a sentence)
    if cut == 0 or (cut > 0 and text[cut - 1] in "/\\" and (os.path.isabs(text[:cut]) or " " not in text[:cut])):
        text = text[cut + len(head):]
    return f"FAILED {shown if shown is not None else video}: {text}"
