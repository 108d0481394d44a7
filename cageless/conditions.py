"""Operating conditions of a video and where they come from.

A video's conditions are merged key by key from three sources, highest
precedence first:

1. a sidecar with the video's stem: ``n3000.toml`` or ``n3000.json`` beside
   ``n3000.cine``;
2. a ``conditions.csv`` in the folder, with columns ``file, speed_rpm``
   and optionally ``radial_load_n, axial_load_n, fps, px_per_mm, camera_roll_deg``;
3. the file name, e.g. ``n3000_Fr500_Fa0.cine``.

Only ``speed_rpm`` is required; the loads default to 0 and the camera keys to
what the video file says (``None`` here). A malformed source is an error, never
silently skipped, and every error names the file it is about.

A sidecar or ``conditions.csv`` may also describe the bearing a video shows,
when it is not the configured one: ``n_balls``, ``ball_diameter_mm`` and
``pitch_diameter_mm`` (:data:`BEARING_KEYS`). They are kept apart from the
operating conditions (:attr:`ResolvedConditions.bearing_keys`) and applied with
:func:`bearing_with_keys`.
"""

from __future__ import annotations

import dataclasses
import json
import logging
import math
import os
import re
import tomllib
from collections.abc import Mapping
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import pandas as pd

from cageless.bearing import Bearing, Geometry
from cageless.errors import CagelessError, ConditionsError, MissingConditionsError, ParameterError, suggest
from cageless.units import rpm_to_rad_s

__all__ = [
    "CONDITION_KEYS",
    "BEARING_KEYS",
    "VIDEO_SUFFIXES",
    "IMAGE_SUFFIXES",
    "OperatingConditions",
    "ResolvedConditions",
    "LabEntry",
    "is_qc_folder",
    "refuse_shared_names",
    "read_sidecar",
    "read_conditions_csv",
    "parse_file_name",
    "resolve_conditions",
    "find_videos",
    "discover_lab",
    "bearing_with_keys",
]

log = logging.getLogger(__name__)

CONDITION_KEYS = ("speed_rpm", "radial_load_n", "axial_load_n", "fps", "px_per_mm", "camera_roll_deg")
#: Optional keys describing the bearing a video shows (a sidecar or a conditions.csv column).
BEARING_KEYS = ("n_balls", "ball_diameter_mm", "pitch_diameter_mm")
_SOURCE_KEYS = CONDITION_KEYS + BEARING_KEYS
VIDEO_SUFFIXES = (".cine", ".avi", ".mp4", ".mkv")
IMAGE_SUFFIXES = (".tif", ".tiff", ".png")
CONDITIONS_CSV = "conditions.csv"
_POSITIVE_KEYS = ("speed_rpm", "fps", "px_per_mm")
_NON_NEGATIVE_KEYS = ("radial_load_n", "axial_load_n")


@dataclass(frozen=True)
class OperatingConditions:
    """The conditions a video was shot at (or a simulation is run for).

    Parameters
    ----------
    speed_rpm
        Inner-ring speed (rpm), finite and > 0.
    radial_load_n
        Radial load on the inner ring (N), >= 0; it acts toward -z.
    axial_load_n
        Axial load (N), >= 0.
    fps
        Frame rate override (frames/s), or ``None`` to take it from the video.
    px_per_mm
        Image scale override (pixels/mm), or ``None`` to measure it from the ring.
    camera_roll_deg
        Camera roll (deg), counter-clockwise from the bearing frame; ``None`` means 0.
    """

    speed_rpm: float
    radial_load_n: float = 0.0
    axial_load_n: float = 0.0
    fps: float | None = None
    px_per_mm: float | None = None
    camera_roll_deg: float | None = None

    def __post_init__(self) -> None:
        for key in CONDITION_KEYS:
            value = getattr(self, key)
            if value is None and key not in ("speed_rpm", "radial_load_n", "axial_load_n"):
                continue
            if isinstance(value, bool) or not isinstance(value, int | float):
                raise ParameterError(key, "must be a number", value)
            if not math.isfinite(value):
                raise ParameterError(key, "must be finite", value)
            if key in _POSITIVE_KEYS and value <= 0:
                raise ParameterError(key, "must be > 0", value)
            if key in _NON_NEGATIVE_KEYS and value < 0:
                raise ParameterError(
                    key, "must be >= 0 (the load direction is fixed by the bearing frame)", value
                )

    @property
    def speed_rad_s(self) -> float:
        """Inner-ring speed in rad/s."""
        return rpm_to_rad_s(self.speed_rpm)

    def to_dict(self) -> dict[str, float | None]:
        """Return the conditions as a plain dict keyed as in ``CONDITION_KEYS``."""
        return asdict(self)

    @classmethod
    def from_mapping(cls, values: Mapping[str, Any]) -> OperatingConditions:
        """Build conditions from a mapping, refusing unknown keys with a suggestion."""
        for key in values:
            if key not in CONDITION_KEYS:
                raise ParameterError(key, "is not a condition key" + suggest(key, CONDITION_KEYS))
        if "speed_rpm" not in values:
            raise ParameterError("speed_rpm", "is required")
        return cls(**dict(values))


@dataclass(frozen=True)
class ResolvedConditions:
    """Conditions of one video together with where each value came from.

    Attributes
    ----------
    video
        The video file (or image-sequence folder).
    conditions
        The merged conditions.
    origin
        For each key that a source gave, a description of that source.
    bearing_keys
        The :data:`BEARING_KEYS` the sources gave (empty: the configured bearing).
    """

    video: Path
    conditions: OperatingConditions
    origin: dict[str, str] = field(default_factory=dict)
    bearing_keys: dict[str, float] = field(default_factory=dict)


@dataclass(frozen=True)
class LabEntry:
    """One video of a lab folder: its conditions, or the error that stops it."""

    video: Path
    resolved: ResolvedConditions | None = None
    error: CagelessError | None = None

    @property
    def ok(self) -> bool:
        """True when the conditions were resolved."""
        return self.error is None


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
        table = pd.read_csv(path, dtype={"file": str}, skipinitialspace=True, sep=sep, decimal=decimal)
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
            rows[name] = _csv_values(path, line, row, table.columns)
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
            raise ConditionsError(
                path, f"missing column '{required}' (the header has {found}).",
                f"Columns are: file, {', '.join(CONDITION_KEYS)} (only file and speed_rpm are required), "
                "separated by commas.",
            )
    for col in list(table.columns):
        if col != "file" and col not in _SOURCE_KEYS:
            hint = suggest(col, _SOURCE_KEYS)
            if hint:  # a misspelled key would silently lose its value
                raise ConditionsError(path, f"unknown column '{col}'." + hint)
            log.warning("%s: ignoring column '%s'; the columns read are file, %s", path, col, ", ".join(_SOURCE_KEYS))
            table = table.drop(columns=col)
    return table


def _csv_values(path: Path, line: int, row: pd.Series, columns: pd.Index) -> dict[str, float]:
    """The numeric condition values of one CSV row, empty cells left out."""
    values: dict[str, float] = {}
    for key in _SOURCE_KEYS:
        if key not in columns or pd.isna(row[key]):
            continue
        try:
            values[key] = float(row[key])
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


def _sidecar_for(video: Path) -> Path | None:
    stem = video.name if video.is_dir() else video.stem
    candidates = [video.with_name(stem + ext) for ext in (".toml", ".json")]
    present = [c for c in candidates if c.is_file()]
    if len(present) > 1:
        raise ConditionsError(video, f"both {present[0].name} and {present[1].name} exist.", "Keep one sidecar.")
    return present[0] if present else None


def _csv_row(video: Path, table: Mapping[str, Mapping[str, float]]) -> Mapping[str, float] | None:
    stem = video.name if video.is_dir() else video.stem
    return table.get(video.name, table.get(stem))


def _csv_row_error(video: Path, row_errors: Mapping[str, ConditionsError]) -> ConditionsError | None:
    """The error of the CSV row that names ``video``, if that row was malformed."""
    stem = video.name if video.is_dir() else video.stem
    return row_errors.get(video.name, row_errors.get(stem))


def _csv_lists(path: Path, video: Path) -> bool:
    """Whether a ``conditions.csv`` that failed to read could name ``video``.

    True when its ``file`` column names the video, or when not even that column can be read: then any
    video may depend on it. A video the table does not name takes its conditions from its other sources.
    """
    try:
        sep, _ = _csv_dialect(path)
        names = pd.read_csv(path, dtype=str, skipinitialspace=True, sep=sep, keep_default_na=False)
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError, OSError):
        return True
    names.columns = [str(c).strip() for c in names.columns]
    if "file" not in names.columns:
        return True
    listed = {str(n).strip() for n in names["file"]}
    return bool({video.name, video.stem} & listed)


def _read_csv_for(video: Path, csv_path: Path, row_errors: dict[str, ConditionsError]) -> dict[str, dict[str, float]]:
    """The folder's ``conditions.csv`` for one video: its error if the video depends on it, else ``{}``."""
    try:
        return read_conditions_csv(csv_path, row_errors)
    except ConditionsError as exc:
        if _csv_lists(csv_path, video):
            raise
        log.warning("%s; %s is not listed there and takes its conditions from its other sources", exc, video.name)
        return {}


def _warn_disagreement(video: Path, sources: list[tuple[str, Mapping[str, float] | None]]) -> None:
    """Log each key two sources give different values for, naming which one wins."""
    given = [(label, values) for label, values in sources if values]
    for i, (label, values) in enumerate(given):
        for lower_label, lower in given[i + 1:]:
            for key in sorted(set(values) & set(lower)):
                if not math.isclose(values[key], lower[key], rel_tol=1e-9):
                    log.warning(
                        "%s: %s = %g from the %s overrides %g from the %s; remove one if it is wrong",
                        video.name, key, values[key], label, lower[key], lower_label,
                    )


def resolve_conditions(
    video: str | Path, csv_table: Mapping[str, Mapping[str, float]] | None = None,
    fallback_speed_rpm: float | None = None,
) -> ResolvedConditions:
    """Merge a video's conditions from sidecar, ``conditions.csv`` and file name.

    Parameters
    ----------
    video
        The video file or image-sequence folder.
    csv_table
        An already-read ``conditions.csv`` (see :func:`read_conditions_csv`). When
        ``None``, the folder's ``conditions.csv`` is read if present.
    fallback_speed_rpm
        A speed for a video whose sources give none (``track --speed-rpm``); the
        other keys its sources give are kept.

    Raises
    ------
    ConditionsError
        When a source is malformed, or no source gives ``speed_rpm``.
    """
    video = Path(video)
    if csv_table is None:
        csv_path = video.parent / CONDITIONS_CSV
        row_errors: dict[str, ConditionsError] = {}
        csv_table = _read_csv_for(video, csv_path, row_errors) if csv_path.is_file() else {}
        row_error = _csv_row_error(video, row_errors)
        if row_error is not None:
            raise row_error
    sources: list[tuple[str, Mapping[str, float] | None]] = []
    sidecar = _sidecar_for(video)
    sources.append((f"sidecar {sidecar.name}" if sidecar else "", read_sidecar(sidecar) if sidecar else None))
    sources.append((CONDITIONS_CSV, _csv_row(video, csv_table)))
    sources.append(("file name", parse_file_name(video)))
    _warn_disagreement(video, sources)
    merged: dict[str, float] = {}
    origin: dict[str, str] = {}
    for label, values in reversed(sources):  # lowest precedence first, higher ones overwrite
        for key, value in (values or {}).items():
            merged[key] = value
            origin[key] = label
    if "speed_rpm" not in merged and fallback_speed_rpm is not None:
        merged["speed_rpm"], origin["speed_rpm"] = float(fallback_speed_rpm), "--speed-rpm"
    if "speed_rpm" not in merged:
        raise MissingConditionsError(
            video, "no operating conditions found.",
            f"Give them in a sidecar ({video.stem}.toml with speed_rpm = ...), a row of "
            f"{CONDITIONS_CSV}, or the file name (e.g. n3000_Fr500_Fa0{video.suffix}).",
        )
    bearing_keys = {k: merged.pop(k) for k in BEARING_KEYS if k in merged}
    for key, value in bearing_keys.items():
        if not (math.isfinite(value) and value > 0) or (key == "n_balls" and (value != int(value) or value < 3)):
            need = "a whole number >= 3" if key == "n_balls" else "a finite number > 0"
            raise ConditionsError(video, f"invalid bearing key from {origin[key]}: {key} = {value:g} must be {need}.")
    try:
        conditions = OperatingConditions.from_mapping(merged)
    except ParameterError as exc:
        raise ConditionsError(video, f"invalid condition from {origin.get(exc.parameter, 'a source')}: {exc}") from exc
    return ResolvedConditions(video=video, conditions=conditions, origin=origin, bearing_keys=bearing_keys)


def bearing_with_keys(bearing: Bearing, resolved: ResolvedConditions) -> Bearing:
    """``bearing`` with the ball count and diameters a video's sources give (:data:`BEARING_KEYS`).

    The diametral clearance and the groove curvature factors are kept: the races sit at
    ``d_m -/+ (D + P_d / 2)`` (Harris & Kotzalas, *Rolling Bearing Analysis*, 5th ed., vol. 1, ch. 2).
    A ball of another diameter keeps the material: its mass scales as ``D^3`` (a homogeneous sphere).

    Raises
    ------
    ConditionsError
        When the keys describe a bearing that cannot exist (e.g. Z balls do not fit), naming the video.
    """
    keys = resolved.bearing_keys
    if not keys:
        return bearing
    g = bearing.geometry
    d = keys.get("ball_diameter_mm", g.ball_diameter_m * 1e3) * 1e-3
    d_m = keys.get("pitch_diameter_mm", g.pitch_diameter_m * 1e3) * 1e-3
    half = d + 0.5 * g.diametral_clearance_m
    try:
        geometry = Geometry(inner_race_diameter_m=d_m - half, outer_race_diameter_m=d_m + half, ball_diameter_m=d,
                            inner_curvature_factor=g.inner_curvature_factor,
                            outer_curvature_factor=g.outer_curvature_factor,
                            n_balls=int(keys.get("n_balls", g.n_balls)))
    except CagelessError as exc:
        raise ConditionsError(resolved.video, f"the bearing keys ({', '.join(sorted(keys))}) give an impossible "
                              f"bearing: {exc}") from exc
    label = ", ".join(f"{k} = {v:g}" for k, v in sorted(keys.items()))
    # a ball of another diameter, of the same steel, has the mass of a homogeneous sphere scaled by (D/D0)^3
    masses = dataclasses.replace(bearing.masses,
                                 ball_mass_kg=bearing.masses.ball_mass_kg * (d / g.ball_diameter_m) ** 3)
    return dataclasses.replace(bearing, geometry=geometry, masses=masses, name=f"{bearing.name} ({label})")


def _is_image_sequence(folder: Path) -> bool:
    if is_qc_folder(folder):
        return False
    return any(
        p.suffix.lower() in IMAGE_SUFFIXES and re.search(r"\d", p.stem) for p in folder.iterdir()
    )


def is_qc_folder(folder: Path) -> bool:
    """Whether ``folder`` is the QC folder of a cageless output (its PNGs are QC images, not a video's frames):
    a folder holding a tracker's ``*.candidates.csv`` beside ``*.frameNNNNNN.png`` images."""
    names = [p.name for p in folder.iterdir()] if folder.is_dir() else []
    return any(n.endswith(".candidates.csv") for n in names) and any(
        re.search(r"\.frame\d+\.png$", n) for n in names)


def find_videos(folder: str | Path) -> list[Path]:
    """List the videos of a lab folder: video files and numbered image-sequence sub-folders.

    Raises
    ------
    ConditionsError
        When ``folder`` is not a directory.
    """
    folder = Path(folder)
    if not folder.is_dir():
        raise ConditionsError(folder, "is not a folder.", "Point at the lab folder that holds the videos.")
    found = []
    for p in sorted(folder.iterdir()):
        if p.name.startswith("."):
            continue
        if p.is_file() and p.suffix.lower() in VIDEO_SUFFIXES:
            found.append(p)
        elif p.is_dir() and _is_image_sequence(p):
            found.append(p)
    return found


def _dangling_links(folder: Path) -> list[Path]:
    """Symbolic links in ``folder`` whose target is missing (they would otherwise be skipped silently)."""
    return [p for p in sorted(folder.iterdir()) if not p.name.startswith(".") and p.is_symlink() and not p.exists()]


def refuse_shared_names(entries: list[LabEntry]) -> list[LabEntry]:
    """Fail every video whose output name (``<stem>.trace.h5``) another video of the run shares, e.g. ``x.cine``
    and ``x.mkv``: one trace would overwrite the other. The others are unaffected."""
    def stem(p: Path) -> str:
        return p.name if p.is_dir() else p.stem

    by_stem: dict[str, list[Path]] = {}
    for e in entries:
        by_stem.setdefault(stem(e.video), []).append(e.video)
    out = []
    for e in entries:
        others = [p for p in by_stem[stem(e.video)] if p != e.video]
        if others and e.error is None:
            e = LabEntry(video=e.video, error=ConditionsError(
                e.video, f"has the same name as {', '.join(str(p) for p in others)}: their traces would overwrite "
                f"each other ({stem(e.video)}.trace.h5).", "Rename one of them, or track them into separate "
                "output folders."))
        out.append(e)
    return out


def discover_lab(folder: str | Path, fallback_speed_rpm: float | None = None) -> list[LabEntry]:
    """Find every video of a lab folder and resolve its conditions.

    ``fallback_speed_rpm`` is the speed of a video whose sources give none (see
    :func:`resolve_conditions`).

    A video whose conditions cannot be resolved gets an entry carrying the
    error; the others are unaffected. A bad row of ``conditions.csv`` fails only
    the video it names. A ``conditions.csv`` that cannot be read as a table
    (a missing or misspelled column, bad syntax) fails the videos it lists, and
    every video when not even its ``file`` column can be read.
    """
    folder = Path(folder)
    videos = find_videos(folder)
    csv_path = folder / CONDITIONS_CSV
    csv_error: ConditionsError | None = None
    table: dict[str, dict[str, float]] = {}
    row_errors: dict[str, ConditionsError] = {}
    if csv_path.is_file():
        try:
            table = read_conditions_csv(csv_path, row_errors)
        except ConditionsError as exc:
            csv_error = exc
    known = {v.name for v in videos} | {v.stem for v in videos}
    for name in sorted((set(table) | set(row_errors)) - known):
        log.warning("%s: row '%s' matches no video in the folder", csv_path, name)
    entries = [LabEntry(video=p, error=ConditionsError(
        p, f"is a broken symbolic link (to {os.readlink(p)}): the file it points to is missing.",
        "Fix or remove the link.")) for p in _dangling_links(folder)]
    unlisted = [v for v in videos if csv_error is not None and not _csv_lists(csv_path, v)]
    if unlisted:
        log.warning("%s; %s it does not list take%s %s conditions from %s other sources", csv_error,
                    *(("the video", "s", "its", "its") if len(unlisted) == 1 else
                      (f"the {len(unlisted)} videos", "", "their", "their")))
    for video in videos:
        error = (csv_error if video not in unlisted else None) or _csv_row_error(video, row_errors)
        if error is not None:
            entries.append(LabEntry(video=video, error=error))
            continue
        try:
            entries.append(LabEntry(video=video, resolved=resolve_conditions(video, table, fallback_speed_rpm)))
        except ConditionsError as exc:
            entries.append(LabEntry(video=video, error=exc))
    return refuse_shared_names(entries)
