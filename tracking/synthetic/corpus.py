"""Render one corpus clip from a seed: the video, its conditions, its bearing and its ground truth.

Public API (stable)::

    render_clip(seed: int, folder: Path, long: bool = False) -> ClipSpec
    load_clip(seed: int, folder: Path, long: bool = False) -> ClipSpec | None

``render_clip`` writes into ``folder`` (and reuses a clip already there when its
parameters and the software version match):

* ``c<seed>_n<rpm>_Fr<N>_Fa0.cine`` (8-bit, packed 12-bit, or 16-bit words holding
  12 or 16 bits) or ``.avi`` (MJPG, 8 bit, container rate <= 1000 fps: the true
  rate is in the sidecar);
* ``<stem>.toml``: the conditions sidecar (``speed_rpm``, loads, ``fps``,
  ``px_per_mm``, ``camera_roll_deg``, and the bearing: ``n_balls``,
  ``ball_diameter_mm``, ``pitch_diameter_mm``);
* ``<stem>.bearing.toml``: the bearing as a ``--config`` file (``[bearing.geometry]``);
* ``<stem>.truth.csv``: one row per frame and ball, :data:`TRUTH_COLUMNS`;
* ``<stem>.truth.json``: the parameters, the bearing, the software version.

Ground truth is at each frame's time stamp (mid-exposure); ``angle_rad`` is the
unwrapped orbital angle of the ball centre in the frame where the inner ring
turns +theta (a mirrored video is read back into it, and its trace says
``direction = -1``), balls numbered counter-clockwise from the ball just after the
largest gap at the start. ``speed_rad_s`` is the instantaneous revolution speed
and ``slip`` is ``1 - speed / omega_c`` with the pure-rolling cage speed.
"""

from __future__ import annotations

import hashlib
import struct
import json
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import cv2
import numpy as np
import pandas as pd

from cageless._version import __version__
from cageless.atomic import atomic_path, atomic_write_text
from cageless.balls import ball_order, normalise_unwrapped
from cageless.bearing import Bearing
from cageless.conditions import OperatingConditions
from cageless.errors import VideoError
from cageless.kinematics import theoretical_cage_speed
from cageless.units import rpm_to_rad_s
from cageless.tracking.io import write_cine
from cageless.tracking.synthetic.appearance import ClipParams, draw_params
from cageless.tracking.synthetic.motion import KinematicLaw
from cageless.tracking.synthetic.scene3d import FrameState, SceneRenderer

__all__ = ["ClipSpec", "render_clip", "load_clip", "clip_truth", "TRUTH_COLUMNS", "clip_stem", "simulate_motion",
           "conditions_of", "describe"]

TRUTH_COLUMNS = ("frame", "time_s", "ball", "angle_rad", "speed_rad_s", "slip", "centre_u_px", "centre_v_px",
                 "highlight_u_px", "highlight_v_px", "highlight_visible")
_AVI_MAX_FPS = 1000.0
_SPEED_DT = 1e-6
#: Bumped when what render_clip writes changes, so cached clips are rendered again.
_FORMAT = 8


@dataclass
class ClipSpec:
    """A rendered corpus clip: where it is, what it shows and the truth.

    Attributes
    ----------
    seed, params
        The seed and its parameter draw.
    video, sidecar, bearing_toml, truth_csv, truth_json
        The files written.
    bearing
        The bearing shown (Z, ball and pitch diameters).
    conditions
        The operating conditions as the sidecar gives them.
    truth
        Ground truth, one row per frame and ball (:data:`TRUTH_COLUMNS`).
    omega_c
        Pure-rolling cage speed (rad/s).
    render_s
        Wall time of the render (0 when reused from the folder).
    """

    seed: int
    params: ClipParams
    video: Path
    sidecar: Path
    bearing_toml: Path
    truth_csv: Path
    truth_json: Path
    bearing: Bearing
    conditions: OperatingConditions
    truth: pd.DataFrame
    omega_c: float
    render_s: float = 0.0

    @property
    def n_frames(self) -> int:
        """Frames in the video."""
        return int(self.truth.frame.nunique())


def clip_stem(params: ClipParams, long: bool = False) -> str:
    """File stem of a clip: seed, speed and load (the lab folder's file-name convention)."""
    return (f"c{params.seed:05d}{'L' if long else ''}_n{params.speed_rpm:.0f}_Fr{params.radial_load_n:.0f}_Fa0")


def _key(params: ClipParams, long: bool) -> str:
    text = json.dumps({"params": params.to_dict(), "long": long, "version": __version__, "format": _FORMAT},
                      sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def load_clip(seed: int, folder: str | Path, long: bool = False) -> ClipSpec | None:
    """The clip of ``seed`` already rendered in ``folder`` by this version, or ``None``."""
    params = draw_params(seed)
    folder = Path(folder)
    stem = clip_stem(params, long)
    meta_path = folder / f"{stem}.truth.json"
    if not meta_path.is_file():
        return None
    meta = json.loads(meta_path.read_text())
    video = folder / meta["video"]
    if meta.get("key") != _key(params, long) or not video.is_file():
        return None
    truth = pd.read_csv(folder / f"{stem}.truth.csv")
    return _spec(params, folder, stem, video, truth, 0.0)


def _spec(params: ClipParams, folder: Path, stem: str, video: Path, truth: pd.DataFrame, wall: float) -> ClipSpec:
    b = params.bearing
    return ClipSpec(seed=params.seed, params=params, video=video, sidecar=folder / f"{stem}.toml",
                    bearing_toml=folder / f"{stem}.bearing.toml", truth_csv=folder / f"{stem}.truth.csv",
                    truth_json=folder / f"{stem}.truth.json", bearing=b, conditions=conditions_of(params),
                    truth=truth, omega_c=theoretical_cage_speed(b.geometry, rpm_to_rad_s(params.speed_rpm)),
                    render_s=wall)


def conditions_of(params: ClipParams) -> OperatingConditions:
    """The conditions a lab would write down for this clip.

    ``fps`` only for AVI, whose container cannot hold the rate: for a cine it would override the per-frame
    time stamps, and with them the gaps that dropped frames leave.
    """
    fps = params.fps if params.container == "avi-mjpg" else None
    return OperatingConditions(speed_rpm=round(params.speed_rpm, 3), radial_load_n=round(params.radial_load_n, 1),
                               axial_load_n=0.0, fps=fps, px_per_mm=round(params.px_per_mm, 6),
                               camera_roll_deg=round(params.roll_deg, 6))


def simulate_motion(params: ClipParams, n_frames: int) -> dict[str, np.ndarray]:
    """Frame plan and ball motion: kept frame indices, time stamps (s), angles, speeds, ring angle, dark flags.

    The ball motion is :class:`~cageless.tracking.synthetic.motion.KinematicLaw` (hard balls on the pitch circle,
    slip in the unloaded zone, bunching, cyclic order kept), sampled at each time stamp and 1 us either
    side in one integration, so the speed is a central difference of the true angle.
    """
    rng = np.random.default_rng([params.seed, 3])
    keep = rng.random(n_frames) >= params.dropped_frame_rate
    keep[0] = keep[-1] = True
    index = np.flatnonzero(keep)
    times = index / params.fps
    dark = np.random.default_rng([params.seed, 4]).random(len(index)) < params.dark_frame_rate
    dark[:2] = False
    law = KinematicLaw(params.geometry, params.speed_rpm, slip_peak=params.slip_peak,
                       restitution=params.restitution, seed=params.seed, direction=params.direction)
    t0 = 2 * _SPEED_DT
    samples = (t0 + times[:, None] + np.array([-_SPEED_DT, 0.0, _SPEED_DT])[None, :]).ravel()
    motion = law.sample(samples)
    ang = motion.angle.reshape(len(times), 3, -1)
    order = ball_order(ang[0, 1])
    angle = normalise_unwrapped(ang[:, 1][:, order])
    speed = (ang[:, 2] - ang[:, 0])[:, order] / (2 * _SPEED_DT)
    ring = rpm_to_rad_s(params.speed_rpm) * (times + t0)
    return {"index": index, "times": times, "angle": angle, "speed": speed, "ring": ring, "dark": dark}


def _truth(params: ClipParams, renderer: SceneRenderer, m: dict[str, np.ndarray], omega_c: float) -> pd.DataFrame:
    t, z = m["angle"].shape
    uc, vc = renderer.to_undistorted(m["angle"], renderer.rp)
    du, dv = renderer.highlight_offset_px
    hu, hv = renderer.distort(uc + du, vc + dv)
    cu, cv = renderer.distort(uc, vc)
    vis = np.repeat(~m["dark"][:, None], z, axis=1)
    if params.land_mode == "hidden":  # the highlight must lie in the visible band
        rr = np.hypot(uc + du - renderer.centre[0], vc + dv - renderer.centre[1]) / renderer.s
        vis &= (rr > renderer.r_il) & (rr < renderer.r_ol)
    return pd.DataFrame({
        "frame": np.repeat(m["index"], z), "time_s": np.repeat(m["times"], z), "ball": np.tile(np.arange(z), t),
        "angle_rad": m["angle"].ravel(), "speed_rad_s": m["speed"].ravel(), "slip": 1 - m["speed"].ravel() / omega_c,
        "centre_u_px": cu.ravel(), "centre_v_px": cv.ravel(), "highlight_u_px": hu.ravel(),
        "highlight_v_px": hv.ravel(), "highlight_visible": vis.ravel(),
    })


def clip_truth(seed: int, long: bool = False) -> tuple[ClipParams, pd.DataFrame, float]:
    """The parameters, ground truth and cage speed (rad/s) of a clip, without rendering its frames."""
    params = draw_params(seed)
    m = simulate_motion(params, params.n_frames_long if long else params.n_frames)
    omega_c = theoretical_cage_speed(params.geometry, rpm_to_rad_s(params.speed_rpm))
    return params, _truth(params, SceneRenderer(params, geometry_only=True), m, omega_c), omega_c


def _frames(renderer: SceneRenderer, m: dict[str, np.ndarray]) -> Iterator[np.ndarray]:
    for i in range(len(m["times"])):
        state = FrameState(time_s=float(m["times"][i]), angle=m["angle"][i], speed=m["speed"][i],
                           ring_angle=float(m["ring"][i]), dark=bool(m["dark"][i]))
        yield renderer.frame(state, int(m["index"][i]))


def render_clip(seed: int, folder: str | Path, long: bool = False) -> ClipSpec:
    """Render the clip of ``seed`` into ``folder`` (reused if already there); see the module docstring.

    Parameters
    ----------
    seed
        The clip's seed (:func:`~cageless.tracking.synthetic.appearance.draw_params`).
    folder
        Output folder, created if needed.
    long
        Render the long variant (one cage revolution) instead of the short CI clip.
    """
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    cached = load_clip(seed, folder, long)
    if cached is not None:
        return cached
    start = time.perf_counter()
    params = draw_params(seed)
    stem = clip_stem(params, long)
    n = params.n_frames_long if long else params.n_frames
    renderer = SceneRenderer(params)
    m = simulate_motion(params, n)
    omega_c = theoretical_cage_speed(params.geometry, rpm_to_rad_s(params.speed_rpm))
    truth = _truth(params, renderer, m, omega_c)
    video = _write_video(folder / stem, params, _frames(renderer, m), m["times"])
    _write_sidecars(folder, stem, params)
    atomic_write_text(folder / f"{stem}.truth.csv", truth.to_csv(index=False, float_format="%.10g"))
    wall = time.perf_counter() - start
    meta = {"key": _key(params, long), "software_version": __version__, "video": video.name, "seed": seed,
            "long": long, "n_frames_taken": len(m["times"]), "n_frames_requested": n,
            "dropped_frames": sorted(set(range(n)) - set(m["index"].tolist())),
            "dark_frames": m["index"][m["dark"]].tolist(), "params": params.to_dict(),
            "bearing": params.bearing.to_dict(), "omega_c_rad_s": omega_c,
            "highlight_offset_px": list(renderer.highlight_offset_px), "centre_px": list(renderer.centre),
            "radii_m": {"bore": renderer.r_bore, "inner_land": renderer.r_il, "outer_land": renderer.r_ol,
                        "outer": renderer.r_od}, "render_s": wall, "opencv": cv2.__version__,
            "columns": list(TRUTH_COLUMNS)}
    atomic_write_text(folder / f"{stem}.truth.json", json.dumps(meta, indent=1, default=float))
    return _spec(params, folder, stem, video, truth, wall)


def _write_sidecars(folder: Path, stem: str, params: ClipParams) -> None:
    c = conditions_of(params)
    g = params.geometry
    lines = [f"{k} = {v!r}" for k, v in c.to_dict().items() if v is not None]
    lines += [f"n_balls = {g.n_balls}", f"ball_diameter_mm = {g.ball_diameter_m * 1e3!r}",
              f"pitch_diameter_mm = {g.pitch_diameter_m * 1e3!r}"]
    atomic_write_text(folder / f"{stem}.toml", "\n".join(lines) + "\n")
    geo = "\n".join(f"{k} = {v!r}" for k, v in params.bearing.to_dict()["geometry"].items())
    atomic_write_text(folder / f"{stem}.bearing.toml",
                      f"# The bearing of {stem} (use with --config)\n[bearing.geometry]\n{geo}\n")


def _write_video(base: Path, params: ClipParams, frames: Iterator[np.ndarray], times: np.ndarray) -> Path:
    if params.container == "avi-mjpg" and params.codec == "mpeg4":
        return _write_mpeg4(base.with_suffix(".avi"), frames, params, len(times))
    if params.container == "avi-mjpg":
        return _write_mjpg(base.with_suffix(".avi"), frames, params)
    fmt = params.container.removeprefix("cine-")
    return write_cine(base.with_suffix(".cine"), frames, n_frames=len(times), fps=params.fps, fmt=fmt,
                      real_bpp=params.bit_depth, timestamps_s=times, exposure_s=params.exposure_s,
                      description=f"cageless corpus clip, seed {params.seed}")


def _write_mjpg(path: Path, frames: Iterator[np.ndarray], params: ClipParams) -> Path:
    """Motion-JPEG in AVI: each frame JPEG-encoded by OpenCV at the clip's quality, in a plain AVI 1.0
    RIFF file (Microsoft AVI RIFF reference: ``avih``/``strh``/``strf`` headers, ``00dc`` chunks, ``idx1``)."""
    fps = min(params.fps, _AVI_MAX_FPS)
    jpegs = []
    for frame in frames:
        ok, buf = cv2.imencode(".jpg", frame, [cv2.IMWRITE_JPEG_QUALITY, int(params.jpeg_quality)])
        if not ok:
            raise VideoError(path, "OpenCV cannot JPEG-encode a frame.")
        jpegs.append(buf.tobytes())
    with atomic_path(path) as tmp:
        tmp.write_bytes(_avi_bytes(jpegs, params.width, params.height, fps))
    cap = cv2.VideoCapture(str(path))
    found = 0
    while cap.grab():
        found += 1
    cap.release()
    if found != len(jpegs):
        raise VideoError(path, f"the MJPG file holds {found} of {len(jpegs)} frames.")
    return path


def _write_mpeg4(path: Path, frames: Iterator[np.ndarray], params: ClipParams, n: int) -> Path:
    """MPEG-4 Part 2 (Xvid) in AVI through OpenCV's FFmpeg writer at its default bit rate: motion-compensated
    inter-frame prediction, so a frame's artefacts depend on the frames before it."""
    fps = min(params.fps, _AVI_MAX_FPS)
    with atomic_path(path) as tmp:
        out = tmp.with_suffix(".avi")  # OpenCV picks the container by the extension
        try:
            writer = cv2.VideoWriter(str(out), cv2.VideoWriter_fourcc(*"XVID"), fps,
                                     (params.width, params.height), False)
            if not writer.isOpened():
                raise VideoError(path, "OpenCV cannot open an MPEG-4 (XVID) writer.")
            for frame in frames:
                writer.write(frame)
            writer.release()
            out.replace(tmp)
        finally:
            out.unlink(missing_ok=True)
    cap = cv2.VideoCapture(str(path))
    found = 0
    while cap.grab():
        found += 1
    cap.release()
    if found != n:
        raise VideoError(path, f"the MPEG-4 file holds {found} of {n} frames.")
    return path


def _chunk(tag: bytes, data: bytes) -> bytes:
    return tag + struct.pack("<I", len(data)) + data + (b"\0" if len(data) % 2 else b"")


def _avi_bytes(jpegs: list[bytes], width: int, height: int, fps: float) -> bytes:
    n, biggest = len(jpegs), max(len(j) for j in jpegs)
    usec = int(round(1e6 / fps))
    avih = struct.pack("<14I", usec, int(biggest * fps), 0, 0x10, n, 0, 1, biggest, width, height, 0, 0, 0, 0)
    strh = b"vidsMJPG" + struct.pack("<IHHIIIIIIiI4h", 0, 0, 0, 0, 1000, int(round(fps * 1000)), 0, n, biggest,
                                     -1, 0, 0, 0, width, height)
    strf = struct.pack("<IiiHH4sIiiII", 40, width, height, 1, 24, b"MJPG", width * height * 3, 0, 0, 0, 0)
    strl = _chunk(b"LIST", b"strl" + _chunk(b"strh", strh) + _chunk(b"strf", strf))
    hdrl = _chunk(b"LIST", b"hdrl" + _chunk(b"avih", avih) + strl)
    movi, index, offset = [], [], 4
    for j in jpegs:
        c = _chunk(b"00dc", j)
        index.append(b"00dc" + struct.pack("<III", 0x10, offset, len(j)))
        movi.append(c)
        offset += len(c)
    body = b"AVI " + hdrl + _chunk(b"LIST", b"movi" + b"".join(movi)) + _chunk(b"idx1", b"".join(index))
    return b"RIFF" + struct.pack("<I", len(body)) + body


def describe(params: ClipParams) -> dict[str, Any]:
    """A one-line summary of a clip's factors (for tables)."""
    return {"Z": params.n_balls, "res": f"{params.width}x{params.height}", "px/mm": round(params.px_per_mm, 1),
            "bits": params.bit_depth, "fmt": params.container, "rpm": round(params.speed_rpm),
            "slip%": round(100 * params.slip_peak, 1), "faces": params.ring_face, "lands": params.land_mode,
            "fps": int(params.fps), "sat": params.saturated, "dbl": params.second_light_rel > 0,
            "jpeg": params.jpeg_quality, "codec": params.codec, "dir": params.direction}


