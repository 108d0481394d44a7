"""Synthetic lab folders: several clips with their conditions and ground truth.

Two presets:

``lab``
    The bundled sample (``sample_data/lab``): the paper's field of view binned
    4x (320 x 200 px at 3.125 px/mm), 10,000 fps, three conditions (1800, 3000
    and 6000 rpm at 500 N), each clip long enough for every ball to travel a
    third of an orbit, so the 14 balls together cover 360 deg about 4-5 times.
    The conditions are given in the three ways a lab folder allows (sidecar, conditions.csv, file name), and the clips
    use three formats:

    * ``run_1800/``: 8-bit PNG sequence, conditions in the sidecar ``run_1800.toml``
      (with ``fps`` and a 2 deg camera roll), highlight dropouts and hot pixels;
    * ``clip_3000rpm.mkv``: 8-bit FFV1 in Matroska, conditions in ``conditions.csv``
      (with ``fps``), bearing off-centre;
    * ``n6000_Fr500_Fa0.cine``: packed 12-bit cine, conditions in the file name,
      dropped frames visible in its time stamps.

``full``
    Full-size footage for benchmarks: 1280 x 800 px at 12.5 px/mm (the paper's
    camera), 10,000 fps, 12-bit data in 16-bit cine words (how Phantom Camera
    Control saves by default), the same three conditions.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from tqdm.auto import tqdm

from cageless._version import __version__
from cageless.atomic import atomic_write_text
from cageless.bearing import Geometry
from cageless.errors import ParameterError
from cageless.parameter_sets import wang2026
from cageless.tracking.synthetic.camera import Appearance, Camera
from cageless.tracking.synthetic.clip import frames_for_revolutions, render_clip
from cageless.tracking.synthetic.motion import KinematicLaw
from cageless.tracking.synthetic.render import Renderer

__all__ = ["ClipSpec", "PRESETS", "make_lab"]

log = logging.getLogger(__name__)


@dataclass(frozen=True)
class ClipSpec:
    """One clip of a synthetic lab folder."""

    name: str
    speed_rpm: float
    fmt: str
    conditions_via: str  # "sidecar" | "csv" | "name"
    camera: Camera
    appearance: Appearance
    radial_load_n: float = 500.0


_SMALL = Camera(width=320, height=200, px_per_mm=3.125, bit_depth=8, read_noise_e=25.0)
_FULL = Camera(width=1280, height=800, px_per_mm=12.5, bit_depth=12)

PRESETS: dict[str, list[ClipSpec]] = {
    "lab": [
        ClipSpec("run_1800", 1800, "png", "sidecar", replace(_SMALL, roll_deg=2.0),
                 Appearance(dropout_rate=0.01, n_hot_pixels=6)),
        ClipSpec("clip_3000rpm.mkv", 3000, "ffv1", "csv", replace(_SMALL, centre_offset_px=(6.5, -4.0)), Appearance()),
        ClipSpec("n6000_Fr500_Fa0.cine", 6000, "cine-p12", "name", replace(_SMALL, bit_depth=12),
                 Appearance(dropped_frame_rate=0.02, highlight_peak=1.05)),
    ],
    "full": [
        ClipSpec("n1800_Fr500_Fa0.cine", 1800, "cine-16", "name", replace(_FULL, roll_deg=1.0),
                 Appearance(dropout_rate=0.01, n_hot_pixels=40)),
        ClipSpec("n3000_Fr500_Fa0.cine", 3000, "cine-16", "name", replace(_FULL, centre_offset_px=(25.0, -12.0)),
                 Appearance()),
        ClipSpec("n6000_Fr500_Fa0.cine", 6000, "cine-16", "name", _FULL, Appearance(dropped_frame_rate=0.01)),
    ],
}

_REVOLUTIONS = {"lab": 0.34, "full": 0.1}


def make_lab(
    out: str | Path, preset: str = "lab", seed: int = 2026, revolutions: float | None = None,
    geometry: Geometry | None = None, workers: int = 1, progress: bool = True,
) -> list[dict[str, Any]]:
    """Render a synthetic lab folder.

    Parameters
    ----------
    out
        Folder to write (created; existing clips of the same names are replaced atomically).
    preset
        ``"lab"`` or ``"full"`` (see the module docstring).
    seed
        Seed; clip k uses ``seed + k``.
    revolutions
        Orbits each ball travels per clip; default 0.34 (lab) or 0.1 (full).
    geometry
        Bearing geometry; default the paper's.
    workers
        Processes rendering frames in parallel.
    progress
        Show a progress bar.

    Returns
    -------
    list of dict
        Per clip: the video path, its ground-truth files and frame count.
    """
    if preset not in PRESETS:
        raise ParameterError("preset", f"must be one of {sorted(PRESETS)}", preset)
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    g = geometry or wang2026.geometry()
    revs = _REVOLUTIONS[preset] if revolutions is None else revolutions
    results, csv_rows = [], []
    for k, spec in enumerate(tqdm(PRESETS[preset], desc="clips", unit="clip", disable=not progress)):
        n = frames_for_revolutions(g, spec.speed_rpm, spec.camera.fps, revs)
        renderer = Renderer(g, spec.camera, spec.appearance, seed=seed + k)
        law = KinematicLaw(g, spec.speed_rpm, seed=seed + k)
        res = render_clip(out / spec.name, renderer, n, law=law, fmt=spec.fmt, workers=workers, progress=progress)
        log.info("%s: %d frames", res["video"], res["n_frames"])
        _write_conditions(out, spec, csv_rows)
        results.append({k2: v for k2, v in res.items() if k2 != "truth"})
    if csv_rows:
        header = "file,speed_rpm,radial_load_n,axial_load_n,fps\n"
        atomic_write_text(out / "conditions.csv", header + "".join(csv_rows))
    atomic_write_text(out / "README.md", _readme(preset, seed, revs, results))
    return results


def _write_conditions(out: Path, spec: ClipSpec, csv_rows: list[str]) -> None:
    cam = spec.camera
    if spec.conditions_via == "sidecar":
        text = (f"speed_rpm = {spec.speed_rpm:g}\nradial_load_n = {spec.radial_load_n:g}\naxial_load_n = 0\n"
                f"fps = {cam.fps:g}\ncamera_roll_deg = {cam.roll_deg:g}\n")
        atomic_write_text(out / f"{Path(spec.name).stem}.toml", text)
    elif spec.conditions_via == "csv":
        csv_rows.append(f"{spec.name},{spec.speed_rpm:g},{spec.radial_load_n:g},0,{cam.fps:g}\n")


def _readme(preset: str, seed: int, revs: float, results: list[dict[str, Any]]) -> str:
    lines = [
        f"# Synthetic lab folder (preset `{preset}`)",
        "",
        f"Rendered by cageless {__version__} with seed {seed}: every ball travels {revs:g} of an orbit per clip.",
        "Regenerate with `python sample_data/make_lab.py` (or `cageless sample DIR --preset "
        f"{preset} --seed {seed}`). Nothing here is real footage: it is rendered from a kinematic",
        "ball-motion law (balls slip in the unloaded zone, bunch and jump at contacts, never overlap),",
        "with the appearance of real high-speed footage (offset, sometimes saturated highlights; brushed",
        "rings with static and turning glints; flicker; shot and read noise; dropouts; dropped frames).",
        "",
        "| clip | frames | conditions from |",
        "|---|---|---|",
    ]
    for spec, res in zip(PRESETS[preset], results, strict=True):
        via = {"sidecar": f"sidecar `{Path(spec.name).stem}.toml`", "csv": "`conditions.csv`", "name": "file name"}
        lines.append(f"| `{Path(res['video']).name}` ({spec.fmt}, {spec.speed_rpm:g} rpm) | {res['n_frames']} | "
                     f"{via[spec.conditions_via]} |")
    lines += [
        "",
        "Ground truth beside each clip: `<clip>.truth.csv` (one row per frame and ball: frame, time_s, ball,",
        "angle_rad, radius_m, centre and highlight pixel positions, highlight_visible, highlight_peak) and",
        "`<clip>.truth.json` (camera, appearance, motion law, dropped frames). Pixel centres are at integer",
        "(u, v); angles are unwrapped orbital angles in the bearing frame (x along the shaft toward the camera,",
        "z up, angle counter-clockwise as the camera sees it).",
        "",
    ]
    return "\n".join(lines)
