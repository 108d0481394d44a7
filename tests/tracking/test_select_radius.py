"""The ball circle against the pitch circle of a stated scale (corpus FRESH2 seed 7218).

On 7218 (12 balls, dim doubled highlights over dark faces) the ball selection chose the bright wedges between
neighbouring balls: 12 tracks on one circle at the cage speed, in cyclic order, so every consistency check held,
but on a circle of 84.2 px where the stated px_per_mm puts the pitch circle at 99.5 px (-0.31 ball diameters of
49.4 px). Each track followed the middle of a gap, not a ball (17.1 mrad RMS against the truth, after the
scorer removed the half-pitch offset). A stated scale now bounds the circle's radius
(:data:`~cageless.tracking.select.PRIOR_RADIUS_TOL`); without one nothing changes.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest

from cageless.bearing import default_bearing
from cageless.conditions import OperatingConditions
from cageless.tracking.pipeline import track_video
from cageless.tracking.select import PRIOR_RADIUS_TOL, SelectionError, check_radius
from cageless.tracking.synthetic.camera import Appearance, Camera
from cageless.tracking.synthetic.clip import frames_for_revolutions, render_clip
from cageless.tracking.synthetic.corpus import render_clip as corpus_clip
from cageless.tracking.synthetic.motion import KinematicLaw

sys.path.insert(0, str(Path(__file__).parent))
from adversarial import BrightBandRenderer  # noqa: E402

B = default_bearing()
G = B.geometry
CAM = Camera(width=640, height=400, px_per_mm=6.25, bit_depth=12)


def test_the_wedge_circle_of_seed_7218_is_refused():
    """The radii measured on 7218: the wedges' circle is refused, with the numbers in the message."""
    with pytest.raises(SelectionError, match=r"radius 84\.2 px.* 99\.5 px \(-0\.31 ball diameters"):
        check_radius("c07218.cine", 84.16, 99.45, 49.39)


@pytest.mark.parametrize("off", [-0.15, -0.017, 0.0, 0.017, 0.15])
def test_circles_within_the_tolerance_pass(off):
    """The largest offset a TUNING clip's selected circle showed is 0.017 ball diameters (seed 1017)."""
    assert PRIOR_RADIUS_TOL == 0.15
    check_radius("clip", 100.0 + off * 40.0, 100.0, 40.0)


@pytest.fixture(scope="module")
def clip(tmp_path_factory):
    d = tmp_path_factory.mktemp("radius")
    r = BrightBandRenderer(G, CAM, Appearance(highlight_peak=0.85), seed=11)
    return d, render_clip(d / "bright.cine", r, frames_for_revolutions(G, 3000, CAM.fps, 0.3),
                          law=KinematicLaw(G, 3000, seed=11), fmt="cine-16")


def test_the_right_scale_tracks(clip):
    d, c = clip
    res = track_video(c["video"], OperatingConditions(3000, 500, px_per_mm=CAM.px_per_mm), B, progress=False)
    r_pitch = 0.5 * G.pitch_diameter_m * 1e3 * CAM.px_per_mm
    assert res.trace.n_balls == 14
    assert abs(res.qc.selection["circle_radius_px"] - r_pitch) < 0.01 * G.ball_diameter_m * 1e3 * CAM.px_per_mm


def test_seed_7218_is_refused_without_a_trace(tmp_path):
    """End to end on the corpus clip: exit with the radius message, no trace, the selection QC image."""
    spec = corpus_clip(7218, os.environ.get("CAGELESS_CORPUS_CACHE") or tmp_path / "corpus")
    out = tmp_path / "out"
    with pytest.raises(SelectionError, match=r"radius 84\.\d px, but the pitch circle at the stated px_per_mm is "
                                             r"99\.5 px \(-0\.31 ball diameters") as exc:
        track_video(spec.video, spec.conditions, spec.bearing, out_dir=out, progress=False)
    assert "No trace written" in str(exc.value)
    assert not list(out.rglob("*.trace.h5"))
    assert (out / "qc" / f"{spec.video.stem}.selection.png").is_file()
