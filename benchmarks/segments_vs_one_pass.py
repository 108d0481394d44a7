"""Tracking a clip in segments on two threads against one pass: the accuracy check of the segment length.

    python benchmarks/segments_vs_one_pass.py [CLIP ...] [--long-seeds 7004 7011] [--corpus DIR]

Tracks each clip with ``TrackOptions(threads=1)`` (one pass) and ``threads=2`` (overlapping segments of at
least ``segments.MIN_SEGMENT`` frames, stitched), scores both against the clip's truth where it has the
corpus's truth columns (:func:`cageless.tracking.synthetic.score.score_trace`: found balls, identity swaps,
angle RMS, speed RMS, slip-profile MAE) and prints the largest differences between the two traces.
``CLIP`` is a benchmark clip (``bench_*.cine`` of ``benchmarks/track.py``, 3000 rpm, the paper's bearing);
``--long-seeds`` takes the long corpus variants from ``--corpus`` (rendered by the corpus tests).
"""

from __future__ import annotations

import argparse
import logging
import warnings
from pathlib import Path

import numpy as np
import pandas as pd

KEYS = ("n_found", "swaps", "angle_rms_mrad", "speed_rms_pct", "slip_mae_pp")


def _inputs(args: argparse.Namespace) -> list[tuple[Path, object, object, pd.DataFrame]]:
    from cageless.bearing import default_bearing
    from cageless.conditions import OperatingConditions
    from cageless.tracking.synthetic.corpus import load_clip

    out = [(c, OperatingConditions(3000.0, 500.0), default_bearing(), pd.read_csv(c.with_suffix(".truth.csv")))
           for c in args.clips]
    for seed in args.long_seeds:
        spec = load_clip(seed, args.corpus / "long", long=True)
        if spec is None:
            raise SystemExit(f"seed {seed}: no long clip in {args.corpus / 'long'}; run the corpus tests first")
        out.append((spec.video, spec.conditions, spec.bearing, spec.truth))
    return out


def main() -> None:
    from cageless.tracking.pipeline import TrackOptions, track_video
    from cageless.tracking.segments import MIN_SEGMENT as _MIN_SEGMENT
    from cageless.tracking.synthetic.score import score_trace

    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("clips", type=Path, nargs="*")
    ap.add_argument("--long-seeds", type=int, nargs="*", default=[7004, 7011])
    ap.add_argument("--corpus", type=Path, default=Path("/tmp/cageless-corpus"))
    args = ap.parse_args()
    logging.disable(logging.WARNING)
    print(f"segments of at least {_MIN_SEGMENT} frames")
    for clip, cond, bearing, truth in _inputs(args):
        traces = {}
        for threads in (1, 2):
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                res = track_video(clip, cond, bearing, TrackOptions(threads=threads), progress=False)
            traces[threads] = res.trace
            try:
                s = score_trace(res.trace, truth, bearing).to_dict()
                text = ", ".join(f"{k} {s[k]:.4g}" for k in KEYS)
            except KeyError:  # the benchmark clip's truth has positions, not speeds
                text = "no speed truth"
            print(f"{clip.name}: {res.trace.n_samples} frames, threads {threads}: {text}", flush=True)
        a, b = traces[1], traces[2]
        print(f"  one pass vs segments: valid flags differ on {int((a.valid != b.valid).sum())} samples; angle RMS "
              f"{1e3 * np.sqrt(np.nanmean((a.angle - b.angle) ** 2)):.5f} mrad, max "
              f"{1e3 * np.nanmax(np.abs(a.angle - b.angle)):.4f} mrad; slip max {100 * np.nanmax(np.abs(a.slip - b.slip)):.4f} pp")


if __name__ == "__main__":
    main()
