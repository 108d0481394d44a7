"""Bit-identity of tracking between two source trees: the check of a refactor that must not change results.

    python benchmarks/trace_identity.py --baseline OLD_SOURCE_TREE CLIP [CLIP ...] [--out DIR] [--timing]
                                        [--speed-rpm RPM]

Tracks every clip with ``cageless track CLIP -o DIR/<tree>`` (the clip's sidecar gives its conditions and
bearing) from a fresh interpreter for this tree and for the baseline tree (e.g. ``git archive`` of main
unpacked in a folder), then compares every numeric dataset of the two traces bit for bit (provenance and
the creation time are skipped; the QC and config JSON are compared as text). Prints one row per clip: identical, or the datasets
that differ with their largest difference. Exits 1 when any clip differs or fails in only one tree.

With ``--timing`` it also prints each run's wall time (one cold process each: a rough figure on a shared
machine; use ``benchmarks/track.py --speed`` for speed).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time
from pathlib import Path

import h5py
import numpy as np

HERE = Path(__file__).resolve().parents[1]
_PRELUDE = (
    "import sys; sys.meta_path[:] = [f for f in sys.meta_path if '__editable__' not in repr(f)]; "
    "sys.path.insert(0, {src!r}); import cageless; cageless.__path__.append({src!r}); "
)
_CLI = _PRELUDE + "from cageless.app.cli import main; sys.exit(main({argv!r}))"


def _track(src: Path, clip: Path, out: Path, extra: list[str] | None = None) -> tuple[int, float]:
    """Track ``clip`` with the source tree ``src`` into ``out`` (``extra``: more arguments of ``cageless track``);
    return the exit code and the wall time."""
    out.mkdir(parents=True, exist_ok=True)
    t0 = time.perf_counter()
    argv = ["track", str(clip), "-o", str(out), "-q", *(extra or [])]
    proc = subprocess.run([sys.executable, "-c", _CLI.format(src=str(src), argv=argv)],
                          capture_output=True, text=True, env={**os.environ, "CAGELESS_CACHE_DIR": str(out / ".c")})
    return proc.returncode, time.perf_counter() - t0


#: Attributes that legitimately differ between two runs (when, where, with which source tree).
_SKIP_ATTRS = ("created_utc", "provenance_json")


def _arrays(path: Path) -> dict[str, np.ndarray]:
    """Every numeric dataset of an HDF5 file by its path, and every root attribute (as ``@name``) but the
    run's own (:data:`_SKIP_ATTRS`); text attributes (the QC and config JSON) as byte arrays."""
    found: dict[str, np.ndarray] = {}

    def visit(name: str, obj: object) -> None:
        if isinstance(obj, h5py.Dataset) and obj.dtype.kind in "biufc":
            found[name] = np.asarray(obj[()])

    with h5py.File(path, "r") as f:
        f.visititems(visit)
        for k, v in f.attrs.items():
            if k not in _SKIP_ATTRS:
                found[f"@{k}"] = np.frombuffer(v.encode(), np.uint8) if isinstance(v, str) else np.asarray(v)
    return found


def compare(a: Path, b: Path) -> list[str]:
    """The datasets that differ between two trace files (bitwise; NaN equals NaN), with their largest difference."""
    x, y = _arrays(a), _arrays(b)
    diffs = [f"{k}: only in one" for k in sorted(set(x) ^ set(y))]
    for k in sorted(set(x) & set(y)):
        p, q = x[k], y[k]
        if p.shape != q.shape or p.dtype != q.dtype:
            diffs.append(f"{k}: shape/dtype {p.shape} {p.dtype} vs {q.shape} {q.dtype}")
        elif p.tobytes() != q.tobytes():
            d = np.nanmax(np.abs(p.astype(np.float64) - q.astype(np.float64))) if p.size else 0.0
            diffs.append(f"{k}: max |diff| {d:.3g}")
    return diffs


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("clips", type=Path, nargs="+")
    ap.add_argument("--baseline", type=Path, required=True, help="the other cageless source tree")
    ap.add_argument("--out", type=Path, default=Path("/tmp/cageless-trace-identity"))
    ap.add_argument("--timing", action="store_true")
    ap.add_argument("--speed-rpm", type=float, help="the shaft speed, for clips without a sidecar or conditions "
                    "(e.g. the benchmark clip of benchmarks/track.py, 3000)")
    args = ap.parse_args()
    extra = ["--speed-rpm", str(args.speed_rpm)] if args.speed_rpm else []
    bad = 0
    for clip in args.clips:
        runs = {}
        for name, src in (("baseline", args.baseline.resolve()), ("this", HERE)):
            runs[name] = _track(src, clip, args.out / name, extra)
        trace = f"{clip.stem}.trace.h5"
        codes = {k: v[0] for k, v in runs.items()}
        timing = "  ".join(f"{k} {v[1]:.1f} s" for k, v in runs.items()) if args.timing else ""
        if codes["this"] != codes["baseline"]:
            bad += 1
            print(f"{clip.name}: exit codes differ {codes}  {timing}")
            continue
        if codes["this"] != 0:
            print(f"{clip.name}: both exit {codes['this']} (no trace)  {timing}")
            continue
        diffs = compare(args.out / "baseline" / trace, args.out / "this" / trace)
        bad += bool(diffs)
        n = len(_arrays(args.out / "this" / trace))
        print(f"{clip.name}: " + (f"identical ({n} datasets)" if not diffs else "DIFFERS: " + "; ".join(diffs))
              + f"  {timing}")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
