"""Cost of the ball selection and of per-frame tracking with and without it, on the same footage.

    python benchmarks/track_select.py CLIP.cine --speed-rpm 3000 [--repeats 3]

Per-frame tracking runs twice over the same frames, interleaved, best of ``--repeats``:

* ``count start``: the tracker starts from the first frame whose full detection shows Z balls
  (no chosen ball circle; the tracker before the selection stage existed);
* ``selected``: the tracker starts from the selection's anchors and looks for missed balls among
  blob candidates on the chosen circle.

The one-off selection (candidate detection on a few bursts of frames, tracklets, the circle and the
cyclic choice) is timed on its own. The machine may be shared: read the ratio, not the absolute times.
"""

from __future__ import annotations

import argparse
import dataclasses
import time
from pathlib import Path

from cageless.bearing import default_bearing
from cageless.conditions import OperatingConditions
from cageless.tracking.io import open_video
from cageless.tracking.link import track_frames
from cageless.tracking.locate import background_frame, locate_bearing
from cageless.tracking.pipeline import SELECT_K_SIGMA, TrackOptions, _CroppedFrames, _setup


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("clip", type=Path)
    ap.add_argument("--speed-rpm", type=float, required=True)
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args()
    bearing, options = default_bearing(), TrackOptions()
    with open_video(args.clip) as video:
        bg = background_frame(video)
        loc = locate_bearing(bg, args.clip)
        rows, cols = loc.crop(video.frame_shape)
        frames = _CroppedFrames(video, rows, cols, options.chunk)
        t0 = time.perf_counter()
        setup, sel = _setup(video, loc, bg, bearing, options, frames, OperatingConditions(args.speed_rpm), args.clip,
                            SELECT_K_SIGMA[0])
        t_select = time.perf_counter() - t0
        plain = dataclasses.replace(setup, ring=None, anchors=())
        times = video.times
        best = {"count start": float("inf"), "selected": float("inf")}
        for _ in range(args.repeats):
            for name, s in (("count start", plain), ("selected", setup)):
                t0 = time.perf_counter()
                track_frames(frames, times, s, str(args.clip))
                best[name] = min(best[name], time.perf_counter() - t0)
        n = len(video)
    print(f"{args.clip.name}: {n} frames, crop {rows.stop - rows.start} x {cols.stop - cols.start} px, "
          f"best of {args.repeats}, one thread")
    print(f"{'stage':<14}{'s':>9}{'frames/s':>11}{'us/frame':>10}")
    for name, t in best.items():
        print(f"{name:<14}{t:>9.3f}{n / t:>11.0f}{1e6 * t / n:>10.1f}")
    print(f"{'selection':<14}{t_select:>9.3f}{'':>11}{'(once)':>10}")
    print(f"per-frame ratio selected / count start: {best['selected'] / best['count start']:.3f}")
    print(f"bursts {len(sel.counts)}, ball counts per burst {sel.counts}")


if __name__ == "__main__":
    main()
