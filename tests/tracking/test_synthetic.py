"""The synthetic renderer: its ground truth agrees with its pixels, and its motion obeys the rules."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from cageless.errors import ParameterError
from cageless.kinematics import theoretical_cage_speed
from cageless.parameter_sets import wang2026
from cageless.units import rpm_to_rad_s
from cageless.tracking.io import open_video
from cageless.tracking.synthetic.camera import Appearance, Camera
from cageless.tracking.synthetic.clip import render_clip
from cageless.tracking.synthetic.motion import KinematicLaw, paper_slip_peak
from cageless.tracking.synthetic.render import Renderer

G = wang2026.geometry()
PHI_MIN = 2 * math.asin(G.ball_diameter_m / G.pitch_diameter_m)  # smallest centre angle between touching balls
CLEAN = Appearance(n_static_glints=0, n_turning_glints=0, n_ring_marks=0, flicker_amplitude=0.0,
                   highlight_peak=0.8, highlight_peak_spread=0.0)
QUIET = Camera(width=480, height=320, px_per_mm=5.0, bit_depth=16, read_noise_e=0.0, full_well_e=1e9)


@pytest.mark.parametrize("speed_rpm", [1800, 6000])
def test_kinematic_law_never_overlaps_or_passes(speed_rpm):
    m = KinematicLaw(G, speed_rpm, seed=4).sample(np.arange(600) / 10_000)
    gaps = np.diff(np.concatenate([m.angle, m.angle[:, :1] + 2 * np.pi], axis=1), axis=1)
    assert gaps.min() >= PHI_MIN - 1e-9  # centres never closer than one ball diameter (to 1e-9 rad = 23 pm)
    assert np.all(gaps > 0)  # the cyclic order never changes


def test_kinematic_law_slips_in_the_unloaded_zone():
    t = np.arange(3000) / 10_000
    m = KinematicLaw(G, 3000, seed=1).sample(t)
    omega_c = theoretical_cage_speed(G, rpm_to_rad_s(3000))
    slip = 1 - np.gradient(m.angle, t, axis=0) / omega_c
    unloaded = np.sin(m.angle) > 0
    assert slip[unloaded].mean() > 0.01 > 0 > slip[~unloaded].mean()
    # The speed jumps at contacts: some frame-to-frame speed changes far exceed the smooth drive.
    assert np.abs(np.diff(slip, axis=0)).max() > 0.02


def test_kinematic_law_is_seeded():
    t = np.arange(50) / 10_000
    a = KinematicLaw(G, 1800, seed=3).sample(t).angle
    np.testing.assert_array_equal(a, KinematicLaw(G, 1800, seed=3).sample(t).angle)
    assert not np.array_equal(a, KinematicLaw(G, 1800, seed=4).sample(t).angle)


def test_paper_slip_peak_interpolates_table_2():
    # Wang et al. 2026, Table 2, 500 N theoretical slip: 22.8 %, 6.7 %, 0.82 %.
    assert paper_slip_peak(1800) == pytest.approx(0.228)
    assert paper_slip_peak(3000) == pytest.approx(0.067)
    assert paper_slip_peak(6000) == pytest.approx(0.0082)
    assert 0.067 > paper_slip_peak(4000) > 0.0082


def _centroid(img: np.ndarray, u: float, v: float, half: int) -> tuple[float, float]:
    u0, v0 = int(round(u)), int(round(v))
    win = np.clip(img[v0 - half:v0 + half + 1, u0 - half:u0 + half + 1], 0, None)
    vv, uu = np.mgrid[v0 - half:v0 + half + 1, u0 - half:u0 + half + 1]
    return float((win * uu).sum() / win.sum()), float((win * vv).sum() / win.sum())


@pytest.mark.parametrize(("roll_deg", "offset", "direction"), [(0.0, (0.0, 0.0), 1), (7.0, (13.3, -9.6), 1),
                                                               (-4.0, (-5.0, 3.0), -1)])
def test_truth_matches_the_rendered_highlights(tmp_path, roll_deg, offset, direction):
    """Render a noiseless frame with and without highlights; the difference is the highlights alone,
    and its intensity-weighted centroid must sit on the ground-truth highlight position."""
    cam = replace(QUIET, roll_deg=roll_deg, centre_offset_px=offset)
    law = KinematicLaw(G, 3000, seed=2, direction=direction)
    lit = render_clip(tmp_path / "lit.cine", Renderer(G, cam, CLEAN, seed=2), 3, law=law, fmt="cine-16")
    dark = render_clip(tmp_path / "dark.cine", Renderer(G, cam, replace(CLEAN, highlight_peak=0.0), seed=2), 3,
                       law=law, fmt="cine-16")
    with open_video(lit["video"]) as a, open_video(dark["video"]) as b:
        diffs = [a[i].astype(np.float64) - b[i].astype(np.float64) for i in range(3)]
    truth = lit["truth"]
    rows = truth[truth.highlight_visible]
    sigma_px = CLEAN.highlight_sigma * G.ball_diameter_m * cam.px_per_m
    r = Renderer(G, cam, CLEAN, seed=2)
    cx, cy = cam.centre_px
    errors = []
    for row in rows.itertuples():
        rad = math.hypot(row.highlight_u_px - cx, row.highlight_v_px - cy) / cam.px_per_m
        margin = 4.5 * sigma_px / cam.px_per_m
        if not (r.radii.inner_land + margin < rad < r.radii.outer_land - margin):
            continue  # a ring land would clip this highlight
        u, v = _centroid(diffs[row.frame], row.highlight_u_px, row.highlight_v_px, int(4 * sigma_px))
        errors.append(math.hypot(u - row.highlight_u_px, v - row.highlight_v_px))
    assert len(errors) >= 8
    assert max(errors) < 0.002  # px: the truth is where the pixels put the highlight


def test_truth_is_consistent_with_the_camera_model(tmp_path):
    cam = replace(QUIET, roll_deg=12.0, centre_offset_px=(20.0, -11.0))
    res = render_clip(tmp_path / "c.cine", Renderer(G, cam, CLEAN, seed=1), 4,
                      law=KinematicLaw(G, 1800, seed=1), fmt="cine-16")
    t = res["truth"]
    cx, cy = cam.centre_px
    image_angle = np.arctan2(-(t.centre_v_px - cy), t.centre_u_px - cx)
    # DESIGN §3: bearing angle = image angle - camera roll.
    np.testing.assert_allclose(np.angle(np.exp(1j * (image_angle - math.radians(12.0) - t.angle_rad))), 0, atol=1e-9)
    np.testing.assert_allclose(np.hypot(t.centre_u_px - cx, t.centre_v_px - cy), t.radius_m * cam.px_per_m, rtol=1e-9)
    # The highlight offset is the same for every ball.
    du, dv = t.highlight_u_px - t.centre_u_px, t.highlight_v_px - t.centre_v_px
    assert du.std() < 1e-9 and dv.std() < 1e-9


def test_dropped_frames_show_in_time_stamps_and_truth(tmp_path):
    look = replace(CLEAN, dropped_frame_rate=0.2)
    res = render_clip(tmp_path / "d.cine", Renderer(G, QUIET, look, seed=5), 30,
                      law=KinematicLaw(G, 3000, seed=5), fmt="cine-p12" if QUIET.bit_depth == 12 else "cine-16")
    frames = res["truth"].frame.unique()
    assert 30 > len(frames) >= 15
    with open_video(res["video"]) as video:
        assert len(video) == len(frames)
        np.testing.assert_allclose(video.times, frames / QUIET.fps, atol=1e-9)


def test_noise_glints_and_saturation(tmp_path):
    cam = Camera(width=320, height=200, px_per_mm=3.125, bit_depth=12)
    look = Appearance(highlight_peak=1.6, n_hot_pixels=5, dropout_rate=0.05)
    res = render_clip(tmp_path / "n.cine", Renderer(G, cam, look, seed=9), 10, law=KinematicLaw(G, 1800, seed=9),
                      fmt="cine-p12")
    with open_video(res["video"]) as video:
        f = video[3]
    assert (f == cam.max_dn).sum() >= 5 + 10  # hot pixels plus flat-topped highlights
    assert not res["truth"].highlight_visible.all()  # some dropouts


def test_rendering_is_deterministic(tmp_path):
    def make(name):
        return render_clip(tmp_path / name, Renderer(G, QUIET, Appearance(dropout_rate=0.02), seed=8), 5,
                           law=KinematicLaw(G, 3000, seed=8), fmt="cine-16")["video"].read_bytes()
    assert make("a.cine") == make("b.cine")


def test_bad_render_arguments(tmp_path):
    with pytest.raises(ParameterError, match="camera.exposure_s"):
        Camera(fps=10_000, exposure_s=2e-4)
    with pytest.raises(ParameterError, match="exactly one"):
        render_clip(tmp_path / "x.cine", Renderer(G, QUIET), 5)
    with pytest.raises(ParameterError, match="8-bit"):
        render_clip(tmp_path / "x.mkv", Renderer(G, QUIET), 5, law=KinematicLaw(G, 3000), fmt="ffv1")
    with pytest.raises(ParameterError, match="speed_rpm"):
        KinematicLaw(G, 0.0)


def test_render_from_a_simulation_trace(tmp_path):
    """A simulation trace drives the renderer: the truth angles are the trace's, resampled."""
    from cageless.trace import SimulationInfo, Trace

    t = np.linspace(0, 2e-3, 41)
    base = np.pi / 2 + np.arange(14) * (PHI_MIN + 0.001)
    angle = base[None, :] + 120.0 * t[:, None] + 0.01 * np.sin(2000 * t)[:, None]
    sim = SimulationInfo(scene_json="{}", effects_json="{}", solver="test", rtol=1e-6, atol=1e-9, n_steps=1,
                         n_rhs=1, wall_s=0.0)
    trace = Trace(source="simulation", time=t, angle=angle, speed=np.gradient(angle, t, axis=0),
                  slip=np.zeros_like(angle), valid=np.ones_like(angle, bool), speed_rpm=3000.0, radial_load_n=500.0,
                  axial_load_n=0.0, ball_diameter_m=G.ball_diameter_m, pitch_diameter_m=G.pitch_diameter_m,
                  simulation=sim)
    res = render_clip(tmp_path / "s.cine", Renderer(G, QUIET, CLEAN, seed=1), 10, motion_source=trace, fmt="cine-16")
    truth = res["truth"]
    # Frame time t_i is read from the trace at t_i + exposure (the motion starts one exposure early).
    ball3 = truth[truth.ball == 3]
    t_motion = ball3.time_s.to_numpy() + QUIET.exposure_s
    np.testing.assert_allclose(ball3.angle_rad, np.interp(t_motion, t, angle[:, 3]), atol=1e-6)


def test_parallel_rendering_is_identical(tmp_path):
    def make(name, workers):
        look = Appearance(dropout_rate=0.05, dropped_frame_rate=0.1)
        return render_clip(tmp_path / name, Renderer(G, QUIET, look, seed=6), 40, law=KinematicLaw(G, 3000, seed=6),
                           fmt="cine-16", workers=workers)["video"].read_bytes()
    assert make("one.cine", 1) == make("two.cine", 2)


def test_full_preset_renders_the_papers_camera(tmp_path):
    from cageless.tracking.synthetic.lab import make_lab

    results = make_lab(tmp_path, preset="full", revolutions=0.005, progress=False)
    with open_video(results[0]["video"]) as video:
        assert video.frame_shape == (800, 1280) and video.metadata.bit_depth == 12
        assert video.metadata.storage == "16-bit words"
