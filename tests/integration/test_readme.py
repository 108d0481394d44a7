"""The README's two set-up commands are present and the CI script runs the test one."""

from __future__ import annotations

import re

from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parents[2]


def _marked(marker: str) -> str:
    text = (REPO_ROOT / "README.md").read_text(encoding="utf-8")
    m = re.search(rf"<!-- {marker} -->\n```bash\n(.+)\n```", text)
    assert m, f"README.md lacks the <!-- {marker} --> block"
    return m.group(1)


def test_readme_has_both_commands():
    assert _marked("main-command").startswith("python3 -m venv .venv")
    assert _marked("main-command").endswith("cageless report sample_data/lab -o report")
    assert re.search(r"python -m pytest( |$)", _marked("test-command"))


def test_ci_reads_the_readme_test_command():
    ci = (REPO_ROOT / ".ci" / "run").read_text(encoding="utf-8")
    assert "<!-- test-command -->" in ci and 'bash -euo pipefail -c "$cmd"' in ci
