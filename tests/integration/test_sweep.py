"""`cageless sweep`: grid parsing, the tables and plot, and the same table locally and on a LocalCluster."""

from __future__ import annotations

import pandas as pd
import pytest

from cageless import __version__
from cageless.app.cli import main
from cageless.errors import ParameterError
from cageless.simulation.sweep import parse_vary, run_sweep, sweep_grid


def test_vary_specs_and_grid():
    v = parse_vary(["lubricant.viscosity=0.02:0.06:5", "speed_rpm=1800,3000"])
    assert v["lubricant.dynamic_viscosity_pa_s"] == pytest.approx([0.02, 0.03, 0.04, 0.05, 0.06])
    assert v["speed_rpm"] == [1800.0, 3000.0]
    grid = sweep_grid(v, seeds=4)
    assert len(grid) == 5 * 2 * 4 and grid[0] == {"lubricant.dynamic_viscosity_pa_s": 0.02, "speed_rpm": 1800.0,
                                                   "seed": 0}
    with pytest.raises(ParameterError, match="Did you mean 'cho_n_s_m'"):
        parse_vary(["cho_n_sm=1,2"])
    with pytest.raises(ParameterError, match="start:stop:count"):
        parse_vary(["cho_n_s_m=1:2"])


def test_sweep_cli_writes_tables_and_plot(tmp_path, capsys):
    out = tmp_path / "sw"
    assert main(["sweep", "--speed-rpm", "6000", "--vary", "cho_n_s_m=2500,7500", "--seeds", "2",
                 "--duration", "0.005", "--settle", "0.005", "-q", "-o", str(out)]) == 0
    runs = pd.read_csv(out / "runs.csv")
    summary = pd.read_csv(out / "summary.csv")
    assert len(runs) == 4 and set(runs.status) == {"ok"}
    assert list(summary.runs) == [2, 2] and (out / "peak_slip.png").stat().st_size > 1000
    assert set(runs.software_version) == set(summary.software_version) == {__version__}
    assert "peak_slip_mean_pct" in capsys.readouterr().out


def test_sweep_on_a_local_cluster_matches_the_local_run():
    distributed = pytest.importorskip("distributed", reason="dask[distributed] (the test extra) is not installed")
    vary = {"cho_n_s_m": [2500.0, 7500.0]}
    kw = dict(seeds=2, speed_rpm=6000.0, radial_load_n=500.0, duration_s=0.005, settle_s=0.005, progress=False)
    local = run_sweep(vary, **kw)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cl:
        remote = run_sweep(vary, scheduler=cl.scheduler_address, **kw)
    pd.testing.assert_frame_equal(local.drop(columns="wall_s"), remote.drop(columns="wall_s"))


def test_one_run_per_point_shows_no_spread():
    """A grid point with one run has no seed spread: NaN (a blank cell), not 0 (new user, --seeds 1); two runs
    give the population standard deviation, |9 - 11| / 2 = 1."""
    from cageless.simulation.sweep import summarise

    runs = pd.DataFrame({"x": [1.0, 2.0, 2.0], "peak_slip_pct": [5.0, 9.0, 11.0], "status": ["ok"] * 3})
    s = summarise(runs, ["x"])
    assert s.peak_slip_std_pct.isna().tolist() == [True, False] and s.peak_slip_std_pct.iloc[1] == 1.0
    assert s.runs.tolist() == [1, 2] and s.peak_slip_mean_pct.tolist() == [5.0, 10.0]


def test_sweep_takes_the_bearing_options_of_simulate(tmp_path, monkeypatch):
    """`--clearance-um` and `--dry` reach a sweep's runs as they reach `cageless simulate`'s (sweep refused them as
    unknown options), through the same override path: the bearing is named after the change."""
    import cageless.simulation.sweep as sweep_module
    from cageless.errors import UsageError

    seen = []

    def stop(vary, seeds, *args, **kwargs):
        seen.append(args[6])  # run_sweep(vary, seeds, speed, radial, axial, duration, settle, parameters, bearing, ...)
        raise UsageError("stopped before running")

    monkeypatch.setattr(sweep_module, "run_sweep", stop)
    argv = ["sweep", "--vary", "cho_n_s_m=2500", "-q", "-o", str(tmp_path / "sw"), "--clearance-um", "32", "--dry",
            "--vary", "geometry.ball_diameter_m=8e-3"]
    assert main(argv) == 2
    (bearing,) = seen
    assert bearing.lubricant is None
    assert bearing.geometry.diametral_clearance_m == pytest.approx(32e-6, rel=1e-9)
    assert bearing.name == "wang2026 (lubricant = none) (geometry.diametral_clearance_m = 3.2e-05)"
    assert main(["sweep", "--vary", "cho_n_s_m=2500", "-o", str(tmp_path / "x"), "--clearance-um", "-50"]) == 2
