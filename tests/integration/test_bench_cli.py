"""`cageless bench tracking` runs end to end on a short clip (the timings themselves are not tested)."""

from __future__ import annotations

import json

import pytest

from cageless.app.cli import main


@pytest.mark.slow
def test_bench_tracking_smoke(tmp_path, capsys):
    out = tmp_path / "b.json"
    assert main(["bench", "tracking", "--dir", str(tmp_path), "--frames", "40", "--repeats", "1",
                 "--json", str(out), "-q"]) == 0
    text = capsys.readouterr().out
    assert "Detector" in text and "SG window" in text
    r = json.loads(out.read_text())
    assert r["end_to_end"]["angle_rms_mrad"] < 0.1
    assert {d["detector"] for d in r["detectors"]} == {"mask", "weighted", "window"}
