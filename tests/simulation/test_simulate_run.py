"""`cageless simulate` end to end on the planar core: refusals, the trace it writes, and failures."""

from __future__ import annotations

import json

import numpy as np
import pytest

from cageless.app.cli import main
from cageless.conditions import OperatingConditions
from cageless.errors import UsageError
from cageless.trace import read_trace
from cageless.simulation.effects import choose_model
from cageless.simulation.run import initial_state, simulate
from cageless.simulation.scene import Scene

FORCE_OFF = ["--effect", "race_traction=off", "--effect", "ehl_film=off", "--effect", "ball_ball_film=off", "--force"]


def test_unsupported_scenes_are_refused_with_the_way_out(tmp_path, capsys):
    out = tmp_path / "x.h5"
    assert main(["simulate", "--speed-rpm", "3000", "--orientation", "vertical", "--level", "planar", "--force",
                 "-o", str(out)]) == 2
    assert "the planar level cannot carry" in capsys.readouterr().err
    assert main(["simulate", "--speed-rpm", "3000", "--dry", "-o", str(out)]) == 2  # no cited dry friction
    assert "--set dry_friction_coefficient=" in capsys.readouterr().err
    assert main(["simulate", "--speed-rpm", "3000", "--set", "restitution=1.5", "-o", str(out)]) == 2
    assert "--set restitution=1.5: must lie in [0, 1]" in capsys.readouterr().err
    assert not out.exists()


def test_full_model_run_writes_traction_and_films(tmp_path, capsys):
    out = tmp_path / "full.trace.h5"
    assert main(["simulate", "--speed-rpm", "6000", "--radial-load-n", "500", "--duration", "0.005", "-q",
                 "-o", str(out), "--set", "cho_n_s_m=2500"]) == 0
    # 5 ms is inside the 76 ms start-up at 6000 rpm: no transient peak is printed as a slip
    assert "no settled slip: the run is within the 76 ms start-up" in capsys.readouterr().out
    tr = read_trace(out)
    c = tr.groups["contacts"]
    assert {"inner_traction", "outer_traction", "inner_film", "outer_film"} <= set(c)
    loaded = c["inner_normal"] > 50
    # Hamrock-Dowson films of a few tenths of a micrometre where the balls carry the load.
    assert 0.05e-6 < np.nanmedian(c["inner_film"][loaded]) < 1e-6
    for race in ("inner", "outer"):  # docs/traces.md: a film is NaN exactly where its contact is open
        np.testing.assert_array_equal(np.isnan(c[f"{race}_film"]), c[f"{race}_normal"] == 0)
    assert tr.provenance["config"]["parameters"]["cho_n_s_m"] == 2500


def test_run_writes_a_simulation_trace(tmp_path, capsys):
    out = tmp_path / "sim.trace.h5"
    code = main(["simulate", "--speed-rpm", "3000", "--radial-load-n", "500", "--duration", "0.003", "-q",
                 "-o", str(out), *FORCE_OFF])
    assert code == 0
    text = capsys.readouterr().out
    # the summary names the method used, switches included (this short run probes inside the start-up)
    assert "complete (auto: dp5" in text and "contact episodes" in text and "at the stability edge" in text
    tr = read_trace(out)
    assert tr.source == "simulation" and tr.status == "complete"
    assert tr.n_samples == 31 and tr.n_balls == 14
    assert np.all(np.isfinite(tr.angle))
    assert set(tr.groups) == {"balls", "contacts", "inner_ring"}
    effects = {e["name"]: e for e in json.loads(tr.simulation.effects_json)["effects"]}
    assert effects["race_traction"]["forced"] and not effects["race_traction"]["on"]
    assert tr.simulation.solver.startswith("auto: dp5") and tr.simulation.n_steps > 0
    assert tr.provenance["config"]["solver"]["rtol"] == 1e-6
    # wall_s is the solver's time, total_wall_s the whole run's (setup, model, compile, solve, observables)
    sim = tr.simulation
    assert 0 < sim.wall_s < sim.total_wall_s and f"({sim.total_wall_s:.2f} s in all)" in text
    # The ring carries the 500 N load plus its weight: it sits about 6 um below the centre.
    assert tr.groups["inner_ring"]["position"][:, 2].mean() == pytest.approx(-6.3e-6, rel=0.2)


def test_initial_state_is_quasi_static():
    scene = Scene(conditions=OperatingConditions(3000.0, 500.0))
    theta, radius, ring = initial_state(scene)
    assert ring[1] < 0 and np.all(np.diff(theta) > 0)
    assert radius.max() > 0.5 * scene.bearing.geometry.pitch_diameter_m  # loaded balls pushed outward


def test_solver_failure_is_an_incomplete_trace(tmp_path):
    scene = Scene(conditions=OperatingConditions(3000.0, 500.0), duration_s=0.002)
    choice = choose_model(scene, effects={"race_traction": False, "ehl_film": False, "ball_ball_film": False},
                          force=True)
    out = tmp_path / "bad.trace.h5"
    # runs out of steps before the end: the switch takes this scene to ark4 after its first 0.1 ms chunk, which
    # then reaches 2 ms in 182 steps and 30 rejections (with CVODE as the only stiff backend 300 ran out at ~0.3 ms)
    res = simulate(scene, choice, out=out, progress=False, max_steps=100)
    assert not res.solution.success
    tr = read_trace(out)
    assert tr.status.startswith("incomplete: ")
    assert not tr.valid[-1].any()
    with pytest.raises(UsageError, match="vertical shaft"):  # refused before anything runs
        vertical = Scene(conditions=OperatingConditions(3000.0, 500.0), orientation="vertical")
        simulate(vertical, choose_model(vertical, level="planar", force=True), progress=False)


@pytest.mark.parametrize("axial", [0.0, 400.0])
def test_ball_ball_friction_is_in_the_trace(axial):
    """Ball-ball friction (magnitude, N) where neighbours touch: zero where apart, never above the peak of the
    traction curve times the normal force (simulation.parameters: peak 0.06), and present in the packed start."""
    from cageless.simulation.effects import choose_model
    from cageless.simulation.parameters import ModelParameters
    from cageless.simulation.run import simulate
    from cageless.simulation.scene import Scene
    from cageless.conditions import OperatingConditions

    scene = Scene(conditions=OperatingConditions(3000.0, 500.0, axial), duration_s=0.01, initial_gap_fraction=0.0)
    c = simulate(scene, choose_model(scene), progress=False).trace.groups["contacts"]
    f, q = c["ball_ball_traction"], c["ball_ball_normal"]
    assert np.all(f >= 0) and np.all(f[q == 0] == 0)
    assert np.all(f <= ModelParameters().traction_peak_coefficient * q + 1e-12)
    assert np.sum(f > 0.01) > 10  # the packed balls rub at the start


def test_one_run_object_sets_up_every_run():
    """Simulation(scene, parameters, choices).run() gives the trace simulate() gives (the same run, set up once),
    refuses bad settings when it is made, and an ensemble member differs only in its seed."""
    from cageless.errors import ParameterError
    from cageless.simulation.parameters import ModelParameters
    from cageless.simulation.simulation import Choices, Simulation

    scene = Scene(conditions=OperatingConditions(3000.0, 500.0), duration_s=5e-4)
    sim = Simulation(scene, ModelParameters(restitution=0.6), Choices(method="dp5", sample_rate_hz=20_000.0))
    trace = sim.run()
    ref = simulate(scene, choose_model(scene), ModelParameters(restitution=0.6), method="dp5", sample_rate_hz=20_000.0,
                   progress=False)
    np.testing.assert_array_equal(trace.angle, ref.trace.angle)
    np.testing.assert_array_equal(sim.solution.y, ref.solution.y)
    assert trace.config["solver"]["method"] == "dp5" and trace.config["parameters"]["restitution"] == 0.6
    with pytest.raises(ParameterError, match="Did you mean 'LSODA'"):
        Simulation(scene, choices=Choices(method="LSDOA"))
    with pytest.raises(UsageError, match="contradicts the scene"):
        Simulation(scene, choices=Choices(effects={"gravity": False}))
    member = sim.with_seed(3)
    assert member.scene.seed == 3 and member.choices is sim.choices and member.model is sim.model


def test_a_config_file_is_one_of_the_traces_inputs(tmp_path, capsys):
    """Every output records its input identities: `simulate --config fit.toml` lists the TOML, with its SHA-256,
    beside the parameter values it set (a new user's trial found `inputs: []`)."""
    import hashlib

    cfg = tmp_path / "fit.toml"
    cfg.write_text("[parameters]\nrestitution = 0.5\n")
    out = tmp_path / "sim.trace.h5"
    assert main(["simulate", "--speed-rpm", "3000", "--radial-load-n", "500", "--duration", "0.002", "-q",
                 "--config", str(cfg), "-o", str(out)]) == 0
    prov = read_trace(out).provenance
    assert [i["name"] for i in prov["inputs"]] == [str(cfg)]
    assert prov["inputs"][0]["sha256"] == hashlib.sha256(cfg.read_bytes()).hexdigest()
    assert prov["config"]["parameters"]["restitution"] == 0.5
