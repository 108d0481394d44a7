"""The catalogue's rows about bad input files (issue 17): the weak messages made clear, and the classes of
input that already held (corrupt cine, PNG, sidecar and CSV; mixed lab folders), kept as cases."""

from __future__ import annotations

import shutil
import struct
import subprocess
import sys
from pathlib import Path

import h5py
import numpy as np
import pytest
from faultlib import assert_clean, cli, flip_bits, parts

from cageless.bearing import default_bearing
from cageless.tracking.io import write_cine
from cageless.tracking.io.cine import CineReader
from cageless.tracking.io.cine_layout import SETUP_FIELDS
from cageless.tracking.synthetic.camera import Appearance, Camera
from cageless.tracking.synthetic.clip import render_clip
from cageless.tracking.synthetic.motion import KinematicLaw
from cageless.tracking.synthetic.render import Renderer

G = default_bearing().geometry
SMALL = Camera(width=320, height=200, px_per_mm=3.125, bit_depth=8)


def _clip(path: Path, n: int = 40, fmt: str = "cine-8") -> Path:
    return render_clip(path, Renderer(G, SMALL, Appearance(), seed=7), n, law=KinematicLaw(G, 3000, seed=7),
                       fmt=fmt)["video"]


@pytest.fixture(scope="module")
def cine40(tmp_path_factory) -> Path:
    return _clip(tmp_path_factory.mktemp("cine") / "n3000_Fr500.cine")


@pytest.fixture(scope="module")
def png30(tmp_path_factory) -> Path:
    return _clip(tmp_path_factory.mktemp("png") / "n3000_Fr500", n=30, fmt="png")


# -- the weak messages made clear -------------------------------------------------------------------------

def test_r16_stated_speed_is_checked_against_the_video(tmp_path, capsys, mini_lab):
    """The 3000 r/min clip stated as 2800 r/min: QC warns (speed mismatch and negative slip), never silent;
    stated as 2500 r/min its balls orbit at 1.17 x the cage speed, outside what a ball can do: refused."""
    lab = tmp_path / "lab"
    shutil.copytree(mini_lab, lab)
    (lab / "clip_3000rpm.toml").write_text("speed_rpm = 2800\n")
    run = cli(capsys, "track", lab, "-o", tmp_path / "o", "--workers", "1", "-q")
    assert_clean(run, 0, "the stated speed 2800 r/min disagrees with the video", "check speed_rpm",
                 "negative slip")
    (lab / "clip_3000rpm.toml").write_text("speed_rpm = 2500\n")
    run = cli(capsys, "track", lab, "-o", tmp_path / "o3", "--workers", "1", "-q")
    assert_clean(run, 1, "clip_3000rpm.mkv", "outside the plausible 0.6-1.1", "Check speed_rpm")
    assert not list((tmp_path / "o3").glob("*.trace.h5"))
    # and at its true speed: no such warning (the synthetic law's loaded zone runs ~5 % fast; the limit is 8 %)
    (lab / "clip_3000rpm.toml").unlink()
    run = cli(capsys, "track", lab, "-o", tmp_path / "o2", "--workers", "1", "-q")
    assert_clean(run, 0)
    assert "disagrees" not in run.text and "negative slip" not in run.text


def test_r26_a_bit_flipped_trace_given_to_compare(tmp_path, capsys, video_trace, sim_trace):
    bad = tmp_path / "flipped.trace.h5"
    shutil.copy(sim_trace, bad)
    flip_bits(bad, n=400)
    run = cli(capsys, "compare", video_trace, bad)
    assert_clean(run, 1, "flipped.trace.h5")
    assert run.err.startswith("error: ") and run.err.count("\n") == 1


def test_r31_truncated_cine_has_a_cli_flag(tmp_path, capsys, cine40):
    lab = tmp_path / "lab"
    lab.mkdir()
    cut = lab / "n3000_Fr500.cine"
    data = cine40.read_bytes()
    cut.write_bytes(data[: len(data) - 6 * 320 * 200])  # the last six frames cut off
    run = cli(capsys, "track", cut, "-o", tmp_path / "o", "--workers", "1", "-q")
    assert_clean(run, 1, "n3000_Fr500.cine", "is truncated", "--allow-truncated")
    assert "allow_truncated=True" not in run.text
    run = cli(capsys, "track", cut, "-o", tmp_path / "o", "--workers", "1", "-q", "--allow-truncated")
    assert_clean(run, 0, "frames", "truncated; using its 34 complete frames of 40 (6 dropped)")
    assert (tmp_path / "o" / "n3000_Fr500.trace.h5").is_file()
    run = cli(capsys, "info", cut)  # the hint names a flag that info also takes
    assert_clean(run, 1, "is truncated", "--allow-truncated")
    run = cli(capsys, "info", cut, "--allow-truncated")
    assert_clean(run, 0, "frames            34")
    # report's track jobs take the flag too (its failed row gives the same hint)
    from cageless.app.lab import _track_job
    from cageless.conditions import OperatingConditions
    from cageless.config import bearing_from_config

    job = (str(cut), OperatingConditions(speed_rpm=3000.0, radial_load_n=500.0), bearing_from_config({}),
           str(tmp_path / "r"), None)
    status, why = _track_job(*job)
    assert status == "failed" and "--allow-truncated" in why
    status, path = _track_job(*job, True)
    assert status == "ok" and Path(path).is_file()


def test_r32_png_sequence_with_a_missing_frame_names_it(tmp_path, capsys, png30):
    seq = tmp_path / "n3000_Fr500"
    shutil.copytree(png30, seq)
    (seq / "frame_000012.png").unlink()
    run = cli(capsys, "track", seq, "-o", tmp_path / "o", "--fps", "10000", "-q")
    assert_clean(run, 1, "frame_000012.png", "is missing", "from 11", "to 13")
    assert not list(tmp_path.rglob("*.trace.h5"))


def test_r33_png_sequence_with_a_stray_frame_names_it(tmp_path, capsys, png30):
    seq = tmp_path / "n3000_Fr500"
    shutil.copytree(png30, seq)
    shutil.copy(seq / "frame_000003.png", seq / "scan7.png")
    run = cli(capsys, "track", seq, "-o", tmp_path / "o", "--fps", "10000", "-q")
    assert_clean(run, 1, "scan7.png", "does not belong to the sequence")


@pytest.mark.parametrize("text", [
    "file;speed_rpm;radial_load_n;axial_load_n;fps\nclip_3000rpm.mkv;3000;500,0;0;10000\n",
    "file;speed_rpm;radial_load_n;axial_load_n;fps\nclip_3000rpm.mkv;3000;500;0;10000\n",
], ids=["decimal-commas", "semicolons"])
def test_r34_semicolon_csv_is_read(tmp_path, capsys, mini_lab, text):
    from cageless.conditions import read_conditions_csv

    lab = tmp_path / "lab"
    shutil.copytree(mini_lab, lab)
    (lab / "conditions.csv").write_text(text)
    assert read_conditions_csv(lab / "conditions.csv") == {
        "clip_3000rpm.mkv": {"speed_rpm": 3000.0, "radial_load_n": 500.0, "axial_load_n": 0.0, "fps": 10000.0}}


def test_r34_unreadable_csv_says_what_was_found(tmp_path, capsys, mini_lab):
    lab = tmp_path / "lab"
    shutil.copytree(mini_lab, lab)
    (lab / "conditions.csv").write_text("video|rpm\nclip_3000rpm.mkv|3000\n")
    run = cli(capsys, "track", lab, "-o", tmp_path / "o", "-q")
    assert_clean(run, 1, "conditions.csv", "missing column 'file'", "the header has 'video|rpm'")


def test_r35_extra_csv_column_is_ignored_with_a_warning(tmp_path, capsys, mini_lab, caplog):
    from cageless.conditions import read_conditions_csv

    csv = tmp_path / "conditions.csv"
    csv.write_text("file,speed_rpm,operator\nclip_3000rpm.mkv,3000,bob\n")
    with caplog.at_level("WARNING"):
        assert read_conditions_csv(csv) == {"clip_3000rpm.mkv": {"speed_rpm": 3000.0}}
    assert "ignoring column 'operator'" in caplog.text and "radial_load_n" in caplog.text
    csv.write_text("file,speed_rpm,radial_lod_n\nclip_3000rpm.mkv,3000,500\n")  # a typo loses a value: refused
    from cageless.errors import ConditionsError

    with pytest.raises(ConditionsError, match="radial_lod_n.*Did you mean 'radial_load_n'"):
        read_conditions_csv(csv)


def test_r36_cine_realbpp_7_is_refused(tmp_path, capsys, cine40):
    bad = tmp_path / "n3000_Fr500.cine"
    data = bytearray(cine40.read_bytes())
    with CineReader(cine40) as r:
        offset = r.header["off_setup"] + SETUP_FIELDS["real_bpp"][0]
    struct.pack_into("<I", data, offset, 7)
    bad.write_bytes(bytes(data))
    run = cli(capsys, "info", bad)
    assert_clean(run, 1, "n3000_Fr500.cine", "7 significant bits", "RealBPP", f"byte offset {offset}")


def test_r36_packed_cine_realbpp_7_is_refused(tmp_path, capsys):
    """The bundled 6000 rpm clip is packed 12-bit (P12L); a RealBPP of 7 there is as corrupt as anywhere."""
    src = Path(__file__).resolve().parents[2] / "sample_data" / "lab" / "n6000_Fr500_Fa0.cine"
    bad = tmp_path / "n6000_Fr500.cine"
    data = bytearray(src.read_bytes())
    with CineReader(src) as r:
        assert r.metadata.to_dict()["bit_depth"] == 12
        offset = r.header["off_setup"] + SETUP_FIELDS["real_bpp"][0]
    struct.pack_into("<I", data, offset, 7)
    bad.write_bytes(bytes(data))
    run = cli(capsys, "info", bad)
    assert_clean(run, 1, "n6000_Fr500.cine", "7 significant bits", "packed 12-bit")


def test_r37_dangling_symlink_in_a_lab_is_reported(tmp_path, capsys, mini_lab):
    lab = tmp_path / "lab"
    shutil.copytree(mini_lab, lab)
    (lab / "n1800_Fr500.cine").symlink_to(tmp_path / "gone.cine")
    run = cli(capsys, "track", lab, "-o", tmp_path / "o", "--workers", "1", "-q")
    assert_clean(run, 1, "n1800_Fr500.cine", "broken symbolic link", "gone.cine", "ok     clip_3000rpm.mkv")


def test_r39_old_trace_schema_is_refused(tmp_path, capsys, video_trace, sim_trace):
    old = tmp_path / "old.trace.h5"
    shutil.copy(video_trace, old)
    with h5py.File(old, "r+") as f:
        f.attrs["schema"] = "cageless-trace/0"
    run = cli(capsys, "compare", old, sim_trace)
    assert_clean(run, 1, "old.trace.h5", "cageless-trace/0", "older than this cageless reads")


def test_r40_compare_given_a_folder(tmp_path, capsys, sim_trace):
    run = cli(capsys, "compare", tmp_path, sim_trace)
    assert_clean(run, 1, str(tmp_path), "is a folder, not a trace file")
    assert "does not exist" not in run.text


# -- the classes of input that already held ---------------------------------------------------------------

def _cut_header(p: Path) -> None:
    p.write_bytes(p.read_bytes()[:30])


def _wrong_magic(p: Path) -> None:
    data = bytearray(p.read_bytes())
    data[0:2] = b"XX"
    p.write_bytes(bytes(data))


def _zero_frames(p: Path) -> None:
    data = bytearray(p.read_bytes())
    struct.pack_into("<I", data, 20, 0)
    p.write_bytes(bytes(data))


def _colour(p: Path) -> None:
    data = bytearray(p.read_bytes())
    with CineReader(p) as r:
        offset = r.header["off_image_header"] + 14
    struct.pack_into("<H", data, offset, 24)
    p.write_bytes(bytes(data))


@pytest.mark.parametrize(("damage", "needle"), [
    (_cut_header, "too short"), (_wrong_magic, "wrong magic bytes"), (_zero_frames, "zero frames"),
    (_colour, "colour cine"),
], ids=["held-cine-header-cut", "held-cine-wrong-magic", "held-cine-zero-frames", "held-cine-colour"])
def test_held_corrupt_cine(tmp_path, capsys, cine40, damage, needle):
    bad = tmp_path / "n3000_Fr500.cine"
    shutil.copy(cine40, bad)
    damage(bad)
    run = cli(capsys, "track", bad, "-o", tmp_path / "o", "--workers", "1", "-q")
    assert_clean(run, 1, "n3000_Fr500.cine", needle)
    assert not list(tmp_path.rglob("*.trace.h5")) and not parts(tmp_path)


@pytest.mark.parametrize(("name", "text", "needle"), [
    ("clip_3000rpm.toml", "speed_rpm = = 3\n", "cannot parse the sidecar"),
    ("clip_3000rpm.toml", "speed_rmp = 3000\n", "unknown key 'speed_rmp'"),
    ("clip_3000rpm.json", '{"speed_rpm": "fast"}', "'speed_rpm' must be a number"),
    ("conditions.csv", "file,radial_load_n\nclip_3000rpm.mkv,500\n", "missing column 'speed_rpm'"),
    ("conditions.csv", "file,speed_rpm\nclip_3000rpm.mkv,3000\nclip_3000rpm.mkv,3000\n", "listed twice"),
    ("conditions.csv", "file,speed_rpm\nclip_3000rpm.mkv,fast\n", "is not a number"),
    ("conditions.csv", "file,speed_rpm\nclip_3000rpm.mkv,-3000\n", "must be > 0"),
], ids=["held-sidecar-syntax", "held-sidecar-unknown-key", "held-sidecar-not-a-number", "held-csv-missing-speed",
        "held-csv-duplicate", "held-csv-not-a-number", "held-csv-negative-speed"])
def test_held_bad_conditions(tmp_path, capsys, mini_lab, name, text, needle):
    lab = tmp_path / "lab"
    shutil.copytree(mini_lab, lab)
    (lab / name).write_text(text)
    run = cli(capsys, "track", lab, "-o", tmp_path / "o", "-q")
    assert_clean(run, 1, "FAILED", name, needle)
    assert not list(tmp_path.rglob("*.trace.h5"))
    assert not (tmp_path / "o").exists()  # nothing was written: no empty output folder either


def test_held_damaged_png(tmp_path, capsys, png30):
    seq = tmp_path / "n3000_Fr500"
    shutil.copytree(png30, seq)
    (seq / "frame_000007.png").write_bytes(b"\x89PNG broken")
    run = cli(capsys, "track", seq, "-o", tmp_path / "o", "--fps", "10000", "-q")
    assert_clean(run, 1, "frame_000007.png", "cannot be read as an image")


def test_held_mixed_lab_folder_finishes_the_rest(tmp_path, capsys, mini_lab, cine40):
    lab = tmp_path / "lab"
    shutil.copytree(mini_lab, lab)
    shutil.copy(cine40, lab / "n3000_Fr500.cine")
    _wrong_magic(lab / "n3000_Fr500.cine")
    (lab / "mystery.avi").write_bytes(b"\0" * 100)
    run = cli(capsys, "track", lab, "-o", tmp_path / "o", "--workers", "1", "-q")
    assert_clean(run, 1, "FAILED n3000_Fr500.cine", "wrong magic", "mystery.avi: no operating conditions found",
                 "ok     clip_3000rpm.mkv")
    assert (tmp_path / "o" / "clip_3000rpm.trace.h5").is_file()


@pytest.mark.parametrize(("argv", "needle"), [
    (["track", "{tmp}/nowhere.cine", "-o", "{tmp}/o"], "no such file or folder"),
    (["track", "{tmp}/notes.txt", "-o", "{tmp}/o", "--speed-rpm", "3000"], "is not a video cageless reads"),
    (["info", "{tmp}/notes.txt"], "is not a video cageless reads"),
    (["compare", "{tmp}/nowhere.trace.h5", "{tmp}/nowhere.trace.h5"], "does not exist"),
    (["report", "{tmp}/empty", "-o", "{tmp}/o"], "no videos found"),
], ids=["held-missing-video", "held-unknown-suffix", "held-info-unknown-suffix", "held-compare-missing",
        "held-report-empty-folder"])
def test_held_missing_and_unknown_inputs(tmp_path, capsys, argv, needle):
    (tmp_path / "notes.txt").write_text("x")
    (tmp_path / "empty").mkdir()
    run = cli(capsys, *[a.replace("{tmp}", str(tmp_path)) for a in argv])
    assert_clean(run, 1, needle)


def test_held_determinism_of_a_corrupt_free_rerun(tmp_path, capsys, mini_lab):
    """The same input tracked twice gives the same numbers (the trace's datasets byte for byte)."""
    a, b = tmp_path / "a", tmp_path / "b"
    for out in (a, b):
        assert_clean(cli(capsys, "track", mini_lab, "-o", out, "--workers", "1", "-q"), 0)
    with h5py.File(a / "clip_3000rpm.trace.h5") as fa, h5py.File(b / "clip_3000rpm.trace.h5") as fb:
        for name in ("time", "angle", "speed", "slip", "valid"):
            assert np.array_equal(fa[name][()], fb[name][()])


def test_held_write_cine_roundtrip_is_untouched_by_checks(tmp_path):
    """The RealBPP check accepts every depth write_cine makes (8-bit and 16-bit words)."""
    frames = np.zeros((3, 8, 8), np.uint16)
    for fmt in ("8", "16"):
        p = write_cine(tmp_path / f"x{fmt}.cine", frames.astype(np.uint8 if fmt == "8" else np.uint16),
                       fps=1000, fmt=fmt)
        with CineReader(p) as r:
            assert len(r) == 3


def test_a_cine_renamed_avi_gives_one_clean_line(tmp_path, capsys):
    """A new user's check: OpenCV's own console warning must not leak past the one-line error."""
    src = Path(__file__).resolve().parents[2] / "sample_data" / "lab" / "n6000_Fr500_Fa0.cine"
    bad = tmp_path / "n6000_Fr500.avi"
    shutil.copy(src, bad)
    # OpenCV writes to the process's stderr, below Python's: run the command in its own process
    run = subprocess.run([sys.executable, "-m", "cageless", "track", str(bad), "-o", str(tmp_path / "o"),
                          "--workers", "1", "-q"], capture_output=True, text=True, timeout=300)
    assert run.returncode == 1 and "n6000_Fr500.avi" in run.stdout + run.stderr
    assert "[ WARN" not in run.stderr and "Traceback" not in run.stderr


def test_an_empty_mp4_gives_one_line_not_ffmpegs_too(tmp_path):
    """FFmpeg's own "moov atom not found" went to the terminal before cageless's error about the same file."""
    from faultlib import cli_subprocess

    empty = tmp_path / "empty.mp4"
    empty.write_bytes(b"")
    run = cli_subprocess("info", empty)
    assert_clean(run, 1, "OpenCV cannot open this video")
    assert run.err.count("\n") == 1 and "moov atom" not in run.err, run.err


def test_a_typed_speed_wins_for_a_named_video_and_is_said_to_lose_in_a_folder(tmp_path, capsys, cine40):
    """`--speed-rpm` on a video named on the command line overrides its file name, and says so (a new user typed
    3000 for n6000_*.cine and had to rename the file); in a folder the videos' own conditions win, and the run says
    the typed value is not used (an earlier user got 6000 without a word)."""
    from cageless.app.cli.track import collect_inputs
    from cageless.errors import ConditionsError

    clip = tmp_path / "n6000_Fr500.cine"
    shutil.copy(cine40, clip)
    (entry,) = collect_inputs([str(clip)], 3000.0)
    assert entry.resolved.conditions.speed_rpm == 3000.0
    assert entry.resolved.conditions.radial_load_n == 500.0  # the other keys still come from the name
    assert entry.resolved.origin["speed_rpm"] == "--speed-rpm"
    assert "--speed-rpm 3000 overrides 6000 r/min from its file name" in capsys.readouterr().err
    (entry,) = collect_inputs([str(tmp_path)], 3000.0)
    assert entry.resolved.conditions.speed_rpm == 6000.0
    assert "--speed-rpm 3000 is not used: its file name gives 6000 r/min" in capsys.readouterr().err
    collect_inputs([str(clip)], 6000.0)  # the same value: nothing to say
    assert capsys.readouterr().err == ""
    (clip.with_suffix(".toml")).write_text("speed_rpm = = 1\n")  # a malformed sidecar stays an error
    (entry,) = collect_inputs([str(clip)], 3000.0)
    assert not entry.ok and isinstance(entry.error, ConditionsError)


def test_a_typed_speed_keeps_the_other_conditions_a_sidecar_gives(tmp_path, capsys, cine40):
    """A video whose sidecar gives its loads but no speed takes the typed speed and keeps the loads, named or in a
    folder (a review found both dropped silently: the typed speed replaced the whole entry)."""
    from cageless.app.cli.track import collect_inputs

    clip = tmp_path / "clip.cine"
    shutil.copy(cine40, clip)
    clip.with_suffix(".toml").write_text("radial_load_n = 500\naxial_load_n = 20\n")
    for given in ([str(clip)], [str(tmp_path)]):
        (entry,) = collect_inputs(given, 3000.0)
        c = entry.resolved.conditions
        assert (c.speed_rpm, c.radial_load_n, c.axial_load_n) == (3000.0, 500.0, 20.0)
        assert entry.resolved.origin["speed_rpm"] == "--speed-rpm"
        assert entry.resolved.origin["radial_load_n"] == "sidecar clip.toml"
    assert capsys.readouterr().err == ""  # nothing overridden, nothing to say

def test_typed_loads_fill_in_or_override_like_the_typed_speed(tmp_path, capsys, caplog, cine40):
    """`--radial-load-n` / `--axial-load-n` behave as `--speed-rpm`: a video with only a speed gets the typed
    load (a new user's `track clip --speed-rpm 3000` recorded 0 N, and `compare` against the 500 N simulation of
    the README's quick start refused the pair); a named video's own load is overridden with a warning; in a
    folder the video's own load wins. A video with no radial load anywhere is resolved at 0 N with a warning."""
    from cageless.app.cli.track import collect_inputs

    clip = tmp_path / "n3000.cine"
    shutil.copy(cine40, clip)
    with caplog.at_level("WARNING"):
        (entry,) = collect_inputs([str(clip)], None)
    assert entry.resolved.conditions.radial_load_n == 0.0
    assert "no radial load given: 0 N (an unloaded bearing) is assumed" in caplog.text
    caplog.clear()
    with caplog.at_level("WARNING"):
        (entry,) = collect_inputs([str(clip)], None, {"radial_load_n": 500.0, "axial_load_n": None})
    c = entry.resolved.conditions
    assert (c.speed_rpm, c.radial_load_n, c.axial_load_n) == (3000.0, 500.0, 0.0)
    assert entry.resolved.origin["radial_load_n"] == "--radial-load-n"
    assert "no radial load" not in caplog.text and "--radial-load-n" not in capsys.readouterr().err
    named = tmp_path / "n3000_Fr1000.cine"
    clip.rename(named)
    (entry,) = collect_inputs([str(named)], None, {"radial_load_n": 500.0})
    assert entry.resolved.conditions.radial_load_n == 500.0
    assert "--radial-load-n 500 overrides 1000 N from its file name" in capsys.readouterr().err
    (entry,) = collect_inputs([str(tmp_path)], None, {"radial_load_n": 500.0})
    assert entry.resolved.conditions.radial_load_n == 1000.0
    assert "--radial-load-n 500 is not used: its file name gives 1000 N" in capsys.readouterr().err


def test_a_cine_with_no_complete_frame_does_not_suggest_allow_truncated(tmp_path, capsys, cine40):
    """Cut before its first frame's pixels, `--allow-truncated` cannot help, and the error says so instead of
    suggesting the flag it was given (a new user's trial); cut inside the headers, it says to re-copy the file."""
    data = cine40.read_bytes()
    cut = tmp_path / "n3000_Fr500.cine"
    cut.write_bytes(data[: len(data) - 40 * 320 * 200 + 100])  # every frame's pixels cut off
    run = cli(capsys, "info", cut, "--allow-truncated")
    assert_clean(run, 1, "is truncated", "Not one frame is complete, so --allow-truncated cannot help")
    cut.write_bytes(data[:300])
    run = cli(capsys, "info", cut)
    assert_clean(run, 1, "lies past the end of the file", "re-copy it")


def test_compare_given_the_traces_the_other_way_round_swaps_them(capsys, video_trace, sim_trace):
    """A new user's trial typed the simulation first: the traces say which is which, so the run swaps them with a
    warning and prints the same row as the right order."""
    right = cli(capsys, "compare", video_trace, sim_trace, "--settle", "0")
    swapped = cli(capsys, "compare", sim_trace, video_trace, "--settle", "0")
    assert right.code == 0 and swapped.code == 0, swapped.text
    assert "is the simulation and" in swapped.text and "is the simulation and" not in right.text
    row = [ln for ln in right.text.splitlines() if ln.startswith("| ")][-1]
    assert row in swapped.text
    assert float(row.split("|")[5].split("±")[0]) > 0  # the theoretical slip (%), in the row the two share


@pytest.mark.parametrize("command", ["report", "track"])
def test_held_videos_only_in_a_sub_folder_are_named(tmp_path, capsys, command):
    """A lab folder whose clips sit in a sub-folder (newuser2's trial: 'day1/'): the refusal says where they are
    and how to include them, instead of only "no videos found"."""
    (tmp_path / "lab" / "day1").mkdir(parents=True)
    (tmp_path / "lab" / "day1" / "n3000_Fr500_Fa0.cine").write_bytes(b"\0" * 64)
    run = cli(capsys, command, tmp_path / "lab", "-o", tmp_path / "o", "-q")
    assert_clean(run, 1, "no videos found", "'day1' (1 video)", str(tmp_path / "lab" / "day1"))


def test_held_videos_in_a_sub_folder_beside_others_are_not_skipped_silently(tmp_path, caplog):
    """Videos at the top level are read and a sub-folder's are not: a warning names the sub-folder."""
    from cageless.conditions import discover_lab

    lab = tmp_path / "lab"
    (lab / "old runs").mkdir(parents=True)
    (lab / "n3000_Fr500_Fa0.avi").write_bytes(b"\0" * 64)
    for name in ("a.cine", "b.cine"):
        (lab / "old runs" / name).write_bytes(b"\0" * 64)
    (lab / "notes").mkdir()
    (lab / "notes" / "log.txt").write_text("x")
    with caplog.at_level("WARNING", logger="cageless.conditions"):
        entries = discover_lab(lab)
    assert [e.video.name for e in entries] == ["n3000_Fr500_Fa0.avi"]
    assert "'old runs' (2 videos)" in caplog.text and "notes" not in caplog.text


def test_held_a_frame_rate_stated_too_low_is_named(tmp_path, capsys, mini_lab):
    """newuser2's trial: an AVI's container holds at most 1000 frames/s, so a 16,000 frames/s recording tracked
    without its rate looks static and is refused with "0 balls found"; the message named the lighting, the speed
    and the scale but not the frame rate. Here the sample's 10,000 frames/s clip at --fps 1000."""
    run = cli(capsys, "track", mini_lab / "clip_3000rpm.mkv", "--fps", "1000", "-o", tmp_path / "o", "-q")
    assert_clean(run, 1, "0 balls found", "the frame rate (fps", "--fps")
