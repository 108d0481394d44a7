"""Issue 14 (done when): ``cageless report`` on a folder of clips whose sidecars describe another bearing
(here 12 and 13 balls, the paper's bearing has 14) gives one Table-2 row per clip: each clip's bearing
flows through tracking, simulation and comparison."""

from __future__ import annotations

import dataclasses

import pandas as pd
import pytest

from cageless.app.cli import main
from cageless.bearing import default_bearing
from cageless.trace import read_trace
from cageless.tracking.synthetic.camera import Appearance, Camera
from cageless.tracking.synthetic.clip import render_clip
from cageless.tracking.synthetic.motion import KinematicLaw
from cageless.tracking.synthetic.render import Renderer

CAMERA = Camera(width=320, height=200, px_per_mm=3.125, bit_depth=8)
#: A tiny simulation: the report then compares 3 ms after 2 ms of start-up (the point is the plumbing).
QUICK = ("--settle", "0.002", "--duration", "0.003", "-q", "--workers", "1")


def _clip(lab, stem: str, n_balls: int) -> None:
    g = dataclasses.replace(default_bearing().geometry, n_balls=n_balls)
    render_clip(lab / f"{stem}.cine", Renderer(g, CAMERA, Appearance(), seed=n_balls), 60,
                law=KinematicLaw(g, 3000.0, seed=n_balls), fmt="cine-8")
    (lab / f"{stem}.toml").write_text(f"speed_rpm = 3000\nradial_load_n = 500\nn_balls = {n_balls}\n")


@pytest.fixture(scope="module")
def mixed_lab(tmp_path_factory):
    lab = tmp_path_factory.mktemp("mixed_lab")
    _clip(lab, "z12", 12)
    _clip(lab, "z13", 13)
    return lab


def test_a_folder_of_clips_with_their_own_ball_counts_gives_table_rows(mixed_lab, tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["report", str(mixed_lab), "-o", str(out), *QUICK]) == 0, capsys.readouterr()
    table = pd.read_csv(out / "slip_table.csv")
    assert list(table.label) == ["z12.cine", "z13.cine"] and set(table.status) == {"ok"}, table.to_string()
    for z in (12, 13):
        video = read_trace(out / "traces" / f"z{z}.trace.h5")
        sim = read_trace(out / "simulations" / f"n3000_Fr500_Fa0_Z{z}_D9.525_dm46.005.sim.trace.h5")
        assert video.n_balls == sim.n_balls == z
    html = (out / "report.html").read_text()
    assert "n_balls = 12" in html and "n_balls = 13" in html  # each clip's bearing in the reproduction table
    # the same clips without their ball counts are refused by the tracker (14 expected), not compared wrongly
    bare = tmp_path / "bare"
    bare.mkdir()
    (bare / "z12.cine").write_bytes((mixed_lab / "z12.cine").read_bytes())
    (bare / "z12.toml").write_text("speed_rpm = 3000\nradial_load_n = 500\n")
    assert main(["report", str(bare), "-o", str(tmp_path / "out2"), *QUICK]) == 1
    err = capsys.readouterr().err
    assert "FAILED z12.cine" in err and err.count("but 14 are expected") == 1, err  # said once, as it happened


def test_the_report_simulates_twenty_cage_revolutions_after_the_start_up():
    """Closed form (pure-rolling cage speed, Harris & Kotzalas ch. 8): at 3000 r/min the cage turns at
    omega_c = 0.5 x 314.159 x (1 - 9.525 / 46.005) = 124.56 rad/s, one revolution in 50.444 ms; the start-up
    is three revolutions (151.33 ms), then 20 (1.00888 s), unless a video is longer or --duration is given."""
    from cageless.app.lab import REPORT_REVOLUTIONS, LabOptions, _duration

    b = default_bearing()
    rev = 2 * 3.141592653589793 / (0.5 * 3000 * 3.141592653589793 / 30 * (1 - 9.525 / 46.005))
    assert rev == pytest.approx(0.0504441, abs=1e-7) and REPORT_REVOLUTIONS == 20
    assert _duration((3000.0, 500.0, 0.0), [0.01], b, LabOptions()) == pytest.approx(23 * rev, rel=1e-9)
    assert _duration((3000.0, 500.0, 0.0), [2.0], b, LabOptions()) == pytest.approx(3 * rev + 2.0, rel=1e-9)
    assert _duration((3000.0, 500.0, 0.0), [0.01], b, LabOptions(revolutions=1)) == pytest.approx(4 * rev)
    assert _duration((3000.0, 500.0, 0.0), [0.01], b, LabOptions(duration_s=0.05)) == pytest.approx(3 * rev + 0.05)


def test_a_sidecar_ball_diameter_scales_the_ball_mass(tmp_path):
    """A homogeneous sphere of the same steel: m = m0 (D / D0)^3, so the paper's 3.5519 g ball of 9.525 mm
    (Table 1) becomes 3.5519 x (8 / 9.525)^3 = 2.1043 g at 8 mm; the simulation reads this mass."""
    from cageless.conditions import bearing_with_keys, resolve_conditions

    (tmp_path / "n3000.toml").write_text("speed_rpm = 3000\nball_diameter_mm = 8\nn_balls = 16\n")
    (tmp_path / "n3000.cine").write_bytes(b"")
    b = bearing_with_keys(default_bearing(), resolve_conditions(tmp_path / "n3000.cine"))
    assert b.geometry.ball_diameter_m == pytest.approx(8e-3) and b.geometry.n_balls == 16
    assert b.masses.ball_mass_kg == pytest.approx(2.1043e-3, rel=1e-4)
    assert b.masses.inner_ring_mass_kg == default_bearing().masses.inner_ring_mass_kg
