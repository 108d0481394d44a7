"""Cine reading throughput against a plain ``numpy.fromfile`` copy of the same bytes.

For 8-bit, 16-bit and packed 12-bit 1280 x 800 cines (written by our writer,
then read once so they sit in the page cache), it times our reader delivering
every frame through ``iter_chunks`` and, in the same run, ``numpy.fromfile``
reading the same bytes in the same chunks (one call per chunk of 32 frames). The ratio of the two frame
rates is the figure of merit (the issue's aim: >= 0.8). Best of ``--repeats``.

    python benchmarks/read_cine.py [--frames 150] [--repeats 5] [--csv out.csv] [--plot out.png]
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np

from cageless.tracking.io import open_video, write_cine
from cageless.tracking.io.cine import CineReader

W, H, CHUNK = 1280, 800, 32


def _frames(n: int, bits: int) -> np.ndarray:
    rng = np.random.default_rng(0)
    dtype = np.uint8 if bits == 8 else np.uint16
    return rng.integers(0, 1 << bits, size=(n, H, W), dtype=np.int64).astype(dtype)


def _time_reader(path: Path) -> float:
    t0 = time.perf_counter()
    with open_video(path) as video:
        for _, chunk in video.iter_chunks(CHUNK):
            del chunk  # frames are delivered; nothing else is timed
    return time.perf_counter() - t0


def _time_fromfile(path: Path) -> float:
    """The same byte ranges as the reader's chunks, one ``numpy.fromfile`` call per chunk."""
    with CineReader(path) as video:
        starts, size, n = video._data_start.copy(), video._image_size, len(video)
    t0 = time.perf_counter()
    for a in range(0, n, CHUNK):
        b = min(a + CHUNK, n)
        np.fromfile(path, dtype=np.uint8, count=int(starts[b - 1] + size - starts[a]), offset=int(starts[a]))
    return time.perf_counter() - t0


def run(n_frames: int, repeats: int) -> list[dict[str, float | str]]:
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for fmt, bits in (("8", 8), ("16", 16), ("p12", 12)):
            path = write_cine(Path(tmp) / f"b{fmt}.cine", _frames(n_frames, bits), fps=10_000, fmt=fmt, real_bpp=bits)
            _time_reader(path), _time_fromfile(path)  # warm the page cache
            ours = min(_time_reader(path) for _ in range(repeats))
            base = min(_time_fromfile(path) for _ in range(repeats))
            rows.append({"format": {"8": "8-bit", "16": "16-bit", "p12": "packed 12-bit"}[fmt],
                         "reader_fps": n_frames / ours, "fromfile_fps": n_frames / base, "ratio": base / ours,
                         "mb_per_frame": path.stat().st_size / n_frames / 1e6})
    return rows


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--frames", type=int, default=150)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--csv", type=Path)
    ap.add_argument("--plot", type=Path)
    args = ap.parse_args()
    rows = run(args.frames, args.repeats)
    print(f"Cine reading, {W}x{H}, {args.frames} frames from the page cache, best of {args.repeats}")
    print(f"{'format':<15}{'MB/frame':>10}{'reader fps':>12}{'fromfile fps':>14}{'ratio':>8}")
    for r in rows:
        print(f"{r['format']:<15}{r['mb_per_frame']:>10.2f}{r['reader_fps']:>12.0f}{r['fromfile_fps']:>14.0f}"
              f"{r['ratio']:>8.2f}")
    if args.csv:
        import pandas as pd

        pd.DataFrame(rows).to_csv(args.csv, index=False)
    if args.plot:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        fig, ax = plt.subplots(figsize=(5, 3))
        ax.bar([r["format"] for r in rows], [r["ratio"] for r in rows])
        ax.axhline(0.8, ls="--", c="k", lw=0.8)
        ax.set_ylabel("reader / numpy.fromfile")
        fig.tight_layout()
        fig.savefig(args.plot)
        plt.close(fig)


if __name__ == "__main__":
    main()
