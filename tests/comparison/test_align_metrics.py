"""Alignment (a known phase shift is recovered exactly), the metrics on hand-computed cases, and the table."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from cageless import __version__
from cageless.errors import CagelessError, ParameterError
from cageless.trace import SimulationInfo, Trace, VideoInfo
from cageless.comparison.align import MismatchError, align_time, check_compatible, profiles
from cageless.comparison.compare import ComparisonRow, compare
from cageless.comparison.metrics import profile_errors, unloaded_peak
from cageless.comparison.table import table_frame, to_csv, to_html, to_latex, to_markdown, write_tables
from cageless.profiles import PEAK_SMOOTHING_DEG

VIDEO = VideoInfo(fps=10000.0, px_per_mm=12.5, centre_px=(640.0, 400.0), camera_roll_rad=0.0,
                  input_file="x.cine", input_sha256="ab" * 32)
SIM = SimulationInfo(scene_json="{}", effects_json="{}", solver="dp5", rtol=1e-6, atol=1e-9, n_steps=1, n_rhs=1,
                     wall_s=0.1)


def orbit_trace(source: str, slip_of_angle, t_end: float = 0.4, dt: float = 1e-4, z: int = 14, omega: float = 120.0,
                speed_rpm: float = 3000.0, **kw) -> Trace:
    """Balls evenly spaced, each at omega (1 - slip(angle)); slip given as a function of the angle in degrees."""
    t = np.arange(0, t_end, dt)
    theta0 = np.arange(z) * 2 * np.pi / z
    angle = np.empty((len(t), z))
    angle[0] = theta0
    for i in range(1, len(t)):
        s = slip_of_angle(np.degrees(angle[i - 1]) % 360)
        angle[i] = angle[i - 1] + omega * (1 - s) * dt
    deg = np.degrees(angle) % 360
    slip = slip_of_angle(deg)
    return Trace(source=source, time=t, angle=angle, speed=omega * (1 - slip), slip=slip,
                 valid=np.ones_like(angle, dtype=bool), speed_rpm=speed_rpm, radial_load_n=500.0, axial_load_n=0.0,
                 ball_diameter_m=9.525e-3, pitch_diameter_m=46.005e-3, config={},
                 video=VIDEO if source == "video" else None, simulation=SIM if source == "simulation" else None, **kw)


def bump(peak: float, centre: float = 90.0):
    return lambda deg: peak * np.exp(-0.5 * ((deg - centre) / 25.0) ** 2)


def test_metrics_on_hand_computed_profiles():
    # differences 0.01, -0.02, 0.03 (fractions) -> 1, 2, 3 pp: MAE 2, RMSE sqrt(14/3), max 3
    e = profile_errors([0.10, 0.20, 0.30, np.nan], [0.09, 0.22, 0.27, 0.5])
    assert e.mae_pp == pytest.approx(2.0) and e.rmse_pp == pytest.approx(np.sqrt(14 / 3)) and e.max_pp == pytest.approx(3.0)
    assert e.n_points == 3
    with pytest.raises(CagelessError, match="share no angle bin"):
        profile_errors([np.nan], [0.1])
    prof = pd.DataFrame({"angle_deg": [45.0, 135.0, 225.0, 315.0], "mean": [0.1, 0.3, 0.9, np.nan]})
    assert unloaded_peak(prof) == 0.3  # 225 deg lies in the loaded half


def test_profiles_recover_the_slip_law():
    tr = orbit_trace("video", bump(0.06))
    p = profiles(tr, bin_deg=5.0)
    centres = p.slip["angle_deg"].to_numpy()
    np.testing.assert_allclose(p.slip["mean"], bump(0.06)(centres), atol=2e-3)
    assert unloaded_peak(p.slip, sigma_deg=0.0) == pytest.approx(0.06, abs=2e-3)
    # the headline peak is taken after a periodic Gaussian smoothing of sigma s: a Gaussian bump of width w keeps
    # its area and widens to sqrt(w^2 + s^2), so its peak falls by w / sqrt(w^2 + s^2)
    assert unloaded_peak(p.slip) == pytest.approx(0.06 * 25.0 / np.hypot(25.0, PEAK_SMOOTHING_DEG), abs=2e-3)
    assert p.slip_per_ball.shape == (72, 14)


def test_time_alignment_recovers_a_known_shift_exactly():
    sim = orbit_trace("simulation", bump(0.06), t_end=0.3)
    shift_samples = 37
    measured = orbit_trace("video", bump(0.06), t_end=0.3)
    # the "measurement" starts 3.7 ms later in the same motion: its samples are the simulation's, shifted
    measured = Trace(**{**measured.__dict__, "time": sim.time[: -shift_samples] + 0.0,
                        "angle": sim.angle[shift_samples:], "speed": sim.speed[shift_samples:],
                        "slip": sim.slip[shift_samples:], "valid": sim.valid[shift_samples:]})
    res = align_time(measured, sim, ball=3)
    assert res.lag_s == pytest.approx(shift_samples * 1e-4, abs=1e-9)
    assert res.correlation > 0.99


def test_mismatched_traces_are_refused_unless_forced():
    a = orbit_trace("video", bump(0.06), t_end=0.1)
    b = orbit_trace("simulation", bump(0.04), t_end=0.2, speed_rpm=1800.0)
    assert check_compatible(a, b) == ["speed_rpm: measured 3000 rpm, simulated 1800 rpm"]
    with pytest.raises(MismatchError, match="--force"):
        compare(a, b)
    with pytest.raises(MismatchError, match=r"force=True in Python"):  # compare() is also called from Python
        compare(a, b)
    c = compare(a, b, settle_s=0.0, force=True)
    assert c.row.status == "mismatch" and "speed_rpm" in c.row.message


def test_swapped_traces_are_named_as_swapped():
    """compare(simulation, video) says the arguments are swapped; before, it failed with advice to simulate longer
    ("no valid samples after the first ... s of the video trace"), as the simulation's start-up was cut from the
    video. The command line swaps them back with a warning (cageless/app/cli/compare.py)."""
    video = orbit_trace("video", bump(0.06), t_end=0.1)
    sim = orbit_trace("simulation", bump(0.06), t_end=0.2)
    with pytest.raises(ParameterError, match=r"Swap them: compare\(video_trace, simulation_trace\)") as err:
        compare(sim, video)
    assert err.value.parameter == "measured"


def test_compare_row_and_table_formats(tmp_path):
    measured = orbit_trace("video", bump(0.06), t_end=0.4)
    simulated = orbit_trace("simulation", bump(0.04), t_end=0.45)
    c = compare(measured, simulated, settle_s=0.05, label="n3000")
    # the peak is taken after a periodic Gaussian smoothing of sigma s: a Gaussian bump of width w keeps its
    # area and widens to sqrt(w^2 + s^2), so its peak falls by w / sqrt(w^2 + s^2) (6 % -> 5.57 %, 4 % -> 3.71 %
    # for s = 10 deg)
    shrink = 25.0 / np.hypot(25.0, PEAK_SMOOTHING_DEG)
    assert c.row.experimental_slip_pct == pytest.approx(6.0 * shrink, abs=0.02)
    assert c.row.theoretical_slip_pct == pytest.approx(4.0 * shrink, abs=0.02)
    assert c.row.max_error_pp == pytest.approx(2.0, abs=0.1)
    failed = ComparisonRow(1800, 500, 0, float("nan"), float("nan"), float("nan"), float("nan"), float("nan"),
                           label="run_1800", status="failed", message="video unreadable")
    frame = table_frame([c.row, failed])
    assert list(frame.speed_rpm) == [1800, 3000]
    md = to_markdown(frame)
    # every ball of these traces has the same profile: the balls' standard error of each peak is 0
    assert f"| 3000 | 500 | 0 | {4.0 * shrink:.2f} ± 0.00 | {6.0 * shrink:.2f} ± 0.00 |" in md
    assert "standard error from the balls" in md and r"$\pm$" in to_latex(frame)
    assert "run_1800" in md and "peak of the mean slip" in md
    assert r"\toprule" in to_latex(frame) and "<table" in to_html(frame) and "failed" in to_html(frame)
    assert "theoretical_slip_pct" in to_csv(frame).splitlines()[0]
    assert md.splitlines()[0].startswith("| Video | Speed (r/min) |") and "| n3000 | 3000 | 500 |" in md
    unread = ComparisonRow(float("nan"), float("nan"), float("nan"), *[float("nan")] * 5, label="broken.cine",
                           status="failed", message="no such file")
    md = to_markdown(table_frame([c.row, unread]))
    assert "| broken.cine |  |  |  | failed |" in md and "nan" not in md  # an unknown condition is blank
    assert "Note: broken.cine: failed: no such file" in md
    unlabelled = to_markdown(table_frame([compare(measured, simulated, settle_s=0.05).row]))
    assert unlabelled.startswith("| Speed (r/min) |")  # a single comparison without a label has no video column
    paths = write_tables([c.row, failed], tmp_path / "slip_table")
    assert sorted(paths) == ["csv", "html", "md", "tex"] and all(p.exists() for p in paths.values())
    # provenance, as the traces have it: the version that wrote the table, a column pandas reads back
    back = pd.read_csv(paths["csv"])
    assert list(back.software_version) == [__version__] * 2 and back.columns[-1] == "software_version"
    assert list(back.speed_rpm) == [1800, 3000]


def test_figures_restore_rcparams_and_close(tmp_path):
    import matplotlib
    import matplotlib.pyplot as plt

    from cageless.comparison.report import describe_condition, figures

    measured = orbit_trace("video", bump(0.06), t_end=0.2)
    simulated = orbit_trace("simulation", bump(0.04), t_end=0.25)
    d = describe_condition("x", compare(measured, simulated, settle_s=0.05), measured, simulated)
    before = dict(matplotlib.rcParams)
    n_open = len(plt.get_fignums())
    svgs = [f(d) for f in (figures.speed_figure, figures.slip_figure, figures.contact_polar_figure,
                           figures.ring_figure)]
    assert all(s.startswith("<svg") for s in svgs)
    assert len(plt.get_fignums()) == n_open
    assert dict(matplotlib.rcParams) == before


def test_contact_polar_radius_is_logarithmic_when_forces_span_decades():
    """A new user found light rubbing piled up at the centre of the ball-ball polar plot: over a decade of peak
    forces the radius is logarithmic from the lightest contact, showing three decades at most (lighter contacts
    on the inner circle); within a decade it stays linear."""
    from comparison.report.figures import POLAR_DECADES, _log_floor

    assert POLAR_DECADES == 3.0
    assert _log_floor(np.array([0.2, 3.0, 150.0, 0.0, np.nan])) == pytest.approx(0.2)
    assert _log_floor(np.array([1e-7, 3.0, 150.0])) == pytest.approx(0.15)  # 150 N / 10^3
    assert _log_floor(np.array([20.0, 35.0, 150.0])) is None
    assert _log_floor(np.array([5.0])) is None


def test_measured_slip_is_referred_to_the_models_contact_angle():
    """Same orbital speeds, different contact angle: the measured slip is re-referred to the simulation's
    alpha. Reference: omega_c = omega_i (1 - D cos(alpha) / d_m) / 2 (Harris & Kotzalas, *Essential Concepts
    of Bearing Technology*, 5th ed., sect. 8.2), via cageless.kinematics.theoretical_cage_speed."""
    from cageless.bearing import default_bearing
    from cageless.kinematics import theoretical_cage_speed

    g = default_bearing().geometry
    alpha = np.radians(10.7)
    omega_i = 3000 * np.pi / 30
    c0, ca = theoretical_cage_speed(g, omega_i), theoretical_cage_speed(g, omega_i, alpha)
    assert np.allclose((g.ball_diameter_m, g.pitch_diameter_m), (9.525e-3, 46.005e-3))  # orbit_trace geometry
    measured = orbit_trace("video", bump(0.03), omega=c0)
    measured.config["slip_contact_angle_rad"] = 0.0
    simulated = orbit_trace("simulation", bump(0.03), omega=c0, t_end=0.45)
    simulated.config["nominal_contact_angle_rad"] = float(alpha)
    simulated.slip[:] = 1 - simulated.speed / ca  # the model's own reference
    c = compare(measured, simulated, settle_s=0.05)
    assert 100 * (ca / c0 - 1) == pytest.approx(0.46, abs=0.02)  # the cage runs 0.46 % faster at 10.7 deg
    assert c.row.mae_pp < 0.01  # same speeds, same reference: no spurious offset
    assert "contact angle 10.70 deg" in c.row.message and c.row.status == "ok"
    plain = compare(measured, orbit_trace("simulation", bump(0.03), omega=c0, t_end=0.45), settle_s=0.05)
    assert plain.row.message == "" and plain.row.mae_pp < 0.01


@pytest.mark.parametrize("size", [(5.6, 3.4), (3.4, 2.7), (3.4, 3.4)], ids=["full", "card-before", "card"])
def test_slip_figure_legend_fits_inside_the_figure(monkeypatch, size):
    """newuser2's trial: in the report's summary cards (the 3.4 in wide slip figure) the two-column legend was
    wider than the figure, so its labels were cut on both sides ("asured: mean ± 1 std of samples"). Every
    legend must lie inside the figure it is drawn in."""
    import matplotlib.pyplot as plt

    from cageless.comparison.report import describe_condition, figures

    measured = orbit_trace("video", bump(0.06), t_end=0.2)
    simulated = orbit_trace("simulation", bump(0.04), t_end=0.25)
    d = describe_condition("x", compare(measured, simulated, settle_s=0.05), measured, simulated)
    drawn = []
    close = plt.close
    monkeypatch.setattr(plt, "close", lambda fig=None: (drawn.append(fig), close(fig)))
    figures.slip_figure(d, size=size)
    fig = drawn[-1]
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    FigureCanvasAgg(fig).draw()  # plt.close detached the canvas; lay the figure out again as saved
    renderer = fig.canvas.get_renderer()
    box = fig.bbox
    assert fig.legends
    for legend in fig.legends:
        ext = legend.get_window_extent(renderer)
        assert ext.x0 >= box.x0 - 0.5 and ext.x1 <= box.x1 + 0.5, (ext, box)
        assert ext.y0 >= box.y0 - 0.5 and ext.y1 <= box.y1 + 0.5, (ext, box)
