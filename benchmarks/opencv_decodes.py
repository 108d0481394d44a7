"""How often ``cageless track`` decodes each frame of a video read through OpenCV (AVI, MKV, MP4).

    python benchmarks/opencv_decodes.py CLIP [CLIP ...] [--baseline OLD_SOURCE_TREE]

Tracks every clip once with ``cageless track CLIP -o TMP -q`` in a fresh interpreter for this tree (and, with
``--baseline``, for another source tree, e.g. ``git archive`` of an older commit), counting the frames OpenCV
decodes (``VideoCapture.read``), the frames it skips over to seek (``grab``) and the times the file is opened,
and prints them with the clip's frame count and the run's wall and CPU time. One run each: the counts do not
depend on the load, the times do.
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

HERE = Path(__file__).resolve().parents[1]

_CHILD = """
import sys, json, collections, tempfile
sys.meta_path[:] = [f for f in sys.meta_path if '__editable__' not in repr(f)]
sys.path.insert(0, {src!r}); import cageless; cageless.__path__.append({src!r})
import cv2
import cageless.tracking.io.opencv as ocv
counts = collections.Counter()

class Capture:
    def __init__(self, cap):
        self.cap = cap
    def grab(self):
        counts["grab"] += 1
        return self.cap.grab()
    def read(self):
        counts["decode"] += 1
        return self.cap.read()
    def __getattr__(self, name):
        return getattr(self.cap, name)

inner = ocv.OpenCVReader._open
def counted_open(self):
    counts["open"] += 1
    return Capture(inner(self))
ocv.OpenCVReader._open = counted_open
from cageless.app.cli import main
with tempfile.TemporaryDirectory() as out:
    rc = main(["track", {clip!r}, "-o", out, "-q"])
cap = cv2.VideoCapture({clip!r}); n = 0
while cap.grab():
    n += 1
print(json.dumps({{"rc": rc, "frames": n, **counts}}))
"""


def _run(src: Path, clip: Path) -> dict[str, float]:
    with tempfile.TemporaryDirectory(prefix="cageless-decodes-") as cache:
        t0 = time.perf_counter()
        proc = subprocess.Popen([sys.executable, "-c", _CHILD.format(src=str(src), clip=str(clip))],
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                                env={**os.environ, "CAGELESS_CACHE_DIR": cache})
        _, status, usage = os.wait4(proc.pid, 0)
        wall = time.perf_counter() - t0
        out = proc.stdout.read() if proc.stdout else ""
    if os.waitstatus_to_exitcode(status) != 0:
        raise RuntimeError(f"{clip}: the child failed: {proc.stderr.read()[-2000:] if proc.stderr else ''}")
    row = json.loads(out.strip().splitlines()[-1])
    return row | {"wall_s": wall, "cpu_s": usage.ru_utime + usage.ru_stime}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("clips", type=Path, nargs="+")
    ap.add_argument("--baseline", type=Path, help="another cageless source tree to count for, same run")
    args = ap.parse_args()
    trees = {"this": HERE} | ({"baseline": args.baseline.resolve()} if args.baseline else {})
    print(f"{'clip':<34}{'tree':<10}{'frames':>7}{'decoded':>9}{'per frame':>10}{'grabbed':>9}{'opened':>7}"
          f"{'wall s':>8}{'CPU s':>7}")
    for clip in args.clips:
        for name, src in trees.items():
            r = _run(src, clip)
            print(f"{clip.name[:33]:<34}{name:<10}{r['frames']:>7}{r.get('decode', 0):>9}"
                  f"{r.get('decode', 0) / r['frames']:>10.2f}{r.get('grab', 0):>9}{r.get('open', 0):>7}"
                  f"{r['wall_s']:>8.2f}{r['cpu_s']:>7.2f}", flush=True)


if __name__ == "__main__":
    main()
