"""cageless: track, simulate and compare the balls of cageless ball bearings.

The shared core holds the vocabulary every package uses (DESIGN §2):

* :mod:`cageless.bearing` and :mod:`cageless.parameter_sets`: the bearing, in SI units;
* :mod:`cageless.kinematics`: pure-rolling speeds, slip rate, characteristic frequencies;
* :mod:`cageless.conditions`: operating conditions and where they come from;
* :mod:`cageless.trace`: the ``cageless-trace/1`` HDF5 format;
* :mod:`cageless.errors` and :mod:`cageless.provenance`.

The app layer (:mod:`cageless.cli`) is the only place that imports
``tracking``, ``simulation`` and ``comparison``.
"""

from cageless._version import __version__
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
