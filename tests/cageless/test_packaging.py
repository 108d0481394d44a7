"""The install layout: one import name, and the import direction core <- science <- app.

The three science folders (``tracking/``, ``simulation/``, ``comparison/``) sit at the top of the
repository but install as ``cageless.tracking`` and so on, through an explicit package list in
``pyproject.toml``. A folder missing from that list would be silently left out of a wheel, so the
list is checked against the tree here.
"""
from __future__ import annotations

import ast
import tomllib
from pathlib import Path

import pytest

REPO_ROOT = Path(__file__).resolve().parents[2]
SCIENCE = ("tracking", "simulation", "comparison")


def _packages_on_disk() -> set[str]:
    found = set()
    for top in ("cageless", *SCIENCE):
        for init in (REPO_ROOT / top).rglob("__init__.py"):
            parts = init.parent.relative_to(REPO_ROOT).parts
            found.add(".".join(parts) if top == "cageless" else "cageless." + ".".join(parts))
    return found


def test_every_package_folder_is_listed_for_install():
    config = tomllib.loads((REPO_ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    listed = set(config["tool"]["setuptools"]["packages"])
    assert listed == _packages_on_disk()
    mapping = config["tool"]["setuptools"]["package-dir"]
    assert mapping == {f"cageless.{name}": name for name in SCIENCE}


def test_every_python_folder_is_a_package():
    loose = sorted(str(p.relative_to(REPO_ROOT)) for top in ("cageless", *SCIENCE)
                   for p in (REPO_ROOT / top).rglob("*.py") if not (p.parent / "__init__.py").exists())
    assert loose == []


def _imports(path: Path) -> set[str]:
    """Absolute module names imported anywhere in ``path`` (including inside functions)."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom) and node.level == 0 and node.module:
            names.add(node.module)
    return names


def _layer_of(module: str) -> str | None:
    parts = module.split(".")
    if parts[0] in SCIENCE:  # an import of the old top-level name would break after install
        return "bare-" + parts[0]
    if parts[0] != "cageless":
        return None
    if len(parts) == 1:
        return "core"
    return {"app": "app", **{s: s for s in SCIENCE}}.get(parts[1], "core")


def _files(layer: str) -> list[Path]:
    if layer in SCIENCE:
        return sorted((REPO_ROOT / layer).rglob("*.py"))
    main = REPO_ROOT / "cageless" / "__main__.py"  # ``python -m cageless`` runs the CLI: it is app
    if layer == "app":
        return sorted([*(REPO_ROOT / "cageless" / "app").rglob("*.py"), main])
    return sorted(p for p in (REPO_ROOT / "cageless").rglob("*.py")
                  if "app" not in p.relative_to(REPO_ROOT).parts and p != main)


#: What each layer may import. The core is the shared vocabulary (bearing, trace, errors, ...); the three
#: science packages use it and not each other; the app layer (CLI, lab workflow, calibration) sits on top.
ALLOWED = {
    "core": {"core"},
    "tracking": {"core", "tracking"},
    "simulation": {"core", "simulation"},
    "comparison": {"core", "comparison"},
    "app": {"core", "app", *SCIENCE},
}


@pytest.mark.parametrize("layer", sorted(ALLOWED))
def test_imports_point_down_only(layer):
    bad = []
    for path in _files(layer):
        for module in _imports(path):
            target = _layer_of(module)
            if target is not None and target not in ALLOWED[layer]:
                bad.append(f"{path.relative_to(REPO_ROOT)} imports {module}")
    assert bad == []


def test_the_science_packages_import_from_the_repository_folder_without_an_editable_install():
    """Python started in the repository's folder (docs/api.md's tour says to run it from there) finds the source
    ``cageless/`` first on its path, ahead of the installed copy. Before, ``cageless.tracking``,
    ``cageless.simulation`` and ``cageless.comparison`` then failed to import after the README's ``pip install .``
    (ModuleNotFoundError): they live beside ``cageless/`` in the checkout. Here no editable-install finder runs
    (``-S`` skips the ``.pth`` files; the dependencies come through PYTHONPATH)."""
    import os
    import subprocess
    import sys
    import sysconfig

    site = os.pathsep.join(dict.fromkeys(sysconfig.get_paths()[k] for k in ("purelib", "platlib")))
    code = ("import cageless, cageless.comparison.align, cageless.simulation.scene, cageless.tracking.io; "
            "print(cageless.simulation.scene.__file__)")
    run = subprocess.run([sys.executable, "-S", "-c", code], cwd=REPO_ROOT, capture_output=True, text=True,
                         env={**os.environ, "PYTHONPATH": site}, timeout=120)
    assert run.returncode == 0, run.stderr
    assert Path(run.stdout.strip()) == REPO_ROOT / "simulation" / "scene.py"
