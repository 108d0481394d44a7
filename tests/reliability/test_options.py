"""The catalogue's rows about numbers and output paths given on the command line (issue 17).

One case per row: the exit code, a message naming the option or path, no traceback, and nothing
written where the run was refused. Each refused case runs in well under a second: validation comes
before any work.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest
from faultlib import QUICK_REPORT, assert_clean, cli

SIM = ("simulate", "--speed-rpm", "3000", "--radial-load-n", "500", "--duration", "0.002")

# (catalogue row, argv with {tmp}/{lab}/{file}/{dir} placeholders, exit code, needles in the message)
CASES = [
    ("r02-simulate-o-dev-full", [*SIM, "-o", "/dev/full"], 2, ["-o /dev/full", "character device"]),
    ("r03-simulate-o-existing-foreign-file", [*SIM, "-o", "{file}.h5"], 2, ["exists and is not a cageless trace",
                                                                         "--overwrite"]),
    ("r04-simulate-o-folder", [*SIM, "-o", "{dir}"], 2, ["is a folder", ".h5"]),
    ("r05-simulate-o-under-a-file", [*SIM, "-o", "{file}/x.trace.h5"], 2, ["is a file, not a folder"]),
    ("r06-track-o-file", ["track", "{lab}", "-o", "{file}"], 2, ["-o", "is a file, not a folder"]),
    ("r06-track-o-under-a-file", ["track", "{lab}", "-o", "{file}/out"], 2, ["is a file, not a folder"]),
    ("r07-report-o-file", ["report", "{lab}", "-o", "{file}"], 2, ["-o", "is a file, not a folder"]),
    ("r07-report-o-under-a-file", ["report", "{lab}", "-o", "{file}/out"], 2, ["is a file, not a folder"]),
    ("r08-compare-figures-under-a-file", ["compare", "{file}", "{file}", "--figures", "{file}/figs"], 2,
     ["--figures", "is a file, not a folder"]),
    ("r09-simulate-o-csv-name", [*SIM, "-o", "{tmp}/result.csv"], 2, ["result.csv", "HDF5", ".h5"]),
    ("r14-radial-load-5e5", [*SIM, "--radial-load-n", "5e5"], 2, ["--radial-load-n", "plausible range 0 to 100000 N",
                                                                 "--force"]),
    ("r14-speed-1e5", ["simulate", "--speed-rpm", "1e5", "--explain"], 2, ["--speed-rpm", "60000 r/min", "--force"]),
    # beyond the hard bounds (cageless/limits.py: ten times the plausible ranges) --force does not help
    ("r14-radial-load-1e9", [*SIM, "--radial-load-n", "1e9", "--force"], 2,
     ["--radial-load-n 1e+09: must be >= 0 and <= 1000000", "plausible range is 0 to 100000 N"]),
    ("r14-speed-1e7", ["simulate", "--speed-rpm", "1e7", "--explain", "--force"], 2,
     ["--speed-rpm 1e+07: must be > 0 and <= 600000", "60000 r/min"]),
    ("r19-sample-rate-1e12", [*SIM, "--sample-rate", "1e12"], 2, ["--sample-rate", "plausible range"]),
    ("r19-sample-rate-1e12-forced", [*SIM, "--sample-rate", "1e12", "--force"], 2, ["GB", "Lower --sample-rate"]),
    ("r20-duration-1e9", ["simulate", "--speed-rpm", "3000", "--duration", "1e9"], 2, ["--duration", "10 s"]),
    ("r21-seed-negative", [*SIM, "--seed", "-1"], 2, ["--seed -1", "must be >= 0"]),
    ("r22-sample-rate-0", [*SIM, "--sample-rate", "0"], 2, ["--sample-rate 0", "must be > 0"]),
    ("r23-compare-bin-deg-0", ["compare", "{file}", "{file}", "--bin-deg", "0"], 2, ["--bin-deg 0", "must be > 0"]),
    ("r24-simulate-o-proc", [*SIM, "-o", "/proc/x.trace.h5"], 2, ["-o /proc/x.trace.h5", "cannot write in /proc"]),
    ("r25-compare-figures-at-a-file", ["compare", "{file}", "{file}", "--figures", "{file}"], 2,
     ["--figures", "is a file, not a folder"]),
    ("r28-track-fps-negative", ["track", "{lab}", "-o", "{tmp}/o", "--fps", "-1"], 2, ["--fps -1", "must be > 0"]),
    ("r28-track-fps-nan", ["track", "{lab}", "-o", "{tmp}/o", "--fps", "nan"], 2, ["--fps", "finite"]),
    ("r28-info-fps-negative", ["info", "{file}", "--fps", "-1"], 2, ["--fps -1", "must be > 0"]),
    ("sweep-duration-negative", ["sweep", "--duration", "-1", "-o", "{tmp}/o"], 2, ["--duration -1"]),
    ("sweep-o-file", ["sweep", "-o", "{file}"], 2, ["-o", "is a file, not a folder"]),
    ("r29-report-duration-negative", ["report", "{lab}", "-o", "{tmp}/o", "--duration", "-1"], 2,
     ["--duration -1", "must be > 0"]),
    ("r38-restitution-above-1", [*SIM, "--restitution", "1.5"], 2, ["--restitution 1.5", "<= 1"]),
    ("workers-zero", ["track", "{lab}", "-o", "{tmp}/o", "--workers", "0"], 2, ["--workers 0", ">= 1"]),
    ("window-even", ["track", "{lab}", "-o", "{tmp}/o", "--window", "20"], 2, ["--window 20", "odd"]),
    ("unknown-option", ["simulate", "--speed-rpm", "3000", "--durration", "1"], 2, ["--durration"]),
]


@pytest.mark.parametrize(("argv", "code", "needles"), [c[1:] for c in CASES], ids=[c[0] for c in CASES])
def test_refused_before_any_work(tmp_path, capsys, mini_lab, argv, code, needles):
    a_file = tmp_path / "notes"
    a_file.write_text("mine\n")
    (tmp_path / "notes.h5").write_text("mine\n")
    a_dir = tmp_path / "adir"
    a_dir.mkdir()
    before = sorted(p.name for p in tmp_path.rglob("*"))
    subst = {"{tmp}": str(tmp_path), "{lab}": str(mini_lab), "{file}": str(a_file), "{dir}": str(a_dir)}
    args = []
    for a in argv:
        for k, v in subst.items():
            a = a.replace(k, v)
        args.append(a)
    cwd = os.getcwd()
    os.chdir(tmp_path)  # a default output name lands here, where the test can see it
    try:
        run = cli(capsys, *args)
    finally:
        os.chdir(cwd)
    assert_clean(run, code, *needles)
    assert run.err.count("\n") <= 2, run.err  # one line (and argparse's usage hint)
    assert sorted(p.name for p in tmp_path.rglob("*")) == before  # nothing written, nothing replaced
    assert a_file.read_text() == "mine\n" and (tmp_path / "notes.h5").read_text() == "mine\n"
    assert not Path("/dev/full").is_file()


def test_r38_restitution_zero_is_accepted_as_the_help_says(capsys):
    """R = 0 (perfectly plastic) is valid (simulation/parameters.py); the help now says 0 <= R <= 1."""
    run = cli(capsys, "simulate", "--help")
    assert "0 <= R <= 1" in " ".join(run.out.split())
    run = cli(capsys, *SIM, "--restitution", "0", "--explain")
    assert_clean(run, 0)


def test_r14_force_accepts_a_number_outside_the_plausible_range(capsys):
    run = cli(capsys, "simulate", "--speed-rpm", "3000", "--radial-load-n", "2e5", "--force", "--explain")
    assert_clean(run, 0)


def test_r29_report_duration_is_checked_before_tracking(tmp_path, capsys, mini_lab):
    out = tmp_path / "o"
    run = cli(capsys, "report", mini_lab, "-o", out, *QUICK_REPORT[:2], "--duration", "-0.8487")
    assert_clean(run, 2, "--duration -0.8487")
    assert not (out / "traces").exists() and not (out / "report.html").exists()
