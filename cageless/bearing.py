"""Bearing description: geometry, materials, masses and lubricant, in SI units.

All classes are frozen dataclasses that validate themselves on construction:
an impossible bearing cannot exist as an object. Every error names the field
and the rule it broke (:class:`~cageless.errors.GeometryError`,
:class:`~cageless.errors.ParameterError`).

The default bearing is the paper's (Wang et al. 2026, Table 1),
defined in :mod:`cageless.parameter_sets.wang2026`.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from cageless.errors import GeometryError, ParameterError, suggest

__all__ = ["Geometry", "Material", "Masses", "Lubricant", "Bearing", "default_bearing", "clearance_note",
           "CLEARANCE_NAME", "PITCH_NAME", "derived_name"]

#: Clearances smaller than this (m) are round-off of the race diameters and are taken as 0.
_CLEARANCE_ROUND_OFF_M = 1e-12


def _check_positive(owner: str, name: str, value: object) -> None:
    """Raise :class:`ParameterError` unless ``value`` is a finite real number > 0."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ParameterError(f"{owner}.{name}", "must be a number", value)
    if not math.isfinite(value) or value <= 0:
        raise ParameterError(f"{owner}.{name}", "must be a finite number > 0", value)


def _check_all_positive(obj: object, owner: str, skip: tuple[str, ...] = ()) -> None:
    for f in dataclasses.fields(obj):  # type: ignore[arg-type]
        if f.name not in skip:
            _check_positive(owner, f.name, getattr(obj, f.name))


@dataclass(frozen=True)
class Geometry:
    """Internal geometry of a radial deep-groove ball bearing.

    Parameters
    ----------
    inner_race_diameter_m
        Diameter of the inner-ring groove bottom, d_i (m).
    outer_race_diameter_m
        Diameter of the outer-ring groove bottom, d_o (m).
    ball_diameter_m
        Ball diameter, D (m).
    inner_curvature_factor
        Inner groove radius over ball diameter, f_i = r_i / D (> 0.5).
    outer_curvature_factor
        Outer groove radius over ball diameter, f_o = r_o / D (> 0.5).
    n_balls
        Number of balls, Z.

    Notes
    -----
    The pitch diameter is ``(d_i + d_o) / 2`` and the diametral clearance is
    ``d_o - d_i - 2 D`` (Harris & Kotzalas, *Rolling Bearing Analysis*, 5th ed.,
    vol. 1, ch. 2). A negative clearance (interference) is not supported.
    """

    inner_race_diameter_m: float
    outer_race_diameter_m: float
    ball_diameter_m: float
    inner_curvature_factor: float
    outer_curvature_factor: float
    n_balls: int

    def __post_init__(self) -> None:
        _check_all_positive(self, "geometry", skip=("n_balls",))
        if isinstance(self.n_balls, bool) or not isinstance(self.n_balls, int) or self.n_balls < 3:
            raise GeometryError("geometry.n_balls", "must be a whole number >= 3", self.n_balls)
        for name in ("inner_curvature_factor", "outer_curvature_factor"):
            if getattr(self, name) <= 0.5:
                raise GeometryError(
                    f"geometry.{name}",
                    "must be > 0.5 (the groove radius f*D must exceed the ball radius D/2)",
                    getattr(self, name),
                )
        if self.outer_race_diameter_m <= self.inner_race_diameter_m:
            raise GeometryError(
                "geometry.outer_race_diameter_m",
                "must exceed geometry.inner_race_diameter_m",
                self.outer_race_diameter_m,
            )
        if self.diametral_clearance_m < 0:
            raise GeometryError(
                "geometry.ball_diameter_m",
                "the ball does not fit between the races: diametral clearance "
                f"d_o - d_i - 2D = {self.diametral_clearance_m * 1e6:.3f} um < 0 "
                "(interference fits are not supported)",
                self.ball_diameter_m,
            )
        if self.n_balls > self.max_ball_count:
            raise GeometryError(
                "geometry.n_balls",
                f"{self.n_balls} balls of diameter {self.ball_diameter_m * 1e3:.4g} mm do not fit "
                f"on a pitch circle of {self.pitch_diameter_m * 1e3:.4g} mm; at most "
                f"{self.max_ball_count} fit (adjacent ball centres must be at least D apart)",
                self.n_balls,
            )

    @property
    def pitch_diameter_m(self) -> float:
        """Pitch diameter d_m = (d_i + d_o) / 2 (m)."""
        return 0.5 * (self.inner_race_diameter_m + self.outer_race_diameter_m)

    @property
    def diametral_clearance_m(self) -> float:
        """Diametral clearance P_d = d_o - d_i - 2D (m); round-off below 1 pm is 0."""
        c = self.outer_race_diameter_m - self.inner_race_diameter_m - 2.0 * self.ball_diameter_m
        return 0.0 if abs(c) < _CLEARANCE_ROUND_OFF_M else c

    @property
    def max_ball_count(self) -> int:
        """Largest Z whose balls fit on the pitch circle without overlapping.

        Adjacent centres on a circle of radius d_m/2 are a chord ``d_m sin(pi/Z)``
        apart; they fit while that chord is at least D.
        """
        ratio = self.ball_diameter_m / self.pitch_diameter_m
        if ratio >= 1.0:
            return 0
        return math.floor(math.pi / math.asin(ratio) + 1e-9)

    @property
    def inner_groove_radius_m(self) -> float:
        """Inner groove curvature radius r_i = f_i D (m)."""
        return self.inner_curvature_factor * self.ball_diameter_m

    @property
    def outer_groove_radius_m(self) -> float:
        """Outer groove curvature radius r_o = f_o D (m)."""
        return self.outer_curvature_factor * self.ball_diameter_m

    def with_diametral_clearance(self, clearance_m: float) -> Geometry:
        """The same bearing with diametral clearance ``clearance_m`` (m), the pitch diameter kept.

        The races move apart symmetrically: d_i and d_o change by -/+ half the change of P_d. For the
        ranges of the clearance groups see ISO 5753-1 (deep-groove ball bearings of bore over 24 up to
        30 mm, this bearing's size: CN 5-20 um, C3 13-28 um, C4 23-41 um).

        Raises
        ------
        GeometryError
            For a negative or non-finite clearance.
        """
        if not (math.isfinite(clearance_m) and clearance_m >= 0.0):
            raise GeometryError("geometry.diametral_clearance_m", "must be a finite clearance >= 0 m "
                                "(interference fits are not supported)", clearance_m)
        half = 0.5 * (clearance_m - self.diametral_clearance_m)
        return dataclasses.replace(self, inner_race_diameter_m=self.inner_race_diameter_m - half,
                                   outer_race_diameter_m=self.outer_race_diameter_m + half)


@dataclass(frozen=True)
class Material:
    """Elastic material of balls and rings (the same for both).

    Parameters
    ----------
    density_kg_m3
        Mass density (kg/m^3).
    youngs_modulus_pa
        Young's modulus E (Pa).
    poisson_ratio
        Poisson's ratio nu, with -1 < nu < 0.5.
    """

    density_kg_m3: float
    youngs_modulus_pa: float
    poisson_ratio: float

    def __post_init__(self) -> None:
        _check_all_positive(self, "material", skip=("poisson_ratio",))
        nu = self.poisson_ratio
        if isinstance(nu, bool) or not isinstance(nu, int | float) or not (-1.0 < nu < 0.5):
            raise ParameterError("material.poisson_ratio", "must lie in (-1, 0.5)", nu)

    @property
    def effective_modulus_pa(self) -> float:
        """Contact modulus E' = E / (1 - nu^2) of two bodies of this material (Pa).

        This is half the 'reduced modulus' 2/E' = (1-nu1^2)/E1 + (1-nu2^2)/E2
        of Hamrock & Dowson for identical bodies.
        """
        return self.youngs_modulus_pa / (1.0 - self.poisson_ratio**2)


@dataclass(frozen=True)
class Masses:
    """Masses of the moving parts.

    Parameters
    ----------
    ball_mass_kg
        Mass of one ball (kg).
    inner_ring_mass_kg
        Mass of the inner ring (kg).
    shaft_mass_kg
        Mass of the shaft carried with the inner ring (kg).
    """

    ball_mass_kg: float
    inner_ring_mass_kg: float
    shaft_mass_kg: float

    def __post_init__(self) -> None:
        _check_all_positive(self, "masses")

    @property
    def ring_translational_mass_kg(self) -> float:
        """Mass that translates with the inner ring: ring plus shaft (kg)."""
        return self.inner_ring_mass_kg + self.shaft_mass_kg


@dataclass(frozen=True)
class Lubricant:
    """Lubricant properties (Barus pressure and exponential temperature laws).

    Parameters
    ----------
    density_kg_m3
        Density (kg/m^3).
    dynamic_viscosity_pa_s
        Dynamic viscosity eta_0 at the reference temperature and ambient pressure (Pa s).
    pressure_viscosity_coefficient_1_pa
        Barus pressure-viscosity coefficient alpha (1/Pa).
    temperature_viscosity_coefficient_1_k
        Temperature-viscosity coefficient beta (1/K).
    reference_temperature_k
        Temperature at which ``dynamic_viscosity_pa_s`` holds (K).
    """

    density_kg_m3: float
    dynamic_viscosity_pa_s: float
    pressure_viscosity_coefficient_1_pa: float
    temperature_viscosity_coefficient_1_k: float
    reference_temperature_k: float

    def __post_init__(self) -> None:
        _check_all_positive(self, "lubricant")


@dataclass(frozen=True)
class Bearing:
    """A complete bearing: geometry, material, masses and (optionally) lubricant.

    Parameters
    ----------
    geometry, material, masses
        See the respective classes.
    lubricant
        The lubricant, or ``None`` for a dry bearing.
    name
        A label for reports.
    """

    geometry: Geometry
    material: Material
    masses: Masses
    lubricant: Lubricant | None = None
    name: str = "custom"

    def to_dict(self) -> dict[str, Any]:
        """Return a JSON-ready nested dict (SI units, field names carry the unit)."""
        return dataclasses.asdict(self)

    @classmethod
    def from_dict(cls, data: Mapping[str, Any]) -> Bearing:
        """Build a bearing from :meth:`to_dict` output, validating every field.

        Raises
        ------
        ParameterError
            For a missing or unknown section or field, or an invalid value.
        """
        parts: dict[str, Any] = {}
        for section, kind in _SECTIONS.items():
            raw = data.get(section)
            if raw is None:
                if section == "lubricant":
                    parts[section] = None
                    continue
                raise ParameterError(f"bearing.{section}", "is missing")
            parts[section] = _build_section(kind, section, raw)
        unknown = set(data) - set(_SECTIONS) - {"name"}
        if unknown:
            bad = sorted(unknown)[0]
            raise ParameterError(f"bearing.{bad}", "is not a bearing section" + suggest(bad, _SECTIONS))
        return cls(name=str(data.get("name", "custom")), **parts)

    def with_overrides(self, overrides: Mapping[str, Any]) -> Bearing:
        """Return a copy with dotted-name overrides applied, e.g. ``{"geometry.n_balls": 13}``.

        Two names set derived quantities rather than stored fields. ``geometry.pitch_diameter_m`` (m) puts the
        pitch circle there. ``geometry.diametral_clearance_m`` (m, >= 0) moves the races apart symmetrically to
        that clearance after the other overrides, the pitch diameter kept
        (:meth:`Geometry.with_diametral_clearance`). A new ``geometry.ball_diameter_m`` or pitch diameter
        without either race diameter moves the races with it, the clearance kept: they sit at
        ``d_m -/+ (D + P_d / 2)``. A new ball diameter without ``masses.ball_mass_kg`` scales the ball's mass
        as ``D^3`` (the same steel). Race diameters given are taken as they are.

        A copy that differs from this bearing is named after it and the overrides (:func:`derived_name`, e.g.
        ``"wang2026 (geometry.n_balls = 13)"``), and that name is what the outputs record.

        Raises
        ------
        ParameterError
            For an unknown name (with a suggestion) or an invalid value (a negative clearance is a
            :class:`~cageless.errors.GeometryError` naming ``geometry.diametral_clearance_m``).
        """
        data = self.to_dict()
        valid = sorted([*_dotted_names(data), *_DERIVED_NAMES])
        derived: dict[str, Any] = {}
        for key, value in overrides.items():
            section, _, name = key.partition(".")
            if key not in valid:
                if section == "lubricant" and data.get("lubricant") is None:
                    raise ParameterError(key, "the bearing is dry; set the whole lubricant section")
                raise ParameterError(key, "is not a bearing parameter" + suggest(key, valid))
            if key in _DERIVED_NAMES:
                derived[key] = value
                continue
            data[section][name] = value
        _follow_the_ball(data, self, set(overrides), derived.get(PITCH_NAME))
        bearing = Bearing.from_dict(data)
        clearance = derived.get(CLEARANCE_NAME)
        if clearance is not None:
            if isinstance(clearance, bool) or not isinstance(clearance, int | float):
                raise ParameterError(CLEARANCE_NAME, "must be a number in metres, e.g. 32e-6", clearance)
            bearing = dataclasses.replace(bearing, geometry=bearing.geometry.with_diametral_clearance(float(clearance)))
        if dataclasses.replace(bearing, name=self.name) == self:
            return bearing  # nothing changed: the parameter set is still the named one
        return dataclasses.replace(bearing, name=derived_name(self.name, overrides))


def derived_name(name: str, changes: Mapping[str, Any]) -> str:
    """The name of bearing ``name`` with ``changes`` (dotted name -> value) applied, e.g.
    ``"wang2026 (geometry.n_balls = 13)"``: the changes are part of the name, so an output never claims the
    named parameter set for a bearing that is not it."""
    shown = ", ".join(f"{k} = {v:g}" if isinstance(v, int | float) and not isinstance(v, bool) else f"{k} = {v}"
                      for k, v in sorted(changes.items()))
    return f"{name} ({shown})" if shown else name


def _follow_the_ball(data: dict[str, Any], base: Bearing, given: set[str], pitch_m: Any) -> None:
    """Place the races of ``data`` about a new ball or pitch diameter, and scale the ball's mass (in place).

    ``given`` holds the dotted names the overrides set; ``pitch_m`` is ``geometry.pitch_diameter_m`` or
    ``None``. Nothing moves when neither the ball diameter nor the pitch diameter is given, or when a race
    diameter is (then the races are as given).
    """
    races = {"geometry.inner_race_diameter_m", "geometry.outer_race_diameter_m"} & given
    if pitch_m is not None:
        _check_positive("geometry", "pitch_diameter_m", pitch_m)
        if races:
            raise ParameterError(PITCH_NAME, "give either the pitch diameter or the race diameters "
                                 f"({', '.join(sorted(races))}), not both", pitch_m)
    new_ball = "geometry.ball_diameter_m" in given
    if races or not (new_ball or pitch_m is not None):
        return
    g0 = base.geometry
    ball = data["geometry"]["ball_diameter_m"]
    _check_positive("geometry", "ball_diameter_m", ball)
    d_m = g0.pitch_diameter_m if pitch_m is None else float(pitch_m)
    if ball >= d_m:
        raise GeometryError("geometry.ball_diameter_m", f"must be smaller than the pitch diameter "
                            f"{d_m * 1e3:.4g} mm (lengths are in metres: 8e-3 for an 8 mm ball)", ball)
    half = ball + 0.5 * g0.diametral_clearance_m
    data["geometry"]["inner_race_diameter_m"] = d_m - half
    data["geometry"]["outer_race_diameter_m"] = d_m + half
    if new_ball and "masses.ball_mass_kg" not in given:
        data["masses"]["ball_mass_kg"] = base.masses.ball_mass_kg * (ball / g0.ball_diameter_m) ** 3


#: The dotted name that sets the diametral clearance in overrides, ``--config`` and sweeps (not a stored field:
#: the clearance follows from the race diameters).
CLEARANCE_NAME = "geometry.diametral_clearance_m"
#: The dotted name that sets the pitch diameter in overrides and ``--config`` (derived, like the clearance).
PITCH_NAME = "geometry.pitch_diameter_m"
_DERIVED_NAMES = (CLEARANCE_NAME, PITCH_NAME)


_SECTIONS: dict[str, type] = {
    "geometry": Geometry,
    "material": Material,
    "masses": Masses,
    "lubricant": Lubricant,
}


def _build_section(kind: type, section: str, raw: Mapping[str, Any]) -> Any:
    names = [f.name for f in dataclasses.fields(kind)]
    for key in raw:
        if key not in names:
            raise ParameterError(
                f"{section}.{key}", f"is not a {section} field" + suggest(key, names)
            )
    missing = [n for n in names if n not in raw]
    if missing:
        raise ParameterError(f"{section}.{missing[0]}", "is missing")
    return kind(**raw)


def _dotted_names(data: Mapping[str, Any]) -> list[str]:
    return [
        f"{section}.{name}"
        for section, values in data.items()
        if isinstance(values, Mapping)
        for name in values
    ]


def default_bearing() -> Bearing:
    """Return the paper's bearing (Wang et al. 2026, Table 1), lubricated."""
    from cageless.parameter_sets import wang2026

    return wang2026.bearing()


def clearance_note(geometry: Geometry) -> str:
    """One line for ``--explain``: the diametral clearance of ``geometry`` (um) and where it comes from."""
    from cageless.parameter_sets import wang2026

    source = ("Table 1 of Wang et al. 2026 as printed" if geometry == wang2026.geometry()
              else "as given: --clearance-um, geometry.diametral_clearance_m or the race diameters")
    return f"diametral clearance {geometry.diametral_clearance_m * 1e6:.3f} um ({source})"
