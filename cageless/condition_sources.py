"""Reading each source of a video's conditions: a sidecar, a folder's ``conditions.csv`` and the file name.

Each reader checks its source and raises :class:`~cageless.errors.ConditionsError` naming the file and saying
how to fix it; merging the sources is :mod:`cageless.conditions`' work.
"""

from __future__ import annotations

import difflib
import json
import logging
import re
import tomllib
from pathlib import Path
from typing import Any

import pandas as pd

from cageless.errors import ConditionsError, suggest

__all__ = [
    "CONDITION_KEYS",
    "BEARING_KEYS",
    "read_sidecar",
    "read_conditions_csv",
    "csv_listed_names",
    "parse_file_name",
]

log = logging.getLogger("cageless.conditions")

CONDITION_KEYS = ("speed_rpm", "radial_load_n", "axial_load_n", "fps", "px_per_mm", "camera_roll_deg")
#: Optional keys describing the bearing a video shows (a sidecar or a conditions.csv column).
BEARING_KEYS = ("n_balls", "ball_diameter_mm", "pitch_diameter_mm")
_SOURCE_KEYS = CONDITION_KEYS + BEARING_KEYS


def _check_number(path: Path, key: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ConditionsError(path, f"'{key}' must be a number, got {value!r}.")
    return float(value)


def read_sidecar(path: str | Path) -> dict[str, float]:
    """Read a ``.toml`` or ``.json`` sidecar of condition keys.

    Raises
    ------
    ConditionsError
        On a syntax error, a non-table document, an unknown key or a non-numeric value.
    """
    path = Path(path)
    text = path.read_text(encoding="utf-8")
    try:
        data = tomllib.loads(text) if path.suffix == ".toml" else json.loads(text)
    except (tomllib.TOMLDecodeError, json.JSONDecodeError) as exc:
        raise ConditionsError(path, f"cannot parse the sidecar: {exc}.", "Fix its syntax.") from exc
    if not isinstance(data, dict):
        raise ConditionsError(path, "the sidecar must hold a table of condition keys.")
    out: dict[str, float] = {}
    for key, value in data.items():
        if key not in _SOURCE_KEYS:
            hint = suggest(key, _SOURCE_KEYS).strip() or f"Valid keys: {', '.join(_SOURCE_KEYS)}."
            raise ConditionsError(path, f"unknown key '{key}'.", hint)
        out[key] = _check_number(path, key, value)
    return out


def read_conditions_csv(
    path: str | Path, row_errors: dict[str, ConditionsError] | None = None
) -> dict[str, dict[str, float]]:
    """Read a folder's ``conditions.csv`` into ``{file name: {key: value}}``.

    Empty cells are left out (they take the default). Rows are matched to videos
    by file name or by stem.

    Parameters
    ----------
    path
        The CSV file.
    row_errors
        When given, a problem confined to one row (a non-numeric cell, a file
        listed twice) does not fail the whole table: the row is left out and
        its error is stored here under the row's file name, so that only that
        video fails. A row with an empty ``file`` cell is then skipped with a
        warning.

    Raises
    ------
    ConditionsError
        On a missing ``file`` or ``speed_rpm`` column, an unknown column, or
        (without ``row_errors``) a non-numeric cell or a duplicated file.
    """
    path = Path(path)
    sep, decimal = _csv_dialect(path)
    try:
        table = pd.read_csv(path, dtype={"file": str}, skipinitialspace=True, sep=sep, decimal=decimal,
                            thousands="." if decimal == "," else None)
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as exc:
        raise ConditionsError(path, f"cannot parse the CSV: {exc}.") from exc
    table = _checked_columns(path, table)
    rows: dict[str, dict[str, float]] = {}
    seen: set[str] = set()
    for i, row in table.iterrows():
        line = int(i) + 2  # 1-based, after the header
        name = str(row["file"]).strip()
        try:
            if not name or name == "nan":
                raise ConditionsError(path, f"line {line}: empty 'file' cell.", "Name the video in the 'file' column.")
            if name in seen:
                rows.pop(name, None)  # neither row can be trusted
                raise ConditionsError(path, f"line {line}: '{name}' is listed twice.", "Keep one row per video.")
            seen.add(name)
            rows[name] = _csv_values(path, line, row, table.columns, decimal)
        except ConditionsError as exc:
            if row_errors is None:
                raise
            if not name or name == "nan":
                log.warning("%s", exc)
            else:
                row_errors[name] = exc
    return rows


def _checked_columns(path: Path, table: pd.DataFrame) -> pd.DataFrame:
    """The table with stripped column names, its required columns checked and unknown ones dropped."""
    table.columns = [str(c).strip() for c in table.columns]
    for required in ("file", "speed_rpm"):
        if required not in table.columns:
            found = ", ".join(repr(c) for c in table.columns[:8])
            misspelled = difflib.get_close_matches(required, [str(c) for c in table.columns], n=1, cutoff=0.6)
            raise ConditionsError(
                path, f"missing column '{required}' (the header has {found}).",
                (f"Is '{misspelled[0]}' meant to be '{required}'? " if misspelled else "")
                + f"Columns are: file, {', '.join(_SOURCE_KEYS)} (only file and speed_rpm are required), "
                "separated by commas (or by semicolons, with decimal commas).",
            )
    for col in list(table.columns):
        if col != "file" and col not in _SOURCE_KEYS:
            hint = suggest(col, _SOURCE_KEYS)
            if hint:  # a misspelled key would silently lose its value
                raise ConditionsError(path, f"unknown column '{col}'." + hint)
            log.warning("%s: ignoring column '%s'; the columns read are file, %s", path, col, ", ".join(_SOURCE_KEYS))
            table = table.drop(columns=col)
    return table


def _csv_values(path: Path, line: int, row: pd.Series, columns: pd.Index, decimal: str = ".") -> dict[str, float]:
    """The numeric condition values of one CSV row, empty cells left out.

    A cell pandas left as text (a column where another row holds a word) is read in the table's own number
    format: with decimal commas, ``6.000`` is 6000 and ``500,5`` is 500.5, as in the columns pandas parsed.
    """
    values: dict[str, float] = {}
    for key in _SOURCE_KEYS:
        if key not in columns or pd.isna(row[key]):
            continue
        cell = row[key]
        if isinstance(cell, str) and decimal == ",":
            cell = cell.strip().replace(".", "").replace(",", ".")
        try:
            values[key] = float(cell)
        except (TypeError, ValueError):
            raise ConditionsError(
                path, f"line {line}: '{key}' = {row[key]!r} is not a number.", "Write a plain number in that cell."
            ) from None
    return values


def _csv_dialect(path: Path) -> tuple[str, str]:
    """The field separator and decimal mark of a conditions CSV: ``","``/``"."``, or the European ``";"``/``","``.

    A header with semicolons and no commas is read as semicolon-separated (with decimal commas when
    the rows hold digits separated by a comma), and logged.
    """
    try:
        with open(path, encoding="utf-8", errors="replace") as fh:
            lines = [fh.readline() for _ in range(20)]
    except OSError:
        return ",", "."
    header = lines[0]
    if ";" in header and "," not in header:
        decimal = "," if any(re.search(r"\d,\d", line) for line in lines[1:]) else "."
        log.info("%s: read as semicolon-separated%s", path, " with decimal commas" if decimal == "," else "")
        return ";", decimal
    if "\t" in header and "," not in header:
        return "\t", "."
    return ",", "."


_NUMBER = r"(\d+(?:\.\d+)?)"
_TOKEN_PATTERNS = {
    "speed_rpm": re.compile(rf"^n{_NUMBER}(?:rpm)?$", re.IGNORECASE),
    "radial_load_n": re.compile(rf"^fr{_NUMBER}n?$", re.IGNORECASE),
    "axial_load_n": re.compile(rf"^fa{_NUMBER}n?$", re.IGNORECASE),
}
_SUSPECT = re.compile(r"^(?:n\d|f[ra](?![a-z]))", re.IGNORECASE)


def parse_file_name(path: str | Path) -> dict[str, float] | None:
    """Read conditions from a file name such as ``n3000_Fr500_Fa0.cine``.

    Tokens are separated by ``_``, ``-`` or spaces: ``n<rpm>``, ``Fr<N>``,
    ``Fa<N>`` (case-insensitive, optional ``rpm``/``N`` suffix). Other tokens
    are ignored.

    Returns
    -------
    dict or None
        The keys found, or ``None`` when the name carries no conditions.

    Raises
    ------
    ConditionsError
        When a token looks like a condition but cannot be read, a key repeats,
        or loads are given without a speed.
    """
    path = Path(path)
    stem = path.name if path.is_dir() else path.stem
    found: dict[str, float] = {}
    for token in re.split(r"[_\-\s]+", stem):
        matched = False
        for key, pattern in _TOKEN_PATTERNS.items():
            m = pattern.match(token)
            if m:
                if key in found:
                    raise ConditionsError(path, f"the file name gives '{key}' twice.")
                found[key] = float(m.group(1))
                matched = True
        if not matched and _SUSPECT.match(token):
            raise ConditionsError(
                path, f"cannot read the file-name token '{token}'.",
                "Use the pattern n3000_Fr500_Fa0 (speed in rpm, loads in N), or give a sidecar.",
            )
    if not found:
        return None
    if "speed_rpm" not in found:
        raise ConditionsError(path, "the file name gives loads but no speed (e.g. n3000).")
    return found


def csv_listed_names(path: str | Path) -> set[str] | None:
    """The names in a ``conditions.csv``'s ``file`` column, read leniently (every cell as text); None when not
    even that column can be read, so that any video of the folder may depend on the table."""
    path = Path(path)
    try:
        sep, _ = _csv_dialect(path)
        names = pd.read_csv(path, dtype=str, skipinitialspace=True, sep=sep, keep_default_na=False)
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError, OSError):
        return None
    names.columns = [str(c).strip() for c in names.columns]
    if "file" not in names.columns:
        return None
    return {str(n).strip() for n in names["file"]}

