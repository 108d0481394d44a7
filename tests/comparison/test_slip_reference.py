"""Slip referred to a trace's own loaded-zone speed (issue 16): a flat speed bias drops out, and the
table and the report say which reference a row used.

Reference values are closed forms: with orbit speeds w (1 - s(theta)) scaled by a flat factor k, the slip
against the cage speed w is 1 - k (1 - s), and against the loaded-zone speed k w (where s = 0) it is s.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from cageless.errors import CagelessError, ParameterError
from cageless.kinematics import loaded_zone_speed
from cageless.profiles import PEAK_SMOOTHING_DEG
from cageless.trace import Trace, write_trace
from cageless.comparison.compare import SLIP_REFERENCES, compare, refer_to_loaded_zone
from cageless.comparison.table import table_frame, to_csv, to_markdown

sys.path.insert(0, str(Path(__file__).parent))
from test_align_metrics import bump, orbit_trace  # noqa: E402

OMEGA = 120.0


def biased(trace: Trace, k: float) -> Trace:
    """The same motion seen with every orbit speed k times too large, its slip still against OMEGA."""
    speed = trace.speed * k
    return Trace(**{**trace.__dict__, "speed": speed, "slip": 1.0 - speed / OMEGA})


def test_loaded_zone_speed_is_the_median_within_45_deg_of_270():
    angle = np.radians([270.0, 300.0, 240.0, 316.0, 224.0, 90.0] * 4)
    speed = np.array([1.0, 2.0, 3.0, 50.0, 60.0, 70.0] * 4)
    # 316 and 224 deg lie 46 deg from 270: outside; the window holds 1, 2, 3 (x4) -> median 2
    assert loaded_zone_speed(angle, speed) == 2.0
    assert loaded_zone_speed(angle[:6], speed[:6]) is None  # 3 samples < 10
    valid = np.tile([True, True, False, True, True, True], 4)  # 8 samples left in the window: too few
    assert loaded_zone_speed(angle, speed, valid) is None
    assert loaded_zone_speed(np.tile(angle, 2), np.tile(speed, 2), np.tile(valid, 2)) == 1.5


def test_a_flat_speed_bias_drops_out_with_the_loaded_zone_reference():
    sim = orbit_trace("simulation", bump(0.06), omega=OMEGA)
    measured = biased(orbit_trace("video", bump(0.06), omega=OMEGA), 0.97)
    cage = compare(measured, sim, bin_deg=5.0, settle_s=0.0)
    # closed form: 1 - 0.97 (1 - s) against the cage speed, with s the simulation's peak; the peak is taken after
    # a Gaussian smoothing of sigma g, which lowers a Gaussian bump of width 25 deg by 25 / sqrt(25^2 + g^2)
    peak = 6.0 * 25.0 / np.hypot(25.0, PEAK_SMOOTHING_DEG)
    assert cage.row.experimental_slip_pct == pytest.approx(3.0 + 0.97 * peak, abs=0.2)
    assert cage.row.theoretical_slip_pct == pytest.approx(peak, abs=0.2)
    assert cage.row.mae_pp == pytest.approx(3.0, abs=0.3)  # 1 - 0.97 (1 - s) - s = 0.03 (1 - s)
    assert cage.row.slip_reference == "cage"
    lz = compare(measured, sim, bin_deg=5.0, settle_s=0.0, slip_reference="loaded-zone")
    assert lz.row.experimental_slip_pct == pytest.approx(peak, abs=0.2)
    assert lz.row.theoretical_slip_pct == pytest.approx(cage.row.theoretical_slip_pct, abs=0.05)
    assert lz.row.mae_pp < 0.1
    assert lz.row.slip_reference == "loaded-zone"
    assert "video slip referred to its loaded-zone speed 116.4 rad/s" in lz.row.message


def test_the_loaded_zone_reference_leaves_out_the_simulated_start_up():
    sim = orbit_trace("simulation", bump(0.06), omega=OMEGA)
    # the first 0.25 s of 0.4 s runs 10 % fast in the loaded zone: left out, it changes nothing
    fast = sim.speed.copy()
    fast[sim.time < 0.25] *= 1.1
    sim = Trace(**{**sim.__dict__, "speed": fast})
    settled, _ = refer_to_loaded_zone(sim, settle_s=0.25)
    assert settled.config["slip_reference_speed_rad_s"] == pytest.approx(OMEGA, rel=1e-9)
    unsettled, _ = refer_to_loaded_zone(sim)
    assert unsettled.config["slip_reference_speed_rad_s"] == pytest.approx(1.1 * OMEGA, rel=1e-9)


def test_no_loaded_zone_samples_is_a_clear_error_and_unknown_references_are_refused():
    short = orbit_trace("video", bump(0.06), omega=OMEGA, t_end=0.004)  # balls at 0..334 deg barely move
    keep_top = np.sin(short.angle) > 0
    short = Trace(**{**short.__dict__, "valid": keep_top})
    with pytest.raises(CagelessError, match="too few samples in the loaded zone"):
        refer_to_loaded_zone(short)
    sim = orbit_trace("simulation", bump(0.06), omega=OMEGA)
    with pytest.raises(ParameterError, match="slip_reference"):
        compare(sim, sim, slip_reference="outer")


def test_the_table_states_the_reference():
    sim = orbit_trace("simulation", bump(0.06), omega=OMEGA)
    measured = biased(orbit_trace("video", bump(0.06), omega=OMEGA), 0.97)
    rows = [compare(measured, sim, 5.0, 0.0, label="a").row,
            compare(measured, sim, 5.0, 0.0, label="b", slip_reference="loaded-zone").row]
    frame = table_frame(rows)
    assert "slip_reference" in to_csv(frame).splitlines()[0]
    assert list(frame.slip_reference) == ["cage", "loaded-zone"]
    md = to_markdown(frame)
    assert "Slip reference per row" in md and SLIP_REFERENCES["loaded-zone"] in md
    assert f"Slip reference: {SLIP_REFERENCES['cage']}." in to_markdown(table_frame(rows[:1]))


def test_compare_cli_takes_the_reference(tmp_path, capsys):
    from cageless.app.cli import main

    sim = orbit_trace("simulation", bump(0.06), omega=OMEGA)
    measured = biased(orbit_trace("video", bump(0.06), omega=OMEGA), 0.97)
    write_trace(tmp_path / "m.trace.h5", measured)
    write_trace(tmp_path / "s.trace.h5", sim)
    args = ["compare", str(tmp_path / "m.trace.h5"), str(tmp_path / "s.trace.h5"), "--bin-deg", "5", "--settle", "0"]
    assert main(args + ["--slip-reference", "loaded-zone"]) == 0
    out = capsys.readouterr().out
    assert "own loaded-zone speed" in out and "video slip referred to its loaded-zone speed 116.4 rad/s" in out
    theoretical, experimental = _row(out)[3:5]
    # the peak is taken after a Gaussian smoothing of sigma s: a 6 % bump of width 25 deg peaks at
    # 6 * 25 / sqrt(25^2 + s^2) (5.57 % for s = 10 deg); against the cage speed the 3 % scale bias makes it
    # 1 - 0.97 (1 - slip): 3 + 0.97 * 5.57 = 8.40 %
    shrink = 25.0 / np.hypot(25.0, PEAK_SMOOTHING_DEG)
    assert theoretical == pytest.approx(6.0 * shrink, abs=0.1) and experimental == pytest.approx(theoretical, abs=0.02)
    assert main(args) == 0
    out = capsys.readouterr().out
    assert _row(out)[4] == pytest.approx(3.0 + 0.97 * 6.0 * shrink, abs=0.2)
    assert "pure-rolling cage speed of the stated" in out


def _row(markdown: str) -> list[float]:
    line = markdown.splitlines()[2]
    assert markdown.startswith("| Video |")  # compare labels its row with the video trace's file name
    return [float(c.split("±")[0]) for c in line.strip("|").split("|")[1:]]  # "5.54 ± 0.00": the value


def test_a_video_that_failed_its_tracking_qc_is_flagged_in_every_table():
    """The report's card said "tracking QC: fail" while slip_table.csv said ok and the Markdown, LaTeX and HTML
    tables showed nothing (found by a new user on a noisy clip). The row keeps its numbers and says why."""
    from dataclasses import replace

    from cageless.comparison.compare import QC_FAILED
    from cageless.comparison.table import to_html

    sim = orbit_trace("simulation", bump(0.06), omega=OMEGA)
    video = orbit_trace("video", bump(0.06), omega=OMEGA)
    z = video.angle.shape[1]
    good = {"n_balls_found": z, "n_balls_expected": z, "warnings": []}
    low = "low precision: estimated angle precision 2.48 mrad"
    assert compare(replace(video, qc=good), sim, bin_deg=5.0, settle_s=0.0).row.status == "ok"
    row = compare(replace(video, qc={**good, "warnings": [low]}), sim, bin_deg=5.0, settle_s=0.0, label="noisy").row
    assert (row.status, row.message) == (QC_FAILED, f"tracker warning: {low}")
    assert row.experimental_slip_pct == pytest.approx(compare(video, sim, bin_deg=5.0, settle_s=0.0).row
                                                      .experimental_slip_pct)  # the numbers stand
    frame = table_frame([row])
    assert frame.loc[0, "status"] == QC_FAILED and low in to_csv(frame)
    assert f"Note: noisy (3000 r/min, 500 N): {QC_FAILED}: tracker warning: {low}" in to_markdown(frame)
    assert '<tr class="tracking-QC-failed">' in to_html(frame)
