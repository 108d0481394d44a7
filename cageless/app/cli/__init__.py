"""The ``cageless`` command line: one console script with subcommands.

Each subcommand lives in its own module exposing ``register(subparsers, parent)``
and ``run(args, config) -> int``; :data:`SUBCOMMANDS` lists them in help order and
:data:`SUMMARIES` gives each one's help line.

Start-up is lazy: a subcommand's module (and with it numpy, pandas, numba, ...) is
imported only when that subcommand is named, so ``cageless --version`` and
``cageless --help`` import none of them.

Exit codes: 0 success, 1 some inputs failed (the rest done), 2 usage error.
"""

from __future__ import annotations

import argparse
import importlib
import logging
import sys
from collections.abc import Sequence
from contextlib import AbstractContextManager, nullcontext
from pathlib import Path
from typing import Any

from cageless._version import __version__
from cageless.app.cli.common import (ArgumentParser, apply_config_defaults, common_options, config_path_of,
                                     setup_logging)
from cageless.errors import CagelessError, ParameterError, UsageError

__all__ = ["main", "entry_point", "build_parser", "SUBCOMMANDS"]

SUBCOMMANDS: tuple[str, ...] = ("info", "track", "simulate", "compare", "report", "sweep", "calibrate", "sample", "bench")

#: The one-line help of each subcommand, listed by ``cageless --help`` without importing its module
#: (each module's ``register`` uses the same line; a test checks that they agree).
SUMMARIES: dict[str, str] = {
    "info": "show the bearing, its kinematics and characteristic frequencies",
    "track": "track the balls in videos and write trace files",
    "simulate": "simulate the bearing for a scene (--explain: the model and effects it calls for, and why)",
    "compare": "compare a measured and a simulated trace (one Table-2 row)",
    "report": "lab folder -> traces, simulations, slip table and report.html",
    "sweep": "a scene over a parameter grid and seeds: peak slip table and plot",
    "calibrate": "fit open model parameters to a measured slip profile or peak slip",
    "sample": "render synthetic bearing videos with known ground truth",
    "bench": "accuracy-versus-time studies (tables)",
}

EXIT_OK, EXIT_FAILED, EXIT_USAGE = 0, 1, 2

log = logging.getLogger("cageless")

_EPILOG = """\
examples:
  cageless info                       the default bearing and its kinematics at 3000 rpm
  cageless info --speed-rpm 6000 --json
  cageless info clip.cine             what the reader sees in a video
  cageless sample my_lab              render synthetic videos with ground truth
  cageless COMMAND --help             help and examples for one command

exit codes: 0 success, 1 some inputs failed (the rest done), 2 usage error
"""


def build_parser(command: str | None = None) -> ArgumentParser:
    """Build the top-level parser.

    Parameters
    ----------
    command
        Register only this subcommand in full (importing its module); the others are listed by
        name and help line. ``None`` (the default) registers every subcommand in full.
    """
    parser = ArgumentParser(
        prog="cageless",
        description="Track, simulate and compare the balls of cageless ball bearings.",
        epilog=_EPILOG,
        formatter_class=__import__("argparse").RawDescriptionHelpFormatter,
    )
    parser.add_argument("--version", action="version", version=f"cageless {__version__}")
    subparsers = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=ArgumentParser)
    parent = common_options()
    for name in SUBCOMMANDS:
        if command is None or name == command:
            importlib.import_module(f"cageless.app.cli.{name}").register(subparsers, parent)
        else:
            subparsers.add_parser(name, help=SUMMARIES[name], add_help=False)
    return parser


def _command_of(argv: Sequence[str]) -> str | None:
    """The subcommand named in ``argv`` (the first word that is not an option), if it is a known one."""
    for word in argv:
        if not word.startswith("-"):
            return word if word in SUMMARIES else None
    return None


def _check_scheduler(args: argparse.Namespace) -> None:
    """``--scheduler`` needs Dask's ``distributed``: refuse before any work (and any output folder) if missing."""
    if getattr(args, "scheduler", None):
        try:
            importlib.import_module("distributed")
        except ImportError:
            raise UsageError(f"--scheduler {args.scheduler}: needs Dask's distributed package, which is not "
                             "installed. Install it with `pip install 'cageless[dask]'`, or leave out "
                             "--scheduler to run on this machine.") from None


def _parse(parser: ArgumentParser, argv: Sequence[str]) -> argparse.Namespace:
    """Parse ``argv``; an unknown option is refused in the name of the subcommand it was given to, with
    that subcommand's closest option as a hint (argparse itself names only the top-level program)."""
    from cageless.errors import suggest

    args, extra = parser.parse_known_args(argv)
    if not extra:
        return args
    prog = parser.prog
    options: list[str] = []
    if args.command is not None:
        sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction)).choices[args.command]
        prog = sub.prog
        options = [o for a in sub._actions for o in a.option_strings]
    first = next((w.split("=", 1)[0] for w in extra if w.startswith("-")), "")
    hint = suggest(first, options) if first else ""
    raise UsageError(f"{prog}: unrecognized arguments: {' '.join(extra)}.{hint}\nRun '{prog} --help' for usage.")


def _on_terminal(stream: object) -> bool:
    """True when ``stream`` is a terminal: progress bars are drawn only there. In a log file or a pipe each
    redraw (at every ``ok``/``FAILED`` line) would be one more copy of the bar's last state."""
    try:
        return bool(stream.isatty())  # type: ignore[attr-defined]
    except (AttributeError, ValueError):  # no isatty, or a closed stream
        return False


def main(argv: Sequence[str] | None = None) -> int:
    """Run the CLI in-process and return its exit code.

    Parameters
    ----------
    argv
        Arguments without the program name; ``None`` means ``sys.argv[1:]``.

    Returns
    -------
    int
        0 on success, 1 if some inputs failed, 2 on a usage error.
    """
    argv = list(sys.argv[1:] if argv is None else argv)
    command = _command_of(argv)
    parser = build_parser(command or "")  # "" registers no subcommand in full
    try:
        config = apply_config_defaults(parser, command, config_path_of(argv)) if command else {}
        args = _parse(parser, argv)
        if args.command is None:
            parser.print_help()
            return EXIT_USAGE
        setup_logging(args.quiet, args.verbose)
        args.progress = not args.quiet and _on_terminal(sys.stderr)
        _check_scheduler(args)
        module = importlib.import_module(f"cageless.app.cli.{args.command}")
        with _under_bars(args.progress):
            return int(module.run(args, config))
    except SystemExit as exc:  # --help and --version exit through argparse
        return int(exc.code or 0) if isinstance(exc.code, int | None) else EXIT_USAGE
    except (UsageError, ParameterError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return EXIT_USAGE
    except CagelessError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return EXIT_FAILED
    except BrokenPipeError:  # the reader went away (`cageless info --json | head`): stop quietly, as Unix tools do
        import os

        try:  # no second error when Python flushes standard output at exit
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        except (OSError, ValueError, AttributeError):
            pass
        return 141
    except KeyboardInterrupt:
        print("error: interrupted; outputs that were complete are kept, nothing partial is left "
              "(a report re-run skips the finished jobs).", file=sys.stderr)
        return 130
    except Exception as exc:  # noqa: BLE001 - the last line of defence: one line, never a bare traceback
        return _unexpected(exc, argv)


def _under_bars(progress: bool) -> AbstractContextManager[Any]:
    """With progress bars on, log records printed under them, not through them (tqdm's redirect); without, as
    they are (tqdm, 0.03-0.07 s of CPU to import, is then not imported)."""
    if not progress:
        return nullcontext()
    from tqdm.contrib.logging import logging_redirect_tqdm

    return logging_redirect_tqdm()


def _unexpected(exc: BaseException, argv: Sequence[str]) -> int:
    """Report an unexpected exception in one line; keep the traceback in a log file (and show it with -v)."""
    import errno
    import traceback

    text = "".join(traceback.format_exception(exc))
    if isinstance(exc, OSError) and exc.errno in (errno.ENOSPC, errno.EDQUOT):
        where = exc.filename or "the output folder"
        print(f"error: no space left on {where}. Free some space and re-run.", file=sys.stderr)
        return EXIT_FAILED
    if isinstance(exc, MemoryError):
        print(f"error: out of memory ({exc}). Lower the sizes asked for (duration, sample rate, workers).",
              file=sys.stderr)
        return EXIT_FAILED
    log_path = _write_crash_log(text, argv)
    where = f"details in {log_path}" if log_path else "no log file could be written"
    print(f"error: unexpected {type(exc).__name__}: {str(exc).splitlines()[0] if str(exc) else ''} ({where}; "
          "run with -v for the traceback).", file=sys.stderr)
    if "-v" in argv or "--verbose" in argv or any(a.startswith("-vv") for a in argv):
        print(text, file=sys.stderr, end="")
    return EXIT_FAILED


def _write_crash_log(text: str, argv: Sequence[str]) -> str | None:
    import os
    import tempfile
    from datetime import UTC, datetime

    stamp = datetime.now(UTC).strftime("%Y%m%dT%H%M%SZ")
    body = f"cageless {__version__}\nargs: {' '.join(argv)}\n\n{text}"
    from cageless.provenance import cache_dir

    for folder in (cache_dir() / "logs", Path(tempfile.gettempdir())):
        path = folder / f"cageless-error-{stamp}-{os.getpid()}.log"
        try:
            folder.mkdir(parents=True, exist_ok=True)
            path.write_text(body)
            return str(path)
        except OSError:
            continue
    return None


def _terminated(signum: int, frame: object) -> None:
    """``kill -TERM`` stops a run the way Ctrl-C does: workers ended, nothing partial left."""
    raise KeyboardInterrupt


def entry_point() -> None:
    """Console-script entry: exit with :func:`main`'s code.

    Before exiting, every object is moved out of the garbage collector's generations (:func:`gc.freeze`): the
    interpreter's teardown then frees them by reference counting alone, without the collector's passes over
    numba's, SciPy's and pandas' many objects (0.2-0.4 s of CPU after a ``cageless track``; finalisers still run,
    open files are closed as before).
    """
    import gc
    import signal

    signal.signal(signal.SIGTERM, _terminated)
    code = main()
    gc.freeze()
    sys.exit(code)
