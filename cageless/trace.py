"""Trace files: the ``cageless-trace/1`` HDF5 trace format.

A trace carries per-ball orbital angle, revolution speed, slip and a validity
mask over time, plus the conditions and the bearing it belongs to. Video
traces add camera attributes (:class:`VideoInfo`); simulation traces add
solver attributes (:class:`SimulationInfo`), the ``balls/``, ``contacts/`` and
``inner_ring/`` groups and the ``events`` table.

:func:`write_trace` is atomic (temporary file, then rename) and
:func:`read_trace` refuses files with a missing or newer schema or
inconsistent shapes, saying why. A round trip is lossless.
"""

from __future__ import annotations

import io
import json
import re
from collections.abc import Mapping
from dataclasses import asdict, dataclass, field
from datetime import UTC, datetime
from pathlib import Path
from typing import Any, Literal

import h5py
import numpy as np
import numpy.typing as npt
import pandas as pd

from cageless._version import __version__
from cageless.atomic import atomic_path
from cageless.errors import TraceFormatError

__all__ = [
    "SCHEMA",
    "EVENT_COLUMNS",
    "EVENT_KINDS",
    "VideoInfo",
    "SimulationInfo",
    "Trace",
    "write_trace",
    "read_trace",
    "empty_events",
]

SCHEMA_NAME = "cageless-trace"
SCHEMA_MAJOR = 1
SCHEMA = f"{SCHEMA_NAME}/{SCHEMA_MAJOR}"
_SCHEMA_RE = re.compile(rf"^{SCHEMA_NAME}/(\d+)(?:\.(\d+))?$")

EVENT_COLUMNS = ("time", "pair", "angle", "peak_force", "duration", "kind")
EVENT_KINDS = ("impact", "rubbing")
_EVENT_DTYPE = np.dtype(
    [("time", "<f8"), ("pair", "<i8"), ("angle", "<f8"), ("peak_force", "<f8"),
     ("duration", "<f8"), ("kind", "S8")]
)
_BALL_DATASETS = ("angle", "speed", "slip", "valid")
#: Trailing shape of each known group dataset after the leading time axis; "Z" is the ball count.
_GROUP_SHAPES: dict[str, dict[str, tuple[int | str, ...]]] = {
    "balls": {"radius": ("Z",), "axial": ("Z",), "spin": ("Z", 3)},
    "contacts": {
        "inner_normal": ("Z",), "outer_normal": ("Z",), "ball_ball_normal": ("Z",),
        "inner_traction": ("Z",), "outer_traction": ("Z",),
    },
    "inner_ring": {"position": (3,), "tilt": (2,)},
}

FloatArray = npt.NDArray[np.float64]


@dataclass(frozen=True)
class VideoInfo:
    """Root attributes that only video traces carry.

    The input video's identity is ``input_hash`` (hex) by ``input_hash_algorithm`` (``"sha256"``,
    ``"blake3"`` or ``"xxh3_128"``; see :mod:`cageless.provenance`). ``input_sha256`` is kept for traces that name SHA-256: it equals ``input_hash``
    when the algorithm is SHA-256 and is empty otherwise (and then not written). A trace written
    before ``input_hash`` existed carries only ``input_sha256``; it reads as a SHA-256 hash.
    """

    fps: float
    px_per_mm: float
    centre_px: tuple[float, float]
    camera_roll_rad: float
    input_file: str
    input_sha256: str = ""
    input_hash: str = ""
    input_hash_algorithm: str = ""

    def __post_init__(self) -> None:
        algorithm = self.input_hash_algorithm or "sha256"
        digest = self.input_hash or (self.input_sha256 if algorithm == "sha256" else "")
        object.__setattr__(self, "input_hash_algorithm", algorithm)
        object.__setattr__(self, "input_hash", digest)
        if algorithm == "sha256":
            if self.input_sha256 and self.input_sha256 != digest:
                raise ValueError(f"input_sha256 {self.input_sha256!r} differs from input_hash {digest!r}")
            object.__setattr__(self, "input_sha256", digest)
        elif self.input_sha256:
            raise ValueError(f"input_sha256 is given but the input hash algorithm is {algorithm!r}")


@dataclass(frozen=True)
class SimulationInfo:
    """Root attributes that only simulation traces carry."""

    scene_json: str
    effects_json: str
    solver: str
    rtol: float
    atol: float
    n_steps: int
    n_rhs: int
    #: Wall time (s) of the solver alone (its compilation on a first run included).
    wall_s: float
    #: Wall time (s) of the whole run up to the written trace: setup, building the model, compiling, solving and
    #: the observables (the file's own write, which follows, is not in it); None when not recorded (traces from
    #: before it existed).
    total_wall_s: float | None = None


def empty_events() -> pd.DataFrame:
    """Return an empty contact-event table with the fixed columns."""
    return pd.DataFrame({
        "time": pd.Series(dtype="float64"), "pair": pd.Series(dtype="int64"),
        "angle": pd.Series(dtype="float64"), "peak_force": pd.Series(dtype="float64"),
        "duration": pd.Series(dtype="float64"), "kind": pd.Series(dtype="object"),
    })


@dataclass(frozen=True, eq=False)
class Trace:
    """Per-ball orbital motion over time, with the context needed to read it.

    Parameters
    ----------
    source
        ``"video"`` or ``"simulation"``.
    time
        Sample times (s), shape (T,), finite and strictly increasing.
    angle
        Unwrapped orbital angle of each ball centre (rad), shape (T, Z).
    speed
        Revolution speed (rad/s), shape (T, Z), positive along the rotation.
    slip
        Slip rate ``1 - speed / omega_c``, shape (T, Z).
    valid
        False where a value was interpolated over a missed detection, shape (T, Z).
    speed_rpm, radial_load_n, axial_load_n
        Operating conditions.
    ball_diameter_m, pitch_diameter_m
        The bearing the trace belongs to.
    direction
        +1 when the inner ring turned +theta as seen by the camera, -1 when mirrored.
    config
        The resolved configuration (JSON-serialisable).
    video, simulation
        Source-specific attributes; exactly the one matching ``source`` is required.
    groups
        Extra datasets by group, e.g. ``{"balls": {"radius": ...}}``; each has T rows.
    events
        Contact-event table with columns ``EVENT_COLUMNS`` (simulation traces).
    status
        ``"complete"``, or ``"incomplete: <why>"`` for a partial result.
    provenance
        A provenance record (see :mod:`cageless.provenance`), or ``None``.
    qc
        Quality-control summary (video traces: detection rates, fit residual, warnings), or ``None``.
    created_utc, software_version
        Stamped by :func:`write_trace` when ``None``.
    """

    source: Literal["video", "simulation"]
    time: FloatArray
    angle: FloatArray
    speed: FloatArray
    slip: FloatArray
    valid: npt.NDArray[np.bool_]
    speed_rpm: float
    radial_load_n: float
    axial_load_n: float
    ball_diameter_m: float
    pitch_diameter_m: float
    direction: int = 1
    config: dict[str, Any] = field(default_factory=dict)
    video: VideoInfo | None = None
    simulation: SimulationInfo | None = None
    groups: dict[str, dict[str, np.ndarray]] = field(default_factory=dict)
    events: pd.DataFrame | None = None
    status: str = "complete"
    provenance: dict[str, Any] | None = None
    qc: dict[str, Any] | None = None
    created_utc: str | None = None
    software_version: str | None = None

    def __post_init__(self) -> None:
        set_ = object.__setattr__
        set_(self, "time", np.ascontiguousarray(self.time, dtype=np.float64))
        for name in ("angle", "speed", "slip"):
            set_(self, name, np.ascontiguousarray(getattr(self, name), dtype=np.float64))
        set_(self, "valid", np.ascontiguousarray(self.valid, dtype=np.bool_))
        set_(self, "groups", {
            g: {k: np.ascontiguousarray(v) for k, v in ds.items()} for g, ds in self.groups.items()
        })
        self._validate()

    @property
    def n_balls(self) -> int:
        """Number of balls Z."""
        return int(self.angle.shape[1])

    @property
    def n_samples(self) -> int:
        """Number of samples T."""
        return int(self.time.shape[0])

    def _validate(self) -> None:
        if self.source not in ("video", "simulation"):
            raise ValueError(f"source = {self.source!r}: must be 'video' or 'simulation'.")
        if self.time.ndim != 1:
            raise ValueError(f"time has shape {self.time.shape}: must be (T,).")
        t = self.time.shape[0]
        if not np.all(np.isfinite(self.time)) or np.any(np.diff(self.time) <= 0):
            raise ValueError("time must be finite and strictly increasing.")
        if self.angle.ndim != 2 or self.angle.shape[0] != t or self.angle.shape[1] < 1:
            raise ValueError(f"angle has shape {self.angle.shape}: must be (T, Z) with T = {t}.")
        z = self.angle.shape[1]
        for name in _BALL_DATASETS:
            shape = getattr(self, name).shape
            if shape != (t, z):
                raise ValueError(f"{name} has shape {shape}: must be (T, Z) = {(t, z)}.")
        if self.direction not in (1, -1):
            raise ValueError(f"direction = {self.direction!r}: must be +1 or -1.")
        needed = {"video": self.video, "simulation": self.simulation}
        if needed[self.source] is None:
            raise ValueError(f"a {self.source} trace needs its {self.source} attributes.")
        for group, datasets in self.groups.items():
            if "/" in group or group in _BALL_DATASETS or group in ("time", "events"):
                raise ValueError(f"group name {group!r} is reserved or invalid.")
            known = _GROUP_SHAPES.get(group, {})
            for name, arr in datasets.items():
                want = known.get(name)
                expect = None if want is None else (t, *(z if d == "Z" else d for d in want))
                if arr.ndim == 0 or arr.shape[0] != t or (expect is not None and arr.shape != expect):
                    raise ValueError(
                        f"{group}/{name} has shape {arr.shape}: must be {expect or '(T, ...)'} with T = {t}."
                    )
        if self.events is not None:
            cols = tuple(self.events.columns)
            if cols != EVENT_COLUMNS:
                raise ValueError(f"events has columns {cols}: must be {EVENT_COLUMNS}.")
            bad = set(self.events["kind"]) - set(EVENT_KINDS)
            if bad:
                raise ValueError(f"events.kind has {sorted(bad)}: must be one of {EVENT_KINDS}.")


def _utc_now() -> str:
    return datetime.now(UTC).isoformat(timespec="microseconds")


def write_trace(path: str | Path, trace: Trace) -> Path:
    """Write a trace to ``path`` atomically (temporary file, then rename).

    ``created_utc`` and ``software_version`` are stamped when the trace has none.

    Returns
    -------
    pathlib.Path
        The written file.
    """
    path = Path(path)
    # The file is built in memory and written in one go: a full disk then fails a plain write with
    # ENOSPC (a clear error) instead of failing inside the HDF5 library.
    buffer = io.BytesIO()
    with h5py.File(buffer, "w") as f:
        _write_root_attrs(f, trace)
        _write_datasets(f, trace)
    with atomic_path(path) as tmp:
        tmp.write_bytes(buffer.getbuffer())
    return path


def _write_root_attrs(f: h5py.File, trace: Trace) -> None:
    a = f.attrs
    a["schema"] = SCHEMA
    a["source"] = trace.source
    a["created_utc"] = trace.created_utc or _utc_now()
    a["software_version"] = trace.software_version or __version__
    a["config_json"] = json.dumps(trace.config, sort_keys=True)
    a["status"] = trace.status
    if trace.provenance is not None:
        a["provenance_json"] = json.dumps(trace.provenance, sort_keys=True)
    if trace.qc is not None:
        a["qc_json"] = json.dumps(trace.qc, sort_keys=True)
    for name in ("speed_rpm", "radial_load_n", "axial_load_n", "ball_diameter_m", "pitch_diameter_m"):
        a[name] = np.float64(getattr(trace, name))
    a["n_balls"] = np.int64(trace.n_balls)
    a["direction"] = np.int64(trace.direction)
    extra = trace.video if trace.source == "video" else trace.simulation
    for key, value in asdict(extra).items():  # type: ignore[arg-type]
        if key == "input_sha256" and not value:
            continue  # the input was hashed with another algorithm: input_hash names it
        if value is None:
            continue  # not recorded (a simulation's total_wall_s): absent from the file too
        a[key] = np.asarray(value, dtype=np.float64) if key == "centre_px" else value


def _write_datasets(f: h5py.File, trace: Trace) -> None:
    f.create_dataset("time", data=trace.time)
    for name in _BALL_DATASETS:
        f.create_dataset(name, data=getattr(trace, name), compression="gzip", compression_opts=4)
    for group, datasets in trace.groups.items():
        g = f.create_group(group)
        for name, arr in datasets.items():
            g.create_dataset(name, data=arr, compression="gzip", compression_opts=4)
    if trace.events is not None:
        ev = trace.events
        table = np.empty(len(ev), dtype=_EVENT_DTYPE)
        for col in EVENT_COLUMNS:
            values = ev[col].to_numpy()
            table[col] = np.char.encode(values.astype(str), "ascii") if col == "kind" else values
        f.create_dataset("events", data=table)


def _fail(path: Path, message: str, hint: str = "") -> TraceFormatError:
    return TraceFormatError(path, message, hint)


def _check_schema(path: Path, attrs: h5py.AttributeManager) -> None:
    if "schema" not in attrs:
        raise _fail(path, "has no 'schema' attribute, so it is not a cageless trace file.",
                    "Give a *.trace.h5 file written by cageless.")
    schema = str(attrs["schema"])
    m = _SCHEMA_RE.match(schema)
    if m is None:
        raise _fail(path, f"has schema '{schema}', not '{SCHEMA}'.")
    if int(m.group(1)) > SCHEMA_MAJOR:
        raise _fail(path, f"has schema '{schema}', newer than this cageless reads ('{SCHEMA}').",
                    "Upgrade cageless to read it.")
    if int(m.group(1)) < SCHEMA_MAJOR:
        raise _fail(path, f"has schema '{schema}', older than this cageless reads ('{SCHEMA}').",
                    "Re-create it with this version (re-run the track or simulate command).")


def read_trace(path: str | Path) -> Trace:
    """Read a ``cageless-trace/1`` file.

    Raises
    ------
    TraceFormatError
        If the file is missing, not HDF5, has a missing or newer schema, lacks a
        dataset or attribute, or has inconsistent shapes.
    """
    path = Path(path)
    if path.is_dir():
        raise _fail(path, "is a folder, not a trace file.", "Give a *.trace.h5 file.")
    if not path.is_file():
        raise _fail(path, "does not exist.")
    try:
        f = h5py.File(path, "r")
    except (OSError, RuntimeError) as exc:
        from cageless.conditions import VIDEO_SUFFIXES

        if path.suffix.lower() in VIDEO_SUFFIXES:
            raise _fail(path, "is a video, not a trace.", "Track it first (`cageless track VIDEO -o out`) and "
                        "give the out/<name>.trace.h5 it writes.") from None
        raise _fail(path, f"is not a readable HDF5 file ({exc}).") from exc
    try:
        with f:
            _check_schema(path, f.attrs)
            try:
                return _read_body(path, f)
            except KeyError as exc:
                raise _fail(path, f"lacks {exc.args[0]!r}, which {SCHEMA} requires.") from exc
            except ValueError as exc:
                raise _fail(path, f"is inconsistent: {exc}") from exc
    except TraceFormatError:
        raise
    except (OSError, RuntimeError, TypeError, UnicodeDecodeError, SystemError) as exc:
        raise _fail(path, f"is damaged: {exc}.", "Re-create it (re-run the command that wrote it).") from exc


def _attr(a: Mapping[str, Any], key: str) -> Any:
    if key not in a:
        raise KeyError(f"attribute {key}")
    value = a[key]
    return value.decode() if isinstance(value, bytes) else value


def _read_body(path: Path, f: h5py.File) -> Trace:
    a = f.attrs
    source = _attr(a, "source")
    kwargs: dict[str, Any] = {}
    if source == "video":
        if "input_sha256" not in a and "input_hash" not in a:
            raise KeyError("attribute input_hash (or input_sha256)")
        kwargs["video"] = VideoInfo(**{
            k: (tuple(float(x) for x in _attr(a, k)) if k == "centre_px" else _scalar(_attr(a, k)))
            for k in VideoInfo.__dataclass_fields__ if k not in _VIDEO_HASH_FIELDS or k in a
        })
    elif source == "simulation":
        kwargs["simulation"] = SimulationInfo(**{
            k: _scalar(_attr(a, k)) for k in SimulationInfo.__dataclass_fields__ if k in a or k != "total_wall_s"
        })
    data = {}
    for name in ("time", *_BALL_DATASETS):
        if name not in f:
            raise KeyError(f"dataset {name}")
        data[name] = f[name][()]
    groups = {
        g: {k: v[()] for k, v in f[g].items()}
        for g in f if isinstance(f[g], h5py.Group)
    }
    events = _read_events(f["events"][()]) if "events" in f else None
    n_balls = int(_attr(a, "n_balls"))
    if data["angle"].ndim == 2 and data["angle"].shape[1] != n_balls:
        raise ValueError(f"attribute n_balls = {n_balls} but angle has {data['angle'].shape[1]} columns.")
    prov = a.get("provenance_json")
    qc = a.get("qc_json")
    return Trace(
        source=source, **data,
        speed_rpm=float(_attr(a, "speed_rpm")), radial_load_n=float(_attr(a, "radial_load_n")),
        axial_load_n=float(_attr(a, "axial_load_n")), ball_diameter_m=float(_attr(a, "ball_diameter_m")),
        pitch_diameter_m=float(_attr(a, "pitch_diameter_m")), direction=int(_attr(a, "direction")),
        config=json.loads(_attr(a, "config_json")), groups=groups, events=events,
        status=str(a.get("status", "complete")),
        provenance=None if prov is None else json.loads(prov),
        qc=None if qc is None else json.loads(qc),
        created_utc=str(_attr(a, "created_utc")), software_version=str(_attr(a, "software_version")),
        **kwargs,
    )


#: Video attributes of which a trace carries some: ``input_sha256`` alone (older traces),
#: ``input_hash`` with ``input_hash_algorithm``, or all three.
_VIDEO_HASH_FIELDS = ("input_sha256", "input_hash", "input_hash_algorithm")


def _scalar(value: Any) -> Any:
    """Turn numpy scalars from h5py attributes into Python scalars."""
    if isinstance(value, np.integer):
        return int(value)
    if isinstance(value, np.floating):
        return float(value)
    return value.decode() if isinstance(value, bytes) else value


def _read_events(table: np.ndarray) -> pd.DataFrame:
    out = empty_events()
    if len(table) == 0:
        return out
    return pd.DataFrame({
        col: (np.char.decode(table[col], "ascii").astype(object) if col == "kind" else table[col])
        for col in EVENT_COLUMNS
    })
