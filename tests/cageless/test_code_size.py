"""The size limits of the project's code: every file under 600 lines and every function under 60.

Long files and functions are where a reader loses the thread; the limits are the project's standard. The
check reads the source with :mod:`ast`, so a function's length runs from its ``def`` line to its last line,
docstring included. :data:`ALLOWED` lists the few functions known to be over the limit, each with the length
it may not grow past, until they are split.
"""

from __future__ import annotations

import ast
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parents[2]
#: The folders checked: the four packages and the tests (benchmark scripts are not part of the package).
FOLDERS = ("cageless", "tracking", "simulation", "comparison", "tests")
MAX_FILE_LINES = 600
MAX_FUNCTION_LINES = 60
#: (file, function) -> the most lines it may have while it waits to be split.
ALLOWED = {
    ("tracking/kinematics.py", "robust_track_fit"): 61,
}


def _sources() -> list[Path]:
    return sorted(p for folder in FOLDERS for p in (REPO_ROOT / folder).rglob("*.py"))


def long_functions(path: Path) -> list[tuple[str, int]]:
    """(name, lines) of every function or method in ``path`` longer than :data:`MAX_FUNCTION_LINES`."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    return [(node.name, node.end_lineno - node.lineno + 1) for node in ast.walk(tree)
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef)
            and node.end_lineno - node.lineno + 1 > MAX_FUNCTION_LINES]


def test_the_checker_sees_the_sources():
    names = {p.relative_to(REPO_ROOT).as_posix() for p in _sources()}
    assert {"tracking/detect.py", "simulation/solve.py", "cageless/bearing.py", "tests/conftest.py"} <= names
    assert len(names) > 200


def test_every_file_is_under_600_lines():
    long = {p.relative_to(REPO_ROOT).as_posix(): n for p in _sources()
            if (n := p.read_text(encoding="utf-8").count("\n")) > MAX_FILE_LINES}
    assert long == {}


def test_every_function_is_under_60_lines():
    over = {}
    for path in _sources():
        rel = path.relative_to(REPO_ROOT).as_posix()
        for name, n in long_functions(path):
            if n > ALLOWED.get((rel, name), MAX_FUNCTION_LINES):
                over[f"{rel}:{name}"] = n
    assert over == {}
