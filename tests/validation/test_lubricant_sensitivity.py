"""The paper's lubricant sensitivity study, reduced (benchmarks/lubricant_sensitivity.py runs every row).

Reference: Wang, Zhao, Wang, Jin, Appl. Sci. 2026, 16, 9284, §4: at 1800 rpm, 500 N, viscosity 0.02-0.06 Pa s
moves the paper's predicted slip from 24.5 % to 15.9 % (-35 %). The issue's bar is a move of at least 15 %
relative. In cageless the viscosity acts the other way: a more viscous oil raises the hydrodynamic rolling loss
(Chiu 1974) and the film traction's viscosity, so the balls slow more in the unloaded zone (measured with the
benchmark, 2 seeds x 0.1 s: see docs/benchmarks.md). The temperature reaches the slip the same way: 60 degC
thins the oil to exp(-0.027 x 40) = 0.34 of its 20 degC viscosity (the paper's temperature-viscosity
coefficient, Table 1).
"""

from __future__ import annotations

import pytest

from cageless.simulation.sweep import parse_vary, run_sweep, summarise


def _ends(item: str) -> tuple[float, float]:
    vary = parse_vary([item])
    runs = run_sweep(vary, 2, 1800.0, 500.0, duration_s=0.1, workers=2, progress=False)
    assert (runs.status == "ok").all(), runs
    summ = summarise(runs, list(vary)).reset_index(drop=True)
    return float(summ.peak_slip_mean_pct.iloc[0]), float(summ.peak_slip_mean_pct.iloc[-1])


@pytest.mark.slow
def test_viscosity_moves_the_1800_rpm_slip_by_more_than_15_percent():
    low, high = _ends("lubricant.viscosity=0.02,0.06")
    assert (high - low) / low >= 0.15, (low, high)  # rises: the opposite direction to the paper's -35 %


@pytest.mark.slow
def test_a_hotter_oil_lowers_the_slip():
    cold, hot = _ends("oil_temperature_c=20,60")
    assert hot < cold, (cold, hot)
