"""CPU time of the input-identity hash per video frame: the previous way against the current one, same run.

    python benchmarks/input_hash.py CLIP.cine [--repeats 3]

Hashes the whole clip (from the page cache; run it twice if the clip was not read recently) with:

* ``<algorithm>, read``: :func:`cageless.provenance.hash_file` uncached (1 MiB blocks read into one buffer),
  for each of :data:`cageless.provenance.HASH_ALGORITHMS` (BLAKE3: the videos' hash before XXH3-128);
* ``<algorithm>, mapped``: the same hashers fed straight from a memory map of the file, 64 MiB at a time
  (tried for XXH3-128 and not kept: no faster here);

interleaved, best of ``--repeats``, and prints the CPU milliseconds per frame and the one-core frames/s
each allows.
"""

from __future__ import annotations

import argparse
import mmap
import time
from pathlib import Path


def _mapped(path: Path, algorithm: str) -> str:
    from cageless.provenance import _new_digest

    digest = _new_digest(algorithm)
    size = path.stat().st_size
    with open(path, "rb") as fh:
        for offset in range(0, size, 64 << 20):
            with mmap.mmap(fh.fileno(), min(64 << 20, size - offset), access=mmap.ACCESS_READ,
                           offset=offset) as piece, memoryview(piece) as view:
                digest.update(view)
    return str(digest.hexdigest())


def main() -> None:
    from cageless.provenance import HASH_ALGORITHMS, hash_file
    from cageless.tracking.io import open_video

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("clip", type=Path)
    ap.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args()
    with open_video(args.clip) as video:
        n = len(video)
    ways = {f"{a}, read": (lambda a=a: hash_file(args.clip, a, cache=False)) for a in HASH_ALGORITHMS}
    ways |= {f"{a}, mapped": (lambda a=a: _mapped(args.clip, a)) for a in ("blake3", "xxh3_128")}
    best = {k: float("inf") for k in ways}
    for _ in range(args.repeats):
        for name, fn in ways.items():
            c0 = time.process_time()
            fn()
            best[name] = min(best[name], time.process_time() - c0)
    print(f"{args.clip.name}: {n} frames, {args.clip.stat().st_size / n / 1e6:.2f} MB a frame; CPU, best of "
          f"{args.repeats}, interleaved")
    for name, s in best.items():
        print(f"  {name:<18}{1e3 * s / n:8.3f} ms a frame  (one core: at most {n / s:7.0f} frames/s)")


if __name__ == "__main__":
    main()
