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
