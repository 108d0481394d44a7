"""`cageless calibrate`: its refusals, the parameter file it writes, that simulate/sweep take that file
(``--set`` winning), that it runs the same on a LocalCluster, and (slow) that it recovers a known value."""

from __future__ import annotations

import json
import sys
import time
import tomllib
from pathlib import Path

import numpy as np
import pytest

from cageless.app.calibrate import Bound, calibrate, describe_calibration, parse_bounds, target_from_peak
from cageless.app.cli import main
from cageless.errors import ParameterError
from cageless.trace import SimulationInfo, Trace, read_trace, write_trace

sys.path.insert(0, str(Path(__file__).parent))
from calibration_helpers import as_video_trace  # noqa: E402

# A cheap scene for the CI share: 6000 rpm (a cage revolution is 25 ms), 5 ms after a 5 ms start-up.
FAST = ["--speed-rpm", "6000", "--radial-load-n", "500", "--duration", "0.005", "--settle", "0.005"]


def _fake_simulation_trace(path: Path) -> Path:
    t = np.linspace(0.0, 0.01, 11)
    z = np.zeros((11, 14))
    tr = Trace(source="simulation", time=t, angle=z, speed=z, slip=z, valid=z == 0, speed_rpm=3000.0,
               radial_load_n=500.0, axial_load_n=0.0, ball_diameter_m=9.525e-3, pitch_diameter_m=46.005e-3,
               simulation=SimulationInfo("{}", "{}", "dp5", 1e-6, 1e-9, 1, 1, 0.0))
    return write_trace(path, tr)


@pytest.mark.parametrize("vary, message", [
    ("cho_n_sm=2000:8000", "Did you mean 'cho_n_s_m'"),
    ("cho_n_s_m=2000:12000", "leaves the documented range 0..10000"),
    ("restitution=0.9:0.5", "LOW must be below HIGH"),
    ("cho_n_s_m=2000", "write LOW:HIGH"),
    ("strips=1:5", "has no documented physical range"),
])
def test_bad_vary_is_a_one_line_usage_error(vary, message, capsys):
    assert main(["calibrate", "--speed-rpm", "3000", "--radial-load-n", "500", "--target-peak-slip-pct", "2",
                 "--vary", vary]) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1 and "Traceback" not in err


def test_a_trace_that_is_not_a_video_trace_is_refused(tmp_path, capsys):
    path = _fake_simulation_trace(tmp_path / "sim.trace.h5")
    assert main(["calibrate", str(path), "--vary", "cho_n_s_m=2000:8000"]) == 2
    err = capsys.readouterr().err
    assert "is a simulation trace" in err and str(path) in err and err.count("\n") == 1
    assert main(["calibrate", str(tmp_path / "missing.trace.h5"), "--vary", "cho_n_s_m=2000:8000"]) == 2
    assert main(["calibrate", "--speed-rpm", "3000", "--vary", "cho_n_s_m=2000:8000"]) == 2


def test_ranges_are_canonical_and_aliases_accepted():
    b = parse_bounds(["lubricant.viscosity=0.02:0.06", "cho_n_s_m=2000:8000"])
    assert b == [Bound("lubricant.dynamic_viscosity_pa_s", 0.02, 0.06), Bound("cho_n_s_m", 2000.0, 8000.0)]
    with pytest.raises(ParameterError, match="given twice"):
        parse_bounds(["cho_n_s_m=2000:8000", "cho_n_s_m=3000:4000"])


def test_every_documented_range_names_a_parameter_and_is_accepted_whole():
    from cageless.simulation.ranges import DOCUMENTED_RANGES

    bounds = parse_bounds([f"{n}={r.low!r}:{r.high!r}" for n, r in DOCUMENTED_RANGES.items()])
    assert [b.name for b in bounds] == list(DOCUMENTED_RANGES)


def test_calibrate_to_a_target_writes_a_parameter_file_that_simulate_takes(tmp_path, capsys):
    out = tmp_path / "fit.toml"
    rc = main(["calibrate", *FAST, "--target-peak-slip-pct", "1.0", "--vary", "cho_n_s_m=2000:8000",
               "--budget", "3", "--seeds", "1", "-q", "-o", str(out)])
    assert rc == 0, capsys.readouterr()
    doc = tomllib.loads(out.read_text())
    cal = doc["calibration"]
    assert 2000 <= doc["parameters"]["cho_n_s_m"] <= 8000
    assert doc["parameters"]["cho_n_s_m"] == cal["fitted"]["cho_n_s_m"]
    assert cal["ranges"]["cho_n_s_m"] == [2000.0, 8000.0]
    assert cal["evaluations_used"] == len(cal["evaluations"]) == 3 and cal["budget"] == 3
    best = min(cal["evaluations"], key=lambda r: r["objective_pp"])
    assert cal["objective_pp"] == best["objective_pp"] == pytest.approx(abs(best["peak_slip_pct"] - 1.0))
    assert cal["condition"] == "6000 rpm, 500 N radial, 0 N axial" and cal["target_peak_slip_pct"] == 1.0
    assert cal["seed_values"] == [0] and "Brent" in cal["method"] and cal["software_version"]
    assert not list(tmp_path.glob("*.tmp*"))  # written atomically
    capsys.readouterr()
    trace = tmp_path / "run.trace.h5"
    assert main(["simulate", "--speed-rpm", "6000", "--radial-load-n", "500", "--duration", "0.002", "-q",
                 "--config", str(out), "-o", str(trace)]) == 0
    printed = capsys.readouterr().out
    assert "parameters: calibration (cho_n_s_m = " in printed and "fitted at 6000 rpm, 500 N radial" in printed
    cfg = read_trace(trace).config
    assert cfg["parameters"]["cho_n_s_m"] == cal["fitted"]["cho_n_s_m"] and "calibration" in cfg
    assert main(["simulate", "--speed-rpm", "6000", "--radial-load-n", "500", "--duration", "0.002", "-q",
                 "--config", str(out), "--set", "cho_n_s_m=1234", "-o", str(trace)]) == 0
    assert read_trace(trace).config["parameters"]["cho_n_s_m"] == 1234.0  # --set wins over the file


def test_a_bad_parameters_table_names_the_file(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text("[parameters]\ncho_n_sm = 2500\n")
    assert main(["sweep", *FAST[:4], "--vary", "cho_n_s_m=2500,7500", "--config", str(bad)]) == 2
    err = capsys.readouterr().err
    assert str(bad) in err and "Did you mean 'cho_n_s_m'" in err


def test_describe_calibration_names_the_condition_and_the_trace():
    text = describe_calibration({"fitted": {"cho_n_s_m": 3012.0}, "condition": "3000 rpm, 500 N radial, 0 N axial",
                                 "trace_file": "/x/clip.trace.h5", "trace_sha256": "ab" * 32, "metric": "mae",
                                 "objective_pp": 0.12, "evaluations_used": 12, "seeds": 2})
    assert text.startswith("calibration (cho_n_s_m = 3012) fitted at 3000 rpm, 500 N radial, 0 N axial to trace "
                           "clip.trace.h5 (sha256 abababababab)")
    assert describe_calibration(None) is None


def test_calibration_on_a_local_cluster_matches_the_local_run():
    distributed = pytest.importorskip("distributed", reason="dask[distributed] (the test extra) is not installed")
    target = target_from_peak(6000.0, 500.0, 1.0, duration_s=0.005)
    kw = dict(budget=3, seeds=2, settle_s=0.005, progress=False)
    local = calibrate(target, [Bound("restitution", 0.5, 0.95)], **kw)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cl:
        remote = calibrate(target, [Bound("restitution", 0.5, 0.95)], scheduler=cl.scheduler_address, **kw)
    assert json.dumps(local.evaluations) == json.dumps(remote.evaluations)
    assert local.fitted == remote.fitted


def test_report_takes_a_calibration_and_names_its_condition(tmp_path, capsys):
    import shutil

    lab = tmp_path / "lab"
    lab.mkdir()
    shutil.copy(Path(__file__).resolve().parents[2] / "sample_data" / "lab" / "n6000_Fr500_Fa0.cine", lab)
    config = tmp_path / "fit.toml"
    config.write_text('[parameters]\ncho_n_s_m = 2500.0\n\n[calibration]\n'
                      'condition = "3000 rpm, 500 N radial, 0 N axial"\ntarget_peak_slip_pct = 2.2\n'
                      'metric = "peak miss"\nobjective_pp = 0.01\nevaluations_used = 12\nseeds = 2\n'
                      '[calibration.fitted]\ncho_n_s_m = 2500.0\n')
    out = tmp_path / "out"
    assert main(["report", str(lab), "-o", str(out), "-q", "--config", str(config), "--duration", "0.01",
                 "--settle", "0.005"]) == 0
    note = "calibration (cho_n_s_m = 2500) fitted at 3000 rpm, 500 N radial, 0 N axial to target peak slip 2.2 %"
    assert f"parameters: {note}" in capsys.readouterr().out
    assert note in (out / "report.html").read_text()
    sim = read_trace(next((out / "simulations").glob("*.trace.h5")))
    assert sim.config["parameters"]["cho_n_s_m"] == 2500.0


def test_several_parameters_use_a_design_then_nelder_mead(tmp_path, capsys):
    out = tmp_path / "fit2.toml"
    assert main(["calibrate", *FAST, "--target-peak-slip-pct", "1.0", "--vary", "restitution=0.5:0.95",
                 "--vary", "lubricant.viscosity=0.02:0.06", "--budget", "5", "--seeds", "1", "-q",
                 "-o", str(out)]) == 0
    doc = tomllib.loads(out.read_text())
    cal = doc["calibration"]
    assert cal["evaluations_used"] == 5 and "Latin hypercube design of 3 points" in cal["method"]
    assert 0.5 <= doc["parameters"]["restitution"] <= 0.95
    assert 0.02 <= doc["bearing"]["lubricant"]["dynamic_viscosity_pa_s"] <= 0.06  # a bearing field: [bearing.*]
    capsys.readouterr()
    assert main(["calibrate", *FAST, "--target-peak-slip-pct", "1.0", "--vary", "restitution=0.5:0.95",
                 "--set", "restitution=0.7"]) == 2
    assert "both held (--set) and varied" in capsys.readouterr().err


# -- recovering a known value ------------------------------------------------------------------------------
# The "measurement" is a simulation with the inlet meniscus distance of the rolling losses r_s = 0.3 mm (seed
# 17, 20 ms start-up left out, 50 ms kept, 6000 rpm, 500 N), written as a video trace; the calibration runs seeds
# 0..1, so it never sees the measured trajectory. Why this parameter: the unloaded-zone slip barely responds to
# C_ho (3000 rpm, 4 seeds: peak 2.157-2.201 % for every C_ho in 2000..8000, measured before issue 16), and since
# the race contacts take their traction from the film regime (the film_traction effect, issue 16) the traction
# curve's sliding coefficient acts only between balls (fitted 0.02145 for a true 0.02, measured), while the
# rolling losses set the slip: at 3000 rpm, 500 N the peak moves from 7.2 % (r_s = 0.16 mm) to 14.3 % (0.66 mm).
# Measured with the profile objective (budget 8, 2 seeds): fitted 0.3068 mm for seed 17 (2.3 %); the tolerances
# are 5 % (profile) and 10 % (one-seed peak target, noisier).
TRUE, RANGE = 0.3e-3, (0.15e-3, 0.6e-3)


def _measured(tmp_path: Path, seed: int) -> tuple[Path, float]:
    from cageless.bearing import default_bearing
    from cageless.conditions import OperatingConditions
    from cageless.simulation.parameters import ModelParameters
    from cageless.simulation.run import peak_unloaded_slip
    from cageless.simulation.scene import Scene
    from cageless.simulation.simulation import Simulation

    scene = Scene(OperatingConditions(6000.0, 500.0, 0.0), default_bearing(), duration_s=0.07, seed=seed)
    trace = Simulation(scene, ModelParameters(meniscus_distance_m=TRUE)).run()
    return as_video_trace(trace, 0.02, tmp_path / f"measured{seed}.trace.h5"), 100 * peak_unloaded_slip(trace, 0.02)


def test_calibration_recovers_a_known_meniscus_distance_from_a_trace(tmp_path, capsys):
    path, _ = _measured(tmp_path, 17)
    out = tmp_path / "fit.toml"
    start = time.perf_counter()
    assert main(["calibrate", str(path), "--vary", f"meniscus_distance_m={RANGE[0]}:{RANGE[1]}",
                 "--settle", "0.02", "--budget", "8", "--seeds", "2", "-q", "-o", str(out)]) == 0
    wall = time.perf_counter() - start
    cal = tomllib.loads(out.read_text())["calibration"]
    fitted = cal["fitted"]["meniscus_distance_m"]
    print(f"true {TRUE}, fitted {fitted:.4g}, {cal['evaluations_used']} evaluations x 2 seeds, {wall:.1f} s, "
          f"MAE {cal['objective_pp']:.3f} pp", file=sys.stderr)
    assert abs(fitted - TRUE) < 0.05 * TRUE
    assert cal["trace_sha256"] and cal["condition"] == "6000 rpm, 500 N radial, 0 N axial"
    assert cal["metric"] == "mae" and cal["evaluations_used"] == 8


@pytest.mark.slow
@pytest.mark.parametrize("seed", [17, 23, 31])
def test_calibration_recovers_it_from_other_measurements_and_from_the_peak(tmp_path, seed):
    path, peak = _measured(tmp_path, seed)
    bound = [Bound("meniscus_distance_m", *RANGE)]
    from cageless.app.calibrate import target_from_trace

    by_trace = calibrate(target_from_trace(path, 0.05), bound, budget=10, seeds=2, settle_s=0.02, progress=False)
    by_peak = calibrate(target_from_peak(6000.0, 500.0, peak, duration_s=0.05), bound, budget=10, seeds=2,
                        settle_s=0.02, progress=False)
    assert abs(by_trace.fitted["meniscus_distance_m"] - TRUE) < 0.05 * TRUE
    assert abs(by_peak.fitted["meniscus_distance_m"] - TRUE) < 0.1 * TRUE
