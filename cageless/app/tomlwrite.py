"""A small TOML writer for the files cageless writes (parameter sets); :mod:`tomllib` only reads.

Covers what those files hold: tables, arrays of tables, strings, booleans, finite and non-finite
floats, integers and flat arrays of them (TOML 1.0).
"""

from __future__ import annotations

import json
import math
import re
from collections.abc import Mapping
from typing import Any

__all__ = ["dumps"]

_BARE = re.compile(r"^[A-Za-z0-9_-]+$")


def _key(k: str) -> str:
    return k if _BARE.match(k) else json.dumps(k)


def _value(v: Any) -> str:
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        return "nan" if math.isnan(v) else ("inf" if v > 0 else "-inf") if math.isinf(v) else repr(v)
    if isinstance(v, str):
        return json.dumps(v, ensure_ascii=False)
    if isinstance(v, list | tuple):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    if hasattr(v, "item"):  # numpy scalars
        return _value(v.item())
    raise TypeError(f"cannot write {type(v).__name__} to TOML")


def _is_table_array(v: Any) -> bool:
    return isinstance(v, list) and bool(v) and all(isinstance(x, Mapping) for x in v)


def _table(name: str, table: Mapping[str, Any], out: list[str]) -> None:
    plain = {k: v for k, v in table.items() if not isinstance(v, Mapping) and not _is_table_array(v)}
    if name and (plain or not table):
        out.append(f"\n[{name}]")
    out.extend(f"{_key(k)} = {_value(v)}" for k, v in plain.items())
    for k, v in table.items():
        full = f"{name}.{_key(k)}" if name else _key(k)
        if isinstance(v, Mapping):
            _table(full, v, out)
        elif _is_table_array(v):
            for item in v:
                out.append(f"\n[[{full}]]")
                out.extend(f"{_key(ik)} = {_value(iv)}" for ik, iv in item.items())


def dumps(doc: Mapping[str, Any]) -> str:
    """``doc`` as TOML text (nested mappings become tables; lists of mappings, arrays of tables)."""
    out: list[str] = []
    _table("", doc, out)
    return "\n".join(out).lstrip("\n") + "\n"
