"""The per-frame step's centroid windows replayed on in-memory frames: this tree against another, same run.

    python benchmarks/centroid_replay.py CLIP --baseline OLD_TREE [--frames 200] [--repeats 7]

Tracks ``CLIP`` (a 3000 rpm clip, e.g. ``bench_1000_9.cine`` of :func:`cageless.tracking.bench.prepare_footage`)
once with this tree to get its set-up (background, mask, threshold, window radius, static pattern) and the
tracked highlight positions, copies the first ``--frames`` cropped frames into memory, and then calls the
compiled centroid of the per-frame step (``detect._centroids``: local background, then up to ``iterations``
re-centred passes) on every ball of every frame, started 0.6 px right of and 0.4 px above the tracked position
(where a prediction lands), with this tree's kernel and with ``OLD_TREE``'s (its ``tracking/detect.py`` loaded
beside it), alternating, ``--repeats`` times each. Prints the CPU time of each (``thread_time``, ms a frame),
their ratio, and the largest difference between the two trees' centroids (px).
"""

from __future__ import annotations

import argparse
import importlib.util
import sys
import time
from pathlib import Path
from types import ModuleType
from typing import Any

import numpy as np


def _load(tree: Path) -> ModuleType:
    spec = importlib.util.spec_from_file_location("baseline_detect", tree / "tracking" / "detect.py")
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    sys.modules["baseline_detect"] = mod  # dataclasses look their module up
    spec.loader.exec_module(mod)
    return mod


def _record(clip: Path, n: int) -> dict[str, Any]:
    """The set-up, the first ``n`` cropped frames and the tracked positions (cropped pixels)."""
    import cageless.tracking.pipeline as pipeline
    from cageless.bearing import default_bearing
    from cageless.conditions import OperatingConditions

    seen: dict[str, Any] = {}
    inner = pipeline.track_frames

    def grab(frames: Any, times: Any, setup: Any, *args: Any, **kwargs: Any) -> Any:
        seen.update(frames=frames, setup=setup)
        return inner(frames, times, setup, *args, **kwargs)

    pipeline.track_frames = grab
    try:
        res = pipeline.track_video(clip, OperatingConditions(3000.0, 500.0), default_bearing(),
                                   pipeline.TrackOptions(threads=1), progress=False)
    finally:
        pipeline.track_frames = inner
    s, frames = seen["setup"], seen["frames"]
    z = res.trace.n_balls
    u = res.table.u_px.to_numpy().reshape(-1, z)[:n] - frames.cols.start
    v = res.table.v_px.to_numpy().reshape(-1, z)[:n] - frames.rows.start
    return {"stack": np.ascontiguousarray(np.stack([frames(i) for i in range(n)])), "bg": s.background,
            "mask": s.mask, "static": s.static_compiled, "half": np.full(z, s.params.window_sigma * max(
                s.highlight_sigma, 1.0)), "thr": s.params.weight_sigma * s.sigma_noise, "iters": s.params.iterations,
            "starts": [(np.ascontiguousarray(u[i] + 0.6), np.ascontiguousarray(v[i] - 0.4)) for i in range(n)]}


def _run(mod: ModuleType, d: dict[str, Any]) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    return [mod._centroids(f, d["bg"], d["mask"], u, v, d["half"], d["thr"], d["iters"], d["static"])
            for f, (u, v) in zip(d["stack"], d["starts"], strict=True)]


def main() -> None:
    from cageless.tracking import detect

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("clip", type=Path)
    ap.add_argument("--baseline", type=Path, required=True, help="the other cageless source tree")
    ap.add_argument("--frames", type=int, default=200)
    ap.add_argument("--repeats", type=int, default=7)
    args = ap.parse_args()
    old = _load(args.baseline)
    d = _record(args.clip, args.frames)
    a, b = _run(detect, d), _run(old, d)
    diff = max(float(np.nanmax(np.abs(np.concatenate([p[0] - q[0], p[1] - q[1]])))) for p, q in zip(a, b, strict=True))
    same = all(np.array_equal(x, y, equal_nan=True) for p, q in zip(a, b, strict=True) for x, y in zip(p, q, strict=True))
    cpu: dict[str, list[float]] = {"this": [], "baseline": []}
    for rep in range(args.repeats):
        order = [("this", detect), ("baseline", old)]
        for name, mod in order if rep % 2 == 0 else order[::-1]:
            c0 = time.thread_time()
            _run(mod, d)
            cpu[name].append(1e3 * (time.thread_time() - c0) / args.frames)
    z = d["half"].size
    print(f"{args.clip.name}: {args.frames} frames x {z} windows; centroids "
          f"{'bit-identical' if same else f'differ by up to {diff:.2g} px'}")
    for name, ms in cpu.items():
        print(f"  {name:<9} CPU {min(ms):.3f} ms a frame best, {np.median(ms):.3f} median of {len(ms)}")
    print(f"  baseline / this: {min(cpu['baseline']) / min(cpu['this']):.2f}x best, "
          f"{np.median(cpu['baseline']) / np.median(cpu['this']):.2f}x median")


if __name__ == "__main__":
    main()
