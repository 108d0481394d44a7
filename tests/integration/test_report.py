"""`cageless report` end to end: the sample lab, re-runs, failures, and footage of a simulation.

The end-to-end check follows the comparison issue: render footage of a known simulation (the renderer
of :mod:`cageless.tracking.synthetic`), run the report on it, and require MAE <= 0.5 percentage points between the
measured and simulated slip profiles, since the "experiment" is the simulation itself; what remains is
the tracking error (<= 0.3 pp slip-profile MAE in the tracking tests).
"""

from __future__ import annotations

import re
import shutil
from dataclasses import replace
from pathlib import Path

import numpy as np
import pandas as pd

from cageless.bearing import default_bearing
from cageless.app.cli import main
from cageless.conditions import OperatingConditions
from cageless.kinematics import startup_duration
from cageless.trace import Trace
from cageless.simulation.effects import choose_model
from cageless.simulation.run import simulate
from cageless.simulation.scene import Scene

LAB = Path(__file__).resolve().parents[2] / "sample_data" / "lab"


def _report_checks(out: Path, n_rows: int) -> str:
    table = pd.read_csv(out / "slip_table.csv")
    assert len(table) == n_rows
    for ext in ("md", "tex", "html"):
        assert (out / f"slip_table.{ext}").exists()
    html = (out / "report.html").read_text()
    assert html.count('src="data:image/svg+xml;base64,') >= 4 * int((table.status != "failed").sum())
    assert "Reproduction" in html and "Tracking quality" in html and "peak of the mean slip profile" in html
    assert not re.search(r"""(src|href)=["']?(https?:)?//""", html)  # offline: no external resources
    return html


#: The report's default simulates 20 cage revolutions after the start-up; these tests check the workflow,
#: not the statistics, so they state a shorter run (one revolution, the default before issue 16).
ONE_REV = ("--revolutions", "1")


def test_sample_lab_report_and_rerun(tmp_path, capsys):
    out = tmp_path / "report"
    assert main(["report", str(LAB), "-o", str(out), "-q", *ONE_REV]) == 0
    text = capsys.readouterr().out
    assert "0 jobs unchanged" in text
    table = pd.read_csv(out / "slip_table.csv")
    assert list(table.speed_rpm) == [1800, 3000, 6000] and set(table.status) == {"ok"}
    assert np.all(np.isfinite(table[["theoretical_slip_pct", "experimental_slip_pct", "mae_pp"]].to_numpy()))
    html = _report_checks(out, 3)
    assert "run_1800" in html and "race_traction: on" in html
    # unchanged inputs and configuration: nothing is redone
    assert main(["report", str(LAB), "-o", str(out), "-q", *ONE_REV]) == 0
    assert "6 jobs unchanged and skipped" in capsys.readouterr().out
    # a changed model parameter redoes the simulations only
    assert main(["report", str(LAB), "-o", str(out), "-q", "--set", "cho_n_s_m=2500", *ONE_REV]) == 0
    assert "3 jobs unchanged and skipped" in capsys.readouterr().out


def test_with_progress_a_failure_is_said_once_as_it_happens_and_listed_at_the_end(tmp_path, capsys):
    """Without -q the failure's reason is printed when it happens; the closing summary names the video only
    (a new user's trial found every reason printed twice)."""
    lab = tmp_path / "lab"
    lab.mkdir()
    (lab / "n3000_Fr500_Fa0.cine").write_bytes(b"not a cine file" * 100)
    assert main(["report", str(lab), "-o", str(tmp_path / "out")]) == 1
    err = capsys.readouterr().err
    assert err.count("not a Phantom cine file") == 1, err
    assert "FAILED n3000_Fr500_Fa0.cine (tracking): wrong magic bytes" in err, err  # named once, not by its path
    assert "failed: n3000_Fr500_Fa0.cine (the reasons are above and in the report)" in err, err


def test_a_bad_video_is_a_failed_row_and_the_rest_completes(tmp_path, capsys):
    lab = tmp_path / "lab"
    lab.mkdir()
    shutil.copy(LAB / "n6000_Fr500_Fa0.cine", lab)
    (lab / "n3000_Fr500_Fa0.cine").write_bytes(b"not a cine file" * 100)
    (lab / "mystery.avi").write_bytes(b"\x00" * 10)  # no conditions anywhere
    (lab / "conditions.csv").write_text("file,speed_rpm,radial_load_n,operator\nn6000_Fr500_Fa0.cine,6000,500,AB\n")
    out = tmp_path / "out"
    assert main(["report", str(lab), "-o", str(out), "-q", *ONE_REV]) == 1
    text = capsys.readouterr().err
    assert "FAILED n3000_Fr500_Fa0.cine" in text and "FAILED mystery.avi" in text
    # a condition whose only video could not be tracked is not simulated (nothing to compare it with)
    assert [p.name for p in (out / "simulations").glob("*.h5")] == ["n6000_Fr500_Fa0.sim.trace.h5"]
    table = pd.read_csv(out / "slip_table.csv")
    assert sorted(table.status) == ["failed", "failed", "ok"]
    html = _report_checks(out, 3)
    assert "n3000_Fr500_Fa0.cine" in html and "failed" in html
    # what was said about the inputs on the console is in the report too (a new user's trial: only the console)
    notices = html.split("<h3>Warnings about the inputs</h3>", 1)[1].split("</ul>", 1)[0]
    assert "ignoring column" in notices and "operator" in notices and notices.count("<li>") >= 1


def _after(trace: Trace, start_s: float) -> Trace:
    """The trace from ``start_s`` on, with time restarted at 0 (footage taken after the start-up)."""
    keep = trace.time >= start_s - 1e-12
    groups = {g: {k: v[keep] for k, v in d.items()} for g, d in trace.groups.items()}
    return replace(trace, time=trace.time[keep] - trace.time[keep][0], angle=trace.angle[keep],
                   speed=trace.speed[keep], slip=trace.slip[keep], valid=trace.valid[keep], groups=groups)


def test_footage_of_a_simulation_compares_within_tracking_accuracy(tmp_path, capsys):
    from cageless.tracking.synthetic.camera import Appearance, Camera
    from cageless.tracking.synthetic.clip import render_clip
    from cageless.tracking.synthetic.render import Renderer

    duration = 0.05
    bearing = default_bearing()
    lab = tmp_path / "lab"
    lab.mkdir()
    camera = Camera(width=640, height=400, px_per_mm=6.25, bit_depth=12)
    for rpm in (3000.0, 6000.0):
        # the report leaves out the same start-up (three cage revolutions) and simulates settle + duration
        settle = startup_duration(rpm, bearing.geometry.ball_diameter_m, bearing.geometry.pitch_diameter_m)
        scene = Scene(conditions=OperatingConditions(rpm, 500.0), duration_s=settle + duration)
        sim = simulate(scene, choose_model(scene), progress=False).trace
        footage = _after(sim, settle)
        n_frames = int(0.95 * duration * camera.fps)
        render_clip(lab / f"n{rpm:g}_Fr500_Fa0.cine", Renderer(bearing.geometry, camera, Appearance(), seed=3),
                    n_frames, motion_source=footage, fmt="cine-16")
    out = tmp_path / "out"
    assert main(["report", str(lab), "-o", str(out), "-q", "--duration", str(duration)]) == 0
    table = pd.read_csv(out / "slip_table.csv")
    assert set(table.status) == {"ok"} and len(table) == 2
    assert np.all(table.mae_pp <= 0.5), table.to_string()
    _report_checks(out, 2)


def test_a_failed_simulation_is_a_failed_row(tmp_path, capsys):
    """A dry bearing (from the configuration) has no cited Coulomb friction, so its simulation fails with the
    way out in the message: the video is tracked, the row is a failure, and the report still completes."""
    lab = tmp_path / "lab"
    lab.mkdir()
    shutil.copy(LAB / "n6000_Fr500_Fa0.cine", lab)
    config = tmp_path / "dry.toml"
    config.write_text("[bearing]\nlubricant = false\n")
    out = tmp_path / "out"
    assert main(["report", str(lab), "-o", str(out), "-q", "--config", str(config)]) == 1
    assert "simulation failed" in capsys.readouterr().err
    table = pd.read_csv(out / "slip_table.csv")
    assert list(table.status) == ["failed"] and "dry_friction_coefficient" in table.message[0]
    assert (out / "traces" / "n6000_Fr500_Fa0.trace.h5").exists()
    assert "dry_friction_coefficient" in (out / "report.html").read_text()


def test_the_report_simulation_is_the_plain_run(tmp_path):
    """The lab workflow adds nothing to a simulation's set-up (duration, seed, parameters, solver): its trace
    is bit-identical to ``Simulation(scene).run()`` of the same scene. (A move of the sample table's
    numbers between two builds therefore comes from elsewhere: numba compiles for the host CPU, and a
    chaotic run turns last-bit differences into ~0.01-0.06 pp of peak slip.)"""
    from cageless.app.lab import LabOptions, run_lab
    from cageless.simulation.simulation import Simulation
    from cageless.trace import read_trace

    lab = tmp_path / "lab"
    lab.mkdir()
    shutil.copy(LAB / "n6000_Fr500_Fa0.cine", lab)
    settle, duration = 0.002, 0.003
    run_lab(lab, tmp_path / "out", LabOptions(duration_s=duration, settle_s=settle, workers=1), progress=False)
    in_report = read_trace(tmp_path / "out" / "simulations" / "n6000_Fr500_Fa0.sim.trace.h5")
    scene = Scene(conditions=OperatingConditions(6000.0, 500.0, 0.0), bearing=default_bearing(),
                  duration_s=settle + duration)
    plain = Simulation(scene).run()
    assert in_report.time.shape == plain.time.shape
    np.testing.assert_array_equal(in_report.angle, plain.angle)
    np.testing.assert_array_equal(in_report.speed, plain.speed)
