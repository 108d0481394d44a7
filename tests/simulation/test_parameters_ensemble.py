"""Open model parameters (`--set`), the traction curve, and seed ensembles."""

from __future__ import annotations

import math

import numpy as np
import pytest

from cageless.app.cli import main
from cageless.errors import ParameterError
from cageless.trace import read_trace
from cageless.simulation.parameters import ModelParameters, parse_set_overrides
from cageless.simulation.traction import regression_coefficients, traction_coefficient


def test_set_overrides_are_parsed_validated_and_suggested():
    assert parse_set_overrides(["cho_n_s_m=2500", "dry_friction_coefficient=none"]) == {
        "cho_n_s_m": 2500.0, "dry_friction_coefficient": None}
    for bad in (["cho_n_s_m"], ["cho_n_s_m=abc"], ["cho_n_s_m=nan"]):
        with pytest.raises(ParameterError):
            parse_set_overrides(bad)
    with pytest.raises(ParameterError, match="Did you mean 'restitution'"):
        ModelParameters().with_overrides({"restitutoin": 0.5})
    with pytest.raises(ParameterError, match="film_thickness_m"):
        ModelParameters(film_thickness_m=-1.0)
    with pytest.raises(ParameterError, match="traction_peak_coefficient"):
        ModelParameters(traction_peak_coefficient=0.03)  # below the sliding value


@pytest.mark.parametrize("peak,s_peak,slide", [(0.06, 0.02, 0.04), (0.09, 0.005, 0.03), (0.05, 0.1, 0.049)])
def test_traction_curve_has_the_stated_peak_and_sliding_value(peak, s_peak, slide):
    """The (A, B, C, D) solved from the readable quantities reproduce them: mu(0) = 0, the maximum mu_peak sits
    at s_peak, and mu tends to the sliding value (the shape of Sakaguchi & Harada 2006 / Gupta's regression)."""
    coef = regression_coefficients(peak, s_peak, slide)
    s = np.linspace(1e-6, 1, 200_001)
    mu = np.array([traction_coefficient(v, coef) for v in s[::100]])
    assert traction_coefficient(0.0, coef) == 0.0
    assert mu.max() == pytest.approx(peak, rel=1e-4)
    assert s[::100][mu.argmax()] == pytest.approx(s_peak, rel=0.01, abs=2e-4)
    assert traction_coefficient(50.0, coef) == pytest.approx(slide, rel=1e-6)
    assert traction_coefficient(-s_peak, coef) == pytest.approx(-peak, rel=1e-6)  # odd in the slip
    assert math.isclose(coef[0], -slide)



def test_dry_friction_follows_the_coulomb_stribeck_curve():
    """mu(u) = [mu_c + (mu_s - mu_c) exp(-(u/v_s)^2)] tanh(u/v_reg) (Olsson et al., Eur. J. Control 4 (1998)
    176-195, with the tanh regularisation of Andersson et al., Tribol. Int. 40 (2007) 580-587), evaluated
    by hand: static 0.15, Coulomb 0.1, v_s = 0.01 m/s, v_reg = 1e-3 m/s, load 10 N."""
    from cageless.simulation.traction import dry_friction

    q, mu_c, mu_s, v_s, v_reg = 10.0, 0.1, 0.15, 0.01, 1e-3
    assert dry_friction(1.0, q, mu_c, v_reg, mu_s, v_s) == pytest.approx(1.0, rel=1e-12)  # far past v_s: Coulomb
    at_vs = (0.1 + 0.05 * math.exp(-1.0)) * math.tanh(10.0) * 10.0  # = 1.18394 N
    assert dry_friction(v_s, q, mu_c, v_reg, mu_s, v_s) == pytest.approx(at_vs, rel=1e-12)
    assert dry_friction(-v_s, q, mu_c, v_reg, mu_s, v_s) == pytest.approx(-at_vs, rel=1e-12)  # odd
    half_vs = (0.1 + 0.05 * math.exp(-0.25)) * math.tanh(5.0) * 10.0  # u = v_s / 2: 1.38928 N, near static
    assert dry_friction(5e-3, q, mu_c, v_reg, mu_s, v_s) == pytest.approx(half_vs, rel=1e-12)
    assert half_vs > at_vs > 1.0
    assert dry_friction(0.3, q, mu_c, v_reg, mu_c, v_s) == pytest.approx(1.0 * math.tanh(300.0), rel=1e-12)
    assert dry_friction(0.3, 0.0, mu_c, v_reg, mu_s, v_s) == 0.0


def test_static_coefficient_is_validated():
    assert ModelParameters(dry_friction_coefficient=0.1, dry_static_coefficient=0.15).stribeck_speed_m_s == 0.01
    for bad in ({"dry_static_coefficient": 0.15},  # without a Coulomb coefficient
                {"dry_friction_coefficient": 0.1, "dry_static_coefficient": 0.05},  # below it
                {"dry_friction_coefficient": 0.1, "dry_static_coefficient": float("nan")}):
        with pytest.raises(ParameterError, match="dry_static_coefficient"):
            ModelParameters(**bad)
    with pytest.raises(ParameterError, match="stribeck_speed_m_s"):
        ModelParameters(stribeck_speed_m_s=0.0)


def test_ensemble_writes_one_trace_per_seed(tmp_path, capsys):
    out = tmp_path / "ens.trace.h5"
    assert main(["simulate", "--speed-rpm", "6000", "--radial-load-n", "500", "--duration", "0.002", "-q",
                 "--ensemble", "2", "-o", str(out)]) == 0
    text = capsys.readouterr().out
    assert "seed 0:" in text and "seed 1:" in text
    a, b = read_trace(tmp_path / "ens_seed0.trace.h5"), read_trace(tmp_path / "ens_seed1.trace.h5")
    assert a.status == b.status == "complete"
    assert not np.allclose(a.angle[0], b.angle[0])  # the seeds perturb the initial gaps
    assert main(["simulate", "--speed-rpm", "6000", "--ensemble", "0", "-o", str(out)]) == 2


def test_ensemble_on_a_local_cluster_matches_the_local_run(tmp_path):
    """One Dask task per seed gives the same traces as the local processes (the run is deterministic)."""
    distributed = pytest.importorskip("distributed", reason="dask[distributed] (the test extra) is not installed")
    from cageless.conditions import OperatingConditions
    from cageless.simulation.ensemble import run_ensemble
    from cageless.simulation.scene import Scene
    from cageless.simulation.simulation import Simulation

    sim = Simulation(Scene(conditions=OperatingConditions(6000.0, 500.0), duration_s=0.002))
    local = run_ensemble(sim, 2, tmp_path / "local.trace.h5", progress=False)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cl:
        remote = run_ensemble(sim, 2, tmp_path / "dask.trace.h5", progress=False, scheduler=cl.scheduler_address)
    for a, b in zip(local, remote, strict=True):
        np.testing.assert_array_equal(read_trace(a["path"]).angle, read_trace(b["path"]).angle)


def test_ensemble_summaries_leave_out_the_start_up_as_a_single_run_does(tmp_path, capsys):
    """Each seed's peak slip is taken after the start-up that compare leaves out, as the single run's summary
    is (the ensemble took it over the whole run: 6.16 % at 6000 rpm and 500 N where the single run of the same
    seed said 2.93 %, a new user's trial); a run that ends within the start-up says it has no settled slip."""
    from cageless.kinematics import startup_duration
    from cageless.simulation.run import peak_unloaded_slip

    out = tmp_path / "ens.trace.h5"
    assert main(["simulate", "--speed-rpm", "6000", "--radial-load-n", "500", "--duration", "0.09", "-q",
                 "--ensemble", "2", "-o", str(out)]) == 0
    lines = [line for line in capsys.readouterr().out.splitlines() if line.startswith("seed ")]
    assert len(lines) == 2
    for k, line in enumerate(lines):
        tr = read_trace(tmp_path / f"ens_seed{k}.trace.h5")
        startup = startup_duration(6000, tr.ball_diameter_m, tr.pitch_diameter_m)  # 75.7 ms
        settled, whole = peak_unloaded_slip(tr, settle_s=startup), peak_unloaded_slip(tr)
        assert f"peak slip in the unloaded zone after 76 ms: {100 * settled:.2f}%" in line, line
        assert abs(settled - whole) > 0.005  # the start-up's transient reads differently
    assert main(["simulate", "--speed-rpm", "6000", "--radial-load-n", "500", "--duration", "0.002", "-q",
                 "--ensemble", "2", "-o", str(tmp_path / "short.trace.h5")]) == 0
    assert capsys.readouterr().out.count("no settled slip: the run is within the 76 ms start-up") == 2


def test_the_default_output_name_holds_the_axial_load(tmp_path, capsys, monkeypatch):
    """Two scenes that differ only in their axial load do not share a default output (the second run
    silently replaced the first's trace, which cageless had written: a new user's trial). A pure radial
    scene keeps the documented name."""
    monkeypatch.chdir(tmp_path)
    for axial in ("200", "0"):
        assert main(["simulate", "--speed-rpm", "6000", "--radial-load-n", "300", "--axial-load-n", axial,
                     "--duration", "0.002", "-q"]) == 0
    assert sorted(p.name for p in tmp_path.glob("*.trace.h5")) == ["sim_6000rpm_Fr300.trace.h5",
                                                                   "sim_6000rpm_Fr300_Fa200.trace.h5"]
    assert read_trace(tmp_path / "sim_6000rpm_Fr300_Fa200.trace.h5").axial_load_n == 200.0
