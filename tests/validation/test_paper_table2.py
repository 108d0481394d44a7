"""The paper's Table 2 as a validation, reduced (benchmarks/paper_table2.py runs all nine conditions).

Reference: Wang, Zhao, Wang, Jin, Appl. Sci. 2026, 16, 9284, Table 2, measured peak slip in the unloaded zone:
11.77 % at 1800 rpm and 4.58 % at 6000 rpm, 500 N. The default parameter set was fitted once, at 3000 rpm /
500 N (simulation/parameter_sets.py); these two conditions are predictions. The issue's aim is a miss of at
most 3 pp (the paper's own model misses them by 11.0 and 3.8 pp). The peak is the maximum of the mean profile
smoothed by a periodic Gaussian of sigma 10 deg (cageless.profiles.unloaded_zone_peak). Measured with the full
benchmark after its re-calibration (r_s = 0.2103 mm): 4 seeds x 0.2 s 9.51 % and 2.93 % (misses -2.26 and
-1.65 pp); the first 0.1 s of seed 0 of those runs 9.26 % and 2.93 % (-2.51 and -1.65 pp). Re-run with `auto`
taking ark4 after the start-up (--no-calibrate, 2026-11-27): 9.67 % and 2.93 % (-2.10 and -1.65 pp).
"""

from __future__ import annotations

import importlib
import sys
from pathlib import Path

import pytest

BENCHMARKS = Path(__file__).resolve().parents[2] / "benchmarks"


@pytest.mark.slow
def test_table2_predictions_within_3_pp():
    sys.path.insert(0, str(BENCHMARKS))  # importable by name, so the worker processes find its functions
    try:
        mod = importlib.import_module("paper_table2")
        rows = mod.run([1800, 6000], [500], seeds=1, duration=0.1, workers=2)
    finally:
        sys.path.remove(str(BENCHMARKS))
    table = mod.format_table(rows, 1, 0.1)
    for r in rows:
        assert r["failed"] == 0, table
        assert abs(r["miss_ours_pp"]) <= 3.0, table
        assert abs(r["miss_ours_pp"]) < abs(r["miss_paper_pp"]), table
