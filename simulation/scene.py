"""The scene a simulation runs for: bearing, conditions, lubricant, orientation, duration, seed.

A :class:`Scene` is validated when it is made, before anything compiles or
solves, and every error names the parameter and the rule.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import Any

from cageless.bearing import Bearing, default_bearing
from cageless.conditions import OperatingConditions
from cageless.errors import ParameterError

__all__ = ["Scene", "ORIENTATIONS"]

#: Shaft orientations: gravity acts radially (horizontal shaft, along -z) or axially (vertical shaft).
ORIENTATIONS = ("horizontal", "vertical")


@dataclass(frozen=True)
class Scene:
    """Everything that decides what to simulate.

    Parameters
    ----------
    conditions
        Speed and loads (``speed_rpm`` > 0).
    bearing
        The bearing; ``bearing.lubricant is None`` makes a dry scene.
    gravity_m_s2
        Gravitational acceleration (m/s^2), >= 0; 0 for no gravity.
    orientation
        ``"horizontal"`` (gravity along -z) or ``"vertical"`` shaft (gravity along the axis).
    misalignment_rad
        Inner-ring tilt (rad), >= 0.
    moment_load_nm
        Moment load on the inner ring (N m), >= 0.
    oil_air_density_kg_m3
        Density of the oil-air mixture the balls churn through (kg/m^3). ``None``: in a lubricated scene the
        mixture of 5 % oil by volume in air (:func:`cageless.simulation.physics.drag.mixture_density`, Parker, NASA
        TP-2275, 1984), in a dry scene none; 0 turns drag off.
    duration_s
        Simulated time after the start (s), > 0.
    speed_ramp_s
        Time for the inner ring to reach its speed from rest (s), >= 0 (0: instantaneous start).
    seed
        Perturbs the initial gaps between balls.
    initial_gap_fraction
        Share of the free arc (the circumference the balls do not fill) spread between neighbours at the
        start, in [0, 1); the rest is the one gap at the top. 0 starts every ball in contact with its
        neighbours; the default 0.05 keeps them a few micrometres apart.
    """

    conditions: OperatingConditions
    bearing: Bearing = field(default_factory=default_bearing)
    gravity_m_s2: float = 9.81
    orientation: str = "horizontal"
    misalignment_rad: float = 0.0
    moment_load_nm: float = 0.0
    oil_air_density_kg_m3: float | None = None
    duration_s: float = 0.05
    speed_ramp_s: float = 0.0
    seed: int = 0
    initial_gap_fraction: float = 0.05

    def __post_init__(self) -> None:
        if not (isinstance(self.initial_gap_fraction, int | float) and 0 <= self.initial_gap_fraction < 1):
            raise ParameterError("scene.initial_gap_fraction", "must lie in [0, 1)", self.initial_gap_fraction)
        for name in ("gravity_m_s2", "misalignment_rad", "moment_load_nm", "speed_ramp_s"):
            value = getattr(self, name)
            if not (isinstance(value, int | float) and math.isfinite(value) and value >= 0):
                raise ParameterError(f"scene.{name}", "must be a finite number >= 0", value)
        if not (math.isfinite(self.duration_s) and self.duration_s > 0):
            raise ParameterError("scene.duration_s", "must be a finite number > 0", self.duration_s)
        if self.orientation not in ORIENTATIONS:
            raise ParameterError("scene.orientation", f"must be one of {ORIENTATIONS}", self.orientation)
        rho = self.oil_air_density_kg_m3
        if rho is not None and not (math.isfinite(rho) and rho >= 0):
            raise ParameterError("scene.oil_air_density_kg_m3", "must be a finite number >= 0 (0: no drag), or None "
                                 "for the default mixture", rho)

    @property
    def mixture_density_kg_m3(self) -> float | None:
        """The oil-air mixture density drag uses (kg/m^3): as given, else the default mixture of a lubricated
        scene (5 % oil by volume), else None (dry, none given)."""
        if self.oil_air_density_kg_m3 is not None:
            return float(self.oil_air_density_kg_m3)
        if self.bearing.lubricant is None:
            return None
        from cageless.simulation.physics.drag import mixture_density

        return mixture_density(self.bearing.lubricant.density_kg_m3)

    @property
    def lubricated(self) -> bool:
        """True when the bearing has a lubricant."""
        return self.bearing.lubricant is not None

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready description (SI units; names carry them)."""
        d = asdict(self)
        d["bearing"] = self.bearing.to_dict()
        return d
