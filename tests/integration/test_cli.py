"""The cageless CLI end to end: in-process through main(), and once through the console script."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys

import pytest

from cageless import __version__
from cageless.app.cli import main


def test_version(capsys):
    assert main(["--version"]) == 0
    assert capsys.readouterr().out.strip() == f"cageless {__version__}"


def test_info_text(capsys):
    assert main(["info"]) == 0
    out = capsys.readouterr().out
    assert "wang2026" in out
    # Hand-computed in tests/validation/test_kinematics_textbook.py: at 3000 rpm, w_c = 124.5574 rad/s.
    assert "pure-rolling cage speed w_c  124.5574 rad/s" in out
    assert "BPFO     277.535 Hz" in out


def test_info_json(capsys):
    assert main(["info", "--speed-rpm", "6000", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["software_version"] == __version__
    assert d["speed_rpm"] == 6000.0
    # FTF at 6000 rpm = 100 Hz * (1 - 0.2070427) / 2 = 39.64786 Hz (Harris & Kotzalas ch. 8).
    assert d["frequencies_hz"]["ftf_hz"] == pytest.approx(39.64786, rel=1e-6)
    assert d["derived"]["max_ball_count"] == 15
    assert d["bearing"]["geometry"]["n_balls"] == 14


def test_unknown_subcommand_is_a_usage_error(capsys):
    assert main(["inof"]) == 2
    err = capsys.readouterr().err
    assert "unknown command 'inof'" in err and "Did you mean 'info'?" in err


def test_an_unknown_option_is_refused_in_the_name_of_its_subcommand(capsys):
    """argparse names only the top-level program for an unrecognized option; the error names the subcommand,
    points at its help and suggests its closest option (a new user's trial found 'cageless: unrecognized')."""
    assert main(["info", "--speed-rmp=1800"]) == 2
    err = capsys.readouterr().err
    assert "cageless info: unrecognized arguments: --speed-rmp=1800." in err, err
    assert "Did you mean '--speed-rpm'?" in err and "Run 'cageless info --help'" in err, err
    assert main(["--bogus"]) == 2
    assert "cageless: unrecognized arguments: --bogus." in capsys.readouterr().err


def test_no_subcommand_prints_help(capsys):
    assert main([]) == 2
    assert "usage: cageless" in capsys.readouterr().out


def test_help_has_examples(capsys):
    assert main(["info", "--help"]) == 0
    assert "examples:" in capsys.readouterr().out


def test_bad_option_value_is_a_usage_error(capsys):
    assert main(["info", "--speed-rpm", "fast"]) == 2
    assert "--speed-rpm: must be a number, got 'fast'" in capsys.readouterr().err
    assert main(["info", "--speed-rpm", "nan"]) == 2
    assert "--speed-rpm: must be a finite number, got 'nan'" in capsys.readouterr().err


def test_config_file(tmp_path, capsys):
    cfg = tmp_path / "lab.toml"
    cfg.write_text("[bearing.geometry]\nn_balls = 13\n\n[info]\nspeed_rpm = 6000\njson = true\n")
    assert main(["info", "--config", str(cfg)]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["speed_rpm"] == 6000
    # BPFO = Z * FTF = 13 * 39.64786 Hz = 515.4222 Hz
    assert d["frequencies_hz"]["bpfo_hz"] == pytest.approx(515.4222, rel=1e-6)
    # The command line wins over the file.
    assert main(["info", "--config", str(cfg), "--speed-rpm", "1800"]) == 0
    assert json.loads(capsys.readouterr().out)["speed_rpm"] == 1800.0


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ("[info]\nspeed_rmp = 1\n", "Did you mean 'speed_rpm'"),
        ("[bearing.geometry]\nn_balls = 16\n", "at most 15 fit"),
        ("[info\n", "not valid TOML"),
        # a bad entry names the file and the entry, not the command-line option nobody typed
        ('[info]\nspeed_rpm = "fast"\n', "bad.toml: [info] speed_rpm = 'fast': must be a number"),
        ('[info]\njson = "yes"\n', "[info] json = 'yes': must be true or false."),
        # unknown tables and keys are refused, not ignored
        ("[reprot]\nrevolutions = 2\n", "bad.toml: unknown table 'reprot'"),
        ("[geometry]\nn_balls = 13\n", "unknown table 'geometry'"),
        ("revolutions = 2\n", "unknown key 'revolutions'"),
        ('[bearing]\nlubricant = "no"\n', "bad.toml: [bearing] lubricant = 'no': must be true or false"),
        ('[bearing]\nn_balls = "14"\n', "[bearing] n_balls = '14': bearing fields go in their table"),
        ('[bearing.geometry]\nn_balls = "14"\n', "bad.toml: geometry.n_balls = '14': must be a whole number"),
    ],
)
def test_bad_config_is_a_usage_error(tmp_path, capsys, text, match):
    cfg = tmp_path / "bad.toml"
    cfg.write_text(text)
    assert main(["info", "--config", str(cfg)]) == 2
    err = capsys.readouterr().err
    assert match in err and "argument --" not in err


def test_missing_config_file(capsys, tmp_path):
    assert main(["info", "--config", str(tmp_path / "nope.toml")]) == 2
    assert "no such file" in capsys.readouterr().err


def test_console_script():
    exe = shutil.which("cageless")
    cmd = [exe] if exe else [sys.executable, "-m", "cageless"]
    out = subprocess.run([*cmd, "--version"], capture_output=True, text=True, check=False)
    assert out.returncode == 0 and out.stdout.strip() == f"cageless {__version__}"
    bad = subprocess.run([*cmd, "frobnicate"], capture_output=True, text=True, check=False)
    assert bad.returncode == 2 and "unknown command 'frobnicate'" in bad.stderr


def test_info_video_json(tmp_path, capsys):
    import numpy as np

    from cageless.tracking.io import write_cine

    path = write_cine(tmp_path / "n3000.cine", np.zeros((4, 8, 8), np.uint16), fps=10000, fmt="p12",
                      timestamps_s=[0, 1e-4, 2e-4, 4e-4])
    assert main(["info", str(path), "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert (d["n_frames"], d["width"], d["height"], d["bit_depth"]) == (4, 8, 8, 12)
    assert d["header_fps"] == 10000 and d["time_source"] == "timestamps"
    # 3 intervals over 4e-4 s (one frame dropped): 7500 fps.
    assert d["timestamp_fps"] == pytest.approx(7500, rel=1e-6)
    assert d["last_time_s"] == pytest.approx(4e-4, abs=1e-9)


def test_info_real_cine_text(shared_dir, capsys):
    assert main(["info", str(shared_dir / "reference" / "cine" / "cine_781.cine")]) == 0
    out = capsys.readouterr().out
    assert "header rate       90000 fps" in out and "time from         timestamps" in out
    # the JSON's duration_s (15 frames at the 9003.2 fps of the time stamps) and the first-to-last span (14
    # periods), both named: the text showed only the span, the JSON only the other (a new user's trial)
    assert "duration          0.00166607 s (15 frames); 0.001555 s first to last frame" in out


def test_info_bad_video_is_exit_1(tmp_path, capsys):
    bad = tmp_path / "bad.cine"
    bad.write_bytes(b"NOPE" * 20)
    assert main(["info", str(bad)]) == 1
    assert "bad.cine: wrong magic bytes" in capsys.readouterr().err


def test_a_bad_set_value_names_the_option_not_the_internal_table(tmp_path, capsys):
    argv = ["simulate", "--speed-rpm", "3000", "-o", str(tmp_path / "x.trace.h5")]
    assert main([*argv, "--set", "cho_n_s_m=-1"]) == 2
    assert capsys.readouterr().err == "error: --set cho_n_s_m=-1: must be >= 0.\n"
    assert main([*argv, "--set", "traction_peak_coefficient=0.001"]) == 2
    assert "--set traction_peak_coefficient=0.001: must exceed traction_sliding_coefficient" in capsys.readouterr().err
    assert not (tmp_path / "x.trace.h5").exists()


def test_a_missing_video_is_named_once(tmp_path, capsys):
    missing = tmp_path / "nowhere.cine"
    assert main(["track", str(missing), "-o", str(tmp_path / "o"), "-q"]) == 1
    cap = capsys.readouterr()
    assert cap.err == f"FAILED {missing}: no such file or folder.\n" and cap.out == ""  # diagnostics on stderr


def test_a_rule_between_two_parameters_names_the_one_to_set_as_well(tmp_path, capsys):
    argv = ["simulate", "--speed-rpm", "3000", "-o", str(tmp_path / "x.trace.h5")]
    assert main([*argv, "--set", "traction_sliding_coefficient=0.1"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("error: --set traction_sliding_coefficient=0.1: traction_peak_coefficient=0.06 must exceed")
    assert "--set traction_peak_coefficient=" in err and "None" not in err
    assert main([*argv, "--set", "no_such=1"]) == 2
    assert capsys.readouterr().err.startswith("error: --set: 'no_such' is not a model parameter")


def test_a_vary_range_that_breaks_a_parameter_rule_is_refused_before_any_run(tmp_path, capsys):
    argv = ["calibrate", "--speed-rpm", "3000", "--radial-load-n", "500", "--target-peak-slip-pct", "7.79",
            "--vary", "traction_sliding_coefficient=0.01:0.2", "-o", str(tmp_path / "fit.toml")]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert "at 0.2, traction_peak_coefficient=0.06 must exceed traction_sliding_coefficient" in err
    assert not (tmp_path / "fit.toml").exists()


def test_a_closed_pipe_ends_quietly(tmp_path):
    """`cageless info --json | head -c 10`: the reader leaves early; no 'unexpected BrokenPipeError' line."""
    import subprocess
    import sys

    code = ("import sys; from cageless.app.cli import main\n"
            "sys.stdout.write = lambda *a: (_ for _ in ()).throw(BrokenPipeError(32, 'Broken pipe'))\n"
            "sys.exit(main(['info', '--speed-rpm', '1800', '--json']))")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert run.returncode == 141 and run.stderr == "", run.stderr


def test_info_on_a_trace_says_what_to_do_with_it(tmp_path, capsys):
    trace = tmp_path / "run_1800.trace.h5"
    trace.write_bytes(b"\x89HDF\r\n\x1a\n")
    assert main(["info", str(trace)]) == 1
    err = capsys.readouterr().err
    assert "is a trace, not a video" in err and "cageless compare" in err and "read_trace" in err


@pytest.mark.parametrize("typed", [[], ["--speed-rpm", "3000"]])
def test_tracking_a_trace_says_it_is_a_trace(tmp_path, capsys, typed):
    """`cageless track run.trace.h5`: told it is a trace and what takes one, not that its name holds no
    conditions, and nothing is tracked (the tracker is not even compiled)."""
    trace = tmp_path / "sim_3000rpm_Fr500.trace.h5"
    trace.write_bytes(b"\x89HDF\r\n\x1a\n")
    assert main(["track", str(trace), "-o", str(tmp_path / "out"), *typed]) == 1
    err = capsys.readouterr().err
    assert "is a trace, not a video" in err and "cageless compare" in err and "cageless report" in err
    assert "conditions" not in err and "token" not in err and "compiling" not in err
    assert not list((tmp_path / "out").glob("*.trace.h5"))


def test_tracking_an_output_folder_says_so(tmp_path, capsys):
    """`cageless track out` (an output folder by mistake): its QC PNGs are not read as an image sequence."""
    out = tmp_path / "out"
    (out / "qc").mkdir(parents=True)
    (out / "clip.trace.h5").write_bytes(b"")
    (out / "qc" / "clip.candidates.csv").write_text("frame,x,y\n")
    (out / "qc" / "clip.frame000086.png").write_bytes(b"")
    assert main(["track", str(out), "-o", str(tmp_path / "o1"), "-q"]) == 1
    err = capsys.readouterr().err
    assert err == f"FAILED {out}: no videos found in this folder. It holds cageless traces: point at the folder of " \
                  "videos instead.\n"
    assert main(["track", str(out / "qc"), "-o", str(tmp_path / "o2"), "-q"]) == 1
    assert "is the QC folder of a cageless output" in capsys.readouterr().err


def test_failed_lines_name_videos_relative_to_their_folder(tmp_path, capsys):
    """Every line of a folder run names the video as the report does (relative to the folder); a video given
    on its own is named as typed."""
    lab = tmp_path / "lab"
    lab.mkdir()
    (lab / "n3000_Fr500.cine").write_bytes(b"NOPE" * 20)  # fails while tracking
    (lab / "mystery.cine").write_bytes(b"NOPE" * 20)  # fails before: no conditions
    assert main(["track", str(lab), "-o", str(tmp_path / "o"), "-q"]) == 1
    err = capsys.readouterr().err.splitlines()
    assert sorted(line.split(":")[0] for line in err) == ["FAILED mystery.cine", "FAILED n3000_Fr500.cine"]
    assert main(["track", str(lab / "n3000_Fr500.cine"), "-o", str(tmp_path / "o"), "-q"]) == 1
    assert capsys.readouterr().err.startswith(f"FAILED {lab / 'n3000_Fr500.cine'}: wrong magic bytes")


def test_a_scheduler_without_dask_distributed_is_a_usage_error(tmp_path, capsys, monkeypatch):
    """`--scheduler` when Dask's distributed is missing: exit 2 before any work, no output folder."""
    monkeypatch.setitem(sys.modules, "distributed", None)  # import distributed -> ImportError
    out = tmp_path / "r"
    assert main(["report", str(tmp_path), "-o", str(out), "--scheduler", "tcp://10.0.0.5:8786"]) == 2
    err = capsys.readouterr().err
    assert "--scheduler tcp://10.0.0.5:8786: needs Dask's distributed package" in err and "cageless[dask]" in err
    assert not out.exists()


def test_two_videos_sharing_a_name_are_refused_not_overwritten(tmp_path, capsys):
    """x.cine and x.mkv would both write x.trace.h5: both fail with the reason, nothing is overwritten."""
    lab = tmp_path / "lab"
    lab.mkdir()
    for name in ("x.cine", "x.mkv"):
        (lab / name).write_bytes(b"NOPE" * 20)
    (lab / "conditions.csv").write_text("file,speed_rpm\nx.cine,6000\nx.mkv,3000\n")
    assert main(["track", str(lab), "-o", str(tmp_path / "o"), "-q"]) == 1
    err = [line for line in capsys.readouterr().err.splitlines() if not line.startswith("WARNING: ")]  # 0 N loads
    assert len(err) == 2 and all("their traces would overwrite each other (x.trace.h5)" in line for line in err)
    assert not list((tmp_path / "o").glob("*.trace.h5"))


def test_a_config_entry_satisfies_a_required_option(tmp_path, capsys):
    """`[simulate] speed_rpm = 3000` gives simulate's required --speed-rpm (the command line still wins:
    test_config_file)."""
    cfg = tmp_path / "c.toml"
    cfg.write_text("[simulate]\nspeed_rpm = 3000\nradial_load_n = 500\n")
    assert main(["simulate", "--config", str(cfg), "--explain", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["level"] == "planar"
    assert main(["simulate", f"--config={cfg}", "--explain"]) == 0
    assert main(["simulate", "--explain"]) == 2  # without the file it is still required
    assert "--speed-rpm" in capsys.readouterr().err


def test_compare_given_a_video_says_to_track_it(tmp_path, capsys):
    video = tmp_path / "clip.mkv"
    video.write_bytes(b"\x1aE\xdf\xa3" + b"\x00" * 60)
    assert main(["compare", str(video), str(video)]) == 1
    err = capsys.readouterr().err
    assert "clip.mkv: is a video, not a trace" in err and "cageless track" in err and "HDF5" not in err


def test_progress_bars_only_on_a_terminal(tmp_path, capsys, monkeypatch):
    """Standard error in a file or a pipe gets the result lines, not the bar's redraws (a new user's trial
    found each `ok`/`FAILED` line followed by another copy of the bar); on a terminal the bar is drawn."""
    import cageless.app.cli as cli

    lab = tmp_path / "lab"
    lab.mkdir()
    for name in ("n3000_Fr500.cine", "n1800_Fr500.cine"):
        (lab / name).write_bytes(b"NOPE" * 20)  # each fails while tracking, after the bar is drawn
    assert main(["track", str(lab), "-o", str(tmp_path / "o")]) == 1
    err = capsys.readouterr().err
    assert "videos:" not in err and "\r" not in err, err
    lines = [line.split(":")[0] for line in err.splitlines() if not line.startswith("compiling the tracker")]
    assert lines == ["FAILED n1800_Fr500.cine", "FAILED n3000_Fr500.cine"]  # and a first compile's notice, if due
    monkeypatch.setattr(cli, "_on_terminal", lambda stream: True)
    assert main(["track", str(lab), "-o", str(tmp_path / "o2")]) == 1
    assert "videos: 100%" in capsys.readouterr().err


def test_failed_lines_name_each_video_once_in_a_folder_with_spaces_and_links(tmp_path, capsys):
    """A lab folder whose path holds spaces and non-ASCII letters, with a video that is a symbolic link to a
    file elsewhere: the FAILED line names the video once, relative to the folder (it named the full path,
    twice: 'FAILED /x/my lab/a.cine: /x/my lab/a.cine: wrong magic bytes', a new user's trial)."""
    store = tmp_path / "camera store"
    store.mkdir()
    (store / "raw 17.cine").write_bytes(b"NOPE" * 20)
    lab = tmp_path / "Prüfstand lab — 2026"
    lab.mkdir()
    (lab / "n3000_Fr500.cine").write_bytes(b"NOPE" * 20)
    (lab / "n6000_Fr500 link.cine").symlink_to(store / "raw 17.cine")
    assert main(["track", str(lab), "-o", str(tmp_path / "o"), "-q"]) == 1
    err = sorted(capsys.readouterr().err.splitlines())
    assert [line.split(": ", 1)[0] for line in err] == ["FAILED n3000_Fr500.cine", "FAILED n6000_Fr500 link.cine"]
    assert all(line.split(": ", 1)[1].startswith("wrong magic bytes") for line in err), err
