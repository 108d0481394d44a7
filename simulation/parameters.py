"""The model parameters the paper leaves open, with their defaults and sources.

Every value here can be changed per run (``cageless simulate --set name=value``)
and is recorded in the trace's configuration. Where a default is a choice inside
a published range rather than a published value, the docstring says so.

Sources
-------
* ``cho_n_s_m``: Wang et al. (2026) §4 vary the race lubricant damping C_ho over
  2500-7500 N s/m in their sensitivity study; the default is the middle, 5000.
* ``film_thickness_m``: the same study varies the oil film thickness h_0 over
  0.1-0.35 um; the default is the middle, 0.225 um. It is the film used by the
  traction law when the ``ehl_film`` effect is off, and the critical film
  thickness Delta_r of the ball-ball squeeze film.
* ``traction_peak_coefficient``, ``traction_peak_slide_roll``,
  ``traction_sliding_coefficient``: the traction curve of
  :mod:`cageless.simulation.traction` (the Sakaguchi & Harada / Gupta regression form the
  paper cites as [22], [23]), stated by its peak 0.06 at a slide-to-roll ratio of
  2 % and its sliding value 0.04. **These are representative values of mineral
  oil traction curves, not the coefficients of the paper's oil**: the paper does
  not print its regression coefficients and no copy of Sakaguchi & Harada (2006)
  was available to this project. They are the first thing to replace with a
  measured curve (``--set``).
* ``restitution``: ball-ball coefficient of restitution R; 0.8 is a
  representative value for lubricated steel spheres. The paper does not give
  one; R is swept in the stability tests.
* ``drag_coefficient``: None, the Reynolds-dependent drag coefficient of
  Schiller & Naumann (1933) joined to Newton's 0.44
  (:mod:`cageless.simulation.physics.drag`); a number fixes C_D instead (0.47 is
  the textbook subcritical value of a smooth sphere, F. M. White, Fluid
  Mechanics, Fig. 7.16). Drag acts in a lubricated scene by default, in the
  oil-air mixture of 5 % oil by volume (Parker, NASA TP-2275, 1984).
* ``strips``: 5 strips across each race contact ellipse in the spatial model, a
  choice; the work-precision study measures what other counts cost.
* ``min_approach_speed_m_s``: 0.01 m/s, a numerical floor on the approach speed
  that scales the ball-ball hysteresis damping (a choice: impacts in these runs
  close at 0.1-1 m/s; slower contacts rebound more elastically, as measured
  steel impacts do at low speed, Goldsmith 1960).
* ``surface_roughness_m``, ``limiting_shear_coefficient``, ``boundary_friction_coefficient``,
  ``boundary_slip_speed_m_s``: the race traction by lubrication regime (the ``film_traction`` effect,
  :mod:`cageless.simulation.physics.film_traction`, which cites each: composite rms roughness 0.1 um, a
  ground race against a finished ball, range 0.02-0.3 um; limiting shear stress over pressure 0.07 inside
  the 0.04-0.1 of mineral oils, Bair & Winer 1979; boundary friction 0.1 of lubricated steel, Harris &
  Kotzalas ch. 4; 5 mm/s, a numerical regularisation of the boundary friction's sign that keeps its slope
  near the traction curve's, docs/physics/lubricant.md).
* ``oil_temperature_c``: 20 degC, the paper's reference temperature (Table 1), at which its viscosity
  0.04 Pa s holds; the oil's viscosity follows eta_0 exp[-beta (T - T_0)] with the paper's beta = 0.027 1/K
  (:mod:`cageless.simulation.physics.viscosity`). Accepted range -20 to 150 degC (mineral oils stay liquid and
  below their flash points there; Harris & Kotzalas ch. 4 list bearing oils used up to about 150 degC).
* ``dry_friction_coefficient``: no default. A dry scene has no film, and the
  Coulomb friction of the bare steel contact must be given (``--set
  dry_friction_coefficient=...``).
* ``dry_static_coefficient``: no default (None: the same as the Coulomb
  coefficient, no Stribeck effect). Given, dry friction rises from the Coulomb
  value to it as the sliding stops, over ``stribeck_speed_m_s``.
* ``stribeck_speed_m_s``: 0.01 m/s, a choice within the 1e-4 to 1e-2 m/s range
  of the Stribeck speeds of metal contacts (Olsson et al., Eur. J. Control 4
  (1998) 176-195, §2); used only with ``dry_static_coefficient``.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from cageless.errors import ParameterError, suggest

__all__ = ["ModelParameters", "parse_set_overrides", "names", "BUILT_IN_NAMES"]


@dataclass(frozen=True)
class ModelParameters:
    """Open model parameters (SI units; the names carry them).

    Parameters
    ----------
    cho_n_s_m
        Race-contact lubricant damping C_ho (N s/m), >= 0.
    film_thickness_m
        Oil film thickness h_0 (m), > 0: the traction film when ``ehl_film`` is off, and the
        critical film Delta_r of the ball-ball squeeze film.
    traction_peak_coefficient
        Peak of the lubricated traction curve, mu_peak, in (0, 1), above the sliding value.
    traction_peak_slide_roll
        Slide-to-roll ratio at the peak, in (0, 1).
    traction_sliding_coefficient
        Traction coefficient at large slide-to-roll ratio, mu_inf, in (0, 1); also the ball-ball
        sliding friction of a lubricated bearing.
    restitution
        Ball-ball coefficient of restitution R, in [0, 1]; 0 is perfectly plastic (represented by a
        rebound below 0.1 %, :data:`cageless.simulation.forces.PLASTIC_CHI`).
    drag_coefficient
        Fixed drag coefficient C_D of a ball in the oil-air mixture, > 0, or None (default) for the
        Reynolds-dependent Schiller-Naumann law.
    dry_friction_coefficient
        Coulomb friction of a dry steel contact, in (0, 1), or None when not given.
    slip_regularisation_m_s
        Sliding speed (m/s) over which the dry Coulomb friction builds up (tanh), > 0.
    dry_static_coefficient
        Static friction of a dry steel contact, at least ``dry_friction_coefficient`` and below 1, or None
        (no Stribeck effect). See :func:`cageless.simulation.traction.dry_friction`.
    stribeck_speed_m_s
        Stribeck speed v_s (m/s) over which dry friction falls from the static to the Coulomb value, > 0.
    strips
        Strips m across each race contact ellipse in the spatial model (1 = point contact), 1..101: an
        accuracy knob (``cageless bench accuracy`` measures its cost).
    min_entrainment_m_s
        Floor on the entrainment speed in the slide-to-roll ratio (m/s), > 0: a contact that rolls
        slower than this is treated as sliding (the film has collapsed), which also bounds the
        traction slope at start-up.
    min_approach_speed_m_s
        Floor (m/s), > 0, on the approach speed v_in that scales the ball-ball hysteresis damping
        chi K delta^1.5 d(delta)/dt / v_in. Contacts that close slower than this (balls that drift
        into touch, rubbing pairs) are damped as if they had closed at this speed, so they rebound
        more elastically than R, as real steel impacts do as the speed falls (Goldsmith, *Impact*,
        1960, ch. 6); without the floor the damping of a contact that closes at rest is unbounded
        and the step collapses to nanoseconds.
    surface_roughness_m
        Composite rms roughness sigma (m) of the race contacts, in the film parameter Lambda = h_min / sigma
        (``film_traction`` effect), > 0.
    limiting_shear_coefficient
        Limiting shear stress over pressure, Lambda_LSS, of the full film, in (0, 1).
    boundary_friction_coefficient
        Friction coefficient mu_b of boundary lubrication (Lambda below 1), in (0, 1).
    boundary_slip_speed_m_s
        Sliding speed (m/s), > 0, over which boundary friction reaches mu_b (tanh regularisation).
    oil_temperature_c
        Oil temperature (degC), in [-20, 150]: the viscosity at ambient pressure is
        eta_0 exp[-beta (T - T_0)] (the lubricant's beta and T_0), in the film, the traction, the rolling losses
        and the ball-ball squeeze film.
    meniscus_distance_m
        Inlet meniscus distance r_s (m) of the hydrodynamic rolling force at the race contacts (the
        ``rolling_losses`` effect, :mod:`cageless.simulation.physics.rolling_force`): how far upstream of the
        contact the inlet is filled with oil; small is starved. Documented range 0.05-2 mm
        (:data:`cageless.simulation.physics.rolling_force.MENISCUS_RANGE_M`).
    """

    cho_n_s_m: float = 5000.0
    film_thickness_m: float = 0.225e-6
    traction_peak_coefficient: float = 0.06
    traction_peak_slide_roll: float = 0.02
    traction_sliding_coefficient: float = 0.04
    restitution: float = 0.8
    drag_coefficient: float | None = None
    dry_friction_coefficient: float | None = None
    slip_regularisation_m_s: float = 1e-3
    dry_static_coefficient: float | None = None
    stribeck_speed_m_s: float = 0.01
    min_entrainment_m_s: float = 0.1
    min_approach_speed_m_s: float = 0.01
    strips: int = 5
    meniscus_distance_m: float = 0.21028806973714847e-3  # fitted: simulation/parameter_sets.py
    surface_roughness_m: float = 0.1e-6
    limiting_shear_coefficient: float = 0.07
    boundary_friction_coefficient: float = 0.1
    boundary_slip_speed_m_s: float = 5e-3
    oil_temperature_c: float = 20.0
    #: Values given for the open parameters of effects added with
    #: :func:`cageless.simulation.effects.register_effect` (name, value); the others take the effect's default.
    added: tuple[tuple[str, float], ...] = ()

    def __post_init__(self) -> None:
        rules = {
            "cho_n_s_m": (lambda v: v >= 0, "must be >= 0"),
            "film_thickness_m": (lambda v: 0 < v < 1e-4, "must lie in (0, 100 um)"),
            "traction_peak_coefficient": (lambda v: 0 < v < 1, "must lie in (0, 1)"),
            "traction_peak_slide_roll": (lambda v: 0 < v < 1, "must lie in (0, 1)"),
            "traction_sliding_coefficient": (lambda v: 0 < v < 1, "must lie in (0, 1)"),
            "restitution": (lambda v: 0 <= v <= 1, "must lie in [0, 1]"),
            "slip_regularisation_m_s": (lambda v: v > 0, "must be > 0"),
            "stribeck_speed_m_s": (lambda v: v > 0, "must be > 0"),
            "min_entrainment_m_s": (lambda v: v > 0, "must be > 0"),
            "min_approach_speed_m_s": (lambda v: v > 0, "must be > 0"),
            "meniscus_distance_m": (lambda v: 0 < v <= 0.01, "must lie in (0, 10 mm]"),
            "surface_roughness_m": (lambda v: 0 < v < 1e-5, "must lie in (0, 10 um)"),
            "limiting_shear_coefficient": (lambda v: 0 < v < 1, "must lie in (0, 1)"),
            "boundary_friction_coefficient": (lambda v: 0 < v < 1, "must lie in (0, 1)"),
            "boundary_slip_speed_m_s": (lambda v: v > 0, "must be > 0"),
            "oil_temperature_c": (lambda v: -20 <= v <= 150, "must lie in [-20, 150] degC"),
        }
        for name, (ok, rule) in rules.items():
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value) \
                    or not ok(value):
                raise ParameterError(f"parameters.{name}", rule, value)
        m = self.strips
        if isinstance(m, bool) or not isinstance(m, int | float) or m != int(m) or not 1 <= m <= 101:
            raise ParameterError("parameters.strips", "must be a whole number in 1..101", m)
        object.__setattr__(self, "strips", int(m))
        mu = self.dry_friction_coefficient
        if mu is not None and not (isinstance(mu, int | float) and math.isfinite(mu) and 0 < mu < 1):
            raise ParameterError("parameters.dry_friction_coefficient", "must lie in (0, 1), or be None", mu)
        cd = self.drag_coefficient
        if cd is not None and not (isinstance(cd, int | float) and not isinstance(cd, bool) and math.isfinite(cd)
                                   and cd > 0):
            raise ParameterError("parameters.drag_coefficient", "must be > 0, or None for the Reynolds-dependent "
                                 "Schiller-Naumann law", cd)
        static = self.dry_static_coefficient
        if static is not None and not (isinstance(static, int | float) and math.isfinite(static) and mu is not None
                                       and mu <= static < 1):
            raise ParameterError("parameters.dry_static_coefficient", "must lie between dry_friction_coefficient "
                                 "(which must be given too) and 1, or be None", static)
        if self.traction_peak_coefficient <= self.traction_sliding_coefficient:
            raise ParameterError("parameters.traction_peak_coefficient", "must exceed traction_sliding_coefficient",
                                 self.traction_peak_coefficient)

    @property
    def traction_coefficients(self) -> tuple[float, float, float, float]:
        """(A, B, C, D) of the traction regression (:func:`cageless.simulation.traction.regression_coefficients`)."""
        from cageless.simulation.traction import regression_coefficients

        return regression_coefficients(self.traction_peak_coefficient, self.traction_peak_slide_roll,
                                       self.traction_sliding_coefficient)

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready values (an added effect's values by name, beside the built-in ones)."""
        out = dataclasses.asdict(self)
        out.update(dict(out.pop("added")))
        return out

    def value(self, name: str) -> float:
        """The value of a built-in parameter, or of an added effect's parameter (its default if not given)."""
        from cageless.simulation.effects import added_parameters

        if name in BUILT_IN_NAMES:
            return getattr(self, name)
        given = dict(self.added)
        if name in given:
            return given[name]
        defaults = added_parameters()
        if name not in defaults:
            raise ParameterError("parameters", f"{name!r} is not a model parameter" + (suggest(name, names())))
        return defaults[name]

    def with_overrides(self, values: Mapping[str, float]) -> ModelParameters:
        """A copy with ``values`` replaced; unknown names get a suggestion. An added effect's parameter
        (:func:`cageless.simulation.effects.register_effect`) is set by its name like a built-in one."""
        from cageless.simulation.effects import added_parameters

        known = names()
        for name in values:
            if name not in known:
                raise ParameterError("--set", f"{name!r} is not a model parameter"
                                     + (suggest(name, known) or f"; the parameters are {', '.join(known)}"))
        extra = {k: v for k, v in values.items() if k in added_parameters()}
        for name, value in extra.items():
            if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
                raise ParameterError(f"parameters.{name}", "must be a finite number", value)
        built_in = {k: v for k, v in values.items() if k not in extra}
        added = tuple(sorted({**dict(self.added), **{k: float(v) for k, v in extra.items()}}.items()))
        return dataclasses.replace(self, **built_in, added=added)


#: The built-in parameters' names (the fields of :class:`ModelParameters` but its ``added`` values).
BUILT_IN_NAMES = tuple(f.name for f in dataclasses.fields(ModelParameters) if f.name != "added")


def names() -> list[str]:
    """Every model parameter's name: the built-in ones, then those of added effects."""
    from cageless.simulation.effects import added_parameters

    return [*BUILT_IN_NAMES, *added_parameters()]


def parse_set_overrides(items: list[str]) -> dict[str, float]:
    """Parse ``--set name=value`` items into numbers (``none`` clears an optional parameter)."""
    out: dict[str, Any] = {}
    for item in items:
        name, sep, text = item.partition("=")
        if not sep or not name.strip():
            raise ParameterError("--set", f"expects name=value, got {item!r} (e.g. --set cho_n_s_m=2500)")
        text = text.strip()
        if text.lower() == "none":
            out[name.strip()] = None
            continue
        try:
            value = float(text)
        except ValueError:
            raise ParameterError("--set", f"{name.strip()}={text!r}: the value must be a number") from None
        if not math.isfinite(value):
            raise ParameterError("--set", f"{name.strip()}: the value must be finite", value)
        out[name.strip()] = value
    return out
