"""The tracking pipeline: one video in, one ``cageless-trace/1`` file and its QC out (DESIGN §8).

:func:`track_video` runs the stages in order: localisation
(:mod:`tracking.locate`), detection and identity (:mod:`tracking.detect`,
:mod:`tracking.link`), geometry (:mod:`tracking.geometry`), kinematics
(:mod:`tracking.kinematics`) and QC (:mod:`tracking.qc`). Frames stream in
chunks, cropped to the ball annulus; memory does not grow with video length
beyond the per-frame track table.
"""

from __future__ import annotations

import logging
import math
import warnings
from collections import OrderedDict
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
from tqdm.auto import tqdm

from cageless.bearing import Bearing
from cageless.conditions import OperatingConditions
from cageless.errors import ParameterError, TrackingError
from cageless.kinematics import slip_rate, theoretical_cage_speed
from cageless.provenance import Provenance
from cageless.trace import Trace, VideoInfo, write_trace
from tracking.detect import DetectorParams, detect_full, noise_sigma, spot_sigma, static_defects
from tracking.geometry import fit_orbit, orbital_angles
from tracking.io import FrameSource, open_video
from tracking.kinematics import DEFAULT_WINDOW, revolution_speed
from tracking.link import BallCountWarning, TrackSetup, track_frames
from tracking.locate import BearingLocation, background_frame, locate_bearing
from tracking.qc import QCReport, build_qc, write_qc

__all__ = ["TrackOptions", "TrackResult", "track_video"]

log = logging.getLogger(__name__)


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
        Make a ball-count mismatch an error instead of a warning.
    chunk
        Frames read per chunk.
    fps
        Frame-rate override (frames/s); default the conditions' ``fps``, then the file's timing.
    qc_frames
        How many overlay images to write.
    """

    detector: DetectorParams = field(default_factory=DetectorParams)
    window: int = DEFAULT_WINDOW
    polyorder: int = 2
    strict: bool = False
    chunk: int = 128
    fps: float | None = None
    qc_frames: int = 3

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


class _CroppedFrames:
    """Random access to cropped frames, reading whole chunks and keeping the last two."""

    def __init__(self, video: FrameSource, rows: slice, cols: slice, chunk: int) -> None:
        self.video, self.rows, self.cols, self.chunk = video, rows, cols, chunk
        self._cache: OrderedDict[int, np.ndarray] = OrderedDict()

    def __call__(self, i: int) -> np.ndarray:
        k = i // self.chunk
        block = self._cache.get(k)
        if block is None:
            a = k * self.chunk
            raw = self.video[a:min(a + self.chunk, len(self.video))]
            block = np.ascontiguousarray(raw[:, self.rows, self.cols])
            self._cache[k] = block
            if len(self._cache) > 2:
                self._cache.popitem(last=False)
        return block[i - k * self.chunk]


def _setup(video: FrameSource, loc: BearingLocation, background: np.ndarray, bearing: Bearing,
           options: TrackOptions, frames: _CroppedFrames) -> TrackSetup:
    rows, cols = frames.rows, frames.cols
    margin = max(1.5, 0.04 * (loc.band_outer - loc.band_inner))
    mask = loc.annulus_mask(video.frame_shape, margin)[rows, cols]
    bg = np.ascontiguousarray(background[rows, cols])
    sample = np.stack([frames(int(i)) for i in np.linspace(0, len(video) - 1, min(4, len(video))).astype(int)])
    sigma = noise_sigma(sample, bg, mask)
    mask = mask & ~static_defects(bg, sigma)
    g = bearing.geometry
    r_mid = 0.5 * (loc.band_inner + loc.band_outer)
    ball_px = g.ball_diameter_m / (0.5 * g.pitch_diameter_m) * r_mid
    base = TrackSetup(background=bg, mask=mask, sigma_noise=sigma, highlight_sigma=0.0,
                      max_area_px=math.pi * (0.25 * ball_px) ** 2, n_balls=g.n_balls, params=options.detector)
    det = detect_full(sample[0], bg, mask, sigma, options.detector, None, base.max_area_px, g.n_balls)
    if len(det) == 0:
        raise TrackingError(video.path, "no ball highlight was found in the ball band.",
                            "Check the lighting and the exposure: the highlights must stand out of the black balls.")
    spots = spot_sigma(sample[0], bg, mask, det.u, det.v, 0.12 * ball_px, options.detector.weight_sigma * sigma)
    return TrackSetup(**{**base.__dict__, "highlight_sigma": float(np.nanmedian(spots))})


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
    fps = options.fps or conditions.fps
    prov = Provenance.start(config={"tracking": options.to_dict(), "conditions": conditions.to_dict(),
                                    **(config or {})}, inputs=[path])
    with warnings.catch_warnings(record=True) as caught, open_video(path, fps=fps) as video:
        warnings.simplefilter("always", BallCountWarning)
        times = video.times
        if len(video) < options.window:
            raise TrackingError(path, f"has {len(video)} frames, fewer than the speed window of {options.window}: "
                                "too short to give a speed.", "Record longer, or lower --window.")
        background = background_frame(video)
        loc = locate_bearing(background, path)
        rows, cols = loc.crop(video.frame_shape)
        frames = _CroppedFrames(video, rows, cols, options.chunk)
        setup = _setup(video, loc, background, bearing, options, frames)
        with tqdm(total=len(video), desc=path.name, unit="frame", disable=not progress, leave=False) as bar:
            table, _ = track_frames(frames, times, setup, str(path), options.strict, bar.update)
        table["u_px"] += cols.start
        table["v_px"] += rows.start
        trace, qc = _finish(path, video, table, loc, conditions, bearing, options, prov,
                            [str(w.message) for w in caught])
    for w in caught:  # recorded for QC; still shown to the caller
        warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    written = None
    if out_dir is not None:
        out_dir = Path(out_dir)
        written = write_trace(out_dir / f"{_stem(path)}.trace.h5", trace)
        write_qc(out_dir / "qc", _stem(path), path, qc, table, trace, options.qc_frames, fps)
    return TrackResult(trace=trace, table=table, qc=qc, path=written)


def _stem(path: Path) -> str:
    return path.name if path.is_dir() else path.stem


def _finish(path: Path, video: FrameSource, table: pd.DataFrame, loc: BearingLocation,
            conditions: OperatingConditions, bearing: Bearing, options: TrackOptions, prov: Provenance,
            warned: list[str]) -> tuple[Trace, QCReport]:
    g = bearing.geometry
    orbit = fit_orbit(table)
    roll = math.radians(conditions.camera_roll_deg or 0.0)
    angle, valid, direction, order = orbital_angles(table, orbit, roll)
    times = video.times
    try:
        speed = revolution_speed(times, angle, options.window, options.polyorder)
    except ParameterError as exc:
        raise TrackingError(path, str(exc)) from exc
    omega_c = theoretical_cage_speed(g, conditions.speed_rad_s)
    px_per_mm = conditions.px_per_mm or orbit.radius / (0.5 * g.pitch_diameter_m * 1e3)
    qc = build_qc(table, order, valid, orbit, loc, direction, px_per_mm, g.n_balls, warned)
    meta = video.metadata
    fps = meta.extra.get("fps_override") or meta.timestamp_fps or meta.header_fps or float("nan")
    trace = Trace(
        source="video", time=times, angle=angle, speed=speed, slip=slip_rate(speed, omega_c), valid=valid,
        speed_rpm=conditions.speed_rpm, radial_load_n=conditions.radial_load_n, axial_load_n=conditions.axial_load_n,
        ball_diameter_m=g.ball_diameter_m, pitch_diameter_m=g.pitch_diameter_m, direction=direction,
        config={"tracking": options.to_dict(), "conditions": conditions.to_dict(), "bearing": bearing.to_dict(),
                "video": meta.to_dict() | {"extra": {}}},
        video=VideoInfo(fps=float(fps), px_per_mm=float(px_per_mm), centre_px=orbit.centre,
                        camera_roll_rad=roll, input_file=path.name, input_sha256=prov.inputs[0].sha256),
        provenance=prov.finish().to_dict(),
        qc=qc.to_dict(),
    )
    return trace, qc

