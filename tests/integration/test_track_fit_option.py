"""``--track-fit``: the tracking's angle smoothing window from the command line and the lab report."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import pytest

from cageless.app.cli import main
from cageless.app.cli.common import track_fit_value
from cageless.app.lab import LabOptions
from cageless.bearing import default_bearing
from cageless.tracking.synthetic.camera import Appearance, Camera
from cageless.tracking.synthetic.clip import render_clip
from cageless.tracking.synthetic.motion import KinematicLaw
from cageless.tracking.synthetic.render import Renderer

B = default_bearing()
SMALL = Camera(width=320, height=200, px_per_mm=3.125, bit_depth=8)


@pytest.mark.parametrize(("text", "value"), [("auto", "auto"), ("AUTO", "auto"), ("1", 1), ("5", 5), ("41", 41)])
def test_accepted_values(text, value):
    assert track_fit_value(text) == value


@pytest.mark.parametrize(("text", "why"), [("3", "odd number of frames >= 5"), ("8", "odd number of frames >= 5"),
                                            ("0", "odd number of frames >= 5"), ("seven", "got 'seven'")])
def test_refused_values(text, why):
    with pytest.raises(argparse.ArgumentTypeError, match=why):
        track_fit_value(text)


def test_track_records_the_fixed_window_and_refuses_an_even_one(tmp_path, capsys):
    """A fixed window reaches the tracker (its QC record says 9 frames, no cross-validation); 8 is refused
    before any work, naming the option."""
    g = B.geometry
    video = render_clip(tmp_path / "clip.cine", Renderer(g, SMALL, Appearance(), seed=7), 60,
                        law=KinematicLaw(g, 3000, seed=7), fmt="cine-8")["video"]
    out = tmp_path / "out"
    assert main(["track", str(video), "-o", str(out), "-q", "--speed-rpm", "3000", "--track-fit", "9"]) == 0
    qc = json.loads((out / "qc" / "clip.qc.json").read_text())
    assert qc["track_fit"] == {"frames": 9}
    assert main(["track", str(video), "-o", str(tmp_path / "bad"), "-q", "--speed-rpm", "3000",
                 "--track-fit", "8"]) == 2
    assert "--track-fit" in capsys.readouterr().err
    assert not (tmp_path / "bad").exists()


def test_report_options_record_the_window_only_when_given():
    """Lab runs with the default keep their recorded options (and cache keys) as before."""
    assert "track_fit" not in LabOptions().to_dict()
    assert LabOptions(track_fit=11).to_dict()["track_fit"] == 11
