"""The read ceiling of a clip: how fast its bytes arrive from the page cache and from the disk, in frames/s.

    python benchmarks/read_ceiling.py CLIP [--block-mib 8] [--repeats 2]

Reads the whole file once in ``--block-mib`` blocks into one reused buffer, three ways, and prints MB/s and the
frames/s that allows at the clip's bytes a frame (the file's size over its frame count):

* **page cache**: buffered ``readinto`` after one read has put the file in the page cache (best of
  ``--repeats``): the ceiling of anything that must see every byte from memory (the input hash included);
* **disk, O_DIRECT**: ``O_DIRECT`` reads, which bypass this machine's page cache (the first of them is the
  honest one: a virtual disk's host may cache what was read before, so later passes read faster);
* **memory map, touched**: every 4 KiB page of a ``mmap`` of the file touched once (page faults included),
  then unmapped: the floor of a reader that maps the frames, like the tracker.

A clip larger than the page cache can hold (a 10,000-frame 1280 x 800 16-bit cine is 20.5 GB) is read from the
disk on every run, so the disk's rate caps the frames/s of any run that hashes every byte.
"""

from __future__ import annotations

import argparse
import mmap
import os
import time
from pathlib import Path

import numpy as np

from cageless.tracking.io import open_video


def _buffered(path: Path, buf: mmap.mmap) -> float:
    t0 = time.perf_counter()
    with open(path, "rb", buffering=0) as fh:
        while fh.readinto(buf):
            pass
    return time.perf_counter() - t0


def _direct(path: Path, buf: mmap.mmap) -> float | None:
    """Seconds to read ``path`` with ``O_DIRECT`` (None where the file system refuses it)."""
    flag = getattr(os, "O_DIRECT", None)
    if flag is None:
        return None
    try:
        fd = os.open(path, os.O_RDONLY | flag)
    except OSError:
        return None
    t0 = time.perf_counter()
    try:
        with open(fd, "rb", buffering=0, closefd=True) as fh:
            while fh.readinto(buf):  # the mmap buffer is page-aligned, as O_DIRECT needs
                pass
    except OSError:
        return None
    return time.perf_counter() - t0


def _mapped(path: Path) -> float:
    t0 = time.perf_counter()
    with open(path, "rb") as fh, mmap.mmap(fh.fileno(), 0, access=mmap.ACCESS_READ) as mm:
        pages = np.frombuffer(mm, dtype=np.uint8)[::mmap.PAGESIZE]
        int(pages.sum(dtype=np.uint64))  # one byte of every page
        del pages
    return time.perf_counter() - t0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("clip", type=Path)
    ap.add_argument("--block-mib", type=int, default=8)
    ap.add_argument("--repeats", type=int, default=2)
    args = ap.parse_args()
    size = args.clip.stat().st_size
    with open_video(args.clip) as video:
        n = len(video)
    per_frame = size / n
    buf = mmap.mmap(-1, args.block_mib << 20)
    rows = []
    direct = [_direct(args.clip, buf) for _ in range(args.repeats)]
    rows += [(f"disk, O_DIRECT, pass {k + 1}", s) for k, s in enumerate(direct) if s is not None]
    _buffered(args.clip, buf)  # into the page cache
    rows.append(("page cache, buffered reads", min(_buffered(args.clip, buf) for _ in range(args.repeats))))
    rows.append(("memory map, every page touched", min(_mapped(args.clip) for _ in range(args.repeats))))
    print(f"{args.clip.name}: {size / 1e9:.2f} GB, {n} frames, {per_frame / 1e6:.3f} MB a frame")
    for name, s in rows:
        print(f"  {name:<34} {size / s / 1e6:8.0f} MB/s  {n / s:8.0f} frames/s")


if __name__ == "__main__":
    main()
