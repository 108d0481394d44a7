"""benchmarks/ark_accuracy_states.py: its settling durations, its table's largest and median errors and CPU ratios,
and the ark4 tolerance rows it runs (solver_speed's candidates); the measure itself is solver_speed's."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).parent))
from effect_helpers import benchmark_module  # noqa: E402


@pytest.fixture(scope="module")
def mod():  # noqa: ANN201
    with benchmark_module("ark_accuracy_states") as module:
        yield module


def test_settle_times(mod) -> None:  # noqa: ANN001
    assert mod.settle_times(0.03, 0.005, 4) == [0.03, 0.035, 0.04, 0.045]


def test_candidates_cover_the_tolerances(mod) -> None:  # noqa: ANN001
    rtols = {key: mod.CANDIDATES[key][2] for key in ("ark4", "ark4-3e-7", "ark4-7")}
    assert rtols == {"ark4": 1e-6, "ark4-3e-7": 3e-7, "ark4-7": 1e-7}
    assert all(mod.CANDIDATES[key][1] == "ark4" for key in rtols)


def test_table_max_median_and_ratio(mod) -> None:  # noqa: ANN001
    keys = ["ark4", "dp5"]
    labels = [mod.CANDIDATES[k][0] for k in keys]
    errors = {labels[0]: [0.03, 0.001, 0.002], labels[1]: [0.004, 0.005, 0.006]}
    cpu = {labels[0]: [2.0, 2.0, 4.0], labels[1]: [20.0, 30.0, 40.0]}
    rows = [{"solver": lab, "settle_s": s, "slip_error_pp": errors[lab][i], "cpu_s_per_sim_s": cpu[lab][i],
             "ok": True, "steps": 100 * (i + 1)} for lab in labels for i, s in enumerate([0.03, 0.035, 0.04])]
    rows[0]["why"] = {"reference_pp": 1e-4}  # resolved: the reference within a tenth of the bar
    rows[1]["why"] = {"reference_pp": 0.005}  # not resolved
    lines = mod.format_table(rows, keys, bar=0.01).splitlines()
    assert lines[0].startswith("| solver | 30 ms | 35 ms | 40 ms | max (pp) | median (pp) | states <= 0.01 pp")
    first = [c.strip() for c in lines[2].split("|")[1:-1]]
    assert first == ["ark4", "0.03", "0.001", "0.002", "0.03", "0.002", "2 of 3 (0 of 1)", "2.00", "1.00", "200"]
    second = [c.strip() for c in lines[3].split("|")[1:-1]]
    assert second[4:9] == ["0.006", "0.005", "3 of 3 (1 of 1)", "30.00", "10.00"]  # ratios 10, 15, 10: median 10
