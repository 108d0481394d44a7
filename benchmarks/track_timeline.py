"""Wall-time timeline of one tracking run: which stage runs when, on which thread, and how long the cores idle.

    python benchmarks/track_timeline.py CLIP [--speed-rpm 3000] [--threads 2] [--repeats 2]

Runs :func:`cageless.tracking.pipeline.track_video` on ``CLIP`` in process once to warm up (numba cache, page
cache, input-hash cache, SciPy imported), then ``--repeats`` times with timers around the pipeline's stages and
the calls inside them that run on other threads (the segments' per-frame loops, the selection's blob responses,
the robust track fits), and prints the last run's intervals in start order: start and end (s from the call),
wall time, the thread's own CPU time (``thread_time``) and the thread. Then a summary: the wall time before the
per-frame loop starts, the loop's, the time after it, and the process's CPU time over the run's wall time (how
many cores it kept busy on average). Nested stages are listed inside their parents' intervals.
"""

from __future__ import annotations

import argparse
import functools
import importlib
import threading
import time
from pathlib import Path
from typing import Any

#: Stages timed: (module, function). The pipeline's stages, then calls that run inside them.
_STAGES = (
    ("cageless.tracking.pipeline", "sample_statistics"), ("cageless.tracking.pipeline", "_locate"),
    ("cageless.tracking.pipeline", "_select"), ("cageless.tracking.pipeline", "select_balls"),
    ("cageless.tracking.pipeline", "static_pattern"), ("cageless.tracking.pipeline", "_track_all"),
    ("cageless.tracking.pipeline", "track_frames"), ("cageless.tracking.pipeline", "stitch"),
    ("cageless.tracking.pipeline", "relock_lobes"), ("cageless.tracking.pipeline", "_finish"),
    ("cageless.tracking.pipeline", "fit_orbit"), ("cageless.tracking.pipeline", "orbital_angles"),
    ("cageless.tracking.pipeline", "remove_place_bias"), ("cageless.tracking.pipeline", "assess_table"),
    ("cageless.tracking.pipeline", "robust_track_fit"), ("cageless.tracking.pipeline", "revolution_speed"),
    ("cageless.tracking.pipeline", "build_qc"),
)
_EVENTS: list[tuple[str, str, float, float, float]] = []
_T0 = [0.0]


def _wrap(module: str, name: str) -> None:
    owner = importlib.import_module(module)
    inner = getattr(owner, name, None)
    if inner is None:  # a stage this tree does not have
        return

    @functools.wraps(inner)
    def timed(*args: Any, **kwargs: Any) -> Any:
        t, c = time.perf_counter(), time.thread_time()
        try:
            return inner(*args, **kwargs)
        finally:
            _EVENTS.append((name, threading.current_thread().name, t - _T0[0], time.perf_counter() - _T0[0],
                            time.thread_time() - c))

    setattr(owner, name, timed)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("clip", type=Path)
    ap.add_argument("--speed-rpm", type=float, default=3000.0)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--repeats", type=int, default=2)
    args = ap.parse_args()
    import scipy.ndimage  # noqa: F401 - imported as the tracker would beside its first stages
    import scipy.optimize  # noqa: F401

    import cageless.tracking.pipeline as pipeline
    from cageless.bearing import default_bearing
    from cageless.conditions import OperatingConditions

    for module, name in _STAGES:
        _wrap(module, name)
    run = functools.partial(pipeline.track_video, args.clip, OperatingConditions(args.speed_rpm, 500.0),
                            default_bearing(), pipeline.TrackOptions(threads=args.threads), progress=False)
    run()
    for _ in range(args.repeats):
        _EVENTS.clear()
        _T0[0], c0 = time.perf_counter(), time.process_time()
        n = run().trace.n_samples
        wall, cpu = time.perf_counter() - _T0[0], time.process_time() - c0
    print(f"{args.clip.name}: {n} frames, {args.threads} thread(s): wall {wall:.3f} s ({n / wall:.0f} frames/s), "
          f"CPU {cpu:.3f} s (all threads)")
    print(f"{'start s':>8}{'end s':>8}{'wall s':>8}{'CPU s':>8}  {'thread':<22}stage")
    for name, thread, a, b, c in sorted(_EVENTS, key=lambda e: (e[2], -e[3])):
        print(f"{a:8.3f}{b:8.3f}{b - a:8.3f}{c:8.3f}  {thread[:21]:<22}{name}")
    loop = [e for e in _EVENTS if e[0] == "_track_all"]
    if loop:
        a, b = loop[-1][2], loop[-1][3]
        print(f"before the loop {a:.3f} s, loop {b - a:.3f} s, after it {wall - b:.3f} s; "
              f"{cpu / wall:.2f} cores busy on average")


if __name__ == "__main__":
    main()
