"""The documentation site builds without warnings, and its tutorial runs as written.

The tutorial (``docs/tutorial.md``) is executed command by command: every ``$ cageless …`` line of
its console blocks and every Python block, in a scratch folder that sees the bundled sample lab. So the
page a new user follows cannot drift from what the tool does.
"""

from __future__ import annotations

import importlib.util
import os
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

REPO_ROOT = Path(__file__).resolve().parents[2]
DOCS = REPO_ROOT / "docs"


def _blocks(text: str, lang: str) -> list[str]:
    return re.findall(rf"```{lang}\n(.*?)```", text, flags=re.S)


def tutorial_commands() -> list[list[str]]:
    """The ``$ cageless …`` lines of the tutorial's console blocks, as argument lists."""
    text = (DOCS / "tutorial.md").read_text(encoding="utf-8")
    lines = [ln for block in _blocks(text, "console") for ln in block.splitlines()]
    return [shlex.split(ln[2:])[1:] for ln in lines if ln.startswith("$ cageless")]


@pytest.mark.skipif(importlib.util.find_spec("mkdocs") is None, reason="mkdocs is not installed (the test extra has it)")
def test_docs_build_strict(tmp_path):
    env = {**os.environ, "NO_MKDOCS_2_WARNING": "1"}
    run = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "-q", "-d", str(tmp_path / "site")],
                         cwd=REPO_ROOT, capture_output=True, text=True, env=env, timeout=600)
    assert run.returncode == 0, run.stdout + run.stderr
    cli = (tmp_path / "site" / "cli" / "index.html").read_text(encoding="utf-8")
    for name in ("track", "simulate", "compare", "report", "sweep", "sample", "bench", "info"):
        assert f"cageless {name}" in cli  # the generated reference covers every subcommand


def test_tutorial_runs_as_written(tmp_path):
    commands = tutorial_commands()
    assert [c[0] for c in commands] == ["info", "track", "simulate", "compare", "report"]
    (tmp_path / "sample_data").symlink_to(REPO_ROOT / "sample_data")
    for argv in commands:
        run = subprocess.run([sys.executable, "-m", "cageless", *argv, "--quiet"], cwd=tmp_path,
                             capture_output=True, text=True, timeout=900)
        assert run.returncode == 0, f"cageless {' '.join(argv)}: {run.stdout}{run.stderr}"
        assert "Traceback" not in run.stderr
    assert (tmp_path / "quick" / "report.html").is_file()
    text = (DOCS / "tutorial.md").read_text(encoding="utf-8")
    for block in _blocks(text, "python"):
        subprocess.run([sys.executable, "-c", block], cwd=tmp_path, check=True, timeout=120)


def test_api_tour_runs_as_written(tmp_path):
    """docs/api.md's quick tour runs from a folder that sees the sample lab: the 6000 rpm clip has 14 balls in
    84 frames (sample_data/lab/README.md) and its simulated run succeeds."""
    blocks = _blocks((DOCS / "api.md").read_text(encoding="utf-8"), "python")
    assert len(blocks) == 1
    (tmp_path / "sample_data").symlink_to(REPO_ROOT / "sample_data")
    run = subprocess.run([sys.executable, "-c", blocks[0]], cwd=tmp_path, capture_output=True, text=True,
                         timeout=900)
    assert run.returncode == 0, run.stdout + run.stderr
    lines = run.stdout.splitlines()
    assert lines[0] == "14 (84, 14)"
    assert lines[-2].startswith("True (")
    assert re.fullmatch(r"\d+\.\d\d % simulated, \d+\.\d\d % measured, MAE \d+\.\d\d pp", lines[-1])
