"""The lab-folder workflow behind ``cageless report LAB -o OUT``.

1. Discover the videos and their conditions.
2. Track each video (``OUT/traces/<video>.trace.h5`` and ``OUT/traces/qc/``).
3. Simulate the matching scene once per distinct condition (``OUT/simulations/``). The simulated time
   is the start-up that the comparison leaves out (three cage revolutions, at least 40 ms, unless
   ``settle_s`` is given) plus the longest video of the condition and at least
   :data:`REPORT_REVOLUTIONS` (20) cage revolutions, unless ``duration_s`` is given. Twenty
   revolutions put every ball through every 1 deg bin twenty times, give the Poincare section about 48
   points (one per shaft revolution) and let the spread come from many passes.
4. Compare each video with its condition's simulation.
5. Write ``OUT/report.html`` and ``OUT/slip_table.{csv,md,tex,html}``.

Work whose inputs and configuration are unchanged is skipped on a re-run: each job has a key (the
SHA-256 of the input file, the resolved configuration, the software version and the digest of the
package's source files, so a changed code base redoes the work) kept with its output
in ``OUT/.cageless-cache.json``. A failing video or simulation becomes a failed row with its message;
the rest completes. Jobs run in local processes on both cores, or on a Dask cluster when a scheduler
address is given (one task per video, one per scene).

This module is the app layer: it alone imports tracking, simulation and comparison.
"""

from __future__ import annotations

import hashlib
import json
import logging
import math
import os
import sys
import time
from collections.abc import Callable, Iterable
from concurrent.futures import Future
from contextvars import ContextVar
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

from tqdm.auto import tqdm

from cageless import __version__
from cageless.atomic import atomic_write_text
from cageless.bearing import Bearing, default_bearing
from cageless.conditions import LabEntry, OperatingConditions, bearing_with_keys, discover_lab, nested_videos_hint
from cageless.errors import CagelessError
from cageless.kinematics import startup_duration, theoretical_cage_speed
from cageless.outputs import clean_stale_parts, output_lock
from cageless.parallel import job_pool
from cageless.profiles import peak_estimator
from cageless.provenance import VIDEO_HASH, code_digest, hash_file, sha256_file
from cageless.trace import read_trace
from cageless.validate import plausible_entry

__all__ = ["LabOptions", "LabResult", "run_lab", "REPORT_REVOLUTIONS"]

CACHE_NAME = ".cageless-cache.json"
#: Cage revolutions a report simulates after the start-up by default (at least; longer videos get longer).
REPORT_REVOLUTIONS = 20.0
#: The files a report writes directly in its output folder.
REPORT_PRODUCTS = ("report.html", "slip_table.csv", "slip_table.md", "slip_table.tex", "slip_table.html")

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class LabOptions:
    """Choices of a lab run (the resolved configuration of the report)."""

    duration_s: float | None = None
    settle_s: float | None = None
    #: Cage revolutions simulated after the start-up, at least (when ``duration_s`` is None).
    revolutions: float = REPORT_REVOLUTIONS
    bin_deg: float = 1.0
    rtol: float = 1e-6
    workers: int = 2
    scheduler: str | None = None
    force: bool = False
    parameters: dict[str, float] = field(default_factory=dict)
    #: The named model parameter set the parameters start from (``--parameter-set``).
    parameter_set: str = "paper-table2"
    #: Where the parameters came from when a calibration file gave them (one line), or None.
    calibration: str | None = None
    n_balls: int | None = None
    #: Track the complete frames of a cut-off ``.cine`` (``--allow-truncated``) instead of failing its row.
    allow_truncated: bool = False
    #: Savitzky-Golay speed window of the tracking (frames, odd; ``None``: the tracker's default, 21).
    window: int | None = None
    #: The tracking's angle smoothing window (frames, or ``"auto"``; ``None``: the tracker's default, ``"auto"``).
    track_fit: int | str | None = None
    #: What slip is referred to in the comparison (a key of ``cageless.comparison.compare.SLIP_REFERENCES``).
    slip_reference: str = "cage"

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready, without the scheduler address (it does not change results)."""
        return {"duration_s": self.duration_s, "settle_s": self.settle_s, "revolutions": self.revolutions,
                "bin_deg": self.bin_deg, "rtol": self.rtol,
                "force": self.force, "parameter_set": self.parameter_set, "parameters": dict(self.parameters),
                "n_balls": self.n_balls,
                "slip_reference": self.slip_reference, "peak_estimator": peak_estimator(),
                **({"calibration": self.calibration} if self.calibration else {}),
                **({"allow_truncated": True} if self.allow_truncated else {}),
                **({"window": self.window} if self.window is not None else {}),
                **({"track_fit": self.track_fit} if self.track_fit is not None else {})}


@dataclass
class LabResult:
    """What a lab run produced."""

    report: Path
    table: Path
    rows: list[Any]
    n_failed: int
    timings: dict[str, float]
    skipped: int = 0


# -- jobs (top-level so processes and Dask workers can run them) --------------------------------------

def say_if_compiling(package: str) -> None:
    """Tell the user, on stderr, when the next run of ``package`` (``"tracking"`` or ``"simulation"``) waits for its
    one-off compile first (its progress bar then stands still for minutes)."""
    if package == "tracking":
        from cageless.tracking import compile_notice
    else:
        from cageless.simulation._cache import compile_notice
    notice = compile_notice()
    if notice:
        tqdm.write(notice, file=sys.stderr)


def _track_job(video: str, conditions: OperatingConditions, bearing: Bearing, out_dir: str,
               n_balls: int | None = None, allow_truncated: bool = False,
               window: int | None = None, track_fit: int | str | None = None) -> tuple[str, str]:
    from cageless.tracking.pipeline import TrackOptions, track_video

    options = TrackOptions(n_balls=n_balls, allow_truncated=allow_truncated)
    if window is not None:
        options = replace(options, window=window)
    if track_fit is not None:
        options = replace(options, track_fit=track_fit)
    try:
        res = track_video(video, conditions, bearing, options, out_dir=out_dir, progress=False,
                          config={"command": "report"})
    except CagelessError as exc:
        return "failed", str(exc)
    return "ok", str(res.path)


def _qc_files(trace_path: Path) -> list[Path]:
    """The QC files a track job writes beside its trace (their presence is part of a cache hit)."""
    stem = trace_path.name[: -len(".trace.h5")]
    qc = trace_path.parent / "qc"
    files = [qc / f"{stem}.qc.json", qc / f"{stem}.slip_profile.csv"]
    try:
        files += [qc / name for name in json.loads(files[0].read_text()).get("overlays", [])]
    except (OSError, ValueError, AttributeError):
        pass
    return files


def _simulate_job(conditions: OperatingConditions, bearing: Bearing, duration_s: float, parameters: dict[str, float],
                  rtol: float, out: str) -> tuple[str, str]:
    from cageless.simulation.parameters import ModelParameters
    from cageless.simulation.scene import Scene
    from cageless.simulation.simulation import Choices, Simulation

    try:
        scene = Scene(conditions=OperatingConditions(conditions.speed_rpm, conditions.radial_load_n,
                                                     conditions.axial_load_n), bearing=bearing, duration_s=duration_s)
        sim = Simulation(scene, ModelParameters().with_overrides(parameters), Choices(rtol=rtol))
        trace = sim.run(out=out, config={"command": "report"})
    except CagelessError as exc:
        return "failed", str(exc)
    if not sim.solution.success:
        return "failed", f"the simulation stopped early: {trace.status}"
    return "ok", out


# -- caching --------------------------------------------------------------------------------------------

class _Cache:
    """Finished jobs of earlier runs: ``{key: {"path": relative to OUT, "sha256": of the output, "also": [...]}}``.

    Paths are relative to the output folder, so a copied or renamed report folder reads its own files.
    A hit is trusted only when the output (and the files in ``also``) exist, the output's SHA-256 is the
    one stored, and the trace reads; anything missing or corrupt is redone.
    """

    VERSION = 2

    def __init__(self, out: Path) -> None:
        self.out = out
        self.path = out / CACHE_NAME
        self.data: dict[str, dict[str, Any]] = {}
        try:
            raw = json.loads(self.path.read_text()) if self.path.exists() else {}
        except (OSError, ValueError):
            raw = {}
        if isinstance(raw, dict) and raw.get("version") == self.VERSION and isinstance(raw.get("jobs"), dict):
            self.data = raw["jobs"]

    @staticmethod
    def key(kind: str, payload: dict[str, Any]) -> str:
        """SHA-256 of the job's kind, inputs and configuration, the software version and the code's digest."""
        text = json.dumps({"kind": kind, "version": __version__, "code": code_digest(), **payload}, sort_keys=True,
                          default=str)
        return hashlib.sha256(text.encode()).hexdigest()

    def hit(self, key: str) -> str | None:
        """The cached output's absolute path when it can be trusted, else ``None`` (and the entry is dropped)."""
        entry = self.data.get(key)
        if not isinstance(entry, dict):
            return None
        path = self.out / str(entry.get("path", ""))
        also = [self.out / str(a) for a in entry.get("also", [])]
        try:
            ok = (path.is_file() and all(a.is_file() for a in also)
                  and sha256_file(path, cache=False) == entry.get("sha256"))
            if ok:
                read_trace(path)
        except (CagelessError, OSError):
            ok = False
        if not ok:
            log.info("%s: cached output missing or damaged; redoing it", path)
            del self.data[key]
            return None
        return str(path)

    def _relative(self, path: str | Path) -> str:
        return os.path.relpath(Path(path).resolve(), self.out.resolve())

    def store(self, key: str, path: str, also: list[Path] | None = None) -> None:
        self.data[key] = {"path": self._relative(path), "sha256": sha256_file(path, cache=False),
                          "also": [self._relative(a) for a in (also or [])]}
        atomic_write_text(self.path, json.dumps({"version": self.VERSION, "jobs": self.data}, indent=1,
                                                sort_keys=True))


# -- executors ------------------------------------------------------------------------------------------

def _announce_failure(label: str, stage: str, message: str, progress: bool) -> None:
    """Say at once that one input failed, so a long run does not hide it until the end."""
    if progress:
        from cageless.app.cli.common import failed_line

        why = failed_line(label, message.splitlines()[0] if message else "")[len(f"FAILED {label}: "):]
        tqdm.write(f"FAILED {label} ({stage}): {why}", file=sys.stderr)


def _run_jobs(pool: Any, jobs: list[tuple[Callable[..., tuple[str, str]], tuple[Any, ...]]], desc: str,
              progress: bool, labels: list[str] | None = None,
              on_result: Callable[[int, tuple[str, str]], None] | None = None) -> list[tuple[str, str]]:
    """Run ``jobs`` on ``pool`` and return their outcomes in job order.

    Each outcome is handed to ``on_result(i, outcome)`` as soon as its job ends, whatever the order, so a
    stage that is interrupted (Ctrl-C) keeps the jobs it finished; a failure is announced as it happens.
    """
    futures: list[Future[Any]] = [pool.submit(fn, *args) for fn, args in jobs]
    out: dict[int, tuple[str, str]] = {}
    with tqdm(total=len(futures), desc=desc, disable=not (progress and _BARS.get()) or not futures,
              leave=False) as bar:
        while len(out) < len(futures):
            ready = [i for i, fut in enumerate(futures) if i not in out and fut.done()]
            if not ready:
                time.sleep(0.05)  # local and Dask futures alike have done(); jobs take seconds
                continue
            for i in ready:
                out[i] = _outcome(futures[i])
                if out[i][0] != "ok" and labels is not None:
                    _announce_failure(labels[i], desc, out[i][1], progress)
                if on_result is not None:
                    on_result(i, out[i])
                bar.update(1)
    return [out[i] for i in range(len(futures))]


def _outcome(fut: Any) -> tuple[str, str]:
    try:
        return fut.result()
    except Exception as exc:  # a crashed worker fails its job only  # noqa: BLE001
        return ("failed", f"{type(exc).__name__}: {exc}")


# -- the workflow ---------------------------------------------------------------------------------------

def _condition_key(c: OperatingConditions) -> tuple[float, float, float]:
    return (c.speed_rpm, c.radial_load_n, c.axial_load_n)


#: A simulation's identity in a lab run: speed, radial and axial load, and the bearing label ("" for the
#: configured bearing, else its ball count and diameters).
SimKey = tuple[float, float, float, str]


def _bearing_label(bearing: Bearing, base: Bearing) -> str:
    if bearing.to_dict() == base.to_dict():
        return ""
    g = bearing.geometry
    return f"Z{g.n_balls}_D{g.ball_diameter_m * 1e3:g}_dm{g.pitch_diameter_m * 1e3:g}"


def _sim_key(e: LabEntry, bearing: Bearing, base: Bearing) -> SimKey:
    return (*_condition_key(e.resolved.conditions), _bearing_label(bearing, base))


def _sim_name(key: SimKey) -> str:
    return f"n{key[0]:g}_Fr{key[1]:g}_Fa{key[2]:g}{'_' + key[3] if key[3] else ''}.sim.trace.h5"


def _entry_bearings(entries: list[LabEntry], bearing: Bearing) -> tuple[dict[Path, Bearing], list[Any]]:
    """Each video's bearing: the configured one with the ball count and diameters its sidecar or
    ``conditions.csv`` gives (``n_balls``, ``ball_diameter_mm``, ``pitch_diameter_mm``); an impossible
    bearing fails that video only."""
    bearings, failed = {}, []
    for e in entries:
        try:
            bearings[e.video] = bearing_with_keys(bearing, e.resolved)
        except CagelessError as exc:
            failed.append(_failed_row(e.video.name, e.resolved.conditions, str(exc)))
    return bearings, failed


def _settle(speed_rpm: float, bearing: Bearing, options: LabOptions) -> float:
    g = bearing.geometry
    return options.settle_s if options.settle_s is not None else startup_duration(
        speed_rpm, g.ball_diameter_m, g.pitch_diameter_m)


def _duration(key: tuple[float, float, float], video_s: Iterable[float], bearing: Bearing,
              options: LabOptions) -> float:
    settle = _settle(key[0], bearing, options)
    if options.duration_s is not None:
        return settle + options.duration_s
    cage = theoretical_cage_speed(bearing.geometry, key[0] * math.pi / 30.0)
    return settle + max([*video_s, options.revolutions * 2 * math.pi / cage])


#: Whether the stages draw progress bars while a :func:`run_lab` that says its progress runs.
_BARS: ContextVar[bool] = ContextVar("cageless_lab_bars", default=True)


def run_lab(folder: str | Path, out: str | Path, options: LabOptions | None = None, bearing: Bearing | None = None,
            progress: bool = True, bars: bool | None = None) -> LabResult:
    """Run the whole workflow on a lab folder; see the module docstring.

    With ``progress`` a failure is said on standard error when it happens, and so is a first compile; ``bars``
    (default: ``progress``) draws progress bars as well (the command line draws them only on a terminal).

    The output folder is locked for the run: a second run into it is refused (:class:`FolderInUseError`),
    and temporary files that killed runs left there are removed first.
    """
    out = Path(out)
    token = _BARS.set(progress if bars is None else bars)
    said = _Said()  # the warnings about the inputs, for the report as well as the console
    logging.getLogger("cageless").addHandler(said)
    try:
        with output_lock(out, "report folder"):
            clean_stale_parts(out)
            return _run_lab(folder, out, options, bearing, progress, said.messages)
    finally:
        logging.getLogger("cageless").removeHandler(said)
        _BARS.reset(token)


class _Said(logging.Handler):
    """Keeps the text of each distinct warning logged in this process (the conditions' sources disagreeing,
    columns ignored, a 0 N load assumed, a video copied twice), in the order said."""

    def __init__(self) -> None:
        super().__init__(level=logging.WARNING)
        self.messages: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:
        text = record.getMessage()
        if text not in self.messages:
            self.messages.append(text)


def _run_lab(folder: str | Path, out: Path, options: LabOptions | None, bearing: Bearing | None,
             progress: bool, notices: list[str]) -> LabResult:
    from cageless.comparison.compare import ComparisonRow
    from cageless.comparison.report import build_report, write_report
    from cageless.comparison.table import write_tables

    options = options or LabOptions()
    bearing = bearing or default_bearing()
    out = Path(out)
    entries = [plausible_entry(e, options.force) for e in discover_lab(folder)]
    if not entries:  # before anything is made in the output folder
        raise CagelessError(f"{folder}: no videos found. A lab folder holds videos (cine, avi/mp4/mkv or image "
                            "folders) with their conditions." + nested_videos_hint(folder))
    (out / "traces").mkdir(parents=True, exist_ok=True)
    (out / "simulations").mkdir(parents=True, exist_ok=True)
    cache, timings, skipped = _Cache(out), {}, 0
    failed: list[ComparisonRow] = [_failed_row(e.video.name, None, str(e.error)) for e in entries if not e.ok]
    bearings, bad = _entry_bearings([e for e in entries if e.ok], bearing)
    failed += bad
    for row in failed:
        _announce_failure(row.label, "conditions", row.message, progress)
    good = [e for e in entries if e.ok and e.video in bearings]
    with job_pool(options.workers, options.scheduler) as pool:
        t0 = time.perf_counter()
        traces, n_skip = _track_all(pool, good, bearings, out, cache, progress, options)
        skipped += n_skip
        timings["tracking"] = time.perf_counter() - t0
        for e in good:
            if isinstance(traces[e.video], CagelessError):
                failed.append(_failed_row(e.video.name, e.resolved.conditions, str(traces[e.video])))
        t0 = time.perf_counter()
        sims, n_skip = _simulate_all(pool, good, traces, bearings, bearing, out, cache, options, progress)
        skipped += n_skip
        timings["simulation"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    descriptions = _compare_all(good, traces, sims, bearings, bearing, options, failed, progress)
    timings["comparison"] = time.perf_counter() - t0
    rows = [d.row for d in descriptions] + failed
    tables = write_tables(rows, out / "slip_table")
    structure = build_report(descriptions, failed, reproduction={
        "lab folder": str(folder), **({"calibration": options.calibration} if options.calibration else {}),
        "configuration": options.to_dict(), "bearing": bearing.to_dict(),
        **{f"bearing of {e.video.name}": bearings[e.video].name for e in good if _bearing_label(bearings[e.video],
                                                                                                  bearing)}},
        timings=timings, notices=notices)
    report = write_report(structure, out / "report.html")
    return LabResult(report=report, table=tables["csv"], rows=rows, n_failed=len(failed), timings=timings,
                     skipped=skipped)


def _compare_all(good: list[LabEntry], traces: dict[Path, Any], sims: dict[SimKey, Any],
                 bearings: dict[Path, Bearing], base: Bearing, options: LabOptions, failed: list[Any],
                 progress: bool = False) -> list[Any]:
    """Compare each tracked video with its simulation; failures are appended to ``failed`` as rows (and
    announced at once when ``progress``, like the other stages' failures)."""
    from cageless.comparison.compare import compare
    from cageless.comparison.report import describe_condition

    descriptions = []
    for e in good:
        tr = traces[e.video]
        if isinstance(tr, CagelessError):
            continue
        sim = sims[_sim_key(e, bearings[e.video], base)]
        if isinstance(sim, CagelessError):
            failed.append(_failed_row(e.video.name, e.resolved.conditions, f"simulation failed: {sim}"))
            continue
        try:
            measured, simulated = read_trace(tr), read_trace(sim)
            settle = _settle(e.resolved.conditions.speed_rpm, bearings[e.video], options)
            c = compare(measured, simulated, options.bin_deg, settle, options.force, label=e.video.name,
                        slip_reference=options.slip_reference)
            descriptions.append(describe_condition(e.video.name, c, measured, simulated))
        except CagelessError as exc:
            failed.append(_failed_row(e.video.name, e.resolved.conditions, str(exc)))
            _announce_failure(e.video.name, "comparison", str(exc), progress)
    return descriptions


def _failed_row(label: str, c: OperatingConditions | None, message: str) -> Any:
    from cageless.comparison.compare import ComparisonRow

    nan = float("nan")
    speed, fr, fa = _condition_key(c) if c is not None else (nan, nan, nan)
    return ComparisonRow(speed, fr, fa, nan, nan, nan, nan, nan, label=label, status="failed", message=message)


def _collect(results: dict[Any, Any], pending: list[Any], keys: list[str],
             cache: _Cache) -> Callable[[int, tuple[str, str]], None]:
    """The ``on_result`` of :func:`_run_jobs`: store job ``i``'s output path in ``results`` and the cache at
    once (so an interrupted run's re-run skips it), or its error in ``results``."""

    def store(i: int, outcome: tuple[str, str]) -> None:
        status, info = outcome
        if status == "ok":
            cache.store(keys[i], info, _qc_files(Path(info)) if isinstance(pending[i], Path) else None)
            results[pending[i]] = info
        else:
            results[pending[i]] = CagelessError(info)

    return store


def _track_all(pool: Any, entries: list[LabEntry], bearings: dict[Path, Bearing], out: Path, cache: _Cache,
               progress: bool, options: LabOptions) -> tuple[dict[Path, Any], int]:
    traces: dict[Path, Any] = {}
    jobs, keys, pending = [], [], []
    n_balls, cut = options.n_balls, {"allow_truncated": True} if options.allow_truncated else {}
    if options.window is not None:  # keys of runs with the default window stay as they were
        cut["window"] = options.window
    if options.track_fit is not None:
        cut["track_fit"] = options.track_fit
    first_of: dict[str, Path] = {}
    for e in entries:
        digest = hash_file(e.video, VIDEO_HASH)
        if first_of.setdefault(digest, e.video) != e.video:
            log.warning("%s holds the same bytes as %s (%s %s): each is a row of the report; remove the copy if it "
                        "was made by mistake", e.video.name, first_of[digest].name, VIDEO_HASH, digest[:12])
        # Keyed on the video's XXH3-128: entries an earlier version keyed on its BLAKE3 do not match (a miss). And
        # on its name, so that a copy (same bytes, same conditions) keeps its own trace instead of the original's.
        key = cache.key("track", {"input": digest, "video": e.video.name,
                                  "conditions": e.resolved.conditions.to_dict(),
                                  "bearing": bearings[e.video].to_dict(), "n_balls": n_balls, **cut})
        hit = cache.hit(key)
        if hit:
            traces[e.video] = hit
            continue
        jobs.append((_track_job, (str(e.video), e.resolved.conditions, bearings[e.video], str(out / "traces"),
                                  n_balls, options.allow_truncated, options.window, options.track_fit)))
        keys.append(key)
        pending.append(e.video)
    if jobs and progress:
        say_if_compiling("tracking")
    _run_jobs(pool, jobs, "tracking", progress, [p.name for p in pending], _collect(traces, pending, keys, cache))
    return traces, len(entries) - len(jobs)


def _simulate_all(pool: Any, entries: list[LabEntry], traces: dict[Path, Any], bearings: dict[Path, Bearing],
                  base: Bearing, out: Path, cache: _Cache, options: LabOptions,
                  progress: bool) -> tuple[dict[SimKey, Any], int]:
    lengths: dict[SimKey, list[float]] = {}
    conditions: dict[SimKey, tuple[OperatingConditions, Bearing]] = {}
    for e in entries:  # a condition none of whose videos could be tracked has nothing to be compared with
        if isinstance(traces[e.video], CagelessError):
            continue
        k = _sim_key(e, bearings[e.video], base)
        conditions.setdefault(k, (e.resolved.conditions, bearings[e.video]))
        tr = read_trace(traces[e.video])
        lengths.setdefault(k, []).append(float(tr.time[-1] - tr.time[0]))
    sims: dict[SimKey, Any] = {}
    jobs, keys, pending = [], [], []
    for k, (c, bearing) in conditions.items():
        duration = _duration(k[:3], lengths[k], bearing, options)
        key = cache.key("simulate", {"conditions": list(k[:3]), "duration_s": duration, "bearing": bearing.to_dict(),
                                     "parameters": options.parameters, "rtol": options.rtol})
        hit = cache.hit(key)
        if hit:
            sims[k] = hit
            continue
        plain = replace(c, fps=None, px_per_mm=None, camera_roll_deg=None)
        jobs.append((_simulate_job, (plain, bearing, duration, dict(options.parameters), options.rtol,
                                     str(out / "simulations" / _sim_name(k)))))
        keys.append(key)
        pending.append(k)
    if jobs and progress:
        say_if_compiling("simulation")
    _run_jobs(pool, jobs, "simulation", progress, [_sim_name(k) for k in pending], _collect(sims, pending, keys, cache))
    return sims, len(conditions) - len(jobs)
