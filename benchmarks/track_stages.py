"""CPU time of each stage of the tracking pipeline, per frame: where the time goes.

    python benchmarks/track_stages.py CLIP [--threads 1] [--copy]

Runs :func:`cageless.tracking.pipeline.track_video` on ``CLIP`` once to warm up (numba cache, page cache,
input-hash cache), then once more with timers around the pipeline's stages (the sample statistics: the median
backgrounds and the motion map in one pass, or in a tree before it the median backgrounds; the localisation, the
ball selection and its blob response maps and tracklet linking, the masks and noise, the per-frame loop with its
compiled step, its Python step and its page drops, the fitting and QC record, and within it
the trace's precision estimate) and prints
each stage's CPU (``process_time``: with ``--threads 1`` each stage's own) and wall time, in ms a frame and in
s. Nested stages are counted in their parents too. With ``--copy`` the per-frame loop gets in-memory copies of
its blocks of frames (the copy not timed): the compiled step's time on the memory map minus that is what reading
the mapped frames costs.
"""

from __future__ import annotations

import argparse
import functools
import time
from collections import defaultdict
from pathlib import Path
from typing import Any

import numpy as np

_TIMES: defaultdict[str, list[float]] = defaultdict(lambda: [0.0, 0.0, 0.0])


def _wrap(owner: Any, name: str) -> None:
    inner = getattr(owner, name, None)
    if inner is None:  # a stage this tree does not have
        return

    @functools.wraps(inner)
    def timed(*args: Any, **kwargs: Any) -> Any:
        t0, c0 = time.perf_counter(), time.process_time()
        try:
            return inner(*args, **kwargs)
        finally:
            row = _TIMES[name]
            row[0] += time.perf_counter() - t0
            row[1] += time.process_time() - c0
            row[2] += 1

    setattr(owner, name, timed)


def main() -> None:
    import cageless.tracking.candidates as candidates
    import cageless.tracking.io.cine as cine
    import cageless.tracking.link as link
    import cageless.tracking.pipeline as pipeline
    import cageless.tracking.select as select
    from cageless.bearing import default_bearing
    from cageless.conditions import OperatingConditions

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("clip", type=Path)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--speed-rpm", type=float, default=3000.0)
    ap.add_argument("--copy", action="store_true", help="the per-frame loop on in-memory copies of its blocks")
    args = ap.parse_args()
    for name in ("sample_statistics", "background_frame", "_locate",
                 "_select", "_track_all", "_finish", "assess_table", "noise_sigma",
                 "static_defects", "static_pattern"):
        _wrap(pipeline, name)
    _wrap(select, "link_tracklets")
    _wrap(candidates, "response_map")
    _wrap(link, "_step")
    _wrap(link, "run_block")
    _wrap(cine.CineReader, "drop_pages")
    if args.copy:
        block = pipeline._CroppedFrames.block
        pipeline._CroppedFrames.block = lambda self, a, b: np.ascontiguousarray(block(self, a, b))  # type: ignore
    run = functools.partial(pipeline.track_video, args.clip, OperatingConditions(args.speed_rpm, 500.0),
                            default_bearing(), pipeline.TrackOptions(threads=args.threads), progress=False)
    run()
    _TIMES.clear()
    t0, c0 = time.perf_counter(), time.process_time()
    n = run().trace.n_samples
    wall, cpu = time.perf_counter() - t0, time.process_time() - c0
    print(f"{args.clip.name}: {n} frames, {args.threads} thread(s){', loop on in-memory copies' if args.copy else ''}:"
          f" {1e3 * cpu / n:.3f} ms of CPU a frame ({cpu:.2f} s), wall {wall:.2f} s ({n / wall:.0f} frames/s)")
    for name, (w, c, k) in sorted(_TIMES.items(), key=lambda item: -item[1][1]):
        print(f"  {name:<18}{int(k):>6} calls  CPU {1e3 * c / n:7.3f} ms a frame ({c:6.2f} s)   wall {w:6.2f} s")


if __name__ == "__main__":
    main()
