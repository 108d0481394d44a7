"""The bundled sample lab folder, and `cageless sample` rendering a fresh one."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from cageless.app.cli import main
from cageless.conditions import discover_lab
from cageless.tracking.io import open_video

LAB = Path(__file__).resolve().parents[2] / "sample_data" / "lab"


def test_sample_folder_fits_its_budget():
    size = sum(p.stat().st_size for p in LAB.rglob("*") if p.is_file())
    assert size <= 30 * 2**20
    assert (LAB / "README.md").is_file()


def test_sample_conditions_come_from_all_three_sources():
    entries = {e.video.name: e for e in discover_lab(LAB)}
    assert sorted(entries) == ["clip_3000rpm.mkv", "n6000_Fr500_Fa0.cine", "run_1800"]
    origin = {name: e.resolved.origin["speed_rpm"] for name, e in entries.items()}
    assert origin == {"run_1800": "sidecar run_1800.toml", "clip_3000rpm.mkv": "conditions.csv",
                      "n6000_Fr500_Fa0.cine": "file name"}
    speeds = {name: e.resolved.conditions.speed_rpm for name, e in entries.items()}
    assert speeds == {"run_1800": 1800, "clip_3000rpm.mkv": 3000, "n6000_Fr500_Fa0.cine": 6000}
    assert all(e.resolved.conditions.radial_load_n == 500 for e in entries.values())


@pytest.mark.parametrize("name", ["run_1800", "clip_3000rpm.mkv", "n6000_Fr500_Fa0.cine"])
def test_sample_clips_match_their_truth_and_cover_the_orbit(name):
    stem = Path(name).stem
    truth = pd.read_csv(LAB / f"{stem}.truth.csv")
    meta = json.loads((LAB / f"{stem}.truth.json").read_text())
    fps = 10_000 if name != "n6000_Fr500_Fa0.cine" else None
    with open_video(LAB / name, fps=fps) as video:
        assert len(video) == truth.frame.nunique() == meta["n_frames_taken"]
        assert video.frame_shape == (200, 320)
        if name.endswith(".cine"):  # dropped frames show as gaps in the time stamps
            np.testing.assert_allclose(video.times, np.unique(truth.time_s), atol=1e-9)
            assert meta["dropped_frames"]
    # The 14 balls together cover every 1-degree bin of the orbit at least 3 times.
    cover = np.zeros(360, dtype=int)
    for _, ball in truth.groupby("ball"):
        deg = np.degrees(ball.angle_rad.to_numpy())
        swept = np.arange(np.floor(deg.min()), np.ceil(deg.max())) % 360
        cover[np.unique(swept.astype(int))] += 1
    assert cover.min() >= 3


def test_cageless_sample_renders_an_accepted_lab(tmp_path, capsys):
    out = tmp_path / "lab"
    assert main(["sample", str(out), "--revolutions", "0.03", "--seed", "11", "-q"]) == 0
    assert "n6000_Fr500_Fa0.cine" in capsys.readouterr().out
    entries = discover_lab(out)
    assert len(entries) == 3 and all(e.ok for e in entries)
    for e in entries:
        with open_video(e.video, fps=e.resolved.conditions.fps) as video:
            assert len(video) >= 5


def test_cageless_sample_rejects_a_bad_preset(tmp_path, capsys):
    assert main(["sample", str(tmp_path), "--preset", "huge"]) == 2
    assert "--preset: invalid choice 'huge'. Choose from: lab, full." in capsys.readouterr().err
