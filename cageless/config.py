"""Configuration files (``--config FILE.toml``) shared by every subcommand.

A configuration file is TOML with two kinds of table:

* ``[bearing.geometry]``, ``[bearing.material]``, ``[bearing.masses]`` and
  ``[bearing.lubricant]`` override fields of the default bearing, by the
  dataclass field names (SI units in the names, e.g. ``ball_diameter_m``);
  ``[bearing] lubricant = false`` makes the bearing dry;
  ``[bearing.geometry] diametral_clearance_m = 32e-6`` sets the diametral clearance, the races moved apart
  symmetrically about the pitch circle (the default bearing has Table 1's zero clearance);
* ``[<subcommand>]`` tables (e.g. ``[info]``) give option defaults for that
  subcommand, by the option's long name with ``-`` or ``_``
  (``speed_rpm = 6000``). Options given on the command line win.

Example
-------
.. code-block:: toml

    [bearing.geometry]
    n_balls = 13

    [info]
    speed_rpm = 6000
"""

from __future__ import annotations

import dataclasses
import tomllib
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from cageless.bearing import Bearing, default_bearing, derived_name
from cageless.errors import UsageError

__all__ = ["load_config", "bearing_from_config"]


def load_config(path: str | Path) -> dict[str, Any]:
    """Read a TOML configuration file.

    Raises
    ------
    UsageError
        If the file is missing or not valid TOML; the message names the file.
    """
    path = Path(path)
    if path.is_dir():
        raise UsageError(f"--config {path}: is a folder; give a TOML file.")
    if not path.is_file():
        raise UsageError(f"--config {path}: no such file.")
    try:
        return tomllib.loads(path.read_text(encoding="utf-8"))
    except tomllib.TOMLDecodeError as exc:
        raise UsageError(f"--config {path}: not valid TOML ({exc}).") from exc
    except UnicodeDecodeError:
        raise UsageError(f"--config {path}: is not a text file (TOML is UTF-8 text).") from None


def bearing_from_config(config: Mapping[str, Any]) -> Bearing:
    """Return the default bearing with the ``[bearing.*]`` overrides of a configuration applied.

    Raises
    ------
    ParameterError
        For an unknown field (with a suggestion) or an invalid value.
    """
    section = dict(config.get("bearing", {}))
    bearing = default_bearing()
    lubricant = section.pop("lubricant", True)
    if not isinstance(lubricant, bool):
        raise UsageError(f"[bearing] lubricant = {lubricant!r}: must be true or false (false makes the bearing dry).")
    if lubricant is False:
        bearing = dataclasses.replace(bearing, lubricant=None)
    name = section.pop("name", None)
    for key, value in section.items():
        if not isinstance(value, Mapping):
            raise UsageError(f"[bearing] {key} = {value!r}: bearing fields go in their table, e.g. "
                             f"[bearing.geometry] n_balls = 14 ([bearing.geometry], [bearing.material], "
                             "[bearing.masses], [bearing.lubricant]).")
    overrides = {
        f"{part}.{key}": value
        for part, values in section.items()
        for key, value in (values.items() if isinstance(values, Mapping) else [(None, values)])
    }
    bearing = bearing.with_overrides(overrides)
    changes = {**overrides, **({"lubricant": "none"} if lubricant is False else {})}
    if name or dataclasses.replace(bearing, name=default_bearing().name) != default_bearing():
        bearing = dataclasses.replace(bearing, name=name or derived_name(default_bearing().name, changes))
    return bearing
