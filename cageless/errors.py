"""Domain exceptions shared by every cageless package.

Every error says *what* is wrong (the parameter, field or file), *which rule*
was broken and, where possible, *how to fix it*. The CLI maps
:class:`UsageError` to exit code 2 and every other :class:`CagelessError` to
exit code 1.
"""

from __future__ import annotations

import difflib
from collections.abc import Iterable
from pathlib import Path

__all__ = [
    "CagelessError",
    "ParameterError",
    "GeometryError",
    "ConditionsError",
    "TraceFormatError",
    "VideoError",
    "TrackingError",
    "SolverError",
    "UsageError",
    "suggest",
    "is_trace_name",
    "trace_not_video",
]


def suggest(name: str, choices: Iterable[str]) -> str:
    """Return a ``" Did you mean 'x'?"`` hint for a misspelled name, or ``""``.

    Parameters
    ----------
    name
        The name the user gave.
    choices
        The valid names.

    Returns
    -------
    str
        A sentence with the closest valid names, or an empty string.
    """
    close = difflib.get_close_matches(name, list(choices), n=3, cutoff=0.6)
    if not close:
        return ""
    quoted = " or ".join(f"'{c}'" for c in close)
    return f" Did you mean {quoted}?"


class CagelessError(Exception):
    """Base class of every error cageless raises on purpose."""


class ParameterError(CagelessError, ValueError):
    """A parameter value breaks a rule.

    Parameters
    ----------
    parameter
        Dotted name of the offending parameter, e.g. ``"geometry.ball_diameter_m"``.
    rule
        The rule that was broken, in words.
    value
        The offending value, if there is one.
    hint
        How to fix it.
    """

    def __init__(self, parameter: str, rule: str, value: object = None, hint: str = "") -> None:
        self.parameter = parameter
        self.rule = rule
        self.value = value
        self.hint = hint
        shown = "" if value is None else f" = {value!r}"
        head, sep, tail = rule.partition(" Did you mean")  # a suggestion appended to the rule is a sentence
        if sep:
            rule = f"{head.rstrip('.;')}.{sep}{tail}"
        text = f"{parameter}{shown}: {rule}{'' if rule.endswith(('.', '?')) else '.'}"
        if hint:
            text += f" {hint}"
        super().__init__(text)


class GeometryError(ParameterError):
    """The bearing geometry is impossible (balls do not fit, f <= 0.5, ...)."""


class _PathError(CagelessError):
    """An error tied to one file."""

    def __init__(self, path: str | Path, message: str, hint: str = "") -> None:
        self.path = Path(path)
        self.message = message
        self.hint = hint
        text = f"{self.path}: {message}"
        if hint:
            text += f" {hint}"
        super().__init__(text)


class ConditionsError(_PathError):
    """The operating conditions of one video are missing or malformed."""


class MissingConditionsError(ConditionsError):
    """No source (sidecar, ``conditions.csv``, file name) gives a video's operating conditions."""


class TraceFormatError(_PathError):
    """A trace file is missing, malformed, or of an unsupported schema."""


class VideoError(_PathError):
    """A video cannot be read: truncated, corrupt, or of an unsupported kind.

    Parameters
    ----------
    path
        The video file.
    message
        What is wrong.
    offset
        Byte offset in the file where the problem was found, if known.
    hint
        How to fix it.
    """

    def __init__(
        self, path: str | Path, message: str, offset: int | None = None, hint: str = ""
    ) -> None:
        self.offset = offset
        if offset is not None:
            end = "." if message.endswith(".") else ""
            message = f"{message.removesuffix('.')} (at byte offset {offset}){end}"
        super().__init__(path, message, hint)


class TrackingError(_PathError):
    """A video was read but could not be tracked (no bearing in view, too short, wrong ball count...)."""


class SolverError(CagelessError):
    """A numerical solve failed (no convergence, non-finite state)."""


class UsageError(CagelessError):
    """The command line or a configuration file was used wrongly (exit code 2)."""


def is_trace_name(path: str | Path) -> bool:
    """True for a path named like a cageless trace (``*.trace.h5``, any case)."""
    return Path(path).name.lower().endswith(".trace.h5")


def trace_not_video(path: str | Path) -> VideoError:
    """The error for a trace given where a video belongs, saying what to do with a trace instead."""
    return VideoError(path, "is a trace, not a video.",
                      hint="Compare it with a simulated trace (`cageless compare VIDEO_TRACE SIM_TRACE`), or give "
                      "`cageless report` the lab folder of videos it came from; read it in Python with "
                      "cageless.trace.read_trace.")
