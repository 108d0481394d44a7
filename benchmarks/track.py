"""Tracking speed and accuracy-versus-time (see tracking/bench.py for what is measured).

    python benchmarks/track.py [--dir bench_footage] [--frames 2400] [--repeats 3] [--json out.json]

The same study runs as `cageless bench tracking`. It renders full-size footage once
(about 2 minutes for 2400 frames on 2 cores, 4.9 GB) and reuses it.
"""

from tracking.bench import main

if __name__ == "__main__":
    main()
