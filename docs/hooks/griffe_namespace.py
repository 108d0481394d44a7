"""A griffe extension that shows the science packages under their installed names.

``tracking/``, ``simulation/`` and ``comparison/`` are top-level folders of the repository that
install as ``cageless.tracking`` and so on (``[tool.setuptools.package-dir]`` in pyproject.toml).
Static analysis finds ``cageless/`` on disk and no ``tracking`` inside it, so this extension loads
each folder and attaches it to the ``cageless`` package, where the API pages look for it.
"""
from __future__ import annotations

from typing import Any

import griffe

SCIENCE = ("tracking", "simulation", "comparison")


class InstalledNamespace(griffe.Extension):
    """Attach ``tracking``, ``simulation`` and ``comparison`` as members of ``cageless``."""

    def on_package(self, *, pkg: griffe.Module, loader: griffe.GriffeLoader, **kwargs: Any) -> None:
        if pkg.name != "cageless":
            return
        for name in SCIENCE:
            module = loader.load(name)
            pkg.set_member(name, module)

    on_package_loaded = on_package  # the name of this hook in griffe 1.x
