"""Extra race-contact force laws, each one physics module plus its parameters.

A law is a compiled function ``law(delta, delta_dot, q, p, s) -> f``: the normal force (N) it adds at a race
contact of overlap ``delta`` (m) closing at ``delta_dot`` (m/s), where the Hertz and damping force is
``q`` (N); ``p`` is the model's parameter vector and ``s`` the index of its row's first parameter slot (the
row's slots follow in their order: ``p[s]``, ``p[s + 1]``, ...; a compile-time constant), so a law never
needs the layout. It is
registered with its row of the effects table (:func:`register_race_law`): the row's flag switches it
(an effect that is off is never evaluated) and the row's slots, filled by the row's ``fill`` from the
run's :class:`~cageless.simulation.parameters.ModelParameters`, are its parameters. Its force acts along the
contact normal in both models (planar and spatial, both races), and its power ``f delta_dot`` is booked
as dissipated.

A law shipped as its own installed package is found through the entry-point group
:data:`ENTRY_POINT_GROUP` when :mod:`cageless.simulation` is imported (:func:`load_installed`), so the command
line, reports and sweeps see it with no other change.

The models compile the registered laws into their race contact (:data:`race_extra`, generated here), so
laws are registered before the models are imported (before the parameter layout is generated), and the
cache key of the compiled kernels includes them (:func:`key`, :mod:`cageless.simulation._cache`). With none
registered, :data:`ANY` is False and the models' race contact compiles exactly as without this module.
"""

from __future__ import annotations

import hashlib
import marshal
import sys
from typing import Any

import numba

from cageless.simulation.effects import EffectSpec, register_effect

__all__ = ["register_race_law", "compose", "key", "registered", "load_installed", "ENTRY_POINT_GROUP"]

#: The entry-point group an installed package names its law modules under (``[project.entry-points."cageless.race_laws"]``
#: in its ``pyproject.toml``); each module registers its law when imported (:func:`load_installed`).
ENTRY_POINT_GROUP = "cageless.race_laws"

_LAWS: list[tuple[str, str | None, Any]] = []  # (flag slot, first parameter slot, compiled law)


def register_race_law(effect: EffectSpec, law: Any) -> None:
    """Add ``effect`` to the effects table and ``law`` (compiled, ``inline="always"`` advised) to the race contact.

    Raises
    ------
    RuntimeError
        When the models are already imported: their parameter layout and kernels are fixed then.
    """
    if "cageless.simulation.models.base" in sys.modules:
        raise RuntimeError("register race-contact laws before the models are imported (simulation.models.base "
                           "generates the parameter layout from the effects table once)")
    register_effect(effect)
    _LAWS.append((effect.flag, effect.slots[0] if effect.slots else None, law))


def load_installed() -> tuple[str, ...]:
    """Import every module installed under :data:`ENTRY_POINT_GROUP` (each registers its law when imported);
    returns their entry-point names. A module that fails to load is skipped with a warning naming it."""
    import warnings
    from importlib.metadata import entry_points

    loaded = []
    for ep in entry_points(group=ENTRY_POINT_GROUP):
        try:
            ep.load()
        except Exception as exc:  # noqa: BLE001 - a broken plugin must not stop the tool
            warnings.warn(f"race-contact law {ep.name!r} ({ep.value}) was not loaded: {exc}", stacklevel=2)
            continue
        loaded.append(ep.name)
    return tuple(loaded)


def registered() -> tuple[str, ...]:
    """Flag slots of the registered laws, in order."""
    return tuple(flag for flag, _, _ in _LAWS)


def key() -> str:
    """A digest of the registered laws (their flags and compiled code), part of the kernels' cache key."""
    h = hashlib.sha256()
    for flag, _, law in _LAWS:
        h.update(flag.encode())
        h.update(marshal.dumps(getattr(law, "py_func", law).__code__))
    return h.hexdigest()


def compose(layout: Any) -> Any:
    """The compiled sum of the registered laws, each under its flag, for the slots of ``layout``."""
    lines = ["def race_extra(delta, delta_dot, q, p):", "    f = 0.0"]
    ns: dict[str, Any] = {}
    for i, (flag, first, law) in enumerate(_LAWS):
        ns[f"law{i}"] = law
        s = layout.index(first) if first is not None else -1
        lines += [f"    if p[{layout.index(flag)}] > 0.5:", f"        f += law{i}(delta, delta_dot, q, p, {s})"]
    lines.append("    return f")
    exec("\n".join(lines), ns)  # noqa: S102 - generated from the registry above, no user text
    return numba.njit(inline="always")(ns["race_extra"])


#: Whether any law is registered (a compile-time constant of the models' race contact).
ANY = False


def freeze() -> bool:
    """Fix :data:`ANY` when the models import (called by :mod:`cageless.simulation.models.contact_laws`)."""
    global ANY
    ANY = bool(_LAWS)
    return ANY
