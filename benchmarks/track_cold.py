"""Where a cold ``cageless track`` spends its time, stage by stage, beside the same run of another tree.

    python benchmarks/track_cold.py CLIP [--baseline OLD_SOURCE_TREE] [--repeats 2] [--speed-rpm 3000]

Runs ``cageless track CLIP -o TMP --speed-rpm 3000 -q`` (the console script's entry) in a fresh interpreter (empty input-hash cache, warm
numba cache, the clip in the page cache as it is) with timers around the pipeline's stages, and prints for each
stage its wall time and the process's CPU time (all threads: the input hash and the late imports run beside the
stages) spent while it ran, and the moment the per-frame loop started (time to first tracked frame):

* ``imports``: from the interpreter's start until the command line is parsed and tracking starts;
* ``sample statistics``, ``localisation``, ``selection and set-up``: the median backgrounds and the motion map
  (:func:`~cageless.tracking.sample_stats.sample_statistics`, one pass; in a tree before it,
  :func:`~cageless.tracking.locate.background_frame`, both calls, with the motion map counted in the localisation),
  ``pipeline._locate`` (without its background), ``pipeline._select`` (the ball selection, masks, noise, static
  defects and, in a tree before the one pass, the selection's quantile background);
* ``per-frame loop``: ``pipeline._track_all``;
* ``fitting``: ``pipeline._finish`` (orbit, place bias, precision estimate, track fit, speed, QC record), which
  also waits for the input hash;
* ``writing``: the trace, its QC images and the selection QC;
* ``track_video``: the whole of :func:`~cageless.tracking.pipeline.track_video` (the stages above but the
  imports, and what lies between them);
* ``exit``: the CPU time after the timers stopped (the command line's summary, the interpreter's shutdown);
* ``total``: the wall time until the timers stopped, and the process's whole CPU time (its rusage).

With ``--baseline`` the same is run for that source tree (e.g. ``git archive`` of main), interleaved, and the
best of ``--repeats`` of each stage is shown for both. On a shared machine the wall times move with the load;
the CPU times much less.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parents[1]

#: The child: import cageless from the given tree, wrap the stages, run the command line, print the timings.
_CHILD = """
import time, sys, json
T0, C0 = time.perf_counter(), time.process_time()
sys.meta_path[:] = [f for f in sys.meta_path if '__editable__' not in repr(f)]
sys.path.insert(0, {src!r})
import cageless; cageless.__path__.append({src!r})
rows = {{}}
def wrap(owner, name, label):
    inner = getattr(owner, name, None)
    if inner is None:  # a stage this tree does not have
        return
    def timed(*a, **k):
        if label == 'track_video':
            rows['imports'] = [time.perf_counter() - T0, time.process_time() - C0]
        if label == 'per-frame loop':
            rows.setdefault('first_frame_s', time.perf_counter() - T0)
        t, c = time.perf_counter(), time.process_time()
        try:
            return inner(*a, **k)
        finally:
            row = rows.setdefault(label, [0.0, 0.0])
            row[0] += time.perf_counter() - t
            row[1] += time.process_time() - c
    setattr(owner, name, timed)
import cageless.tracking.pipeline as p
wrap(p, 'track_video', 'track_video')
wrap(p, 'background_frame', 'sample statistics')
wrap(p, 'sample_statistics', 'sample statistics')
wrap(p, '_locate', 'localisation')
wrap(p, '_select', 'selection and set-up')
wrap(p, '_track_all', 'per-frame loop')
wrap(p, '_finish', 'fitting')
for name in ('write_trace', 'write_qc', 'write_selection_qc'):
    wrap(p, name, 'writing')
import cageless.app.cli as cli
main = cli.main
def timed_main(argv=None):
    rc = main(argv)
    rows['total'] = [time.perf_counter() - T0, time.process_time() - C0]
    print('COLD_JSON ' + json.dumps(rows), flush=True)
    return rc
cli.main = timed_main  # the console script's entry, its exit included, runs this
sys.argv = ['cageless', *{argv!r}]
cli.entry_point()
"""

STAGES = ("imports", "sample statistics", "localisation", "selection and set-up", "per-frame loop", "fitting",
          "writing", "track_video", "exit", "total")


def run_once(src: Path, clip: Path, speed_rpm: float) -> dict[str, list[float]]:
    """One cold run of ``cageless track`` from the tree ``src``; each stage's [wall s, CPU s]."""
    with tempfile.TemporaryDirectory(prefix="cageless-cold-") as tmp:
        argv = ["track", str(clip), "-o", tmp + "/out", "--speed-rpm", str(speed_rpm), "-q"]
        t0 = os.times()
        proc = subprocess.run([sys.executable, "-c", _CHILD.format(src=str(src), argv=argv)], capture_output=True,
                              text=True, env={**os.environ, "CAGELESS_CACHE_DIR": tmp + "/cache"})
        t1 = os.times()
    line = [x for x in proc.stdout.splitlines() if x.startswith("COLD_JSON ")]
    if proc.returncode != 0 or not line:
        raise SystemExit(f"{src}: cageless track failed ({proc.returncode}): {proc.stderr[-2000:]}")
    rows = json.loads(line[-1][len("COLD_JSON "):])
    # The process's whole CPU time from its rusage: the part after the timers stopped (the CLI's summary,
    # the interpreter's shutdown) is "exit".
    cpu = (t1.children_user - t0.children_user) + (t1.children_system - t0.children_system)
    rows["exit"] = [float("nan"), cpu - rows["total"][1]]
    rows["total"] = [rows["total"][0], cpu]
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("clip", type=Path)
    ap.add_argument("--baseline", type=Path, help="another cageless source tree, run interleaved")
    ap.add_argument("--repeats", type=int, default=2)
    ap.add_argument("--speed-rpm", type=float, default=3000.0)
    ap.add_argument("--json", type=Path)
    args = ap.parse_args()
    trees = {"this": HERE} | ({"baseline": args.baseline.resolve()} if args.baseline else {})
    best: dict[str, dict[str, list[float]]] = {}
    for _ in range(args.repeats):
        for name, src in trees.items():
            rows = run_once(src, args.clip.resolve(), args.speed_rpm)
            print(f"  {name}: {json.dumps(rows)}", file=sys.stderr, flush=True)
            old = best.get(name)
            best[name] = rows if old is None else {
                k: ([min(a, b) for a, b in zip(old[k], rows[k], strict=True)] if isinstance(rows[k], list)
                    else min(old[k], rows[k])) for k in rows}
    head = f"{'stage':<22}" + "".join(f"{t + ' wall s':>16}{t + ' CPU s':>15}" for t in trees)
    print(f"cold `cageless track {args.clip.name}`, best of {args.repeats} (CPU: the whole process, all threads)")
    print(head)
    for k in STAGES:
        cells = "".join(f"{best[t].get(k, [float('nan')] * 2)[0]:>16.2f}{best[t].get(k, [float('nan')] * 2)[1]:>15.2f}"
                        for t in trees)
        print(f"{k:<22}{cells}")
    print(f"{'first frame at (s)':<22}" + "".join(f"{best[t]['first_frame_s']:>16.2f}{'':>15}" for t in trees))
    print("sample statistics: the backgrounds (and, from the one-pass tree on, the motion map); in a tree before "
          "it, the selection's quantile background is also inside 'selection and set-up' and the motion map inside "
          "'localisation'. CPU: the process's, all threads, while the stage ran")
    if args.json:
        args.json.write_text(json.dumps(best, indent=1))


if __name__ == "__main__":
    main()
