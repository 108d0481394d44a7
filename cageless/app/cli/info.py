"""``cageless info``: the bearing, its pure-rolling kinematics and characteristic frequencies."""

from __future__ import annotations

import argparse
import json
import math
from typing import Any

from cageless.bearing import Bearing
from cageless.app.cli.common import finite_float
from cageless.config import bearing_from_config
from cageless.errors import CagelessError
from cageless.kinematics import (
    centrifugal_force,
    characteristic_frequencies,
    kinematic_ratios,
    theoretical_cage_speed,
)
from cageless.units import rad_s_to_rpm, rpm_to_rad_s

__all__ = ["register", "run", "describe_bearing"]

_EXAMPLES = """\
examples:
  cageless info                          paper bearing at 3000 rpm
  cageless info clip.cine                what the reader sees in a video (frames, size, timing)
  cageless info frames/ --fps 10000      an image-sequence folder, with its frame rate
  cageless info --speed-rpm 1800 --json  the same as JSON, at 1800 rpm
  cageless info --config lab.toml        with bearing overrides from a TOML file
"""


def _duration(m: dict[str, Any]) -> str:
    """The ``duration_s`` of the JSON (frames over the rate in use), and the span from the first frame's time to
    the last's, which is one frame period shorter."""
    parts = [] if m.get("duration_s") is None else [f"{m['duration_s']:.6g} s ({m['n_frames']} frames)"]
    if m.get("last_time_s") is not None:
        parts.append(f"{m['last_time_s']:.6g} s first to last frame")
    return "; ".join(parts) or "unknown"


def register(subparsers: Any, parent: argparse.ArgumentParser) -> None:
    """Add the ``info`` subcommand."""
    p = subparsers.add_parser(
        "info", parents=[parent], help="show the bearing, its kinematics and characteristic frequencies",
        description="Print the bearing (default: the paper's, Table 1), its derived pure-rolling "
        "kinematics and its characteristic frequencies at an inner-ring speed.",
        epilog=_EXAMPLES, formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("video", nargs="?", help="a video file or image folder to describe instead of the bearing")
    p.add_argument("--fps", type=finite_float, default=None, help="frame-rate override for VIDEO (frames/s)")
    p.add_argument("--allow-truncated", action="store_true",
                   help="describe the complete frames of a truncated .cine instead of refusing it")
    p.add_argument("--speed-rpm", type=finite_float, default=3000.0, help="inner-ring speed in rpm (default 3000)")
    p.add_argument(
        "--contact-angle-deg", type=finite_float, default=0.0,
        help="contact angle in degrees for the kinematics (default 0, pure radial load)",
    )
    p.add_argument("--json", action="store_true", help="print JSON instead of text")


def describe_bearing(bearing: Bearing, speed_rpm: float, contact_angle_deg: float = 0.0) -> dict[str, Any]:
    """Return the bearing, its derived quantities and its kinematics at ``speed_rpm``, JSON-ready (SI)."""
    g = bearing.geometry
    alpha = math.radians(contact_angle_deg)
    omega_i = rpm_to_rad_s(speed_rpm)
    omega_c = theoretical_cage_speed(g, omega_i, alpha)
    return {
        "bearing": bearing.to_dict(),
        "derived": {
            "pitch_diameter_m": g.pitch_diameter_m,
            "diametral_clearance_m": g.diametral_clearance_m,
            "max_ball_count": g.max_ball_count,
            "inner_groove_radius_m": g.inner_groove_radius_m,
            "outer_groove_radius_m": g.outer_groove_radius_m,
            "ring_translational_mass_kg": bearing.masses.ring_translational_mass_kg,
        },
        "speed_rpm": speed_rpm,
        "contact_angle_rad": alpha,
        "ratios": kinematic_ratios(g, alpha).to_dict(),
        "inner_speed_rad_s": omega_i,
        "cage_speed_rad_s": omega_c,
        "cage_speed_rpm": rad_s_to_rpm(omega_c),
        "centrifugal_force_n": centrifugal_force(bearing.masses, g, omega_c),
        "frequencies_hz": characteristic_frequencies(g, speed_rpm, alpha).to_dict(),
    }


def _format_text(d: dict[str, Any]) -> str:
    b, der, r, f = d["bearing"], d["derived"], d["ratios"], d["frequencies_hz"]
    g, m, mat, lub = b["geometry"], b["masses"], b["material"], b["lubricant"]
    mm = 1e3
    lines = [
        f"Bearing: {b['name']}",
        f"  races (inner/outer)          {g['inner_race_diameter_m'] * mm:.3f} / {g['outer_race_diameter_m'] * mm:.3f} mm",
        f"  ball diameter D              {g['ball_diameter_m'] * mm:.4f} mm, Z = {g['n_balls']}",
        f"  curvature factors f_i / f_o  {g['inner_curvature_factor']:.4g} / {g['outer_curvature_factor']:.4g}",
        f"  masses ball / ring / shaft   {m['ball_mass_kg']:.5g} / {m['inner_ring_mass_kg']:.5g} / {m['shaft_mass_kg']:.5g} kg",
        f"  material                     E = {mat['youngs_modulus_pa'] / 1e9:.4g} GPa, nu = {mat['poisson_ratio']:.3g}, "
        f"rho = {mat['density_kg_m3']:.5g} kg/m^3",
        "  lubricant                    "
        + ("none (dry)" if lub is None else f"eta0 = {lub['dynamic_viscosity_pa_s']:.4g} Pa s, "
           f"alpha = {lub['pressure_viscosity_coefficient_1_pa']:.3g} 1/Pa, rho = {lub['density_kg_m3']:.4g} kg/m^3"),
        "Derived",
        f"  pitch diameter d_m           {der['pitch_diameter_m'] * mm:.4f} mm",
        f"  diametral clearance          {der['diametral_clearance_m'] * 1e6:.3f} um",
        f"  most balls that fit          {der['max_ball_count']}",
        f"  gamma = D cos(a)/d_m         {r['gamma']:.6f}",
        f"  cage speed ratio w_c/w_i     {r['cage_ratio']:.6f}",
        f"  ball spin ratio (rel. cage)  {r['ball_spin_ratio']:.6f}",
        f"At {d['speed_rpm']:g} rpm (inner ring turning, outer ring fixed, contact angle "
        f"{math.degrees(d['contact_angle_rad']):g} deg)",
        f"  inner-ring speed w_i         {d['inner_speed_rad_s']:.4f} rad/s",
        f"  pure-rolling cage speed w_c  {d['cage_speed_rad_s']:.4f} rad/s ({d['cage_speed_rpm']:.3f} rpm)",
        f"  centrifugal force per ball   {d['centrifugal_force_n']:.4f} N (at w_c, pitch radius)",
        f"  FTF   {f['ftf_hz']:10.3f} Hz",
        f"  BPFO  {f['bpfo_hz']:10.3f} Hz",
        f"  BPFI  {f['bpfi_hz']:10.3f} Hz",
        f"  BSF   {f['bsf_hz']:10.3f} Hz",
    ]
    return "\n".join(lines)


def describe_video(path: str, fps: float | None = None, allow_truncated: bool = False) -> dict[str, Any]:
    """Return what the reader sees in a video, JSON-ready."""
    from cageless.tracking.io import open_video

    with open_video(path, fps=fps, allow_truncated=allow_truncated) as video:
        meta = video.metadata.to_dict()
        meta["extra"] = {k: v for k, v in meta["extra"].items() if k != "exposure_per_frame_s"}
        try:
            t = video.times
            meta["first_time_s"], meta["last_time_s"] = float(t[0]), float(t[-1])
        except CagelessError as exc:
            meta["notes"].append(str(exc))
    return meta


def _format_video(m: dict[str, Any]) -> str:
    def fps(v: float | None) -> str:
        return "unknown" if v is None else f"{v:.6g} fps"

    lines = [
        f"Video: {m['path']}",
        f"  format            {m['format']} ({m['storage']})",
        f"  frames            {m['n_frames']}",
        f"  size              {m['width']} x {m['height']} px, {m['dtype']}, {m['bit_depth']}-bit",
        f"  header rate       {fps(m['header_fps'])}",
        f"  time-stamp rate   {fps(m['timestamp_fps'])}",
        f"  time from         {m['time_source'] or 'nothing (give --fps)'}",
        "  duration          " + _duration(m),
        "  exposure          " + ("unknown" if m["exposure_s"] is None else f"{m['exposure_s'] * 1e6:.4g} us"),
    ]
    if m["camera"]:
        lines.append(f"  camera            {m['camera']}")
    lines += [f"  note: {n}" for n in m["notes"]]
    return "\n".join(lines)


def run(args: argparse.Namespace, config: dict[str, Any]) -> int:
    """Print the bearing or video description; return the exit code."""
    from cageless.validate import check_options

    check_options(args, ("fps", "speed_rpm"), force=False)
    if args.video is not None:
        meta = describe_video(args.video, args.fps, args.allow_truncated)
        print(json.dumps(meta, indent=2) if args.json else _format_video(meta))
        return 0
    bearing = bearing_from_config(config)
    description = describe_bearing(bearing, float(args.speed_rpm), float(args.contact_angle_deg))
    if args.json:
        from cageless._version import __version__

        print(json.dumps({"software_version": __version__, **description}, indent=2))
    else:
        print(_format_text(description))
    return 0
