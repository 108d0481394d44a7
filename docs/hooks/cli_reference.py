"""MkDocs hook: fill the command-line reference from the real argument parsers.

A page containing the marker ``<!-- cli-reference -->`` gets, in its place, the ``--help``
text of ``cageless`` and of every subcommand, so the reference cannot drift from the code.
"""

from __future__ import annotations

import argparse
import os
from typing import Any

MARKER = "<!-- cli-reference -->"


def _help(parser: argparse.ArgumentParser) -> str:
    os.environ.setdefault("COLUMNS", "100")
    return parser.format_help().rstrip()


def _reference() -> str:
    from cageless.app.cli import SUBCOMMANDS, build_parser

    parser = build_parser()
    parts = ["## cageless", "", "```text", _help(parser), "```", ""]
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    for name in SUBCOMMANDS:
        parts += [f"## cageless {name}", "", "```text", _help(sub.choices[name]), "```", ""]
    return "\n".join(parts)


def on_page_markdown(markdown: str, page: Any, **_: Any) -> str:
    """Replace the marker with the generated reference."""
    if MARKER not in markdown:
        return markdown
    return markdown.replace(MARKER, _reference())
