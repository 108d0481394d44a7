"""A simulated run dressed as a measured (video) trace, for the calibration tests."""

from __future__ import annotations

from pathlib import Path

from cageless.trace import Trace, VideoInfo, write_trace


def as_video_trace(sim: Trace, settle_s: float, path: str | Path) -> Path:
    """Write the samples of ``sim`` after ``settle_s`` as a video trace (a stand-in for a measurement)."""
    keep = sim.time >= settle_s
    video = Trace(source="video", time=sim.time[keep] - sim.time[keep][0], angle=sim.angle[keep],
                  speed=sim.speed[keep], slip=sim.slip[keep], valid=sim.valid[keep], speed_rpm=sim.speed_rpm,
                  radial_load_n=sim.radial_load_n, axial_load_n=sim.axial_load_n,
                  ball_diameter_m=sim.ball_diameter_m, pitch_diameter_m=sim.pitch_diameter_m,
                  config={"made_from": "a simulation, as a stand-in measurement"},
                  video=VideoInfo(fps=1.0 / float(sim.time[1] - sim.time[0]), px_per_mm=10.0, centre_px=(0.0, 0.0),
                                  camera_roll_rad=0.0, input_file="simulated", input_sha256="0" * 64))
    return write_trace(path, video)
