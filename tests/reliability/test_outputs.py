"""The catalogue's rows about writing outputs: foreign files, a full disk, a second writer, stale temporaries,
and the last-resort handler (issue 17)."""

from __future__ import annotations

import json
import os
import shutil
import time
from pathlib import Path

import pytest
from faultlib import assert_clean, cli, parts

from cageless.atomic import atomic_write_text
from cageless.outputs import FolderInUseError, clean_stale_parts, output_lock


def test_r01_sample_does_not_overwrite_a_users_recording(tmp_path, capsys):
    lab = tmp_path / "u"
    lab.mkdir()
    (lab / "n6000_Fr500_Fa0.cine").write_text("MINE\n")
    (lab / "conditions.csv").write_text("file,speed_rpm\nmine.cine,1000\n")
    run = cli(capsys, "sample", lab, "--revolutions", "0.05", "-q")
    assert_clean(run, 2, "n6000_Fr500_Fa0.cine", "conditions.csv", "--overwrite")
    assert (lab / "n6000_Fr500_Fa0.cine").read_text() == "MINE\n"
    assert (lab / "conditions.csv").read_text() == "file,speed_rpm\nmine.cine,1000\n"
    assert sorted(p.name for p in lab.iterdir()) == ["conditions.csv", "n6000_Fr500_Fa0.cine"]  # no lock file left


def test_r01_sample_may_replace_what_it_wrote_itself(tmp_path, capsys, monkeypatch):
    """A re-run into a folder that ``cageless sample`` filled is allowed (its manifest lists the names)."""
    calls = []
    monkeypatch.setattr("cageless.tracking.synthetic.lab.make_lab", lambda out, **kw: calls.append(out) or [])
    lab = tmp_path / "s"
    assert_clean(cli(capsys, "sample", lab, "-q"), 0)
    for name in ("n6000_Fr500_Fa0.cine", "conditions.csv"):
        (lab / name).write_text("rendered\n")
    assert_clean(cli(capsys, "sample", lab, "-q"), 0)
    assert len(calls) == 2


def test_sample_does_not_replace_a_file_edited_since_it_wrote_it(tmp_path, capsys, monkeypatch):
    """The manifest records what each file held: a conditions.csv the user edited is kept, not restored."""
    monkeypatch.setattr("cageless.tracking.synthetic.lab.make_lab", lambda out, **kw: [])
    lab = tmp_path / "s"
    lab.mkdir()
    assert_clean(cli(capsys, "sample", lab, "-q"), 0)
    (lab / "conditions.csv").write_text("rendered\n")
    assert_clean(cli(capsys, "sample", lab, "-q"), 0)  # the second run records what it wrote
    (lab / "conditions.csv").write_text("edited by hand\n")
    assert_clean(cli(capsys, "sample", lab, "-q"), 2, "conditions.csv", "edited since", "--overwrite")
    assert (lab / "conditions.csv").read_text() == "edited by hand\n"
    assert_clean(cli(capsys, "sample", lab, "-q", "--overwrite"), 0)
    manifest = json.loads((lab / ".cageless-sample.json").read_text())
    assert "clip_3000rpm.toml" not in manifest["files"] and "run_1800.toml" in manifest["files"]


def test_r03_simulate_overwrite_flag_replaces_a_foreign_file(tmp_path, capsys):
    target = tmp_path / "x.trace.h5"
    target.write_text("not a trace\n")
    run = cli(capsys, "simulate", "--speed-rpm", "3000", "--radial-load-n", "500", "--duration", "0.002",
              "-o", target, "--overwrite", "-q")
    assert_clean(run, 0, str(target))
    assert target.read_bytes()[:4] == b"\x89HDF"


def test_r02_atomic_writer_never_renames_over_a_device(tmp_path):
    from cageless.atomic import OutputError

    with pytest.raises(OutputError, match="/dev/null: is a device"):
        atomic_write_text("/dev/null", "x")
    assert Path("/dev/null").is_char_device()


def test_r17_simulate_on_a_full_disk(full_disk, capsys):
    target = full_disk / "x.trace.h5"
    run = cli(capsys, "simulate", "--speed-rpm", "3000", "--radial-load-n", "500", "--duration", "0.003",
              "-o", target, "-q")
    assert_clean(run, 1, "no space left on", str(full_disk))
    assert not target.exists() and not parts(full_disk)


def test_r18_track_on_a_full_disk(full_disk, capsys, mini_lab):
    out = full_disk / "traces"
    run = cli(capsys, "track", mini_lab, "-o", out, "-q", "--workers", "1")
    assert_clean(run, 1, "FAILED", "no space left on")
    assert not list(full_disk.rglob("*.trace.h5")) and not parts(full_disk)
    assert not (out / "qc").exists() or not any((out / "qc").iterdir())  # no empty or partial QC


def test_a_rerun_whose_qc_cannot_be_written_keeps_the_earlier_trace(tmp_path, capsys, mini_lab, monkeypatch):
    """A re-run that fails writing its QC (here a permission error, as in a read-only qc folder) fails that video
    and leaves the trace of the earlier run as it was (found in a new-user trial: it was deleted)."""
    out = tmp_path / "o"
    assert_clean(cli(capsys, "track", mini_lab, "-o", out, "-q", "--workers", "1"), 0)
    trace = out / "clip_3000rpm.trace.h5"
    before = trace.read_bytes()

    def refuse(folder, *args, **kwargs):
        raise PermissionError(13, "Permission denied", str(folder / "x.png"))

    monkeypatch.setattr("cageless.tracking.pipeline.write_qc", refuse)
    run = cli(capsys, "track", mini_lab, "-o", out, "-q", "--workers", "1")
    assert run.code == 1 and "FAILED clip_3000rpm.mkv" in run.err and "Traceback" not in run.err
    assert trace.read_bytes() == before and not parts(out)


def test_r13_a_second_writer_is_refused(tmp_path, capsys, mini_lab):
    out = tmp_path / "report"
    with output_lock(out):
        run = cli(capsys, "report", mini_lab, "-o", out, "-q")
        assert_clean(run, 1, str(out), "in use by another cageless run", f"pid {os.getpid()}")
        run = cli(capsys, "track", mini_lab, "-o", out, "-q")
        assert_clean(run, 1, "in use by another cageless run")
    assert not (out / "traces").exists() and not (out / "report.html").exists()
    with output_lock(out):  # released: free again
        pass


def test_r13_the_lock_is_per_process(tmp_path):
    """A second process cannot take the lock (flock locks are per open file; filelock keeps one per path)."""
    import subprocess
    import sys

    out = tmp_path / "o"
    code = ("import sys; from cageless.outputs import output_lock, FolderInUseError\n"
            "try:\n    output_lock(sys.argv[1]).__enter__()\n"
            "except FolderInUseError as e:\n    print(e); sys.exit(3)\n")
    with output_lock(out):
        proc = subprocess.run([sys.executable, "-c", code, str(out)], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 3 and "in use" in proc.stdout
    with pytest.raises(FolderInUseError):
        with output_lock(out), output_lock(out):
            pass


def test_r42_stale_part_files_are_cleaned_safely(tmp_path):
    """Only our temporary names, only abandoned ones (old enough and not locked by a live writer)."""
    import fcntl

    folder = tmp_path / "traces"
    folder.mkdir()
    old = folder / ".clip.trace.h5.abcd1234.part"
    live = folder / ".live.trace.h5.efgh5678.part"
    fresh = folder / ".fresh.trace.h5.ijkl9012.part"
    foreign = folder / "user-download.part"
    for p in (old, live, fresh, foreign):
        p.write_text("x")
    long_ago = time.time() - 30
    for p in (old, live, foreign):
        os.utime(p, (long_ago, long_ago))
    fd = os.open(live, os.O_RDONLY)
    fcntl.flock(fd, fcntl.LOCK_EX)  # a writer still at work
    try:
        assert clean_stale_parts(tmp_path) == [old]
    finally:
        os.close(fd)
    assert live.exists() and fresh.exists() and foreign.exists()
    # the atomic writer also removes abandoned temporaries of its own target
    atomic_write_text(folder / "live.trace.h5", "new")
    assert not live.exists() and foreign.exists() and fresh.exists()


def test_r42_track_removes_parts_of_killed_runs_in_its_folder(tmp_path, capsys, mini_lab):
    out = tmp_path / "o"
    out.mkdir()
    stale = out / ".clip_3000rpm.trace.h5.k1ll3d00.part"
    stale.write_text("half a trace")
    os.utime(stale, (time.time() - 30, time.time() - 30))
    assert_clean(cli(capsys, "track", mini_lab, "-o", out, "-q", "--workers", "1"), 0)
    assert not parts(out) and (out / "clip_3000rpm.trace.h5").is_file()


def test_r30_unexpected_error_is_one_line_with_a_log(capsys, monkeypatch):
    def boom(args, config):
        raise RuntimeError("something nobody planned for\nsecond line")

    monkeypatch.setattr("cageless.app.cli.info.run", boom)
    run = cli(capsys, "info")
    assert_clean(run, 1, "unexpected RuntimeError: something nobody planned for", "run with -v for the traceback")
    assert run.err.count("\n") == 1
    log_path = run.err.split("details in ")[1].split(";")[0]
    assert "Traceback" in Path(log_path).read_text() and "boom" in Path(log_path).read_text()
    run = cli(capsys, "info", "-v")
    assert run.code == 1 and "Traceback" in run.err  # asked for with -v


def test_r30_disk_full_escaping_anywhere_is_one_line(capsys, monkeypatch):
    import errno

    def full(args, config):
        raise OSError(errno.ENOSPC, "No space left on device", "/data/out/x.png")

    monkeypatch.setattr("cageless.app.cli.info.run", full)
    assert_clean(cli(capsys, "info"), 1, "no space left on /data/out/x.png")


def test_track_and_report_do_not_replace_files_they_did_not_write(tmp_path, capsys):
    """A new user's check: track and report into folders holding the user's own files of the same names."""
    video = Path(__file__).resolve().parents[2] / "sample_data" / "lab" / "n6000_Fr500_Fa0.cine"
    out = tmp_path / "to"
    out.mkdir()
    (out / "n6000_Fr500_Fa0.trace.h5").write_text("MINE")
    run = cli(capsys, "track", video, "-o", out, "--workers", "1", "-q")
    assert_clean(run, 1, "n6000_Fr500_Fa0.trace.h5 exists and is not a cageless trace")
    assert (out / "n6000_Fr500_Fa0.trace.h5").read_text() == "MINE"
    rep = tmp_path / "ro"
    rep.mkdir()
    (rep / "report.html").write_text("MINE")
    run = cli(capsys, "report", video.parent, "-o", rep, "-q")
    assert_clean(run, 2, "already holds report.html, which cageless did not write")
    assert (rep / "report.html").read_text() == "MINE" and not (rep / "traces").exists()


def test_simulate_does_not_replace_a_measured_trace(tmp_path, capsys, video_trace):
    target = tmp_path / "measured.trace.h5"
    shutil.copy(video_trace, target)
    before = target.read_bytes()
    run = cli(capsys, "simulate", "--speed-rpm", "6000", "--radial-load-n", "500", "--duration", "0.002",
              "-o", target)
    assert_clean(run, 2, "holds a measured (video) trace")
    assert target.read_bytes() == before


def test_config_that_is_not_text_is_a_usage_error(tmp_path, capsys):
    bad = tmp_path / "bin.toml"
    bad.write_bytes(b"\xff\xfe\x00garbage")
    run = cli(capsys, "info", "--config", bad)
    assert_clean(run, 2, "--config", "bin.toml", "is not a text file")
    run = cli(capsys, "info", "--config", tmp_path)
    assert_clean(run, 2, "is a folder; give a TOML file")


def test_report_on_an_empty_lab_leaves_no_output_folder(tmp_path, capsys):
    (tmp_path / "empty").mkdir()
    run = cli(capsys, "report", tmp_path / "empty", "-o", tmp_path / "out", "-q")
    assert_clean(run, 1, "no videos found")
    assert not (tmp_path / "out").exists()


def test_figures_under_a_device_names_the_device_once(tmp_path, capsys, video_trace, sim_trace):
    run = cli(capsys, "compare", video_trace, sim_trace, "--figures", "/dev/full/x")
    assert_clean(run, 2, "--figures /dev/full/x: /dev/full is a character device, not a folder")
    assert "/dev/full/x/x" not in run.text
