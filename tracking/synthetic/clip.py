"""Render a whole clip to disk: the video, its ground truth, and how it was made.

Writes ``<stem><suffix>`` (``.cine``, ``.avi``/``.mkv`` FFV1, or an image folder),
``<stem>.truth.csv`` (one row per frame and ball, :data:`TRUTH_COLUMNS`) and
``<stem>.truth.json`` (camera, appearance, motion law, seed, dropped frames,
software version). Frames stream to the writer; with ``workers > 1`` chunks of
frames render in parallel processes and are written in order.
"""

from __future__ import annotations

import json
import math
import multiprocessing
from collections.abc import Iterator
from concurrent.futures import ProcessPoolExecutor
from dataclasses import asdict
from pathlib import Path
from typing import Any

import numpy as np
from tqdm.auto import tqdm

from cageless._version import __version__
from cageless.atomic import atomic_write_text
from cageless.balls import ball_order, normalise_unwrapped
from cageless.errors import ParameterError
from cageless.kinematics import theoretical_cage_speed
from cageless.units import rpm_to_rad_s
from cageless.tracking.io import write_cine, write_ffv1, write_image_sequence
from cageless.tracking.synthetic.motion import BallMotion, KinematicLaw
from cageless.tracking.synthetic.render import TRUTH_COLUMNS, Renderer

__all__ = ["render_clip", "ClipResult"]

_CHUNK = 16


class ClipResult(dict[str, Any]):
    """Paths and summary of a rendered clip (a dict: ``video``, ``truth_csv``, ``truth_json``, ``n_frames``...)."""


def _motion_times(renderer: Renderer, times: np.ndarray, speed_rpm: float) -> tuple[np.ndarray, int]:
    g = renderer.geometry
    omega = 1.3 * theoretical_cage_speed(g, rpm_to_rad_s(speed_rpm))  # allow for fast balls
    speed_px_s = omega * 0.5 * g.pitch_diameter_m * renderer.camera.px_per_m
    offsets = renderer.exposure_offsets(speed_px_s)
    # Motion starts one exposure before the first frame so every sub-sample time is >= 0.
    t = (times[:, None] + offsets[None, :] + renderer.camera.exposure_s).ravel()
    return t, len(offsets)


def _render_chunk(args: tuple[Renderer, BallMotion, np.ndarray, np.ndarray, int, int]) -> list[np.ndarray]:
    renderer, motion, index, times, sub, start = args
    vis = renderer.visibility(len(times) + start)[start:]
    peaks = renderer.peaks(len(times) + start)[start:] * vis
    return [renderer.render_frame(motion, int(index[i]), list(range(i * sub, (i + 1) * sub)), peaks[i], float(times[i]))
            for i in range(len(times))]


def _frames(renderer: Renderer, motion: BallMotion, index: np.ndarray, times: np.ndarray, sub: int,
            workers: int) -> Iterator[np.ndarray]:
    if workers <= 1:
        yield from renderer.frames(motion, index, times, sub)
        return
    jobs = []
    for a in range(0, len(times), _CHUNK):
        b = min(a + _CHUNK, len(times))
        rows = slice(a * sub, b * sub)
        part = BallMotion(times=motion.times[rows], angle=motion.angle[rows], radius=motion.radius[rows],
                          ring_angle=motion.ring_angle[rows], ring_offset=motion.ring_offset[rows],
                          direction=motion.direction)
        jobs.append((renderer, part, index[a:b], times[a:b], sub, a))
    # spawn, not fork: numba's thread pool does not survive a fork.
    with ProcessPoolExecutor(max_workers=workers, mp_context=multiprocessing.get_context("spawn")) as pool:
        for chunk in pool.map(_render_chunk, jobs):
            yield from chunk


def render_clip(
    path: str | Path,
    renderer: Renderer,
    n_frames: int,
    law: KinematicLaw | None = None,
    motion_source: Any = None,
    speed_rpm: float | None = None,
    fmt: str = "cine-p12",
    workers: int = 1,
    progress: bool = False,
) -> ClipResult:
    """Render ``n_frames`` camera frames (fewer if frames are dropped) to ``path`` with ground truth.

    Parameters
    ----------
    path
        Output video: ``x.cine``, ``x.avi``/``x.mkv`` (8-bit FFV1), or a folder for images.
    renderer
        The scene and camera.
    n_frames
        Frames the camera would take; dropped frames are left out (gaps in the time stamps).
    law
        The built-in kinematic law, or ``None`` when ``motion_source`` is given.
    motion_source
        A :class:`~cageless.trace.Trace` to take the ball motion from instead of ``law``.
    speed_rpm
        Inner-ring speed; default the law's or the trace's.
    fmt
        ``"cine-8"``, ``"cine-16"``, ``"cine-p10"``, ``"cine-p12"``, ``"ffv1"``, ``"tif"`` or ``"png"``.
    workers
        Processes rendering in parallel.
    progress
        Show a per-frame progress bar.
    """
    path = Path(path)
    if (law is None) == (motion_source is None):
        raise ParameterError("law", "give exactly one of law and motion_source")
    if n_frames < 2:
        raise ParameterError("n_frames", "must be >= 2", n_frames)
    speed = speed_rpm or (law.speed_rpm if law is not None else motion_source.speed_rpm)
    index, times = renderer.plan(n_frames)
    t_motion, sub = _motion_times(renderer, times, speed)
    if law is not None:
        motion = law.sample(t_motion)
    else:
        motion = BallMotion.from_trace(motion_source, t_motion + motion_source.time[0])
    motion = _number_balls(motion)
    truth = renderer.truth(motion, index, times, sub)
    frames = tqdm(_frames(renderer, motion, index, times, sub, workers), total=len(times), desc=path.name,
                  unit="frame", disable=not progress, leave=False)
    video = _write_video(path, frames, len(times), times, renderer, fmt)
    stem = path.name if fmt in ("tif", "png") else path.stem
    truth_csv = path.with_name(f"{stem}.truth.csv")
    atomic_write_text(truth_csv, truth.to_csv(index=False, float_format="%.9g"))
    meta = _metadata(renderer, video, fmt, (index, times, n_frames), sub, speed, motion, law)
    truth_json = path.with_name(f"{stem}.truth.json")
    atomic_write_text(truth_json, json.dumps(meta, indent=1, default=float))
    return ClipResult(video=video, truth_csv=truth_csv, truth_json=truth_json, n_frames=len(times), truth=truth)


def _metadata(renderer: Any, video: Path, fmt: str, frames: tuple[np.ndarray, np.ndarray, int], sub: int,
              speed: float, motion: BallMotion, law: Any) -> dict[str, Any]:
    """The clip's ``.truth.json``: how it was made. ``frames`` is (frame indices taken, their times, frames
    requested)."""
    index, times, n_frames = frames
    return {
        "software_version": __version__, "video": video.name, "format": fmt, "seed": renderer.seed,
        "n_frames_taken": int(len(times)), "n_frames_requested": int(n_frames),
        "dropped_frames": sorted(set(range(n_frames)) - set(index.tolist())),
        "exposure_subsamples": sub, "speed_rpm": speed, "columns": list(TRUTH_COLUMNS),
        "camera": asdict(renderer.camera), "appearance": asdict(renderer.look),
        "centre_px": list(renderer.camera.centre_px), "ring_radii_m": asdict(renderer.radii),
        "highlight_offset_px": list(renderer._light_px), "direction": motion.direction,
        "motion": _describe_law(law) if law is not None else {"source": "trace"},
        "conventions": "pixel centres at integer (u, v); angle_rad is the unwrapped orbital angle in the "
                       "bearing frame at mid-exposure; time_s is the frame time stamp",
    }


def _number_balls(motion: BallMotion) -> BallMotion:
    """Renumber balls by the project's convention: counter-clockwise from the ball just after the largest gap at the
    start, ball 0's angle in [0, 2 pi) and each next ball ahead of the previous one."""
    order = ball_order(motion.angle[0])
    angle = normalise_unwrapped(motion.angle[:, order])
    return BallMotion(times=motion.times, angle=angle, radius=motion.radius[:, order], ring_angle=motion.ring_angle,
                      ring_offset=motion.ring_offset, direction=motion.direction)


def _describe_law(law: KinematicLaw) -> dict[str, Any]:
    d = {k: v for k, v in asdict(law).items() if k != "geometry"}
    d["source"] = "kinematic law"
    return d


def _write_video(path: Path, frames: Iterator[np.ndarray], n: int, times: np.ndarray, renderer: Renderer,
                 fmt: str) -> Path:
    cam = renderer.camera
    if fmt.startswith("cine-"):
        kind = fmt.removeprefix("cine-")
        bits = {"8": 8, "16": cam.bit_depth, "p10": 10, "p12": 12}.get(kind)
        if bits is None or (kind != "16" and bits != cam.bit_depth):
            raise ParameterError("fmt", f"{fmt} does not fit a {cam.bit_depth}-bit camera")
        return write_cine(path, frames, n_frames=n, fps=cam.fps, fmt=kind, real_bpp=bits, timestamps_s=times,
                          exposure_s=cam.exposure_s, description="cageless synthetic bearing video")
    if fmt == "ffv1":
        if cam.bit_depth != 8:
            raise ParameterError("fmt", "FFV1 output is 8-bit; use an 8-bit camera")
        if len(times) > 1 and not np.allclose(np.diff(times), 1 / cam.fps):
            raise ParameterError("fmt", "FFV1 keeps no time stamps, so it cannot show dropped frames")
        return write_ffv1(path, frames, fps=cam.fps)
    if fmt in ("tif", "png"):
        return write_image_sequence(path, frames, times_s=times, suffix=f".{fmt}")
    raise ParameterError("fmt", "must be cine-8, cine-16, cine-p10, cine-p12, ffv1, tif or png", fmt)


def frames_for_revolutions(geometry: Any, speed_rpm: float, fps: float, revolutions: float) -> int:
    """Frames needed for each ball to travel ``revolutions`` orbits at the pure-rolling cage speed."""
    omega_c = theoretical_cage_speed(geometry, rpm_to_rad_s(speed_rpm))
    return int(math.ceil(revolutions * 2 * math.pi / omega_c * fps))
