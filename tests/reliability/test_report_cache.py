"""The catalogue's rows about the report cache and its re-runs (issue 17).

Each test copies a finished report of a one-video lab and re-runs on the copy, in-process (the jobs run
in a thread), so a case costs the verification, at most one redone job, and the report writing.
"""

from __future__ import annotations

import json
import shutil

import pandas as pd
from faultlib import QUICK_REPORT, assert_clean, cli, flip_bits, parts

from cageless.app.lab import CACHE_NAME


def _copy(report_template, tmp_path, name="report"):
    out = tmp_path / name
    shutil.copytree(report_template, out)
    return out


def _skipped(text: str) -> int:
    return int(text.split("; ")[-1].split(" jobs unchanged")[0])


def test_r10_cache_paths_are_relative_to_the_output_folder(report_template, tmp_path, capsys, mini_lab,
                                                           in_process_pool):
    cache = json.loads((report_template / CACHE_NAME).read_text())
    paths = [job["path"] for job in cache["jobs"].values()]
    assert sorted(paths) == ["simulations/n3000_Fr500_Fa0.sim.trace.h5", "traces/clip_3000rpm.trace.h5"]
    # a copied (renamed) report folder reads its own files: damage the original's, the copy still skips
    out = _copy(report_template, tmp_path, "renamed")
    run = cli(capsys, "report", mini_lab, "-o", out, *QUICK_REPORT)
    assert_clean(run, 0, f"{out}/report.html")
    assert _skipped(run.out) == 2
    assert str(report_template) not in (out / CACHE_NAME).read_text()


def test_r11_deleted_qc_outputs_are_restored(report_template, tmp_path, capsys, mini_lab, in_process_pool):
    out = _copy(report_template, tmp_path)
    qc = out / "traces" / "qc"
    removed = sorted(p.name for p in qc.glob("clip_3000rpm.frame*.png"))
    assert removed
    for name in removed:
        (qc / name).unlink()
    run = cli(capsys, "report", mini_lab, "-o", out, *QUICK_REPORT)
    assert_clean(run, 0)
    assert _skipped(run.out) == 1  # the simulation only; tracking was redone
    assert sorted(p.name for p in qc.glob("clip_3000rpm.frame*.png")) == removed


def test_r12_a_corrupt_cached_video_trace_is_redone(report_template, tmp_path, capsys, mini_lab, in_process_pool):
    out = _copy(report_template, tmp_path)
    trace = out / "traces" / "clip_3000rpm.trace.h5"
    flip_bits(trace)
    run = cli(capsys, "report", mini_lab, "-o", out, *QUICK_REPORT)
    assert_clean(run, 0)
    assert _skipped(run.out) == 1
    table = pd.read_csv(out / "slip_table.csv")
    assert list(table.status) == ["ok"]
    from cageless.trace import read_trace

    read_trace(trace)  # whole again


def test_r27_a_corrupt_cached_simulation_is_redone(report_template, tmp_path, capsys, mini_lab, in_process_pool):
    out = _copy(report_template, tmp_path)
    sim = out / "simulations" / "n3000_Fr500_Fa0.sim.trace.h5"
    flip_bits(sim)
    run = cli(capsys, "report", mini_lab, "-o", out, *QUICK_REPORT)
    assert_clean(run, 0)
    assert _skipped(run.out) == 1
    assert list(pd.read_csv(out / "slip_table.csv").status) == ["ok"] and not parts(out)


def test_r27_a_truncated_cached_simulation_is_redone(report_template, tmp_path, capsys, mini_lab, in_process_pool):
    out = _copy(report_template, tmp_path)
    sim = out / "simulations" / "n3000_Fr500_Fa0.sim.trace.h5"
    sim.write_bytes(sim.read_bytes()[:1000])
    run = cli(capsys, "report", mini_lab, "-o", out, *QUICK_REPORT)
    assert_clean(run, 0)
    assert _skipped(run.out) == 1


def test_changed_code_under_the_same_version_redoes_everything(report_template, tmp_path, capsys, mini_lab,
                                                              in_process_pool, monkeypatch):
    """The job keys hold the digest of the package's sources: an edited checkout or an upgrade that kept the
    version number does not reuse traces the old code wrote."""
    from cageless.app import lab

    out = _copy(report_template, tmp_path)
    monkeypatch.setattr(lab, "code_digest", lambda: "0" * 64)
    run = cli(capsys, "report", mini_lab, "-o", out, *QUICK_REPORT)
    assert_clean(run, 0)
    assert _skipped(run.out) == 0


def test_code_digest_covers_the_science_packages():
    from pathlib import Path

    import cageless.simulation
    from cageless.provenance import code_digest

    assert len(code_digest()) == 64 and code_digest() == code_digest()
    assert (Path(cageless.simulation.__file__).parent / "kernels.py").is_file()  # a source the digest reads


def test_r10_an_old_or_damaged_cache_file_redoes_everything(report_template, tmp_path, capsys, mini_lab,
                                                           in_process_pool):
    out = _copy(report_template, tmp_path)
    (out / CACHE_NAME).write_text('{"abc": "repA/traces/x.h5"}')  # the old, cwd-relative format
    run = cli(capsys, "report", mini_lab, "-o", out, *QUICK_REPORT)
    assert_clean(run, 0)
    assert _skipped(run.out) == 0


def test_r15_impossible_sidecar_speed_is_a_failed_row(tmp_path, capsys, mini_lab, in_process_pool):
    lab = tmp_path / "lab"
    shutil.copytree(mini_lab, lab)
    (lab / "clip_3000rpm.toml").write_text("speed_rpm = 1e12\n")
    run = cli(capsys, "report", lab, "-o", tmp_path / "out", *QUICK_REPORT)
    # refused as the conditions are built (cageless.limits' hard rule: above 600 000 r/min), naming the source
    assert_clean(run, 1, "clip_3000rpm", "speed_rpm = 1000000000000.0", "<= 600000 r/min",
                 "Plausible values are 1 to 60000 r/min", "sidecar clip_3000rpm.toml")
    table = pd.read_csv(tmp_path / "out" / "slip_table.csv")
    assert list(table.status) == ["failed"]  # never a "complete" 100 % slip


def test_a_failed_job_is_announced_when_it_fails(capsys):
    """A long report says at once which input failed, not only in the summary at the end."""
    from concurrent.futures import ThreadPoolExecutor

    from cageless.app.lab import _run_jobs

    def ok() -> tuple[str, str]:
        return ("ok", "a.trace.h5")

    def crash() -> tuple[str, str]:
        raise RuntimeError("worker died\nsecond line")

    with ThreadPoolExecutor(1) as pool:
        out = _run_jobs(pool, [(ok, ()), (crash, ())], "tracking", True, ["a.cine", "b.cine"])
    assert out == [("ok", "a.trace.h5"), ("failed", "RuntimeError: worker died\nsecond line")]
    assert "FAILED b.cine (tracking): RuntimeError: worker died\n" in capsys.readouterr().err


def test_an_interrupted_stage_keeps_the_jobs_it_finished(tmp_path, capsys, mini_lab, in_process_pool, monkeypatch):
    """Ctrl-C in the middle of a stage: the jobs of that stage that had finished are in the cache, and the
    re-run skips them. (They were stored only when the whole stage ended, so the re-run redid every
    finished simulation of an interrupted simulation stage: a new user's trial.)"""
    import pytest

    from cageless.app import lab
    from cageless.app.lab import LabOptions, run_lab

    folder = tmp_path / "lab"
    shutil.copytree(mini_lab, folder)
    shutil.copy(folder / "clip_3000rpm.mkv", folder / "second.mkv")
    (folder / "conditions.csv").write_text("file,speed_rpm,radial_load_n,fps\nclip_3000rpm.mkv,3000,500,10000\n"
                                           "second.mkv,3000,600,10000\n")
    real = lab._track_job

    def interrupted_at_the_second(video, *args):
        if video.endswith("second.mkv"):
            raise KeyboardInterrupt
        return real(video, *args)

    monkeypatch.setattr(lab, "_track_job", interrupted_at_the_second)
    out = tmp_path / "out"
    with pytest.raises(KeyboardInterrupt):
        run_lab(folder, out, LabOptions(duration_s=0.003, settle_s=0.002), progress=False)
    assert [job["path"] for job in json.loads((out / CACHE_NAME).read_text())["jobs"].values()] == \
        ["traces/clip_3000rpm.trace.h5"]
    monkeypatch.setattr(lab, "_track_job", real)
    run = cli(capsys, "report", folder, "-o", out, *QUICK_REPORT)
    assert_clean(run, 0)
    assert _skipped(run.out) == 1  # the first video's tracking


def test_report_window_reaches_the_tracker_and_its_cache_key(tmp_path, capsys, mini_lab, in_process_pool,
                                                             monkeypatch):
    """`report --window N` tracks with that speed window (a clip shorter than the default 21 frames failed its
    row with 'Record longer, or lower --window', an option report did not have: a new user's trial); another
    window is another tracking job, and an even one is refused before any work."""
    import cageless.tracking.pipeline as pipeline

    windows = []
    real = pipeline.track_video

    def recording(video, conditions, bearing, options, **kw):
        windows.append(options.window)
        return real(video, conditions, bearing, options, **kw)

    monkeypatch.setattr(pipeline, "track_video", recording)
    out = tmp_path / "out"
    assert_clean(cli(capsys, "report", mini_lab, "-o", out, "--window", "11", *QUICK_REPORT), 0)
    run = cli(capsys, "report", mini_lab, "-o", out, *QUICK_REPORT)
    assert_clean(run, 0)
    assert windows == [11, 21] and _skipped(run.out) == 1  # the simulation; the tracking was redone
    assert cli(capsys, "report", mini_lab, "-o", tmp_path / "o2", "--window", "12", *QUICK_REPORT).code == 2


def test_a_video_copied_under_another_name_is_pointed_out(tmp_path, capsys, mini_lab, in_process_pool):
    """Two videos with the same bytes in one lab folder (a copy made by mistake counts one measurement twice):
    the report still has both rows, and warns, naming both (it said nothing: a new user's trial)."""
    folder = tmp_path / "lab"
    shutil.copytree(mini_lab, folder)
    shutil.copy(folder / "clip_3000rpm.mkv", folder / "copy of clip.mkv")
    with open(folder / "conditions.csv", "a") as fh:
        fh.write("copy of clip.mkv,3000,500,0,10000\n")
    run = cli(capsys, "report", folder, "-o", tmp_path / "out", *QUICK_REPORT)
    assert_clean(run, 0, "WARNING: copy of clip.mkv holds the same bytes as clip_3000rpm.mkv (xxh3_128 ")
    assert len(pd.read_csv(tmp_path / "out" / "slip_table.csv")) == 2


def test_a_copy_keeps_its_own_trace_on_a_re_run(tmp_path, capsys, mini_lab, in_process_pool):
    """newuser2's trial: the tracking cache was keyed on the video's bytes and conditions only, so a copy and its
    original shared one cache entry, and on a re-run both rows were served by one trace (the report's QC section
    named the original's file on the copy's row). Each video keeps its own cached trace."""
    folder = tmp_path / "lab"
    shutil.copytree(mini_lab, folder)
    shutil.copy(folder / "clip_3000rpm.mkv", folder / "copy of clip.mkv")
    with open(folder / "conditions.csv", "a") as fh:
        fh.write("copy of clip.mkv,3000,500,0,10000\n")
    out = tmp_path / "out"
    assert_clean(cli(capsys, "report", folder, "-o", out, *QUICK_REPORT), 0)
    run = cli(capsys, "report", folder, "-o", out, *QUICK_REPORT)
    assert_clean(run, 0)
    assert _skipped(run.out) == 3  # two videos and one simulation, nothing redone
    paths = sorted(job["path"] for job in json.loads((out / CACHE_NAME).read_text())["jobs"].values()
                   if job["path"].startswith("traces/"))
    assert paths == ["traces/clip_3000rpm.trace.h5", "traces/copy of clip.trace.h5"]
