"""Named slots of a model's compiled parameter vector.

The compiled kernels take their parameters as one float array (numba compiles and caches one variant
for it). Which number sits where is decided here, once, from names: a model's own body slots (its
geometry, masses and drive), then, for every row of the effects table
(:data:`cageless.simulation.effects.EFFECTS`), the effect's on/off flag and the slots of the parameters its
unit reads. A model reads a slot through a module-level integer constant taken from its layout
(``P_KO = LAYOUT.index("KO")``), which numba freezes into the compiled code as a literal, so a named
slot costs nothing at run time. Code outside a model reads a value by name
(:meth:`cageless.simulation.problem.Problem.parameter`), never by position.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping

import numpy as np
import numpy.typing as npt

__all__ = ["ParameterLayout"]


class ParameterLayout:
    """An ordered set of slot names; slot ``i`` of the parameter vector holds ``names[i]``."""

    def __init__(self, names: Iterable[str]) -> None:
        self.names = tuple(names)
        self._index = {n: i for i, n in enumerate(self.names)}
        if len(self._index) != len(self.names):
            dup = sorted({n for n in self.names if self.names.count(n) > 1})
            raise ValueError(f"parameter slots named twice: {', '.join(dup)}")

    def __len__(self) -> int:
        return len(self.names)

    def __contains__(self, name: object) -> bool:
        return name in self._index

    def __repr__(self) -> str:
        return f"ParameterLayout({len(self)} slots: {', '.join(self.names)})"

    def index(self, name: str) -> int:
        """Position of slot ``name``."""
        try:
            return self._index[name]
        except KeyError:
            raise KeyError(f"no parameter slot {name!r}; the slots are {', '.join(self.names)}") from None

    def slots(self, *names: str) -> tuple[int, ...]:
        """Positions of ``names``, in order (for unpacking into module constants)."""
        return tuple(self.index(n) for n in names)

    def extend(self, names: Iterable[str]) -> ParameterLayout:
        """This layout followed by ``names`` (a model that adds slots to another's)."""
        return ParameterLayout((*self.names, *names))

    def zeros(self) -> npt.NDArray[np.float64]:
        """A parameter vector of this layout, every slot 0."""
        return np.zeros(len(self))

    def fill(self, p: npt.NDArray[np.float64], values: Mapping[str, float]) -> None:
        """Write ``values`` (slot name -> value) into ``p``."""
        for name, value in values.items():
            p[self.index(name)] = value

    def value(self, p: npt.NDArray[np.float64], name: str) -> float:
        """The value of slot ``name`` in ``p``."""
        return float(p[self.index(name)])
