"""Operating conditions: the three sources, their precedence, and per-file errors (DESIGN §5)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from cageless.conditions import (
    OperatingConditions,
    discover_lab,
    find_videos,
    parse_file_name,
    read_conditions_csv,
    read_sidecar,
    resolve_conditions,
)
from cageless.errors import ConditionsError, ParameterError


def _touch(path: Path) -> Path:
    path.write_bytes(b"\0")
    return path


def test_file_name_pattern(tmp_path):
    assert parse_file_name(tmp_path / "n3000_Fr500_Fa0.cine") == {
        "speed_rpm": 3000.0, "radial_load_n": 500.0, "axial_load_n": 0.0,
    }
    assert parse_file_name(tmp_path / "run2-n1800rpm-Fr1000N.avi") == {"speed_rpm": 1800.0, "radial_load_n": 1000.0}
    assert parse_file_name(tmp_path / "notes_fast.avi") is None


@pytest.mark.parametrize(
    ("name", "match"),
    [
        ("n3000_Fr_Fa0.cine", "token 'Fr'"),
        ("n3k_Fr500.cine", "token 'n3k'"),
        ("n3000_Fr500x.cine", "token 'Fr500x'"),
        ("n3000_n1800.cine", "twice"),
        ("Fr500_Fa0.cine", "no speed"),
    ],
)
def test_unparsable_names_are_errors_naming_the_file(tmp_path, name, match):
    with pytest.raises(ConditionsError, match=match) as err:
        parse_file_name(tmp_path / name)
    assert err.value.path.name == name


def test_sidecar_toml_and_json(tmp_path):
    (tmp_path / "a.toml").write_text("speed_rpm = 6000\nradial_load_n = 500.5\ncamera_roll_deg = -1.5\n")
    assert read_sidecar(tmp_path / "a.toml") == {"speed_rpm": 6000.0, "radial_load_n": 500.5, "camera_roll_deg": -1.5}
    (tmp_path / "b.json").write_text(json.dumps({"speed_rpm": 1800, "fps": 10000}))
    assert read_sidecar(tmp_path / "b.json") == {"speed_rpm": 1800.0, "fps": 10000.0}


@pytest.mark.parametrize(
    ("name", "text", "match"),
    [
        ("bad.toml", "speed_rpm = = 3", "cannot parse"),
        ("bad.json", "{speed_rpm: 3}", "cannot parse"),
        ("typo.toml", "speed_rmp = 3000", "Did you mean 'speed_rpm'"),
        ("str.toml", 'speed_rpm = "fast"', "must be a number"),
        ("list.json", "[1, 2]", "table of condition keys"),
    ],
)
def test_malformed_sidecars(tmp_path, name, text, match):
    (tmp_path / name).write_text(text)
    with pytest.raises(ConditionsError, match=match) as err:
        read_sidecar(tmp_path / name)
    assert err.value.path == tmp_path / name


def test_conditions_csv(tmp_path):
    csv = tmp_path / "conditions.csv"
    csv.write_text("file,speed_rpm,radial_load_n,axial_load_n,px_per_mm\na.cine,3000,500,0,\nb,1800,1000,300,12.5\n")
    rows = read_conditions_csv(csv)
    assert rows["a.cine"] == {"speed_rpm": 3000.0, "radial_load_n": 500.0, "axial_load_n": 0.0}
    assert rows["b"]["px_per_mm"] == 12.5


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ("file,radial_load_n\na.cine,500\n", "missing column 'speed_rpm'"),
        ("name,speed_rpm\na.cine,500\n", "missing column 'file'"),
        ("file,speed_rpm,radial_load\na.cine,3000,5\n", "Did you mean 'radial_load_n'"),
        ("file,speed_rpm\na.cine,fast\n", "line 2: 'speed_rpm'"),
        ("file,speed_rpm\na.cine,3000\na.cine,1800\n", "line 3: 'a.cine' is listed twice"),
        ("", "cannot parse"),
    ],
)
def test_malformed_csv(tmp_path, text, match):
    csv = tmp_path / "conditions.csv"
    csv.write_text(text)
    with pytest.raises(ConditionsError, match=match) as err:
        read_conditions_csv(csv)
    assert err.value.path == csv


def test_precedence_is_sidecar_then_csv_then_name(tmp_path):
    video = _touch(tmp_path / "n3000_Fr500_Fa0.cine")
    # Name only.
    r = resolve_conditions(video)
    assert r.conditions == OperatingConditions(3000.0, 500.0, 0.0)
    assert r.origin["speed_rpm"] == "file name"
    # CSV overrides the name, key by key.
    (tmp_path / "conditions.csv").write_text("file,speed_rpm,radial_load_n\nn3000_Fr500_Fa0.cine,3100,\n")
    r = resolve_conditions(video)
    assert (r.conditions.speed_rpm, r.conditions.radial_load_n) == (3100.0, 500.0)
    assert r.origin == {"speed_rpm": "conditions.csv", "radial_load_n": "file name", "axial_load_n": "file name"}
    # The sidecar overrides both.
    (tmp_path / "n3000_Fr500_Fa0.toml").write_text("speed_rpm = 3200\ncamera_roll_deg = 2.0\n")
    r = resolve_conditions(video)
    assert r.conditions.speed_rpm == 3200.0
    assert r.conditions.camera_roll_deg == 2.0
    assert r.conditions.radial_load_n == 500.0
    assert r.origin["speed_rpm"] == "sidecar n3000_Fr500_Fa0.toml"


def test_disagreeing_sources_are_logged(tmp_path, caplog):
    video = _touch(tmp_path / "n3000_Fr500_Fa0.cine")
    (tmp_path / "conditions.csv").write_text("file,speed_rpm,radial_load_n\nn3000_Fr500_Fa0.cine,1800,500\n")
    with caplog.at_level("WARNING", logger="cageless.conditions"):
        r = resolve_conditions(video)
    assert r.conditions.speed_rpm == 1800.0
    # The agreeing load is not reported; the speed is, with both values and both sources.
    assert [m for m in caplog.messages if "overrides" in m] == [
        "n3000_Fr500_Fa0.cine: speed_rpm = 1800 from the conditions.csv overrides 3000 from the file name; "
        "remove one if it is wrong"
    ]


def test_a_bad_csv_row_fails_only_its_video(tmp_path):
    good, bad = _touch(tmp_path / "good.cine"), _touch(tmp_path / "bad.cine")
    (tmp_path / "conditions.csv").write_text("file,speed_rpm\ngood.cine,3000\nbad.cine,fast\n,1800\n")
    entries = {e.video.name: e for e in discover_lab(tmp_path)}
    assert entries["good.cine"].resolved.conditions.speed_rpm == 3000.0
    assert "line 3: 'speed_rpm' = 'fast' is not a number" in str(entries["bad.cine"].error)
    assert resolve_conditions(good).conditions.speed_rpm == 3000.0  # a single video ignores the other row
    with pytest.raises(ConditionsError, match="line 3"):
        resolve_conditions(bad)
    row_errors: dict = {}
    assert read_conditions_csv(tmp_path / "conditions.csv", row_errors) == {"good.cine": {"speed_rpm": 3000.0}}
    assert list(row_errors) == ["bad.cine"]


def test_two_sidecars_are_ambiguous(tmp_path):
    video = _touch(tmp_path / "clip.cine")
    (tmp_path / "clip.toml").write_text("speed_rpm = 1\n")
    (tmp_path / "clip.json").write_text('{"speed_rpm": 2}')
    with pytest.raises(ConditionsError, match="Keep one sidecar"):
        resolve_conditions(video)


def test_no_source_is_a_per_file_error(tmp_path):
    video = _touch(tmp_path / "clip.cine")
    with pytest.raises(ConditionsError, match="no operating conditions found") as err:
        resolve_conditions(video)
    assert err.value.path == video
    assert "clip.toml" in str(err.value)


def test_invalid_values_name_the_source(tmp_path):
    video = _touch(tmp_path / "clip.avi")
    (tmp_path / "clip.json").write_text('{"speed_rpm": -5}')
    with pytest.raises(ConditionsError, match=r"sidecar clip.json.*speed_rpm.*must be > 0"):
        resolve_conditions(video)


def test_operating_conditions_validation():
    with pytest.raises(ParameterError, match="finite"):
        OperatingConditions(math.nan)
    with pytest.raises(ParameterError, match=">= 0"):
        OperatingConditions(3000.0, radial_load_n=-1.0)
    with pytest.raises(ParameterError, match="Did you mean 'axial_load_n'"):
        OperatingConditions.from_mapping({"speed_rpm": 1.0, "axial_load": 3.0})
    assert OperatingConditions(3000).speed_rad_s == pytest.approx(314.159265, rel=1e-8)


def test_lab_folder_one_bad_file_does_not_stop_the_rest(tmp_path):
    _touch(tmp_path / "n1800_Fr500.cine")
    _touch(tmp_path / "mystery.avi")
    _touch(tmp_path / "n6000_Fr500.mp4")
    _touch(tmp_path / "notes.txt")
    seq = tmp_path / "n3000_Fr500"
    seq.mkdir()
    for i in range(3):
        _touch(seq / f"frame_{i:05d}.tif")
    entries = {e.video.name: e for e in discover_lab(tmp_path)}
    assert sorted(entries) == ["mystery.avi", "n1800_Fr500.cine", "n3000_Fr500", "n6000_Fr500.mp4"]
    assert not entries["mystery.avi"].ok
    assert isinstance(entries["mystery.avi"].error, ConditionsError)
    assert entries["n3000_Fr500"].resolved.conditions.speed_rpm == 3000.0
    assert entries["n6000_Fr500.mp4"].resolved.conditions.radial_load_n == 500.0


def test_bad_csv_fails_every_video_with_its_name(tmp_path):
    _touch(tmp_path / "n1800.cine")
    (tmp_path / "conditions.csv").write_text("file\nn1800.cine\n")
    (entry,) = discover_lab(tmp_path)
    assert not entry.ok and "conditions.csv" in str(entry.error)


def test_a_misspelled_csv_column_fails_only_the_videos_the_csv_lists(tmp_path, caplog):
    """A new user's one typo in a column name of conditions.csv failed every video of the folder, even one whose
    sidecar gave all its conditions and which the table did not list."""
    _touch(tmp_path / "n1800.cine")
    _touch(tmp_path / "other.cine")
    (tmp_path / "other.toml").write_text("speed_rpm = 3000\nradial_load_n = 500\n")
    (tmp_path / "conditions.csv").write_text("file,speed_rpm,radial_lod_n\nn1800.cine,1800,500\n")
    with caplog.at_level("WARNING"):
        entries = {e.video.name: e for e in discover_lab(tmp_path)}
    assert not entries["n1800.cine"].ok and "Did you mean 'radial_load_n'" in str(entries["n1800.cine"].error)
    assert entries["other.cine"].resolved.conditions == OperatingConditions(3000.0, 500.0)
    assert "the video it does not list takes its conditions from its other sources" in caplog.text
    assert resolve_conditions(tmp_path / "other.cine").conditions.speed_rpm == 3000.0  # one video: the same
    with pytest.raises(ConditionsError, match="radial_lod_n"):
        resolve_conditions(tmp_path / "n1800.cine")


def test_find_videos_refuses_a_file(tmp_path):
    with pytest.raises(ConditionsError, match="is not a folder"):
        find_videos(_touch(tmp_path / "x.cine"))
    assert find_videos(tmp_path) == [tmp_path / "x.cine"]


def test_sidecar_can_describe_the_bearing(tmp_path):
    """n_balls, ball_diameter_mm and pitch_diameter_mm in a sidecar replace the configured geometry; the
    races follow as d_m -/+ (D + P_d/2) (Harris & Kotzalas, 5th ed., vol. 1, ch. 2)."""
    from cageless.bearing import default_bearing
    from cageless.conditions import bearing_with_keys

    (tmp_path / "n3000.cine").write_bytes(b"")
    (tmp_path / "n3000.toml").write_text("speed_rpm = 3000\nn_balls = 16\nball_diameter_mm = 6.0\n"
                                         "pitch_diameter_mm = 31.0\n")
    r = resolve_conditions(tmp_path / "n3000.cine")
    assert r.conditions == OperatingConditions(3000.0)
    assert r.bearing_keys == {"n_balls": 16.0, "ball_diameter_mm": 6.0, "pitch_diameter_mm": 31.0}
    g = bearing_with_keys(default_bearing(), r).geometry
    assert (g.n_balls, g.ball_diameter_m, g.pitch_diameter_m) == (16, pytest.approx(6e-3), pytest.approx(31e-3))
    assert g.diametral_clearance_m == pytest.approx(default_bearing().geometry.diametral_clearance_m, abs=1e-12)
    assert bearing_with_keys(default_bearing(), resolve_conditions(tmp_path / "n3000.cine")) is not None
    (tmp_path / "n3000.toml").write_text("speed_rpm = 3000\nn_balls = 40\nball_diameter_mm = 6.0\n")
    with pytest.raises(ConditionsError, match=r"n3000.cine.*impossible bearing.*do not fit"):
        bearing_with_keys(default_bearing(), resolve_conditions(tmp_path / "n3000.cine"))
    (tmp_path / "n3000.toml").write_text("speed_rpm = 3000\nn_balls = 12.5\n")
    with pytest.raises(ConditionsError, match=r"n3000.cine.*n_balls = 12.5 must be a whole number"):
        resolve_conditions(tmp_path / "n3000.cine")


def test_a_european_csv_reads_thousands_separators_and_a_misspelled_header_is_named(tmp_path):
    """Semicolons with decimal commas: `3.000` is 3000 r/min, not 3 (a new user's spreadsheet export read as 3
    r/min, inside the plausible range, and failed only later in the ball selection). A misspelled required column
    is named with the column it probably is."""
    from cageless.errors import ConditionsError

    path = tmp_path / "conditions.csv"
    path.write_text("file;speed_rpm;radial_load_n\nclip.cine;3.000;500,5\n", encoding="utf-8")
    assert read_conditions_csv(path) == {"clip.cine": {"speed_rpm": 3000.0, "radial_load_n": 500.5}}
    path.write_text("file,speed_rmp\nclip.cine,3000\n", encoding="utf-8")
    with pytest.raises(ConditionsError, match="Is 'speed_rmp' meant to be 'speed_rpm'"):
        read_conditions_csv(path)


def test_a_european_csv_reads_thousands_beside_a_bad_row(tmp_path):
    """A bad cell in another row (`drei`) leaves the column as text; `6.000` is still 6000 r/min and `500,5`
    still 500.5 N. (It read 6 r/min, inside the plausible range, so the video failed later in the ball
    selection instead: a new user's trial.)"""
    from cageless.errors import ConditionsError

    path = tmp_path / "conditions.csv"
    path.write_text("file;speed_rpm;radial_load_n\na.cine;6.000;500,5\nb.mkv;drei;1.200,25\n", encoding="utf-8")
    errors: dict[str, ConditionsError] = {}
    assert read_conditions_csv(path, row_errors=errors) == {"a.cine": {"speed_rpm": 6000.0, "radial_load_n": 500.5}}
    assert list(errors) == ["b.mkv"] and "'speed_rpm' = 'drei' is not a number" in str(errors["b.mkv"])


@pytest.mark.parametrize(("kwargs", "parameter", "rule"), [
    ({"speed_rpm": 1e9}, "speed_rpm", "must be > 0 and <= 600000 r/min"),
    ({"speed_rpm": -3000.0}, "speed_rpm", "must be > 0 and <= 600000 r/min"),
    ({"speed_rpm": float("nan")}, "speed_rpm", "must be finite"),
    ({"speed_rpm": 3000.0, "radial_load_n": 5e6}, "radial_load_n", "must be >= 0 and <= 1000000 N"),
    ({"speed_rpm": 3000.0, "axial_load_n": -1.0}, "axial_load_n",
     "must be >= 0 and <= 1000000 N (the load direction is fixed by the bearing frame)"),
    ({"speed_rpm": 3000.0, "camera_roll_deg": 400.0}, "camera_roll_deg", "must be >= -360 and <= 360 deg"),
])
def test_conditions_refuse_what_the_command_line_refuses(kwargs, parameter, rule):
    """From Python as on the command line (the same hard rules, cageless.limits.LIMITS): 1e9 r/min was accepted
    by the constructor. The bounds: 600 000 r/min and 1 MN, ten times the plausible ranges (cageless/limits.py)."""
    with pytest.raises(ParameterError) as err:
        OperatingConditions(**kwargs)
    assert err.value.parameter == parameter and err.value.rule == rule


def test_conditions_beyond_the_plausible_range_but_within_the_hard_rule_are_kept():
    """What ``--force`` lets through on the command line, the constructor takes too."""
    c = OperatingConditions(100_000.0, 200_000.0, 0.0)
    assert (c.speed_rpm, c.radial_load_n) == (100_000.0, 200_000.0)
    from cageless.errors import UsageError
    from cageless.validate import check_value

    rule = r"--speed-rpm 1e\+09: must be > 0 and <= 600000 \(the plausible range is 1 to 60000 r/min\)\."
    with pytest.raises(UsageError, match=rule):
        check_value("speed_rpm", 1e9, force=True)
