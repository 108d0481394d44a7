"""The contact trajectory of spatial traces (the paper's figure 13): trace field, description and figure.

The contact point lies on the raceway, so it lies on the ball's surface less the Hertz overlap
delta = (Q / K)^(2/3) (Harris & Kotzalas, *Essential Concepts*, 5th ed., sect. 6.4): its distance from
the ball centre is D/2 - delta, and the line from the ball centre to it makes the reported contact angle
with the radial plane.
"""

from __future__ import annotations

import numpy as np
import pytest

from cageless.conditions import OperatingConditions
from cageless.comparison.report.describe import contact_track
from cageless.simulation.effects import choose_model
from cageless.simulation.models.spatial_geometry import ring_rotations
from cageless.simulation.run import simulate
from cageless.simulation.scene import Scene


@pytest.fixture(scope="module")
def spatial():
    scene = Scene(conditions=OperatingConditions(3000.0, 500.0, 400.0), duration_s=0.01)
    return simulate(scene, choose_model(scene), progress=False)


def test_contact_points_lie_on_the_ball_surface_at_the_contact_angle(spatial):
    tr, pr = spatial.trace, spatial.problem
    d = pr.parameter("D")
    c, balls = tr.groups["contacts"], tr.groups["balls"]
    centre = np.stack([balls["axial"], balls["radius"] * np.cos(tr.angle), balls["radius"] * np.sin(tr.angle)], -1)
    for race, stiffness in (("inner", pr.parameter("KI")), ("outer", pr.parameter("KO"))):
        arm = c[f"{race}_point"] - centre
        loaded = c[f"{race}_normal"] > 1.0
        assert loaded.mean() > 0.3  # the axial load presses many balls on both races
        overlap = (c[f"{race}_normal"] / stiffness) ** (2 / 3)
        length = np.linalg.norm(arm, axis=-1)
        assert np.allclose(length[loaded], 0.5 * d - overlap[loaded], atol=1e-8)
        if race == "inner":  # the angle is in the race's frame, which tilts with the inner ring
            arm = np.einsum("tzi,tij->tzj", arm, ring_rotations(pr, spatial.solution.y))
        radial = np.hypot(arm[..., 1], arm[..., 2])
        angle = np.arctan2(arm[..., 0], radial)  # the arm points along the normal, away from the groove centre
        assert np.allclose(angle[loaded], c[f"{race}_angle"][loaded], atol=1e-6)
        assert np.degrees(np.median(np.abs(c[f"{race}_angle"][loaded]))) > 5  # a real contact angle


def test_contact_track_is_described_and_drawn(spatial):
    from cageless.comparison.report.describe import ConditionDescription
    from cageless.comparison.report.figures import contact_track_figure

    track = contact_track(spatial.trace, 0.005, max_points=500)
    assert track is not None and len(track["orbital_angle"]) <= 500
    assert track["inner_point"].shape == (len(track["orbital_angle"]), 3)
    assert np.all((track["orbital_angle"] >= 0) & (track["orbital_angle"] < 2 * np.pi))
    svg = contact_track_figure(ConditionDescription(label="x", row=None, contact_track=track))  # type: ignore[arg-type]
    assert svg.startswith("<svg") and "contact angle" in svg


def test_planar_traces_have_no_contact_track():
    scene = Scene(conditions=OperatingConditions(3000.0, 500.0), duration_s=0.002)
    tr = simulate(scene, choose_model(scene), progress=False).trace
    assert "inner_point" not in tr.groups["contacts"] and contact_track(tr, 0.0) is None


def test_the_report_of_a_spatial_condition_shows_the_contact_trajectory(spatial, tmp_path):
    """A combined-load condition through compare -> describe -> structure -> HTML: the contact-trajectory
    figure is in the self-contained report, and the row says the measured slip was referred to the model's
    contact angle."""
    from dataclasses import replace

    from cageless.trace import VideoInfo
    from cageless.comparison.compare import compare
    from cageless.comparison.report.describe import describe_condition
    from cageless.comparison.report.render import write_report
    from cageless.comparison.report.structure import build_report

    sim = spatial.trace
    video = replace(sim, source="video", simulation=None, groups={}, events=None, config={"slip_contact_angle_rad": 0.0},
                    video=VideoInfo(fps=10000.0, px_per_mm=12.5, centre_px=(640.0, 400.0), camera_roll_rad=0.0,
                                    input_file="combined.cine", input_sha256="ab" * 32))
    c = compare(video, sim, settle_s=0.005)
    assert "contact angle" in c.row.message and c.row.status == "ok"
    html = write_report(build_report([describe_condition("combined", c, video, sim)]), tmp_path / "r.html").read_text()
    assert "Contact trajectory on the raceways" in html and html.count("data:image/svg+xml;base64,") >= 5
