"""The planar model's state layout (the spatial model's starts with it)."""

from __future__ import annotations

from dataclasses import dataclass

__all__ = ["PlanarLayout"]


@dataclass(frozen=True)
class PlanarLayout:
    """Where each quantity sits in the state vector of ``n_balls`` balls."""

    n_balls: int

    @property
    def size(self) -> int:
        """Number of states, 5 Z + 6."""
        return 5 * self.n_balls + 6

    def slices(self) -> dict[str, slice]:
        """Named slices: r, theta, r_dot, theta_dot, spin, ring (y, z, y', z'), input work, dissipated energy."""
        z = self.n_balls
        return {"r": slice(0, z), "theta": slice(z, 2 * z), "r_dot": slice(2 * z, 3 * z),
                "theta_dot": slice(3 * z, 4 * z), "spin": slice(4 * z, 5 * z), "ring": slice(5 * z, 5 * z + 4),
                "input_work": slice(5 * z + 4, 5 * z + 5), "dissipated": slice(5 * z + 5, 5 * z + 6)}
