"""Tracking speed and accuracy-versus-time (see tracking/bench.py for what is measured).

    python benchmarks/track.py [--dir bench_footage] [--frames 2400] [--repeats 3] [--json out.json]

The same study runs as `cageless bench tracking`. It renders full-size footage once
(about 2 minutes for 2400 frames on 2 cores, 4.9 GB) and reuses it.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from tracking.bench import format_tables, run_benchmark


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--dir", type=Path, default=Path("bench_footage"))
    ap.add_argument("--frames", type=int, default=2400)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--json", type=Path)
    args = ap.parse_args()
    args.dir.mkdir(parents=True, exist_ok=True)
    result = run_benchmark(args.dir, args.frames, args.repeats)
    print(format_tables(result))
    if args.json:
        args.json.write_text(json.dumps(result, indent=1))


if __name__ == "__main__":
    main()
