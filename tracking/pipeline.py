"""The tracking pipeline: one video in, one ``cageless-trace/1`` file and its QC out.

:func:`track_video` runs the stages in order: localisation
(:mod:`cageless.tracking.locate`), detection and identity (:mod:`cageless.tracking.detect`,
:mod:`cageless.tracking.link`), geometry (:mod:`cageless.tracking.geometry`), kinematics
(:mod:`cageless.tracking.kinematics`) and QC (:mod:`cageless.tracking.qc`). Frames stream in
chunks, cropped to the ball annulus; memory does not grow with video length
beyond the per-frame track table.
"""

from __future__ import annotations

import logging
import math
import sys
import threading
import warnings
from collections.abc import Callable, Iterator
from concurrent.futures import ThreadPoolExecutor
from contextlib import contextmanager
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from cageless.atomic import atomic_path
from cageless.bearing import Bearing
from cageless.conditions import OperatingConditions
from cageless.errors import ParameterError, TrackingError
from cageless.kinematics import slip_rate, theoretical_cage_speed
from cageless.outputs import is_foreign_file
from cageless.provenance import VIDEO_HASH, Provenance
from cageless.trace import Trace, VideoInfo, write_trace
from cageless.tracking.cropped import _CroppedFrames, _CropView
from cageless.tracking.detect import (DetectorParams, noise_sigma, spot_sigma, static_defects,
                                      static_pattern)
from cageless.tracking.geometry import fit_orbit, orbital_angles
from cageless.tracking.io import FrameSource, open_video
from cageless.tracking.kinematics import DEFAULT_WINDOW, revolution_speed, robust_track_fit
from cageless.tracking.track_window import choose_track_fit
from cageless.tracking.link import BallCountWarning, TrackSetup, track_frames
from cageless.tracking.lobes import relock_lobes
from cageless.tracking.locate import BearingLocation, background_frame, locate_bearing
from cageless.tracking.locate_motion import (DROPOUT_GAIN, frame_gains, holds_the_motion, locate_by_motion, motion_map,
                                             plausible_band)
from cageless.tracking.qc import (QC_LIMITS, QCReport, build_qc, refuse_located, refuse_selection, selection_frame,
                                  slip_warnings, write_qc, write_selection_qc)
from cageless.tracking.qc import qc_stem as _stem
from cageless.tracking.sample_stats import sample_statistics
from cageless.tracking.segments import MIN_SEGMENT, OVERLAP, bounds_at_anchors, stitch
from cageless.tracking.select import SPEED_BAND, Selection, SelectionError, select_balls
from cageless.tracking.position_bias import remove_place_bias
from cageless.tracking.precision import assess_table, precision_warning

__all__ = ["TrackOptions", "TrackResult", "track_video"]

log = logging.getLogger(__name__)

#: How the input video is hashed for its provenance (XXH3-128), in a background thread while the frames
#: are tracked.
INPUT_HASH = VIDEO_HASH
#: Quantile of the sampled frames that the ball selection subtracts (see :func:`_setup`).
SELECT_QUANTILE = 0.25
#: Frames spread over the video whose minimum tells a static defect (bright in all of them) from a trace
#: that passing highlights leave in the median background.
_DEFECT_FRAMES = 16


@dataclass(frozen=True)
class TrackOptions:
    """Tracking settings.

    Parameters
    ----------
    detector
        Detection settings, including the detector choice.
    window
        Savitzky-Golay window for the revolution speed (frames, odd).
    polyorder
        Savitzky-Golay polynomial order.
    strict
        Kept for old configurations: a ball count other than the bearing's (or ``n_balls``) is always an error.
    chunk
        Frames read per chunk (two chunks are cached: 64 full-size 16-bit frames are 131 MB).
    fps
        Frame-rate override (frames/s); default the conditions' ``fps``, then the file's timing.
    qc_frames
        How many overlay images to write.
    threads
        Segments tracked in parallel threads for videos of 1,000 frames or more (each at least 500 frames).
    allow_truncated
        Track the complete frames of a truncated ``.cine`` instead of refusing it.
    n_balls
        The ball count the video shows, when it differs from the bearing's (default: the bearing's).
    track_fit
        Frames of the robust local quadratic each ball's angle is read from (1: the raw angles), or ``"auto"``
        (default): the window of :data:`~cageless.tracking.track_window.LADDER` (7-41 frames) with the least
        cross-validated error on the clip (:func:`~cageless.tracking.track_window.choose_track_fit`; 7 frames
        was the fixed default before); samples off the ball's path are dropped
        (:func:`~cageless.tracking.kinematics.robust_track_fit`).
    """

    detector: DetectorParams = field(default_factory=DetectorParams)
    window: int = DEFAULT_WINDOW
    polyorder: int = 2
    strict: bool = False
    chunk: int = 64
    fps: float | None = None
    qc_frames: int = 3
    threads: int = 2
    allow_truncated: bool = False
    n_balls: int | None = None
    track_fit: int | str = "auto"

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready settings."""
        return asdict(self)


@dataclass
class TrackResult:
    """What tracking one video produced."""

    trace: Trace
    table: pd.DataFrame
    qc: QCReport
    path: Path | None = None


def _locate(video: FrameSource, background: np.ndarray, bearing: Bearing, path: Path,
            px_per_mm: float | None = None, spread: np.ndarray | None = None) -> BearingLocation:
    """The bearing and its ball band from brightness; from motion when that fails, gives a band that
    does not fit a ball, a band where little moves (dark ring faces, balls over bright faces), or (at a stated
    ``px_per_mm``) a band that does not hold the pitch circle (corpus seed 7304: a contour centre 0.58 balls off).
    ``spread``: the motion map when the caller has it (:func:`~cageless.tracking.sample_stats.sample_statistics`)."""
    g = bearing.geometry
    ratio = g.ball_diameter_m / (0.5 * g.pitch_diameter_m)
    pitch_px = 0.5 * g.pitch_diameter_m * 1e3 * px_per_mm if px_per_mm else None
    err: TrackingError | None = None
    spread = motion_map(video) if spread is None else spread
    try:
        loc = locate_bearing(background, path)
        if (plausible_band(loc, ratio) and holds_the_motion(spread, loc)
                and (pitch_px is None or loc.band_inner <= pitch_px <= loc.band_outer)):
            return loc
    except TrackingError as exc:
        if "no contrast" in exc.message:
            raise
        err = exc
    alt = locate_by_motion(spread, path, ratio)
    if alt is not None:
        log.info("%s: ball band found from motion (%.0f..%.0f px)", path, alt.band_inner, alt.band_outer)
        return alt
    if err is not None:
        raise err
    return loc


def _setup(video: FrameSource, loc: BearingLocation, background: np.ndarray, bearing: Bearing,
           options: TrackOptions, frames: _CroppedFrames, conditions: OperatingConditions,
           path: Path, k_sigma: float, low: np.ndarray | None = None) -> tuple[TrackSetup, Selection]:
    """Masks and noise level, then the ball selection (:mod:`cageless.tracking.select`) and the highlight width.
    ``low``: the full frames' :data:`SELECT_QUANTILE` background when the caller has it (cropped here)."""
    rows, cols = frames.rows, frames.cols
    margin = max(1.5, 0.04 * (loc.band_outer - loc.band_inner))
    mask = loc.annulus_mask(video.frame_shape, margin)[rows, cols]
    bg = np.ascontiguousarray(background[rows, cols])
    picks = np.linspace(0, len(video) - 1, min(4, len(video))).astype(int)
    spread_at = np.linspace(0, len(video) - 1, min(_DEFECT_FRAMES, len(video))).astype(int)
    video.prefetch([*picks, *spread_at])  # one pass over an MKV/MP4 for both samples
    sample = np.stack([frames(int(i)) for i in picks])
    # Not over a lighting dropout: a dark frame's whole difference from the background is not noise (one dark
    # frame of the 4 made it 4x too large on the long clip of corpus seed 7021, and with it every threshold).
    steady = frame_gains(list(sample)) >= DROPOUT_GAIN
    sigma = noise_sigma(sample[steady] if steady.sum() >= 2 else sample, bg, mask)
    spread = np.stack([frames(int(i)) for i in spread_at])
    defects = static_defects(bg, sigma, frames=spread)
    static = static_pattern(bg, spread, mask, defects)
    mask = mask & ~defects
    g = bearing.geometry
    z = options.n_balls or g.n_balls
    centre0 = (loc.centre[0] - cols.start, loc.centre[1] - rows.start)
    known = bool(conditions.px_per_mm) or loc.source == "brightness"
    r_prior = (0.5 * g.pitch_diameter_m * 1e3 * conditions.px_per_mm if conditions.px_per_mm
               else 0.5 * (loc.band_inner + loc.band_outer))
    # The candidates are found over a low quantile of the frames, not their median: an elongated highlight
    # lying along the orbit covers a pixel for more than half of the time between two balls, and the median
    # then keeps its ghost, which cuts the highlight into stripes (frame minus background).
    # Over the crop only: a per-pixel quantile, so the values of the full frames cropped (tested), on 41 % of the
    # pixels of the 1280 x 800 benchmark clip (0.20 -> 0.045 s of CPU there).
    sel_bg = (background_frame(_CropView(video, rows, cols), quantile=SELECT_QUANTILE, workers=options.threads)
              if low is None else np.ascontiguousarray(low[rows, cols]))
    sel = select_balls(frames, video.times, sel_bg, mask, z=z, ball_diameter_m=g.ball_diameter_m,
                       pitch_diameter_m=g.pitch_diameter_m, omega_i=conditions.speed_rad_s, centre0=centre0,
                       r_prior=r_prior, path=path, prior_known=known, k_sigma=k_sigma,
                       pixel_threshold=options.detector.weight_sigma * sigma,
                       scale_stated=bool(conditions.px_per_mm), workers=options.threads)
    ring = sel.ring
    ball_px = 2 * g.ball_diameter_m / g.pitch_diameter_m * ring.radius  # now from the measured ball circle
    h, w = mask.shape
    vv, uu = np.ogrid[0:h, 0:w]
    # From here on the mask is the band of the measured highlight circle, not the band located from the ring
    # contours: a highlight sits off its ball's centre (lit from the side), so its circle is off the ring
    # centre and, near a ball's rim, its tail reaches past the located band's edge. Cutting the tail there
    # pulled the centroid inwards by up to 1.2 px (1.7 mrad RMS on corpus seed 1013, balls lit at 60 deg).
    mask = ~defects & (
        np.abs(np.hypot(uu - ring.centre[0], vv - ring.centre[1]) - ring.radius) <= 0.5 * ball_px)
    a = sel.anchors[0]
    spots = spot_sigma(frames(a.frame), bg, mask, a.u, a.v, 0.12 * ball_px, options.detector.weight_sigma * sigma)
    hs = float(np.nanmedian(spots)) if np.isfinite(spots).any() else sel.ring.sigma_px
    setup = TrackSetup(background=bg, mask=mask, sigma_noise=sigma, highlight_sigma=hs,
                       max_area_px=math.pi * (0.25 * ball_px) ** 2, n_balls=z, params=options.detector,
                       ring=sel.ring, anchors=tuple(sel.anchors),
                       static=(static, float(spread.max())) if static.any() else None)
    return setup, sel


#: Start thresholds of the ball selection's candidates, in robust standard deviations of the blob response: the
#: usual one, and the one tried when it shows fewer than Z balls (see :func:`_select`).
SELECT_K_SIGMA = (4.0, 3.0)


def _select(video: FrameSource, loc: BearingLocation, background: np.ndarray, bearing: Bearing,
            options: TrackOptions, conditions: OperatingConditions, path: Path, low: np.ndarray | None = None
            ) -> tuple[BearingLocation, _CroppedFrames, TrackSetup, Selection]:
    """:func:`_setup` on the located band; while that shows too few balls, again on a wider band, then with a
    lower candidate threshold, the first error raised when every try fails.

    *A wider band.* When the band, found from the ring faces' brightness, is narrower than a ball, once more on
    the band widened to hold whole balls (:meth:`~cageless.tracking.locate.BearingLocation.holding_balls`):
    where the lands hide part of each ball the dark band between them is narrower than a ball, and a highlight
    near its ball's rim (a light from the side) leaves it over part of the orbit. The narrow band is tried
    first because it keeps the bright face edges out of the search (widening every band to a ball lost 3 of 32
    TUNING clips to the bright wedges between balls).

    *A lower threshold.* A candidate starts a tracklet at :data:`SELECT_K_SIGMA` ``[0]`` robust standard
    deviations of the blob response, measured over the whole band; where the balls run over bright ring faces
    the faces' moving edges raise that spread, and a dim highlight (a quarter of full scale, elongated, lit at
    60 degrees) then hovers about the threshold: its tracklets break, and a render of that look showed 9 of
    16 balls (response 3.1-6.1 noise units; DEV renders of this round, like FRESH seed 7110). What makes a
    ball is the joint consistency the selection checks (one circle, cyclic order, spacing, speed), not one
    blob's strength, so the same choice is made again from the weaker candidates (:data:`SELECT_K_SIGMA`
    ``[1]``), only when the first does not find Z: footage that passes today is tracked as before.
    """
    g = bearing.geometry
    z = options.n_balls or g.n_balls
    wide = loc.holding_balls(g.ball_diameter_m / (0.5 * g.pitch_diameter_m))
    bands = [loc] if wide is loc or loc.source != "brightness" else [loc, wide]
    first: SelectionError | None = None
    for k_sigma in SELECT_K_SIGMA:
        for band in bands:
            try:
                return _select_in(video, band, background, bearing, options, conditions, path, k_sigma, low)
            except SelectionError as exc:
                first = first or exc
                if (exc.found or 0) >= z:
                    raise first from None
                log.info("%s: %s of %d balls (band %.0f..%.0f px, candidates from %.1f sigma); trying again", path,
                         exc.found, z, band.band_inner, band.band_outer, k_sigma)
    assert first is not None
    raise first


def _select_in(video: FrameSource, loc: BearingLocation, background: np.ndarray, bearing: Bearing,
               options: TrackOptions, conditions: OperatingConditions, path: Path, k_sigma: float,
               low: np.ndarray | None = None) -> tuple[BearingLocation, _CroppedFrames, TrackSetup, Selection]:
    rows, cols = loc.crop(video.frame_shape)
    frames = _CroppedFrames(video, rows, cols, options.chunk)
    setup, sel = _setup(video, loc, background, bearing, options, frames, conditions, path, k_sigma, low)
    return loc, frames, setup, sel


def _import_late_modules() -> None:
    """Import what later stages use, so that a cold process does it beside the first stages rather than before
    them: ``scipy.optimize`` (the circle fits of the localisation and the selection's assignments, first needed
    after the median background) and ``scipy.signal`` (the speed, see
    :func:`cageless.tracking.kinematics._savgol_filter`). A stage that needs a module before it is in waits on
    Python's import lock, so nothing is imported twice."""
    try:
        import scipy.optimize  # noqa: F401
        import scipy.signal  # noqa: F401
    except ImportError:  # reported where it is used
        pass


_LATE_IMPORTS: list[threading.Thread] = []


def _start_late_imports() -> None:
    if not _LATE_IMPORTS and not {"scipy.optimize", "scipy.signal"} <= sys.modules.keys():
        _LATE_IMPORTS.append(threading.Thread(target=_import_late_modules, name="cageless-imports", daemon=True))
        _LATE_IMPORTS[0].start()


def track_video(
    path: str | Path, conditions: OperatingConditions, bearing: Bearing, options: TrackOptions | None = None,
    out_dir: str | Path | None = None, progress: bool = True, config: dict[str, Any] | None = None,
) -> TrackResult:
    """Track one video and (with ``out_dir``) write ``<stem>.trace.h5`` and its QC.

    Raises
    ------
    VideoError, TrackingError
        For an unreadable video or one that cannot be tracked; nothing is written then.
    """
    options = options or TrackOptions()
    path = Path(path)
    _start_late_imports()
    target = None if out_dir is None else Path(out_dir) / f"{_stem(path)}.trace.h5"
    if target is not None and is_foreign_file(target):
        raise TrackingError(path, f"{target} exists and is not a cageless trace; cageless does not overwrite files "
                                  "it did not write. Move it, or track into another folder.")
    fps = options.fps or conditions.fps
    prov = Provenance.start(config={"tracking": options.to_dict(), "conditions": conditions.to_dict(),
                                    **(config or {})}, inputs=[path], background=True,
                             hash_algorithm=INPUT_HASH)
    with warnings.catch_warnings(record=True) as caught, \
            open_video(path, fps=fps, allow_truncated=options.allow_truncated) as video:
        warnings.simplefilter("always", BallCountWarning)
        times = video.times
        if len(video) < options.window:
            raise TrackingError(path, f"has {len(video)} frames, fewer than the speed window of {options.window}: "
                                "too short to give a speed.", "Record longer, or lower --window.")
        # the median background, the selection's low quantile and the motion map, from one pass over the frames
        sample = sample_statistics(video, quantile=SELECT_QUANTILE, workers=options.threads)
        background = sample.median
        try:
            loc = _locate(video, background, bearing, path, conditions.px_per_mm, sample.spread)
        except TrackingError as exc:
            refuse_located(exc, path, video[0], out_dir)
        try:
            loc, frames, setup, sel = _select(video, loc, background, bearing, options, conditions, path, sample.low)
        except SelectionError as exc:
            refuse_selection(exc, path, video.__getitem__, loc.crop(video.frame_shape), out_dir)
        del sample  # its low quantile and motion map are done with (8 MB at full size)
        rows, cols = frames.rows, frames.cols
        with _frame_bar(len(video), path.name, progress) as update:
            table = _track_all(path, fps, video, frames, times, setup, options, update)
        table, moved = _relock(table, frames, setup, options)
        table["u_px"] += cols.start
        table["v_px"] += rows.start
        trace, qc = _finish(path, video, table, loc, conditions, bearing, options, prov,
                            [str(w.message) for w in caught],
                            _selection_summary(sel, cols.start, rows.start) | {"balls_moved_to_common_lobe": moved})
        selection_table = sel.table.assign(u_px=sel.table.u_px + cols.start, v_px=sel.table.v_px + rows.start)
        shown_frame = video[selection_frame(sel.table)] if out_dir is not None else None
    for w in caught:  # recorded for QC; still shown to the caller
        warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    if target is None or out_dir is None:
        return TrackResult(trace=trace, table=table, qc=qc, path=None)
    _write(target, Path(out_dir), path, trace, qc, table, options, fps, shown_frame, selection_table, sel,
           (cols.start, rows.start))
    return TrackResult(trace=trace, table=table, qc=qc, path=target)


def _relock(table: pd.DataFrame, frames: _CroppedFrames, setup: TrackSetup, options: TrackOptions
            ) -> tuple[pd.DataFrame, Any]:
    """:func:`~cageless.tracking.lobes.relock_lobes` with the set-up's background, mask and thresholds."""
    det = options.detector
    return relock_lobes(table, frames, setup.background, setup.mask, det.window_sigma * max(setup.highlight_sigma, 1.0),
                        det.weight_sigma * setup.sigma_noise, det.iterations, setup.highlight_sigma,
                        setup.static_compiled)


def _write(target: Path, out_dir: Path, path: Path, trace: Trace, qc: QCReport, table: pd.DataFrame,
           options: TrackOptions, fps: float | None, shown_frame: np.ndarray | None, selection_table: pd.DataFrame,
           sel: Selection, offset: tuple[int, int]) -> None:
    """Write the trace, its QC and the selection's QC. No trace without its QC, and a failed write loses no
    earlier trace: the new trace replaces the old one only once its QC is written (a re-run redoes both)."""
    with atomic_path(target) as pending:
        write_trace(pending, trace)
        write_qc(out_dir / "qc", _stem(path), path, qc, table, trace, options.qc_frames, fps,
                 allow_truncated=options.allow_truncated)
        write_selection_qc(out_dir / "qc", _stem(path), shown_frame, selection_table, sel.ring, offset,
                           f"{qc.n_balls_found} balls selected")


@contextmanager
def _frame_bar(total: int, name: str, progress: bool) -> Iterator[Callable[[int], Any]]:
    """The frames' progress bar's ``update`` (a no-op without ``progress``: tqdm is then not imported)."""
    if not progress:
        yield lambda n=1: None
        return
    from tqdm.auto import tqdm

    with tqdm(total=total, desc=name, unit="frame", leave=False) as bar:
        yield bar.update


def _track_all(path: Path, fps: float | None, video: FrameSource, frames: _CroppedFrames, times: np.ndarray,
               setup: TrackSetup, options: TrackOptions, update: Any) -> pd.DataFrame:
    """Track every frame: in one pass, or in overlapping segments on ``options.threads`` threads."""
    n = len(times)
    k = max(1, min(options.threads, n // MIN_SEGMENT))
    bounds = np.linspace(0, n, k + 1).astype(int)
    if not video.seekable:
        bounds = bounds_at_anchors(bounds, [a.frame for a in setup.anchors])
    if len(bounds) == 2:
        return track_frames(frames, times, setup, str(path), options.strict, update)[0]
    spans = [(int(a), int(min(b + OVERLAP, n))) for a, b in zip(bounds[:-1], bounds[1:], strict=True)]

    def one(span: tuple[int, int]) -> pd.DataFrame:
        a, b = span
        with open_video(path, fps=fps, allow_truncated=options.allow_truncated) as own:
            seg = _CroppedFrames(own, frames.rows, frames.cols, options.chunk, offset=a, stop=b)
            return track_frames(seg, times[a:b], setup, str(path), options.strict, update, offset=a)[0]

    with ThreadPoolExecutor(max_workers=k) as pool:
        parts = list(pool.map(one, spans))
    joined = stitch(parts, spans, times)
    if joined is None:  # the segments' ball identities could not be matched: the one-pass result is the answer
        log.warning("%s: the %d segments' ball identities did not match on their overlaps; tracking in one pass",
                    path.name, k)
        return track_frames(frames, times, setup, str(path), options.strict, update)[0]
    return joined


#: Largest share of interpolated (missed) samples a trace may have.
MAX_LOST_SHARE = 0.3


def _check_tracks(path: Path, times: np.ndarray, angle: np.ndarray, valid: np.ndarray, omega_c: float) -> None:
    """Refuse tracks that are not balls: mean speeds outside the plausible band, or too many misses."""
    lost = 1.0 - float(valid.mean())
    if lost > MAX_LOST_SHARE:
        raise TrackingError(path, f"{lost:.0%} of the ball positions were lost (limit {MAX_LOST_SHARE:.0%}); "
                            "no trace written.", "Check the lighting and focus over the whole clip.")
    span = float(times[-1] - times[0])
    if span <= 0:
        return
    ratio = (angle[-1] - angle[0]) / span / omega_c
    lo, hi = SPEED_BAND
    bad = np.flatnonzero((ratio < lo) | (ratio > hi))
    if bad.size:
        k = int(bad[0])
        raise TrackingError(path, f"ball {k} moves at {ratio[k]:.2f} x the cage speed, outside the plausible "
                            f"{lo}-{hi}; no trace written.", "Check speed_rpm and the bearing description.")


def _track_fit_frames(path: Path, times: np.ndarray, angle: np.ndarray, valid: np.ndarray,
                      track_fit: int | str, workers: int = 2) -> tuple[int, dict[str, Any] | None]:
    """The track fit's window (frames): ``track_fit`` itself, or for ``"auto"`` the cross-validated choice
    (:func:`~cageless.tracking.track_window.choose_track_fit`, its trial fits on ``workers`` threads) with its
    record for QC."""
    if isinstance(track_fit, str):
        if track_fit != "auto":
            raise TrackingError(path, f"track_fit = {track_fit!r} is not a window.",
                                'Give "auto" or an odd number of frames of at least 5 (1: no track fit).')
        choice = choose_track_fit(times, angle, valid, workers=workers)
        return choice.frames, choice.to_dict()
    if track_fit != 1 and (track_fit < 5 or track_fit % 2 == 0):
        raise TrackingError(path, f"track_fit = {track_fit} is not a window.",
                            'Give "auto" or an odd number of frames of at least 5 (1: no track fit).')
    return int(track_fit), None


def _fit_and_speed(path: Path, times: np.ndarray, angle: np.ndarray, valid: np.ndarray, track_fit: int,
                   options: TrackOptions) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The track fit's angles and validity (:func:`~cageless.tracking.kinematics.robust_track_fit`) and the speed
    from them (:func:`~cageless.tracking.kinematics.revolution_speed`); a bad setting is a :class:`TrackingError`."""
    try:
        angle, valid = robust_track_fit(times, angle, valid, track_fit)
        speed = revolution_speed(times, angle, options.window, options.polyorder)
    except ParameterError as exc:
        raise TrackingError(path, str(exc)) from exc
    return angle, valid, speed


def _selection_summary(sel: Selection, du: int, dv: int) -> dict[str, Any]:
    """What the ball selection found, for the QC record (full-image pixels)."""
    t = sel.table
    reasons = t.loc[t.status == "rejected", "reason"].value_counts()
    return {"counts": [int(c) for c in sel.counts],
            "circle_centre_px": (sel.ring.centre[0] + du, sel.ring.centre[1] + dv),
            "circle_radius_px": sel.ring.radius, "direction": sel.ring.direction,
            "speed_over_cage_speed": sel.ring.omega / sel.ring.omega_c,
            "selected": int((t.status == "selected").sum()),
            "rejected": {str(k): int(v) for k, v in reasons.items()}}


def _finish(path: Path, video: FrameSource, table: pd.DataFrame, loc: BearingLocation,
            conditions: OperatingConditions, bearing: Bearing, options: TrackOptions, prov: Provenance,
            warned: list[str], selection: dict[str, Any] | None = None) -> tuple[Trace, QCReport]:
    g = bearing.geometry
    orbit = fit_orbit(table)
    roll = math.radians(conditions.camera_roll_deg or 0.0)
    angle, valid, direction, order = orbital_angles(table, orbit, roll, steady=options.window)
    times = video.times
    angle, place = remove_place_bias(times, angle, valid, orbit.radius)
    omega_c = theoretical_cage_speed(g, conditions.speed_rad_s)
    track_fit, fit_choice = _track_fit_frames(path, times, angle, valid, options.track_fit, options.threads)
    with ThreadPoolExecutor(max_workers=1) as pool:  # the precision estimate beside the track fit and the speed
        pending = pool.submit(assess_table, table, order, times, angle, valid, orbit.centre, orbit.radius, omega_c,
                              options.window, options.polyorder, track_fit)
        try:
            angle, valid, speed = _fit_and_speed(path, times, angle, valid, track_fit, options)
        except TrackingError:
            pending.result()  # its error first, as when it ran first
            raise
        precision = pending.result()
    _check_tracks(path, times, angle, valid, omega_c)
    px_per_mm = conditions.px_per_mm or orbit.radius / (0.5 * g.pitch_diameter_m * 1e3)
    qc = build_qc(table, order, valid, orbit, loc, direction, px_per_mm, g.n_balls, warned)
    slip = slip_rate(speed, omega_c)
    qc.warnings.extend(slip_warnings(angle, speed, slip, valid, omega_c, conditions.speed_rpm))
    qc.selection = selection or {}
    qc.place_bias = place.to_dict()
    qc.precision = {} if precision is None else precision.to_dict()
    qc.track_fit = fit_choice or {"frames": track_fit}
    low = precision_warning(precision, QC_LIMITS)
    if low is not None:
        log.warning("%s: %s", path.name, low)
        qc.warnings.append(low)
    meta = video.metadata
    # a cut-off file tracked with allow_truncated: only its complete frames are in the trace
    qc.warnings.extend(n for n in meta.notes if n.startswith("truncated file"))
    fps = meta.extra.get("fps_override") or meta.timestamp_fps or meta.header_fps or float("nan")
    trace = Trace(
        source="video", time=times, angle=angle, speed=speed, slip=slip, valid=valid,
        speed_rpm=conditions.speed_rpm, radial_load_n=conditions.radial_load_n, axial_load_n=conditions.axial_load_n,
        ball_diameter_m=g.ball_diameter_m, pitch_diameter_m=g.pitch_diameter_m, direction=direction,
        config={"tracking": options.to_dict(), "conditions": conditions.to_dict(), "bearing": bearing.to_dict(),
                "slip_contact_angle_rad": 0.0,
                "video": meta.to_dict() | {"extra": {}}},
        video=VideoInfo(fps=float(fps), px_per_mm=float(px_per_mm), centre_px=orbit.centre,
                        camera_roll_rad=roll, input_file=path.name, input_hash=prov.finish().inputs[0].digest,
                        input_hash_algorithm=prov.inputs[0].algorithm),
        provenance=prov.to_dict(),
        qc=qc.to_dict(),
    )
    return trace, qc

