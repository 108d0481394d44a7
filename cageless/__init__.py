"""cageless: track, simulate and compare the balls of cageless ball bearings.

The shared core holds the vocabulary every package uses:

* :mod:`cageless.bearing` and :mod:`cageless.parameter_sets`: the bearing, in SI units;
* :mod:`cageless.kinematics`: pure-rolling speeds, slip rate, characteristic frequencies;
* :mod:`cageless.conditions`: operating conditions and where they come from;
* :mod:`cageless.trace`: the ``cageless-trace/1`` HDF5 format;
* :mod:`cageless.errors` and :mod:`cageless.provenance`.

The app layer (:mod:`cageless.app.cli`) is the only place that imports
``tracking``, ``simulation`` and ``comparison``.
"""

from __future__ import annotations

import importlib
from pathlib import Path
from typing import TYPE_CHECKING, Any

from cageless._version import __version__

_HERE = Path(__file__).resolve().parent
_SCIENCE = ("tracking", "simulation", "comparison")
if not (_HERE / "tracking").is_dir() and all((_HERE.parent / n / "__init__.py").is_file() for n in _SCIENCE):
    # Imported from a source checkout (Python run in the repository's folder puts its cageless/ first on the
    # path, ahead of an installed copy): tracking/, simulation/ and comparison/ sit beside it there, and this
    # makes them cageless.tracking and so on, as an install (pyproject.toml's package-dir) does.
    __path__.append(str(_HERE.parent))

if TYPE_CHECKING:  # pragma: no cover - for type checkers only
    from cageless.bearing import Bearing, Geometry, Lubricant, Masses, Material, default_bearing
    from cageless.conditions import OperatingConditions
    from cageless.trace import Trace, read_trace, write_trace

__all__ = [
    "__version__",
    "Bearing",
    "Geometry",
    "Lubricant",
    "Masses",
    "Material",
    "OperatingConditions",
    "Trace",
    "default_bearing",
    "read_trace",
    "write_trace",
]

#: Public names and the module that defines each. They are imported on first use (PEP 562), so that
#: ``import cageless`` (and ``cageless --version``) does not pull in pandas, h5py or numpy.
_LAZY = {
    "Bearing": "cageless.bearing", "Geometry": "cageless.bearing", "Lubricant": "cageless.bearing",
    "Masses": "cageless.bearing", "Material": "cageless.bearing", "default_bearing": "cageless.bearing",
    "OperatingConditions": "cageless.conditions",
    "Trace": "cageless.trace", "read_trace": "cageless.trace", "write_trace": "cageless.trace",
}


def __getattr__(name: str) -> Any:
    module = _LAZY.get(name)
    if module is None:
        raise AttributeError(f"module 'cageless' has no attribute {name!r}")
    value = getattr(importlib.import_module(module), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
