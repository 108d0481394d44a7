"""The track fit's window chosen by cross-validation against the fixed 7 frames: accuracy and cost.

    python benchmarks/track_fit_window.py [--frames 3000] [--repeats 3]

Accuracy: the renderer's ball-motion law (tracking/synthetic/motion.py: 14 balls, impacts between neighbours,
speed jumps) sampled at 10,000 frames/s, white localisation noise added; for each speed and noise level the
window chosen (tracking/track_window.py) and the angle and speed errors of the fit against the law, with the
fixed 7-frame window beside it (RMS and largest, after the first and last 30 frames; speed through the default
21-frame Savitzky-Golay filter of both, % of the cage speed). Cost: CPU seconds of the choice and of the two
fits on 10,000 frames of 14 balls, same run, alternating.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from cageless.bearing import default_bearing
from cageless.kinematics import theoretical_cage_speed
from cageless.tracking.kinematics import DEFAULT_WINDOW, revolution_speed, robust_track_fit
from cageless.tracking.synthetic.motion import KinematicLaw
from cageless.tracking.track_window import choose_track_fit
from cageless.units import rpm_to_rad_s

FPS = 10_000.0
EDGE = 30


def _errors(t: np.ndarray, y: np.ndarray, truth: np.ndarray, ref: np.ndarray, omega_c: float,
            frames: int) -> tuple[float, float, float, float]:
    fit, _ = robust_track_fit(t, y, np.ones_like(y, bool), frames)
    e = (fit - truth)[EDGE:-EDGE]
    sp = (revolution_speed(t, fit, DEFAULT_WINDOW) - ref)[EDGE:-EDGE] / omega_c * 100
    return (1e3 * float(np.sqrt(np.mean(e * e))), 1e3 * float(np.abs(e).max()), float(np.sqrt(np.mean(sp * sp))),
            float(np.abs(sp).max()))


def accuracy_table(n_frames: int) -> str:
    """Markdown table: chosen window and errors against the fixed 7 frames on the kinematic law."""
    g = default_bearing().geometry
    t = np.arange(n_frames) / FPS
    lines = ["| r/min | noise (mrad) | window | angle RMS / max (mrad), 7 -> chosen | "
             "speed RMS / max (% of cage speed), 7 -> chosen |", "|---|---|---|---|---|"]
    for rpm in (1800, 3000, 6000):
        truth = KinematicLaw(g, rpm, seed=1).sample(t).angle
        omega_c = theoretical_cage_speed(g, rpm_to_rad_s(rpm))
        ref = revolution_speed(t, truth, DEFAULT_WINDOW)
        for noise in (0.0, 0.02, 0.05, 0.1, 0.3):
            y = truth + np.random.default_rng(0).normal(0, noise * 1e-3, truth.shape)
            n = choose_track_fit(t, y, np.ones_like(y, bool)).frames
            a = _errors(t, y, truth, ref, omega_c, 7)
            b = _errors(t, y, truth, ref, omega_c, n)
            lines.append(f"| {rpm} | {noise} | {n} | {a[0]:.4f} / {a[1]:.3f} -> {b[0]:.4f} / {b[1]:.3f} | "
                         f"{a[2]:.4f} / {a[3]:.3f} -> {b[2]:.4f} / {b[3]:.3f} |")
    return "\n".join(lines)


def cost_table(repeats: int) -> str:
    """Markdown table: CPU seconds of the choice and the fits on 10,000 frames of 14 balls."""
    t = np.arange(10_000) / FPS
    rng = np.random.default_rng(0)
    a = np.cumsum(np.full((len(t), 14), 0.02), axis=0) + rng.normal(0, 1e-3, (len(t), 14))
    ok = np.ones_like(a, bool)
    choose_track_fit(t[:1000], a[:1000], ok[:1000])  # compile
    rows: dict[str, list[float]] = {"choice": [], "fit, 7 frames": [], "fit, chosen": []}
    n = 7
    for _ in range(repeats):
        for name in rows:
            start = time.process_time()
            if name == "choice":
                n = choose_track_fit(t, a, ok).frames
            else:
                robust_track_fit(t, a, ok, 7 if name == "fit, 7 frames" else n)
            rows[name].append(time.process_time() - start)
    base = min(rows["fit, 7 frames"])
    lines = [f"| step (10,000 frames, 14 balls; chosen: {n} frames) | CPU s (best of {repeats}) | x the 7-frame fit |",
             "|---|---|---|"]
    lines += [f"| {k} | {min(v):.3f} | {min(v) / base:.2f} |" for k, v in rows.items()]
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--frames", type=int, default=3000)
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args(argv)
    print(accuracy_table(args.frames) + "\n\n" + cost_table(args.repeats))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
