"""User-facing text never points at the internal design document, which users don't have.

Help texts, messages and docstrings (the API pages of the documentation site are built from the
docstrings) are checked: the package sources must not name it at all.
"""

from __future__ import annotations

from pathlib import Path

import pytest

from cageless.app.cli import SUBCOMMANDS, main

REPO_ROOT = Path(__file__).resolve().parents[2]


def test_no_package_source_names_the_design_document():
    hits = [f"{p.relative_to(REPO_ROOT)}:{i}" for top in ("cageless", "tracking", "simulation", "comparison")
            for p in sorted((REPO_ROOT / top).rglob("*.py"))
            for i, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1) if "DESIGN" in line]
    assert hits == []


@pytest.mark.parametrize("command", SUBCOMMANDS)
def test_help_does_not_name_the_design_document(command, capsys):
    assert main([command, "--help"]) == 0
    text = capsys.readouterr().out
    assert "usage: cageless" in text and "DESIGN" not in text


@pytest.mark.parametrize("command", SUBCOMMANDS)
def test_every_option_with_a_default_states_it(command):
    """An option that has a value when it is not given says which in its help (a new user's trial found
    `simulate --orientation`, `--seed`, `--ensemble`, `--misalignment-rad`, `--moment-load-nm` and
    `calibrate --metric` silent about theirs). Counters (-v) and switches (store_true) are left out."""
    import argparse

    from cageless.app.cli import build_parser

    sub = build_parser()._subparsers._group_actions[0].choices[command]  # type: ignore[union-attr]
    silent = [a.option_strings[-1] for a in sub._actions
              if a.option_strings and a.default not in (None, False, [], argparse.SUPPRESS)
              and not isinstance(a, argparse._CountAction) and "default" not in (a.help or "")]
    assert silent == []
