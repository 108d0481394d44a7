"""Tracking speed: the study behind `cageless bench tracking`, and the speed table of long clips.

    python benchmarks/track.py [--dir bench_footage] [--frames 2400] [--repeats 3] [--json out.json]
    python benchmarks/track.py --speed [--dir bench_footage] [--lengths 1000 5000 10000]
                               [--baseline OLD_SOURCE_TREE] [--repeats 2] [--json out.json] [--clip CLIP]
                               [--from-disk]

Without ``--speed`` it runs the accuracy-versus-time study of :mod:`cageless.tracking.bench`
(detectors, smoothing windows, trackpy on the same frames, peak memory).

With ``--speed`` it renders one full-size clip (1280 x 800 px, 16-bit cine words, 12.5 px/mm,
3000 rpm at 10,000 frames/s; 2 MB a frame) of the longest length once, cuts the shorter
lengths from its start, and for each length measures, each in a fresh process:

* **pipeline frames/s**: :func:`cageless.tracking.pipeline.track_video` in process, input hash cached
  and imports done, ``scipy.optimize``, ``scipy.ndimage`` and ``scipy.signal`` included (which a tree imports
  while it tracks; what the tracker itself sustains on both cores);
* **loop frames/s**: the part of that run spent tracking every frame after the set-up (localisation,
  ball selection) and before the kinematics, i.e. the per-frame cost alone;
* **end to end, cold**: ``cageless track clip.cine --speed-rpm 3000`` from a new interpreter
  with an empty hash cache (imports, hashing, tracking, writing the trace and its QC);
* **peak RSS** of that end-to-end process (``VmHWM``, read as it exits);
* **read from storage**: the bytes that end-to-end process read from the disk (``read_bytes`` of
  ``/proc/self/io``, read as it exits; its hashing thread included) over the clip's size: 0 when the page
  cache held the clip, 1 when the cold run read it once. With ``--from-disk`` the clip is dropped from the
  page cache (``posix_fadvise(DONTNEED)``) before every cold run, so this says how many passes over the
  file a first run on a freshly copied clip makes;

with, for each, the CPU time (all threads; ``process_time`` in process, ``wait4``'s rusage for the cold run) per
frame: on a shared machine the wall-clock figures move with the load, the CPU time much less;

and once: the wall time of ``cageless --version``; the CPU time of hashing the whole clip as a cold run does
(:func:`cageless.provenance.hash_file`, uncached, from the page cache), per frame, which bounds the cold run's
rate when the hash cannot overlap the tracking; and trackpy (``locate`` + ``link``) on the
first 100 frames of the same footage, giving the same-run ratio of our pipeline frames/s to
trackpy's. ``--baseline`` names another cageless source tree (e.g. ``git archive`` of an older
commit); every measurement is then made for both trees, interleaved, best of ``--repeats``, and
the table shows both with their ratio. The page cache holds the clip in every run (one warm-up
run is not counted); numba's on-disk cache is warm.

A 10,000-frame full-size clip is 20.5 GB: where the page cache cannot hold it, every run reads it
from the disk, and the disk's read rate, not the tracker, sets the frames/s (check with ``fincore`` and
``dd iflag=direct``, and with ``--from-disk`` on a clip that does fit).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Any

HERE = Path(__file__).resolve().parents[1]

#: Runs first in every child: import cageless from the given source tree, not the installed one.
_PRELUDE = (
    "import sys, atexit; sys.meta_path[:] = [f for f in sys.meta_path if '__editable__' not in repr(f)]; "
    "sys.path.insert(0, {src!r}); "
    # tracking/, simulation/ and comparison/ install as cageless.tracking, ... (setuptools package-dir).
    "import cageless; cageless.__path__.append({src!r}); "
    # The peak RSS of this process since exec (VmHWM): wait4's ru_maxrss would carry the parent's peak over
    # the fork (the parent maps the clips while cutting them).
    "atexit.register(lambda: print('VMHWM_KB', open('/proc/self/status').read().split('VmHWM:')[1].split()[0], "
    "file=sys.stderr)); "
    # The bytes this process read from storage (not from the page cache), its threads included.
    "atexit.register(lambda: print('READ_BYTES', open('/proc/self/io').read().split('read_bytes:')[1].split()[0], "
    "file=sys.stderr)); "
)
_PIPELINE = _PRELUDE + (
    "import time, json; from cageless.bearing import default_bearing; "
    "from cageless.conditions import OperatingConditions; import cageless.tracking.pipeline as p; "
    "import cageless.provenance as pv; import scipy.signal, scipy.ndimage, scipy.optimize; "
    "h = pv.hash_file({clip!r}, getattr(p, 'INPUT_HASH', 'sha256')) if hasattr(pv, 'hash_file') "
    "else pv.sha256_file({clip!r}); "
    # The tracking loop alone (every frame after the set-up), timed around the pipeline's _track_all.
    "loop = [0.0, 0.0]; inner = p._track_all\n"
    "def timed(*a, **k):\n t0, c0 = time.perf_counter(), time.process_time(); out = inner(*a, **k)\n"
    " loop[0] += time.perf_counter() - t0; loop[1] += time.process_time() - c0\n"
    " return out\n"
    "p._track_all = timed; "
    "t, c = time.perf_counter(), time.process_time(); r = p.track_video({clip!r}, OperatingConditions(3000.0, 500.0), "
    "default_bearing(), progress=False); "
    "print(json.dumps({{'s': time.perf_counter() - t, 'cpu_s': time.process_time() - c, 'n': int(r.trace.n_samples), "
    "'loop_s': loop[0], 'loop_cpu_s': loop[1]}}))"
)
#: The console script's own entry (its exit included), as ``cageless ...`` runs it.
_CLI = _PRELUDE + "sys.argv = ['cageless', *{argv!r}]; from cageless.app.cli import entry_point; entry_point()"
#: CPU time (user + system, s) and bytes read from storage of the last child :func:`_child` ran.
_LAST_CPU_S = float("nan")
_LAST_READ_BYTES = float("nan")


def _child(code: str, env: dict[str, str] | None = None) -> tuple[float, float, str]:
    """Run ``python -c code``; return its wall time (s), peak RSS (MiB) and stdout (the CPU time of the last child
    is left in :data:`_LAST_CPU_S`)."""
    global _LAST_CPU_S, _LAST_READ_BYTES
    t0 = time.perf_counter()
    with tempfile.TemporaryFile("w+") as out:
        proc = subprocess.Popen([sys.executable, "-c", code], stdout=out, stderr=subprocess.PIPE, text=True,
                                env={**os.environ, **(env or {})})
        _, status, usage = os.wait4(proc.pid, 0)
        wall = time.perf_counter() - t0
        _LAST_CPU_S = usage.ru_utime + usage.ru_stime
        proc.returncode = os.waitstatus_to_exitcode(status)
        err = proc.stderr.read() if proc.stderr else ""
        out.seek(0)
        text = out.read()
    if proc.returncode not in (0,):
        raise RuntimeError(f"child failed ({proc.returncode}): {err[-2000:]}")
    peak = [int(line.split()[1]) for line in err.splitlines() if line.startswith("VMHWM_KB")]
    read = [int(line.split()[1]) for line in err.splitlines() if line.startswith("READ_BYTES")]
    _LAST_READ_BYTES = float(read[-1]) if read else float("nan")
    return wall, (peak[-1] / 1024.0 if peak else float("nan")), text


def _clips(folder: Path, lengths: list[int], footage: int | None = None,
           clip: Path | None = None) -> dict[int, Path]:
    """A clip of ``footage`` frames (default the longest length) rendered once, or ``clip``; the others are its
    first frames (written into ``folder``)."""
    from cageless.tracking.bench import prepare_footage
    from cageless.tracking.io import open_video, write_cine

    if clip is not None:
        with open_video(clip) as src:
            longest = len(src)
        video = clip
    else:
        longest = footage or max(lengths)
        video, _ = prepare_footage(folder, longest)
    clips = {longest: video}
    with open_video(video) as src:
        for n in sorted(set(lengths) - {longest}):
            dst = folder / f"{video.stem}_first{n}.cine"
            if not dst.is_file():
                write_cine(dst, (src[i] for i in range(n)), fps=10_000.0, fmt="16",
                           real_bpp=src.metadata.bit_depth, n_frames=n, timestamps_s=src.times[:n])
            clips[n] = dst
    return clips


def _evict(path: Path) -> None:
    """Drop ``path``'s pages from the page cache (clean pages only; the next read comes from the disk)."""
    fd = os.open(path, os.O_RDONLY)
    try:
        os.posix_fadvise(fd, 0, 0, os.POSIX_FADV_DONTNEED)
    finally:
        os.close(fd)


def _measure(src: Path, clip: Path, from_disk: bool = False) -> dict[str, float]:
    """Pipeline frames/s (hash cached), and cold end-to-end frames/s, peak RSS and passes over the file read
    from storage (``from_disk``: the clip evicted from the page cache before the cold run)."""
    with tempfile.TemporaryDirectory(prefix="cageless-speed-") as tmp:
        _, _, out = _child(_PIPELINE.format(src=str(src), clip=str(clip)), {"CAGELESS_CACHE_DIR": tmp + "/c1"})
        r = json.loads(out.strip().splitlines()[-1])
        if from_disk:
            _evict(clip)
        wall, rss, _ = _child(_CLI.format(src=str(src), argv=["track", str(clip), "-o", tmp + "/out",
                                                                "--speed-rpm", "3000", "-q"]),
                              {"CAGELESS_CACHE_DIR": tmp + "/c2"})
    n = r["n"]
    return {"pipeline_fps": n / r["s"], "loop_fps": n / r["loop_s"], "cold_fps": n / wall,
            "cold_s": wall, "peak_rss_mib": rss, "pipeline_cpu_ms": 1e3 * r.get("cpu_s", float("nan")) / n,
            "loop_cpu_ms": 1e3 * r.get("loop_cpu_s", float("nan")) / n, "cold_cpu_ms": 1e3 * _LAST_CPU_S / n,
            "storage_passes": _LAST_READ_BYTES / clip.stat().st_size}


def _hash_cpu_ms(clip: Path, repeats: int) -> float:
    """CPU milliseconds a frame of hashing the whole clip as a cold run does (uncached, from the page cache),
    best of ``repeats``."""
    from cageless.provenance import VIDEO_HASH, hash_file
    from cageless.tracking.io import open_video

    with open_video(clip) as video:
        n = len(video)
    best = float("inf")
    for _ in range(repeats):
        c0 = time.process_time()
        hash_file(clip, VIDEO_HASH, cache=False)
        best = min(best, time.process_time() - c0)
    return 1e3 * best / n


def _video_hash() -> str:
    from cageless.provenance import VIDEO_HASH

    return VIDEO_HASH


def _version_s(src: Path, repeats: int) -> float:
    return min(_child(_CLI.format(src=str(src), argv=["--version"]))[0] for _ in range(repeats))


def _trackpy_fps(clip: Path, n: int = 100) -> float | None:
    try:
        from cageless.tracking.bench import _trackpy
    except ImportError:
        return None
    import pandas as pd

    truth = pd.read_csv(clip.with_suffix(".truth.csv")) if clip.with_suffix(".truth.csv").is_file() else None
    if truth is None:
        return None
    try:
        return float(_trackpy(clip, truth, n)["fps"])
    except ImportError:
        return None


def speed_table(folder: Path, lengths: list[int], repeats: int, baseline: Path | None,
                footage: int | None = None, clip: Path | None = None, from_disk: bool = False) -> dict[str, Any]:
    """Measure every tree on every clip length, interleaved, best of ``repeats`` (``clip``: an existing
    full-size clip instead of the rendered one, the lengths cut from its start; ``from_disk``: every cold run
    starts with the clip out of the page cache)."""
    clips = _clips(folder, lengths, footage, clip)
    trees = {"this": HERE} | ({"baseline": baseline.resolve()} if baseline else {})
    for src in trees.values():  # warm-up: numba caches, page cache
        _measure(src, clips[min(lengths)])
    rows: dict[str, dict[int, dict[str, float]]] = {k: {} for k in trees}
    for _ in range(repeats):
        for n in sorted(lengths):
            for name, src in trees.items():
                m = _measure(src, clips[n], from_disk)
                print(f"  {n} frames, {name}: {json.dumps(m)}", file=sys.stderr, flush=True)  # partial results
                best = rows[name].get(n)
                rows[name][n] = m if best is None else {  # the best of each figure; the peak memory's and reads' worst
                    k: (max if k in ("peak_rss_mib", "storage_passes") or k.endswith("_fps") else min)(best[k], m[k])
                    for k in m}
    version = {name: _version_s(src, 5) for name, src in trees.items()}
    longest = max(lengths)
    tpy = _trackpy_fps(clips[max(clips)])  # the rendered clip has its truth; the cut ones do not
    return {"lengths": sorted(lengths), "rows": {k: {str(n): v for n, v in r.items()} for k, r in rows.items()},
            "version_s": version, "trackpy_fps": tpy, "trackpy_frames": 100, "from_disk": from_disk,
            "hash_cpu_ms": _hash_cpu_ms(clips[max(clips)], repeats), "hash_algorithm": _video_hash()}


def format_speed(r: dict[str, Any]) -> str:
    """The speed table as text."""
    trees = list(r["rows"])
    where = "the cold runs from the disk" if r.get("from_disk") else "from the page cache"
    lines = [f"Tracking speed, 1280x800 16-bit cine {where}, 3000 rpm, both cores"
             + (" (this tree vs baseline, same run)" if len(trees) > 1 else ""),
             f"{'frames':>7} {'tree':<9}{'pipeline f/s':>13}{'loop f/s':>10}{'cold e2e f/s':>14}{'cold e2e s':>11}"
             f"{'peak RSS MiB':>14}{'CPU ms/frame: pipeline':>24}{'loop':>6}{'cold':>6}{'disk passes':>12}"]
    for n in r["lengths"]:
        for t in trees:
            m = r["rows"][t][str(n)]
            lines.append(f"{n:>7} {t:<9}{m['pipeline_fps']:>13.0f}{m['loop_fps']:>10.0f}{m['cold_fps']:>14.0f}"
                         f"{m['cold_s']:>11.2f}"
                         f"{m['peak_rss_mib']:>14.0f}{m.get('pipeline_cpu_ms', float('nan')):>24.3f}"
                         f"{m.get('loop_cpu_ms', float('nan')):>6.3f}{m.get('cold_cpu_ms', float('nan')):>6.3f}"
                         f"{m.get('storage_passes', float('nan')):>12.2f}")
        if len(trees) > 1:
            a, b = r["rows"]["this"][str(n)], r["rows"]["baseline"][str(n)]
            lines.append(f"{'':>7} {'ratio':<9}{a['pipeline_fps'] / b['pipeline_fps']:>12.2f}x"
                         f"{a['loop_fps'] / b['loop_fps']:>9.2f}x{a['cold_fps'] / b['cold_fps']:>13.2f}x"
                         f"{'':>25}{b['pipeline_cpu_ms'] / a['pipeline_cpu_ms']:>23.2f}x"
                         f"{b['loop_cpu_ms'] / a['loop_cpu_ms']:>5.2f}x{b['cold_cpu_ms'] / a['cold_cpu_ms']:>5.2f}x")
    if len(trees) > 1:
        lines.append("ratio: this tree's speed over the baseline's (for CPU: the baseline's CPU time over this tree's)")
    lines.append("disk passes: bytes the cold run read from storage over the clip's size")
    lines.append("cageless --version: " + ", ".join(f"{t} {s:.3f} s" for t, s in r["version_s"].items()))
    if r.get("hash_cpu_ms"):
        lines.append(f"hashing the clip ({r.get('hash_algorithm', 'BLAKE3')}, uncached, from the page cache): {r['hash_cpu_ms']:.3f} ms of CPU a "
                     f"frame, at most {1e3 / r['hash_cpu_ms']:.0f} frames/s on one core")
    if r["trackpy_fps"]:
        longest = str(r["lengths"][-1])
        ratios = ", ".join(f"{t} {r['rows'][t][longest]['pipeline_fps'] / r['trackpy_fps']:.0f}x"
                           for t in trees)
        lines.append(f"trackpy locate+link on {r['trackpy_frames']} frames of the same clip: "
                     f"{r['trackpy_fps']:.1f} frames/s; pipeline / trackpy: {ratios}")
    else:
        lines.append("trackpy: not run (not installed: pip install 'cageless[bench]'; or the clip has no "
                     "<clip>.truth.csv)")
    return "\n".join(lines)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--dir", type=Path, default=Path("bench_footage"))
    ap.add_argument("--frames", type=int, default=2400)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--json", type=Path)
    ap.add_argument("--speed", action="store_true", help="the speed table over clip lengths")
    ap.add_argument("--lengths", type=int, nargs="+", default=[1000, 5000, 10000])
    ap.add_argument("--baseline", type=Path, help="another cageless source tree to compare against")
    ap.add_argument("--footage", type=int, help="frames of the rendered clip the lengths are cut from "
                    "(default the longest length)")
    ap.add_argument("--clip", type=Path, help="an existing full-size 3000 rpm clip to measure instead of "
                    "rendering one (its frame count is the longest length)")
    ap.add_argument("--from-disk", action="store_true", help="drop the clip from the page cache before every "
                    "cold run (how many passes over the file a first run on a fresh copy makes)")
    args = ap.parse_args()
    args.dir.mkdir(parents=True, exist_ok=True)
    if args.speed:
        result = speed_table(args.dir, args.lengths, args.repeats, args.baseline, args.footage, args.clip,
                             args.from_disk)
        print(format_speed(result))
    else:
        from cageless.tracking.bench import format_tables, run_benchmark

        result = run_benchmark(args.dir, args.frames, args.repeats)
        print(format_tables(result))
    if args.json:
        args.json.write_text(json.dumps(result, indent=1))


if __name__ == "__main__":
    main()
