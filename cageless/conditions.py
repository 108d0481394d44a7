"""Operating conditions of a video and where they come from.

A video's conditions are merged key by key from three sources, highest
precedence first:

1. a sidecar with the video's stem: ``n3000.toml`` or ``n3000.json`` beside
   ``n3000.cine``;
2. a ``conditions.csv`` in the folder, with columns ``file, speed_rpm``
   and optionally ``radial_load_n, axial_load_n, fps, px_per_mm, camera_roll_deg``;
3. the file name, e.g. ``n3000_Fr500_Fa0.cine``.

Each source is read by :mod:`cageless.condition_sources`; this module merges them.

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
import logging
import math
import os
import re
from collections.abc import Mapping
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

from cageless.bearing import PITCH_NAME, Bearing
from cageless.condition_sources import (
    BEARING_KEYS,
    CONDITION_KEYS,
    csv_listed_names,
    parse_file_name,
    read_conditions_csv,
    read_sidecar,
)
from cageless.errors import CagelessError, ConditionsError, MissingConditionsError, ParameterError, suggest
from cageless.limits import LIMITS, hard_problem
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
    "nested_video_folders",
    "nested_videos_hint",
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

VIDEO_SUFFIXES = (".cine", ".avi", ".mp4", ".mkv")
IMAGE_SUFFIXES = (".tif", ".tiff", ".png")
CONDITIONS_CSV = "conditions.csv"
_NON_NEGATIVE_KEYS = ("radial_load_n", "axial_load_n")


@dataclass(frozen=True)
class OperatingConditions:
    """The conditions a video was shot at (or a simulation is run for).

    Parameters
    ----------
    speed_rpm
        Inner-ring speed (rpm), > 0 and at most :data:`~cageless.limits.MAX_SPEED_RPM` (600 000).
    radial_load_n
        Radial load on the inner ring (N), >= 0 and at most :data:`~cageless.limits.MAX_LOAD_N` (1 MN); it acts
        toward -z.
    axial_load_n
        Axial load (N), >= 0 and at most :data:`~cageless.limits.MAX_LOAD_N`.
    fps
        Frame rate override (frames/s), or ``None`` to take it from the video.
    px_per_mm
        Image scale override (pixels/mm), or ``None`` to measure it from the ring.
    camera_roll_deg
        Camera roll (deg), counter-clockwise from the bearing frame, within +-360; ``None`` means 0.

    Raises
    ------
    ParameterError
        For a value that breaks the hard rule the command line applies to it (:data:`cageless.limits.LIMITS`),
        naming the parameter and the rule.
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
            problem = hard_problem(key, value)  # the command line's hard rules (cageless.limits)
            if problem:
                lim = LIMITS[key]
                why = " (the load direction is fixed by the bearing frame)" if key in _NON_NEGATIVE_KEYS else ""
                hint = (f"Plausible values are {lim.plausible()}." if value > lim.hard_hi else "")
                raise ParameterError(key, f"{problem} {lim.unit}{why if value < 0 else ''}", value, hint=hint)

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


def _csv_lists(listed: set[str] | None, video: Path) -> bool:
    """Whether a ``conditions.csv`` that failed to read could name ``video``, from the names it lists
    (:func:`~cageless.condition_sources.csv_listed_names`; None: not even its ``file`` column was read, and any
    video may depend on it). A video the table does not name takes its conditions from its other sources.
    """
    return listed is None or bool({video.name, video.stem} & listed)


def _read_csv_for(video: Path, csv_path: Path, row_errors: dict[str, ConditionsError]) -> dict[str, dict[str, float]]:
    """The folder's ``conditions.csv`` for one video: its error if the video depends on it, else ``{}``."""
    try:
        return read_conditions_csv(csv_path, row_errors)
    except ConditionsError as exc:
        if _csv_lists(csv_listed_names(csv_path), video):
            raise
        log.warning("%s %s is not listed there and takes its conditions from its other sources", exc, video.name)
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
    fallback: Mapping[str, float] | None = None,
) -> ResolvedConditions:
    """Merge a video's conditions from sidecar, ``conditions.csv`` and file name.

    Parameters
    ----------
    video
        The video file or image-sequence folder.
    csv_table
        An already-read ``conditions.csv`` (see :func:`read_conditions_csv`). When
        ``None``, the folder's ``conditions.csv`` is read if present.
    fallback
        Values of ``speed_rpm``, ``radial_load_n`` or ``axial_load_n`` typed on the
        command line (``track --speed-rpm``): each stands in where no source gives
        that key; the other keys the sources give are kept.

    A video whose sources give no radial load is resolved at 0 N (an unloaded
    bearing) with a warning naming where to give it.

    Raises
    ------
    ConditionsError
        When a source is malformed, or no source gives ``speed_rpm``.
    """
    video = Path(video)
    merged, origin = _merged_sources(video, csv_table)
    for key, value in (fallback or {}).items():
        if key not in merged and value is not None:
            merged[key], origin[key] = float(value), "--" + key.replace("_", "-")
    if "speed_rpm" not in merged:
        raise MissingConditionsError(
            video, "no operating conditions found.",
            f"Give them in a sidecar ({video.stem}.toml with speed_rpm = ...), a row of "
            f"{CONDITIONS_CSV}, or the file name (e.g. n3000_Fr500_Fa0{video.suffix}).",
        )
    if "radial_load_n" not in merged:
        log.warning("%s: no radial load given: 0 N (an unloaded bearing) is assumed. Give radial_load_n in a sidecar "
                    "(%s.toml), a row of %s or the file name (e.g. _Fr500)", video.name, video.stem, CONDITIONS_CSV)
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


def _merged_sources(video: Path, csv_table: Mapping[str, Mapping[str, float]] | None
                    ) -> tuple[dict[str, float], dict[str, str]]:
    """The keys a video's sources give, higher precedence winning, and which source gave each (see
    :func:`resolve_conditions`); the folder's ``conditions.csv`` is read when ``csv_table`` is None."""
    if csv_table is None:
        csv_path = video.parent / CONDITIONS_CSV
        row_errors: dict[str, ConditionsError] = {}
        csv_table = _read_csv_for(video, csv_path, row_errors) if csv_path.is_file() else {}
        row_error = _csv_row_error(video, row_errors)
        if row_error is not None:
            raise row_error
    sidecar = _sidecar_for(video)
    sources: list[tuple[str, Mapping[str, float] | None]] = [
        (f"sidecar {sidecar.name}" if sidecar else "", read_sidecar(sidecar) if sidecar else None),
        (CONDITIONS_CSV, _csv_row(video, csv_table)),
        ("file name", parse_file_name(video)),
    ]
    _warn_disagreement(video, sources)
    merged: dict[str, float] = {}
    origin: dict[str, str] = {}
    for label, values in reversed(sources):  # lowest precedence first, higher ones overwrite
        for key, value in (values or {}).items():
            merged[key] = value
            origin[key] = label
    return merged, origin


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
    names = {"ball_diameter_mm": "geometry.ball_diameter_m", "pitch_diameter_mm": PITCH_NAME}
    overrides: dict[str, float | int] = {names[k]: v * 1e-3 for k, v in keys.items() if k in names}
    if "n_balls" in keys:
        overrides["geometry.n_balls"] = int(keys["n_balls"])
    try:  # the races follow the ball and pitch diameters, the clearance kept; the ball's mass scales as D^3
        described = bearing.with_overrides(overrides)
    except CagelessError as exc:
        raise ConditionsError(resolved.video, f"the bearing keys ({', '.join(sorted(keys))}) give an impossible "
                              f"bearing: {exc}") from exc
    label = ", ".join(f"{k} = {v:g}" for k, v in sorted(keys.items()))
    return dataclasses.replace(described, name=f"{bearing.name} ({label})")


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


def nested_video_folders(folder: str | Path) -> list[tuple[Path, int]]:
    """Sub-folders of a lab folder that hold video files of their own, with how many (they are not read: a lab
    folder is its own files and its image-sequence sub-folders). Hidden and image-sequence folders are left out."""
    folder = Path(folder)
    if not folder.is_dir():
        return []
    out = []
    for p in sorted(folder.iterdir()):
        if p.name.startswith(".") or not p.is_dir() or _is_image_sequence(p):
            continue
        n = sum(1 for f in p.iterdir() if f.is_file() and f.suffix.lower() in VIDEO_SUFFIXES)
        if n:
            out.append((p, n))
    return out


def nested_videos_hint(folder: str | Path) -> str:
    """A sentence naming the sub-folders of ``folder`` that hold videos, or ``""`` when none do."""
    nested = nested_video_folders(folder)
    if not nested:
        return ""
    names = ", ".join(f"'{p.name}' ({n} video{'s' if n > 1 else ''})" for p, n in nested)
    return (f" Videos in sub-folders are not read: {names}; point at such a folder itself (e.g. "
            f"'{nested[0][0]}') to include them.")


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


def discover_lab(folder: str | Path, fallback: Mapping[str, float] | None = None) -> list[LabEntry]:
    """Find every video of a lab folder and resolve its conditions.

    ``fallback`` holds values typed on the command line for videos whose sources give none (see
    :func:`resolve_conditions`).

    A video whose conditions cannot be resolved gets an entry carrying the
    error; the others are unaffected. A bad row of ``conditions.csv`` fails only
    the video it names. A ``conditions.csv`` that cannot be read as a table
    (a missing or misspelled column, bad syntax) fails the videos it lists, and
    every video when not even its ``file`` column can be read.
    """
    folder = Path(folder)
    videos = find_videos(folder)
    hint = nested_videos_hint(folder)
    if videos and hint:
        log.warning("%s:%s", folder, hint)
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
    listed = csv_listed_names(csv_path) if csv_error is not None else None
    unlisted = [v for v in videos if csv_error is not None and not _csv_lists(listed, v)]
    if unlisted:
        log.warning("%s %s it does not list take%s %s conditions from %s other sources", csv_error,
                    *(("the video", "s", "its", "its") if len(unlisted) == 1 else
                      (f"the {len(unlisted)} videos", "", "their", "their")))
    for video in videos:
        error = (csv_error if video not in unlisted else None) or _csv_row_error(video, row_errors)
        if error is not None:
            entries.append(LabEntry(video=video, error=error))
            continue
        try:
            resolved = resolve_conditions(video, table, fallback)
            entries.append(LabEntry(video=video, resolved=resolved))
        except ConditionsError as exc:
            entries.append(LabEntry(video=video, error=exc))
    return refuse_shared_names(entries)
