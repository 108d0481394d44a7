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


def test_bench_tracking_times_warm_runs_only(monkeypatch):
    """The first tracking run of a process also loads the compiled kernels; the timings leave it out, also
    with --repeats 1. (Right after rendering, `bench tracking --frames 200 --repeats 1` printed 4 frames/s
    on both cores against 39 on one thread, and 55 against 108 when run again: a new user's trial.)"""
    from cageless.tracking import bench

    calls = []

    def fake_track(video, cond, bearing, options, progress=False):
        calls.append(options)
        if len(calls) == 1:  # the process's first run: loading compiled code
            import time

            time.sleep(0.3)
        return "result"

    monkeypatch.setattr(bench, "track_video", fake_track)
    best, res = bench._time_track("clip.cine", bench.TrackOptions(), repeats=1)
    assert res == "result" and best < 0.1 and len(calls) == 2
