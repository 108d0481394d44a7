"""Bad input to tracking: each case gets a clear message, and no partial trace file is left behind."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import cv2
import numpy as np
import pandas as pd
import pytest

from cageless.bearing import default_bearing
from cageless.app.cli import main
from cageless.conditions import OperatingConditions
from cageless.errors import TrackingError, VideoError
from cageless.tracking.qc import _frame_image
from cageless.trace import read_trace
from cageless.tracking.io import write_cine
from cageless.tracking.pipeline import TrackOptions, track_video
from cageless.tracking.synthetic.camera import Appearance, Camera
from cageless.tracking.synthetic.clip import render_clip
from cageless.tracking.synthetic.motion import KinematicLaw
from cageless.tracking.synthetic.render import Renderer

B = default_bearing()
SMALL = Camera(width=320, height=200, px_per_mm=3.125, bit_depth=8)
COND = OperatingConditions(3000.0, 500.0)


def _clip(path: Path, n: int = 40, geometry=None, fmt: str = "cine-8") -> Path:
    g = geometry or B.geometry
    return render_clip(path, Renderer(g, SMALL, Appearance(), seed=7), n, law=KinematicLaw(g, 3000, seed=7),
                       fmt=fmt)["video"]


def test_no_bearing_in_view(tmp_path):
    rng = np.random.default_rng(0)
    noise = rng.integers(0, 40, size=(30, 200, 320), dtype=np.uint8)
    video = write_cine(tmp_path / "empty_bench.cine", noise, fps=10000, fmt="8")
    with pytest.raises(TrackingError, match="empty_bench.cine: .*no bearing in view") as err:
        track_video(video, COND, B, out_dir=tmp_path / "out", progress=False)
    assert not list((tmp_path).rglob("*.trace.h5"))
    # the refusal shows what the tracker saw: the first frame with the reason, named in the message
    png = tmp_path / "out" / "qc" / "empty_bench.refused.png"
    assert f"No trace written; QC: {png}." in str(err.value)
    image = cv2.imread(str(png))
    assert image.shape[:2] == (200 * 3, 320 * 3)  # enlarged by the whole factor ceil(700 / 320) = 3
    plain, _ = _frame_image(noise[0])
    assert (image != plain)[:60].any() and not (image != plain)[120:].any()  # the reason at the top, on the frame


@pytest.mark.parametrize(("level", "name"), [(0, "dark"), (255, "saturated")])
def test_all_dark_and_all_saturated(tmp_path, level, name):
    video = write_cine(tmp_path / f"{name}.cine", np.full((30, 200, 320), level, np.uint8), fps=10000, fmt="8")
    with pytest.raises(TrackingError, match=f"{name}.cine: the frames have no contrast"):
        track_video(video, COND, B, out_dir=tmp_path / "out", progress=False)
    assert not (tmp_path / "out").exists() or not list((tmp_path / "out").rglob("*.trace.h5"))


def test_too_short_for_a_speed(tmp_path):
    video = _clip(tmp_path / "short.cine", n=10)
    with pytest.raises(TrackingError, match="short.cine: has 10 frames, fewer than the speed window of 21"):
        track_video(video, COND, B, out_dir=tmp_path / "out", progress=False)


def test_wrong_ball_count_is_an_error_with_qc_and_no_trace(tmp_path, capsys):
    """13 balls where the bearing has 14: exit 1, no trace, a QC image and the candidate table with reasons;
    --n-balls 13 tracks them."""
    g13 = dataclasses.replace(B.geometry, n_balls=13)
    video = _clip(tmp_path / "thirteen.cine", n=30, geometry=g13)
    with pytest.raises(TrackingError, match=r"thirteen.cine: found 13 balls .* but 14 are expected \(the "
                                            r"bearing's ball count, or --n-balls\)\. No trace written"):
        track_video(video, COND, B, out_dir=tmp_path / "out", progress=False)
    assert not list(tmp_path.rglob("*.trace.h5"))
    assert (tmp_path / "out" / "qc" / "thirteen.selection.png").is_file()
    table = pd.read_csv(tmp_path / "out" / "qc" / "thirteen.candidates.csv")
    assert set(table.status) <= {"selected", "rejected"} and table.reason.notna().sum() > 0
    assert main(["track", str(video), "-o", str(tmp_path / "cli"), "-q", "--speed-rpm", "3000"]) == 1
    text = capsys.readouterr().err
    assert f"FAILED {video}: found 13 balls" in text and "--n-balls 13" in text  # a single video: as typed
    assert not list((tmp_path / "cli").glob("*.trace.h5"))
    assert main(["track", str(video), "-o", str(tmp_path / "cli"), "-q", "--speed-rpm", "3000", "--n-balls", "13"]) == 0
    assert read_trace(tmp_path / "cli" / "thirteen.trace.h5").n_balls == 13


def test_frames_of_varying_size(tmp_path):
    seq = _clip(tmp_path / "seq", n=30, fmt="png")
    frames = sorted(seq.glob("*.png"))
    import cv2

    cv2.imwrite(str(frames[12]), np.zeros((100, 100), np.uint8))
    with pytest.raises(VideoError, match=r"frame_000012.png: is \(100, 100\) uint8, unlike the first image"):
        track_video(seq, dataclasses.replace(COND, fps=10000.0), B, out_dir=tmp_path / "out", progress=False)
    assert not list(tmp_path.rglob("*.trace.h5"))


def test_cli_folder_one_bad_video_does_not_stop_the_rest(tmp_path, capsys):
    lab = tmp_path / "lab"
    lab.mkdir()
    _clip(lab / "n3000_Fr500.cine", n=30)
    (lab / "n1800_Fr500.cine").write_bytes(b"CI" + b"\0" * 30)  # truncated header
    (lab / "mystery.cine").write_bytes(b"\0")  # no conditions anywhere
    out = tmp_path / "out"
    assert main(["track", str(lab), "-o", str(out), "-q", "--workers", "1"]) == 1
    cap = capsys.readouterr()
    assert "ok     n3000_Fr500.cine: 30 frames, 14 balls" in cap.out
    precision = read_trace(out / "n3000_Fr500.trace.h5").qc["precision"]["angle_rms_mrad"]
    assert f", angle precision {precision:.2f} mrad -> " in cap.out  # the trace's own estimate, on its line
    assert "FAILED n1800_Fr500.cine" in cap.err and "too short" in cap.err
    assert "FAILED" in cap.err and "mystery.cine: no operating conditions found" in cap.err
    assert "`--speed-rpm` gives its speed" in cap.err  # the missing-conditions line says how to give them here
    assert [p.name for p in out.glob("*.trace.h5")] == ["n3000_Fr500.trace.h5"]
    tr = read_trace(out / "n3000_Fr500.trace.h5")
    assert tr.source == "video" and tr.speed_rpm == 3000 and tr.qc["n_balls_found"] == 14
    assert (out / "qc" / "n3000_Fr500.qc.json").is_file() and list((out / "qc").glob("n3000_Fr500.frame*.png"))
    import pandas as pd
    from cageless.profiles import angle_profile

    profile = pd.read_csv(out / "qc" / "n3000_Fr500.slip_profile.csv")  # units in the column names
    assert list(profile.columns) == ["angle_deg", "slip_mean_pct", "slip_std_pct", "count"]
    fraction = angle_profile(tr.angle, tr.slip, 1.0, tr.valid)["mean"].to_numpy()
    assert np.allclose(profile.slip_mean_pct, 100.0 * fraction, rtol=1e-5, atol=1e-9, equal_nan=True)
    assert profile["count"].sum() == int(np.sum(np.asarray(tr.valid) & np.isfinite(tr.slip)))


def test_cli_sample_lab_in_parallel(tmp_path, capsys):
    lab = Path(__file__).resolve().parents[2] / "sample_data" / "lab"
    out = tmp_path / "out"
    assert main(["track", str(lab), "-o", str(out), "-q", "--workers", "2"]) == 0
    assert sorted(p.name for p in out.glob("*.trace.h5")) == [
        "clip_3000rpm.trace.h5", "n6000_Fr500_Fa0.trace.h5", "run_1800.trace.h5"]
    tr = read_trace(out / "run_1800.trace.h5")
    assert tr.video.camera_roll_rad == pytest.approx(np.radians(2.0))
    assert tr.video.input_hash_algorithm == "xxh3_128" and tr.video.input_sha256 == ""
    assert tr.provenance["inputs"][0]["xxh3_128"] == tr.video.input_hash
    assert len(tr.video.input_hash) == 32  # 128 bits


def test_cli_speed_for_a_bare_video(tmp_path, capsys):
    video = _clip(tmp_path / "bare.cine", n=30)
    assert main(["track", str(video), "-o", str(tmp_path / "o"), "-q"]) == 1
    assert "no operating conditions found" in capsys.readouterr().err
    assert main(["track", str(video), "-o", str(tmp_path / "o"), "-q", "--speed-rpm", "3000"]) == 0
    assert main(["track", str(video), "-o", str(tmp_path / "o"), "--window", "4"]) == 2


def test_tracking_is_deterministic(tmp_path):
    """The same video and settings give the same trace (timestamps aside)."""
    video = _clip(tmp_path / "det.cine", n=30)
    a = track_video(video, COND, B, progress=False).trace
    b = track_video(video, COND, B, progress=False).trace
    for name in ("time", "angle", "speed", "slip", "valid"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    assert a.video == b.video and a.config == b.config


@pytest.mark.parametrize("command", ["track", "report"])
def test_a_ball_count_that_cannot_fit_is_refused_before_any_work(tmp_path, capsys, command):
    """--n-balls above what fits on the pitch circle was accepted on the command line (a new user's --n-balls 30)
    while the same count in --config was refused. The default bearing: D = 9.525 mm on d_m = 46.01 mm, so
    floor(pi / asin(D / d_m)) = 15 fit (the chord d_m sin(pi / Z) >= D)."""
    video = Path(__file__).parents[2] / "sample_data" / "lab" / "n6000_Fr500_Fa0.cine"
    assert main([command, str(video if command == "track" else video.parent), "-o", str(tmp_path / "out"),
                 "--n-balls", "16"]) == 2
    assert "--n-balls 16: at most 15 balls of 9.525 mm fit on the bearing's 46.01 mm pitch circle" in \
        capsys.readouterr().err
    assert not (tmp_path / "out").exists()


def test_a_truncated_cine_tracked_anyway_says_so_in_its_qc(tmp_path):
    """--allow-truncated tracks the complete frames of a cut-off cine; its QC said "warnings": [] and the report
    "warnings none" (new user). The sample's 84-frame 6000 rpm cine cut 1,000 bytes short: 83 complete frames."""
    video = Path(__file__).parents[2] / "sample_data" / "lab" / "n6000_Fr500_Fa0.cine"
    cut = tmp_path / "n6000_Fr500_Fa0.cine"
    cut.write_bytes(video.read_bytes()[:-1000])
    res = track_video(cut, OperatingConditions(6000, 500), default_bearing(), out_dir=tmp_path / "out", progress=False,
                      options=dataclasses.replace(TrackOptions(), allow_truncated=True))
    assert res.trace.n_samples == 83
    assert "truncated file: 83 of 84 frames are complete" in res.qc.warnings
