"""``cageless track``: videos to ``<video>.trace.h5`` files with QC."""

from __future__ import annotations

import argparse
import logging
import os
import sys
from collections.abc import Callable, Iterator, Mapping
from contextlib import contextmanager
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from cageless.bearing import Bearing
from cageless.app.cli.common import add_track_fit_option, check_n_balls, check_window, failed_line, finite_float
from cageless.conditions import (
    IMAGE_SUFFIXES,
    LabEntry,
    OperatingConditions,
    bearing_with_keys,
    discover_lab,
    is_qc_folder,
    nested_videos_hint,
    refuse_shared_names,
    resolve_conditions,
)
from cageless.config import bearing_from_config
from cageless.errors import CagelessError, MissingConditionsError, is_trace_name, trace_not_video
from cageless.outputs import check_output_dir, clean_stale_parts, output_lock
from cageless.validate import check_options, plausible_entry

__all__ = ["register", "run", "collect_inputs"]

log = logging.getLogger(__name__)

_EXAMPLES = """\
examples:
  cageless track sample_data/lab -o out            every video of a lab folder (sidecar, conditions.csv or file name)
  cageless track clip.cine --speed-rpm 3000 --radial-load-n 500 -o out
                                                   one video whose conditions are nowhere else
  cageless track lab -o out --window 31 --detector weighted --workers 2
"""


#: :data:`cageless.tracking.detect.DETECTORS` and :data:`cageless.tracking.kinematics.DEFAULT_WINDOW`, written out
#: (and tested equal) so that building the parser imports neither module: they bring in numba, SciPy and
#: pandas, and the input's hash starts only after the parser is built (:func:`run`), so that it runs on the
#: other core during those imports instead of after them.
DETECTORS = ("mask", "weighted", "window")
DEFAULT_WINDOW = 21


def register(subparsers: Any, parent: argparse.ArgumentParser) -> None:
    """Add the ``track`` subcommand."""
    p = subparsers.add_parser(
        "track", parents=[parent], help="track the balls in videos and write trace files",
        description="Track every ball in bearing videos and write <video>.trace.h5 plus QC "
        "(qc/<video>.qc.json and overlay PNGs). A folder is read as a lab folder; one failing video is "
        "reported and the others still run (exit code 1).",
        epilog=_EXAMPLES, formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("inputs", nargs="+", metavar="VIDEO_OR_FOLDER", help="videos, image folders or lab folders")
    p.add_argument("-o", "--out", default="traces", help="output folder (default ./traces)")
    p.add_argument("--speed-rpm", type=finite_float,
                   help="inner-ring speed (rpm): for a video named here it wins over its sidecar, conditions.csv "
                   "and file name (with a warning); in a folder it stands in only for videos without conditions")
    p.add_argument("--radial-load-n", type=finite_float,
                   help="radial load (N), recorded in the trace for the comparison: as --speed-rpm (0 N when no "
                   "source gives it, with a warning)")
    p.add_argument("--axial-load-n", type=finite_float, help="axial load (N): as --radial-load-n")
    p.add_argument("--fps", type=finite_float,
                   help="frame-rate override (frames/s; default: the video's time stamps, else its header rate)")
    p.add_argument("--window", type=int, default=DEFAULT_WINDOW,
                   help=f"Savitzky-Golay speed window in frames, odd (default {DEFAULT_WINDOW})")
    p.add_argument("--detector", choices=DETECTORS, default="window",
                   help="centroid method: window refinement (default), weighted, or binary mask")
    add_track_fit_option(p, "auto")
    p.add_argument("--n-balls", type=int, metavar="N",
                   help="ball count the video shows, when it differs from the bearing's; otherwise a video that "
                   "does not show the bearing's count is an error (no trace; the QC image shows what was found)")
    p.add_argument("--strict", action="store_true", help=argparse.SUPPRESS)  # a wrong count is always an error now
    p.add_argument("--workers", type=int, default=2, help="videos tracked in parallel (default 2)")
    p.add_argument("--allow-truncated", action="store_true",
                   help="track the complete frames of a truncated .cine instead of refusing it")
    p.add_argument("--force", action="store_true", help="accept conditions outside their plausible ranges")


#: The conditions ``track`` takes on the command line, by option name.
TYPED = {"speed_rpm": "r/min", "radial_load_n": "N", "axial_load_n": "N"}


def collect_inputs(inputs: list[str], speed_rpm: float | None,
                   loads: Mapping[str, float | None] | None = None) -> list[LabEntry]:
    """Expand the command-line inputs into videos with their conditions (or their errors).

    ``speed_rpm`` and ``loads`` (``radial_load_n``, ``axial_load_n``) are the values typed on the command line
    (None: not given); see :func:`_with_typed` for how they combine with a video's own sources.
    """
    typed = {k: v for k, v in {"speed_rpm": speed_rpm, **(loads or {})}.items() if v is not None}
    entries: list[LabEntry] = []
    for raw in inputs:
        p = Path(raw)
        if not p.exists():
            entries.append(LabEntry(video=p, error=CagelessError(f"{p}: no such file or folder.")))
        elif p.is_file() and is_trace_name(p):  # before its conditions: a trace's name holds none
            entries.append(LabEntry(video=p, error=trace_not_video(p)))
        elif p.is_dir() and is_qc_folder(p):
            entries.append(LabEntry(video=p, error=CagelessError(
                f"{p}: is the QC folder of a cageless output (its images are QC figures, not a video's frames).")))
        elif p.is_dir() and not any(f.suffix.lower() in IMAGE_SUFFIXES for f in p.iterdir()):
            found = discover_lab(p, fallback=typed)
            if not found:
                traces = " It holds cageless traces: point at the folder of videos instead." if any(
                    p.glob("*.trace.h5")) else ""
                entries.append(LabEntry(video=p, error=CagelessError(
                    f"{p}: no videos found in this folder.{traces}{nested_videos_hint(p)}")))
            entries.extend(_with_typed(e, typed, named=False) for e in found)
        else:
            try:
                entry = LabEntry(video=p, resolved=resolve_conditions(p, None, fallback=typed))
            except CagelessError as exc:
                entry = LabEntry(video=p, error=exc)
            entries.append(_with_typed(entry, typed, named=True))
    return refuse_shared_names(entries)


def _with_typed(entry: LabEntry, typed: Mapping[str, float], named: bool) -> LabEntry:
    """Apply the conditions typed on the command line to one video resolved with them as fallbacks.

    For a video named on the command line (``named``) a typed value wins over every other source, and the run
    says which value it replaces. For a video found in a folder it stands in only where no source gives that key
    (the other keys its sources give are kept), and the run says where a source overrules it: one typed value is
    rarely right for a whole folder. A malformed source stays an error either way.
    """
    if not entry.ok:
        return entry  # an error: a malformed source, or no such file (a missing value was filled in when resolving)
    conditions, origin = entry.resolved.conditions, dict(entry.resolved.origin)
    for key, value in typed.items():
        given, flag, unit = getattr(conditions, key), "--" + key.replace("_", "-"), TYPED[key]
        if given == value:
            continue
        source = origin.get(key, "its conditions")
        if not named:
            print(f"warning: {entry.video}: {flag} {value:g} is not used: its {source} gives {given:g} {unit} "
                  "(in a folder the videos' own conditions win; name the video on the command line to override "
                  "them)", file=sys.stderr)
            continue
        print(f"warning: {entry.video}: {flag} {value:g} overrides {given:g} {unit} from its {source}",
              file=sys.stderr)
        conditions, origin[key] = replace(conditions, **{key: value}), flag
    if conditions is entry.resolved.conditions:
        return entry
    return replace(entry, resolved=replace(entry.resolved, conditions=conditions, origin=origin))


def _track_one(job: tuple[Path, OperatingConditions, Bearing, Any, Path]) -> tuple[str, dict[str, Any] | str]:
    from cageless.tracking.pipeline import track_video

    video, conditions, bearing, options, out = job
    try:
        res = track_video(video, conditions, bearing, options, out_dir=out, progress=False)
    except CagelessError as exc:
        return "failed", str(exc)
    except Exception as exc:  # noqa: BLE001 - one video's surprise must not stop the others
        log.debug("tracking %s failed", video, exc_info=True)
        return "failed", f"unexpected {type(exc).__name__}: {exc} (run with -v --workers 1 for the traceback)"
    from cageless.comparison.metrics import unloaded_peak
    from cageless.profiles import angle_profile

    tr = res.trace
    # the peak of the 1 deg mean slip profile in the unloaded zone: the "experimental slip" of compare and report
    peak = unloaded_peak(angle_profile(tr.angle, tr.slip, 1.0, valid=tr.valid))
    return "ok", {"path": str(res.path), "frames": tr.n_samples, "balls": tr.n_balls,
                  "detected": float(np.mean(res.qc.detection_rate)), "warnings": res.qc.warnings,
                  "peak_slip": peak, "precision_mrad": (res.qc.precision or {}).get("angle_rms_mrad")}


def _precision(info: dict[str, Any]) -> str:
    """``", angle precision 0.06 mrad"`` (the trace's self-assessed RMS angle error), or ``""`` without one."""
    value = info.get("precision_mrad")
    return f", angle precision {value:.2f} mrad" if value is not None else ""


def run(args: argparse.Namespace, config: dict[str, Any]) -> int:
    """Track every input; print one summary line per video; return 1 if any failed."""
    check_window(args.window)
    _validate(args)
    check_n_balls(args.n_balls, config)
    bearing = bearing_from_config(config)
    typed = collect_inputs(args.inputs, args.speed_rpm, _typed_loads(args))
    entries = [plausible_entry(e, args.force) for e in typed]
    _prefetch_first_hash(entries, args.workers)
    from cageless.tracking.detect import DetectorParams  # these imports take a second: the hash runs meanwhile
    from cageless.tracking.pipeline import TrackOptions

    options = TrackOptions(detector=replace(DetectorParams(), method=args.detector), window=args.window,
                           strict=args.strict, fps=args.fps, allow_truncated=args.allow_truncated,
                           n_balls=args.n_balls, track_fit=args.track_fit)
    out = Path(args.out)
    with output_lock(out):
        clean_stale_parts(out)
        return _run_locked(args, entries, bearing, options, out)


def _typed_loads(args: argparse.Namespace) -> dict[str, float | None]:
    return {"radial_load_n": args.radial_load_n, "axial_load_n": args.axial_load_n}


def _validate(args: argparse.Namespace) -> None:
    """Numbers in range and the output folder usable, before any work."""
    check_options(args, ("speed_rpm", "radial_load_n", "axial_load_n", "fps", "window", "workers"))
    check_output_dir(args.out, "-o")


def _run_locked(args: argparse.Namespace, entries: list[LabEntry], bearing: Bearing, options: Any, out: Path) -> int:
    failed, _shown = 0, _namer(args.inputs)
    for e in entries:
        if not e.ok:
            hint = (" For a single video, `--speed-rpm` gives its speed on the command line."
                    if isinstance(e.error, MissingConditionsError) else "")
            print(failed_line(e.video, e.error, shown=_shown(e.video)) + hint, file=sys.stderr)
            failed += 1
    jobs = []
    for e in entries:
        if e.ok:
            try:  # a sidecar may describe another bearing (n_balls, ball_diameter_mm, pitch_diameter_mm)
                jobs.append((e.video, e.resolved.conditions, bearing_with_keys(bearing, e.resolved), options, out))
            except CagelessError as exc:
                print(failed_line(e.video, exc, shown=_shown(e.video)), file=sys.stderr)
                failed += 1
    workers = max(1, min(args.workers, len(jobs)))
    if jobs and not args.quiet:
        from cageless.app.lab import say_if_compiling

        say_if_compiling("tracking")
    with _bar(len(jobs), args.progress and bool(jobs)) as (bar, say):
        results = _map(jobs, workers, bar)
        for (video, *_), (status, info) in zip(jobs, results, strict=True):
            if status == "ok":
                warn = f"; QC: {'; '.join(info['warnings'])}" if info["warnings"] else ""
                say(f"ok     {_shown(video)}: {info['frames']} frames, {info['balls']} balls, "
                    f"{100 * info['detected']:.1f}% detected, peak unloaded slip "
                    f"{100 * info['peak_slip']:.2f}%{_precision(info)} -> {info['path']}{warn}", sys.stdout)
            else:
                say(failed_line(video, info, shown=_shown(video)), sys.stderr)
                failed += 1
    return 1 if failed else 0


class _NoBar:
    """Stands in for the progress bar when none is shown."""

    def update(self, n: int = 1) -> None:
        """Nothing to show."""


@contextmanager
def _bar(total: int, shown: bool) -> Iterator[tuple[Any, Callable[[str, Any], None]]]:
    """The videos' progress bar and how to print a line under it; without a bar (``-q``, not a terminal) plain
    prints, and tqdm (0.03-0.07 s of CPU to import) is not imported."""
    if not shown:
        yield _NoBar(), lambda text, file: print(text, file=file)
        return
    from tqdm.auto import tqdm

    with tqdm(total=total, desc="videos", unit="video") as bar:
        yield bar, lambda text, file: tqdm.write(text, file=file)


def _namer(inputs: list[str]) -> Callable[[Path], str]:
    """How a video is named on its ``ok``/``FAILED`` line, the same way on every line of a run: relative to the
    input folder it was found in (as the report names it), else as given on the command line."""
    typed = {Path(os.path.abspath(i)): i for i in inputs}  # not resolved: a linked video stays in its folder
    folders = [full for full in typed if full.is_dir()]

    def shown(video: Path) -> str:
        full = Path(os.path.abspath(video))
        for folder in folders:
            if full != folder and full.is_relative_to(folder):
                return full.relative_to(folder).as_posix()
        return typed.get(full, str(video))

    return shown


def _prefetch_first_hash(entries: list[LabEntry], workers: int) -> None:
    """Start hashing the first video now, when it will be tracked in this process."""
    from cageless.provenance import VIDEO_HASH, prefetch_hash

    ok = [e for e in entries if e.ok]
    if ok and (workers == 1 or len(ok) == 1):
        try:
            prefetch_hash(ok[0].video, VIDEO_HASH)
        except OSError:  # unreadable: the tracker reports it
            pass


def _map(jobs: list[Any], workers: int, bar: Any) -> list[tuple[str, Any]]:
    if workers == 1:
        out = []
        for job in jobs:
            out.append(_track_one(job))
            bar.update(1)
        return out
    from cageless.parallel import job_pool

    with job_pool(workers) as pool:
        out = []
        for res in pool.map(_track_one, jobs):
            out.append(res)
            bar.update(1)
        return out
