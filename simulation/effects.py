"""The validated table of effects, and how a scene chooses among them.

Every effect is one row of :data:`EFFECTS`: a name, the physics, and the rule
that switches it on for a scene, with the reason in words. :func:`choose_model`
applies the rules, then the user's overrides:

* a misspelled effect or level gets a suggestion;
* switching on an effect the scene has nothing to compute for (a lubricant
  effect in a dry scene) is always an error;
* any other override that contradicts the scene (planar under axial load,
  gravity on at g = 0, race contact off) is an error unless ``force`` is given,
  and the choice then records that it was forced.

An effect that is off is never evaluated: the right-hand side is assembled from
the effects that are on (see the simulator issue's numerics).
"""

from __future__ import annotations

import json
from collections.abc import Callable, Mapping
from dataclasses import asdict, dataclass
from typing import Any

from cageless.errors import UsageError, suggest
from cageless.simulation.scene import Scene

__all__ = [
    "EffectSpec", "EffectChoice", "ModelChoice", "EFFECTS", "LEVELS", "LEVEL_DOF", "choose_model", "parse_effect_overrides",
    "describe_table", "check_lubricant", "parameter_slots", "effect_flags", "register_effect", "removable_effects",
]

LEVELS = ("planar", "spatial")


@dataclass(frozen=True)
class EffectSpec:
    """One row of the effects table."""

    name: str
    physics: str
    rule: Callable[[Scene], tuple[bool, str]]
    needs_lubricant: bool = False
    #: Slot of the effect's on/off flag in the models' parameter vector (:mod:`cageless.simulation.layout`).
    flag: str = ""
    #: Slots of the parameters the effect's unit reads (filled by the model from
    #: :class:`~cageless.simulation.parameters.ModelParameters` and the bearing).
    slots: tuple[str, ...] = ()
    #: For an effect added by :func:`register_effect`: its slot values (name -> value) from the run's
    #: :class:`~cageless.simulation.parameters.ModelParameters` (the built-in rows are filled by the models).
    fill: Callable[[Any], Mapping[str, float]] | None = None
    #: For an added effect: its open parameters (name with its unit, default), which ``--set NAME=VALUE``, a
    #: configuration's ``[parameters]`` table and :meth:`ModelParameters.value` reach like the built-in ones.
    parameters: tuple[tuple[str, float], ...] = ()
    #: Effects this one changes the law of: it has nothing to act on, and is switched off with that reason,
    #: when all of them are off (``dry_friction`` replaces the law of ``race_traction`` and
    #: ``ball_ball_friction``).
    acts_on: tuple[str, ...] = ()
    #: False for the contacts without which there is no bearing model (race and ball-ball contact): the
    #: effect ablation (``cageless bench effects``) removes every other effect in turn.
    removable: bool = True
    #: True for an alternative law that no scene switches on by itself (its rule says off): ``--effect NAME=on``
    #: chooses it without ``--force`` (``strip_damping``, the paper's formulation, kept for reproducing it).
    opt_in: bool = False
    #: Levels the effect is built into (an opt-in law may exist in one model only).
    levels: tuple[str, ...] = ("planar", "spatial")


def _always(what: str) -> Callable[[Scene], tuple[bool, str]]:
    return lambda s: (True, what)


def _lubricated(s: Scene) -> tuple[bool, str]:
    return (True, "the scene is lubricated") if s.lubricated else (False, "dry scene: no lubricant")


def _gravity(s: Scene) -> tuple[bool, str]:
    return (True, f"g = {s.gravity_m_s2:g} m/s^2") if s.gravity_m_s2 > 0 else (False, "g = 0")


#: Why the paper's strip formulation of the race damping is off unless asked for.
STRIP_DAMPING_OFF = ("opt-in (--effect strip_damping=on): the paper's strip formulation of C_ho, for reproducing "
                     "the paper; not the default physics")
#: What the explanation says when it is on.
STRIP_DAMPING_ON = ("on by the user: the paper's strip formulation of C_ho (Wang et al. 2026, sec. 2.2), for "
                    "reproducing the paper; not the default physics")


def _race_contact(s: Scene) -> tuple[bool, str]:
    """Race contact is always on; the reason says which races the balls touch, from the clearance and the load."""
    clearance = s.bearing.geometry.diametral_clearance_m
    if clearance <= 0:
        return True, ("zero clearance: the balls touch both races at rest; the loaded contacts' deflection and "
                      "centrifugal force open small gaps on the unloaded side")
    c = s.conditions
    loaded = c.radial_load_n > 0 or c.axial_load_n > 0 or s.moment_load_nm > 0 or s.gravity_m_s2 > 0
    closes = ("they touch the inner race where the load closes the clearance" if loaded else
              "no load or gravity closes it, so the inner ring floats among them")
    return True, (f"diametral clearance {1e6 * clearance:.3g} um: centrifugal force holds the balls on the outer "
                  f"race; {closes}")


def _dry(s: Scene) -> tuple[bool, str]:
    return (False, "the scene is lubricated: traction curve") if s.lubricated else (
        True, "dry scene: bare steel contacts rub with Coulomb-Stribeck friction")


def _drag(s: Scene) -> tuple[bool, str]:
    rho = s.mixture_density_kg_m3
    if rho is None:
        return False, "no oil-air mixture given"
    if rho == 0:
        return False, "oil-air mixture density set to 0"
    if s.oil_air_density_kg_m3 is None:
        return True, f"lubricated: oil-air mixture of {rho:.3g} kg/m^3 (5 % oil by volume, Parker 1984)"
    return True, f"oil-air mixture of {rho:g} kg/m^3"


EFFECTS: tuple[EffectSpec, ...] = (
    EffectSpec("race_contact", "Hertz point contact Q = K delta^1.5 between ball and inner/outer groove",
               _race_contact, flag="F_RACE", slots=("KI", "KO"), removable=False),
    EffectSpec("lubricant_damping", "normal damping C_ho d(delta)/dt at race contacts, never tensile", _lubricated,
               needs_lubricant=True, flag="F_LUB", slots=("CHO",)),
    EffectSpec("strip_damping", "the paper's strip formulation of the race damping: C_ho spread over strips of the "
               "contact ellipse along the rolling direction, each at its own normal speed d(delta)/dt + u x / R_x "
               "(the contact-point velocity omega_b x r_x + v_b), no strip tensile (Wang et al. 2026, sec. 2.2)",
               lambda s: (False, STRIP_DAMPING_OFF), needs_lubricant=True, flag="F_STRIP",
               slots=("SB_I", "SB_O", "SRX_I", "SRX_O"), acts_on=("lubricant_damping",), opt_in=True,
               levels=("planar",)),
    EffectSpec("race_traction", "traction mu(slip) at race contacts (dry: Coulomb-Stribeck)",
               _always("traction drives the balls"), flag="F_TRAC", slots=("TA", "TB", "TC", "TD", "U_FLOOR")),
    EffectSpec("ehl_film", "Hamrock-Dowson central and minimum film at race contacts", _lubricated,
               needs_lubricant=True, flag="F_FILM"),
    EffectSpec("film_traction", "race traction by lubrication regime from Lambda = h_min / sigma: boundary "
               "friction, mixed, full film limited by the Bair-Winer limiting shear stress; the film's viscosity "
               "from Roelands at the mean Hertz pressure and the oil temperature", _lubricated,
               needs_lubricant=True, flag="F_FTRAC", acts_on=("race_traction",),
               slots=("SIGMA", "LSS", "MU_B", "V_REG_B", "U_MIN", "LAM_B", "LAM_F", "ETA_T", "ROE_LN", "ROE_Z",
                      "LHC_I", "LHM_I", "AB_I", "LHC_O", "LHM_O", "AB_O")),
    EffectSpec("rolling_losses", "hydrodynamic rolling force on the ball centre and moment about it at both race "
               "contacts, from the film and the entrainment speed, with inlet starvation (Chiu 1974)", _lubricated,
               needs_lubricant=True, flag="F_ROLL",
               slots=("ETA0", "RC_I", "RH_I", "LT_FILM_I", "LT_FIX_I", "RC_O", "RH_O", "LT_FILM_O", "LT_FIX_O")),
    EffectSpec("ball_ball_contact", "Hertz contact between neighbours with hysteresis damping (restitution R)",
               _always("no cage: neighbours meet"), flag="F_BB", slots=("KB", "CHI", "V_IN_MIN"), removable=False),
    EffectSpec("ball_ball_friction", "friction between neighbours from their surface sliding speed (the race "
               "traction's law; dry: Coulomb-Stribeck)", _always("neighbours rub where they meet"),
               flag="F_BBFRIC"),
    EffectSpec("ball_ball_film", "squeeze film between neighbouring balls", _lubricated, needs_lubricant=True,
               flag="F_BBFILM", slots=("ETA0", "H0")),
    EffectSpec("gravity", "m g on balls and ring", _gravity, flag="F_GRAV", slots=("G",)),
    EffectSpec("drag", "1/2 C_D(Re) rho A V^2 against the orbital motion (Schiller-Naumann C_D) and the churning "
               "moment on the spin", _drag, flag="F_DRAG", slots=("CD", "RHO_MIX", "MU_MIX")),
    EffectSpec("dry_friction", "Coulomb-Stribeck friction of bare steel instead of the traction curve, at race and "
               "ball-ball contacts", _dry, flag="DRY", slots=("MU_DRY", "V_REG", "MU_STATIC", "V_STRIBECK"),
               acts_on=("race_traction", "ball_ball_friction")),
)
_BY_NAME = {e.name: e for e in EFFECTS}


def added_parameters() -> dict[str, float]:
    """The open parameters of the effects added with :func:`register_effect`, with their defaults."""
    return {name: value for e in EFFECTS for name, value in e.parameters}


def register_effect(spec: EffectSpec) -> None:
    """Add a row to the effects table (a new physics unit: see :mod:`cageless.simulation.models.race_laws`).

    Raises
    ------
    ValueError
        For a name, flag or slot already in the table.
    """
    global EFFECTS
    taken = {n for e in EFFECTS for n in (e.name, e.flag, *e.slots)}
    clash = {spec.name, spec.flag, *spec.slots} & taken
    if clash or not spec.flag:
        raise ValueError(f"effect {spec.name!r}: needs a flag slot and new names; taken: {sorted(clash)}")
    EFFECTS = (*EFFECTS, spec)
    _BY_NAME[spec.name] = spec


@dataclass(frozen=True)
class EffectChoice:
    """Whether one effect is on, and why."""

    name: str
    on: bool
    reason: str
    forced: bool = False


#: What each model level integrates, and what it leaves out (simulation/models/planar.py and spatial.py).
LEVEL_DOF: dict[str, str] = {
    "planar": "per ball the orbital radius and angle and the spin about the shaft (3 DOF), the inner ring's "
              "y and z (2; its rotation is prescribed); the centrifugal force comes out of the polar equations; left out: the balls' axial "
              "motion and spin about y and z, the ring's axial motion and tilt",
    "spatial": "per ball the orbital radius, angle and axial position and the full spin vector (6 DOF), the inner "
               "ring's x, y, z and tilt about y and z (5); centrifugal and gyroscopic effects come out of the "
               "inertial-frame equations",
}


@dataclass(frozen=True)
class ModelChoice:
    """The model level and the effects a scene uses, each with its reason."""

    level: str
    level_reason: str
    effects: tuple[EffectChoice, ...]

    @property
    def active(self) -> tuple[str, ...]:
        """Names of the effects that are on."""
        return tuple(e.name for e in self.effects if e.on)

    def to_json(self) -> str:
        """The choice as JSON (stored as ``effects_json`` in simulation traces)."""
        return json.dumps({"level": self.level, "level_reason": self.level_reason,
                           "degrees_of_freedom": LEVEL_DOF.get(self.level, ""),
                           "effects": [asdict(e) for e in self.effects]}, sort_keys=True)

    def explain(self) -> str:
        """Human-readable lines: the level and each effect with its reason."""
        lines = [f"level: {self.level} ({self.level_reason})"]
        if self.level in LEVEL_DOF:
            lines.append(f"  degrees of freedom: {LEVEL_DOF[self.level]}")
        for e in self.effects:
            tag = "on " if e.on else "off"
            lines.append(f"  {tag} {e.name:<18} {e.reason}{' [forced]' if e.forced else ''}")
        return "\n".join(lines)


def _scene_level(s: Scene) -> tuple[str, str]:
    why = []
    if s.conditions.axial_load_n > 0:
        why.append(f"axial load {s.conditions.axial_load_n:g} N")
    if s.misalignment_rad > 0:
        why.append(f"misalignment {s.misalignment_rad:g} rad")
    if s.moment_load_nm > 0:
        why.append(f"moment load {s.moment_load_nm:g} N m")
    if s.orientation == "vertical" and s.gravity_m_s2 > 0:
        why.append("gravity along the shaft (vertical shaft)")
    if why:
        return "spatial", "needed for " + ", ".join(why)
    radial = s.conditions.radial_load_n
    if radial > 0:
        return "planar", f"pure radial load of {radial:g} N on an aligned bearing: ball centres stay in the mid-plane"
    weight = ", the ring's weight its only load" if s.gravity_m_s2 > 0 else ""
    return "planar", (f"radial and axial load 0 N on an aligned bearing{weight}: ball centres stay in the "
                      "mid-plane")


def choose_model(scene: Scene, level: str | None = None, effects: Mapping[str, bool] | None = None,
                 force: bool = False) -> ModelChoice:
    """Decide the model level and effects for ``scene``, then apply the user's overrides.

    Raises
    ------
    UsageError
        For an unknown level or effect (with a suggestion), an effect that needs a lubricant in a dry
        scene, or an override that contradicts the scene without ``force``.
    """
    auto_level, level_reason = _scene_level(scene)
    chosen_level = auto_level
    if level is not None:
        if level not in LEVELS:
            raise UsageError(f"--level {level}: unknown level." + (suggest(level, LEVELS) or f" Use {LEVELS}."))
        if level != auto_level:
            if level == "planar" and not force:
                raise UsageError(f"--level planar contradicts the scene: the spatial level is {level_reason}. "
                                 "Add --force to run the planar model anyway.")
            level_reason = f"forced by the user (the scene alone gives {auto_level}: {level_reason})"
        chosen_level = level
    choices = []
    overrides = dict(effects or {})
    for name in overrides:
        if name not in _BY_NAME:
            raise UsageError(f"--effect {name}: unknown effect." + (suggest(name, _BY_NAME) or
                             f" Effects: {', '.join(_BY_NAME)}."))
    for spec in EFFECTS:
        on, reason = spec.rule(scene)
        if spec.name in overrides and overrides[spec.name] != on:
            want = overrides[spec.name]
            check_lubricant({spec.name: want}, scene.lubricated)
            if want and spec.opt_in:
                choices.append(EffectChoice(spec.name, True, STRIP_DAMPING_ON if spec.name == "strip_damping"
                                            else f"on by the user ({reason})"))
                continue
            if not force:
                raise UsageError(f"--effect {spec.name}={'on' if want else 'off'} contradicts the scene "
                                 f"({reason}). Add --force to override.")
            choices.append(EffectChoice(spec.name, want, f"forced {'on' if want else 'off'} by the user "
                                        f"(the scene alone: {reason})", forced=True))
        else:
            choices.append(EffectChoice(spec.name, on, reason))
    choices = _without_idle(choices, overrides)
    check_lubricant({c.name: c.on for c in choices}, scene.lubricated)
    for c in choices:
        if c.on and chosen_level not in _BY_NAME[c.name].levels:
            raise UsageError(f"--effect {c.name}=on: it is built into the {' and '.join(_BY_NAME[c.name].levels)} "
                             f"model only, and this scene runs at the {chosen_level} level ({level_reason}): drop "
                             f"--effect {c.name}=on, or run a pure radial load on an aligned bearing.")
    return ModelChoice(level=chosen_level, level_reason=level_reason, effects=tuple(choices))


def _without_idle(choices: list[EffectChoice], overrides: Mapping[str, bool]) -> list[EffectChoice]:
    """``choices`` with every effect whose :attr:`EffectSpec.acts_on` effects are all off switched off, with
    that reason (so its flag never claims a law that is not evaluated).

    Raises
    ------
    UsageError
        When the user asked for such an effect explicitly.
    """
    on = {c.name: c.on for c in choices}
    out = []
    for c in choices:
        targets = _BY_NAME[c.name].acts_on
        if c.on and targets and not any(on.get(t, False) for t in targets):
            idle = " and ".join(targets) + (" is" if len(targets) == 1 else " are") + " off"
            if overrides.get(c.name):
                raise UsageError(f"--effect {c.name}=on changes the law of {' or '.join(targets)}, and {idle}: "
                                 f"switch one on or drop --effect {c.name}=on.")
            c = EffectChoice(c.name, False, f"nothing to act on: {idle}", forced=c.forced)
            on[c.name] = False
        out.append(c)
    return out


def check_lubricant(on: Mapping[str, bool], lubricated: bool) -> None:
    """The one check that the effects ``on`` (name -> on) fit the bearing: no lubricant effect on a dry bearing,
    and no dry bearing without its dry friction while a friction law is needed.

    Raises
    ------
    UsageError
        Naming the effect and the override that fixes it.
    """
    if lubricated:
        return
    for spec in EFFECTS:
        if spec.needs_lubricant and on.get(spec.name, False):
            raise UsageError(f"--effect {spec.name}=on needs a lubricant, and the bearing is dry: "
                             f"drop it (--effect {spec.name}=off) or add a lubricant.")
    for name in _BY_NAME["dry_friction"].acts_on:
        if on.get(name, False) and not on.get("dry_friction", False):
            raise UsageError(f"{name} on a dry bearing needs the dry_friction effect (--effect dry_friction=on): "
                             "the traction curve is a lubricated law.")


def parameter_slots(body: tuple[str, ...]) -> tuple[str, ...]:
    """A model's parameter slots: its ``body`` slots, then each effect's flag and parameter slots in table order
    (a slot two effects read is listed once)."""
    names = list(body)
    for spec in EFFECTS:
        for name in (spec.flag, *spec.slots):
            if name not in names:
                names.append(name)
    return tuple(names)


def effect_flags(on: Mapping[str, bool]) -> dict[str, float]:
    """Flag slot -> 1.0 or 0.0 for every effect of the table; an effect ``on`` does not name is off."""
    unknown = set(on) - set(_BY_NAME)
    if unknown:
        name = sorted(unknown)[0]
        raise UsageError(f"--effect {name}: unknown effect." + (suggest(name, _BY_NAME) or
                         f" Effects: {', '.join(_BY_NAME)}."))
    return {spec.flag: float(bool(on.get(spec.name, False))) for spec in EFFECTS}


def parse_effect_overrides(items: list[str]) -> dict[str, bool]:
    """Parse ``NAME=on|off`` strings from the command line."""
    out: dict[str, bool] = {}
    for item in items:
        name, sep, value = item.partition("=")
        if not sep or value.lower() not in ("on", "off"):
            raise UsageError(f"--effect {item}: write NAME=on or NAME=off.")
        out[name.strip()] = value.lower() == "on"
    return out


def removable_effects() -> tuple[str, ...]:
    """The effects an ablation removes in turn: every row of the table but the contacts that make the model and
    the opt-in alternatives (no scene has them on)."""
    return tuple(e.name for e in EFFECTS if e.removable and not e.opt_in)


def describe_table() -> list[dict[str, str]]:
    """The effects table as rows (name, physics), for docs and reports."""
    return [{"name": e.name, "physics": e.physics} for e in EFFECTS]

