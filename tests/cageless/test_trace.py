"""The cageless-trace/1 format (DESIGN §4): lossless round trip, atomic writes, strict reader."""

from __future__ import annotations

import json

import h5py
import hypothesis.extra.numpy as hnp
import numpy as np
import pandas as pd
import pytest
from hypothesis import given
from hypothesis import strategies as st

import cageless.trace as trace_mod
from cageless import __version__
from cageless.errors import TraceFormatError
from cageless.trace import SCHEMA, SimulationInfo, Trace, VideoInfo, read_trace, write_trace

VIDEO = VideoInfo(
    fps=10000.0, px_per_mm=12.5, centre_px=(640.25, 399.75), camera_roll_rad=0.01,
    input_file="n3000_Fr500_Fa0.cine", input_sha256="ab" * 32,
)
SIM = SimulationInfo(
    scene_json='{"speed_rpm": 3000}', effects_json='{"gravity": "g != 0"}', solver="dp5",
    rtol=1e-6, atol=1e-9, n_steps=1234, n_rhs=7404, wall_s=1.5,
)


def make_trace(t: int = 5, z: int = 14, source: str = "video", rng=None, **kw) -> Trace:
    rng = rng or np.random.default_rng(0)
    base = dict(
        source=source, time=np.arange(t) * 1e-4, angle=rng.normal(size=(t, z)),
        speed=rng.normal(size=(t, z)), slip=rng.normal(size=(t, z)), valid=rng.random((t, z)) > 0.1,
        speed_rpm=3000.0, radial_load_n=500.0, axial_load_n=0.0,
        ball_diameter_m=9.525e-3, pitch_diameter_m=46.005e-3, config={"tracking": {"window": 11}},
        video=VIDEO if source == "video" else None, simulation=SIM if source == "simulation" else None,
    )
    base.update(kw)
    return Trace(**base)


def assert_same(a: Trace, b: Trace) -> None:
    for name in ("time", "angle", "speed", "slip", "valid"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
        assert getattr(a, name).dtype == getattr(b, name).dtype
    for name in ("source", "speed_rpm", "radial_load_n", "axial_load_n", "ball_diameter_m",
                 "pitch_diameter_m", "direction", "config", "video", "simulation", "status", "provenance", "qc"):
        assert getattr(a, name) == getattr(b, name), name
    assert a.groups.keys() == b.groups.keys()
    for g in a.groups:
        assert a.groups[g].keys() == b.groups[g].keys()
        for k in a.groups[g]:
            np.testing.assert_array_equal(a.groups[g][k], b.groups[g][k])
    if a.events is None:
        assert b.events is None
    else:
        pd.testing.assert_frame_equal(a.events, b.events)


finite_or_not = st.floats(allow_nan=True, allow_infinity=True, width=64)


@given(
    shape=st.tuples(st.integers(1, 40), st.integers(1, 20)),
    data=st.data(),
    direction=st.sampled_from([1, -1]),
)
def test_round_trip_is_lossless(tmp_path_factory, shape, data, direction):
    t, z = shape
    arr = hnp.arrays(np.float64, (t, z), elements=finite_or_not)
    steps = data.draw(hnp.arrays(np.float64, t, elements=st.floats(1e-6, 1.0)))
    tr = make_trace(
        t, z, time=np.cumsum(steps), angle=data.draw(arr), speed=data.draw(arr), slip=data.draw(arr),
        valid=data.draw(hnp.arrays(np.bool_, (t, z))), direction=direction,
        speed_rpm=data.draw(st.floats(1.0, 1e5)), provenance={"inputs": ["x"]}, qc={"warnings": ["w"]},
    )
    path = tmp_path_factory.mktemp("rt") / "x.trace.h5"
    write_trace(path, tr)
    back = read_trace(path)
    assert_same(tr, back)
    assert back.created_utc and back.software_version == __version__
    # Writing what was read keeps the stamps: a second round trip is identical.
    write_trace(path, back)
    again = read_trace(path)
    assert_same(back, again)
    assert (again.created_utc, again.software_version) == (back.created_utc, back.software_version)


def test_simulation_trace_with_groups_and_events(tmp_path):
    t, z = 7, 14
    rng = np.random.default_rng(1)
    events = pd.DataFrame({
        "time": [0.001, 0.0025], "pair": [3, 13], "angle": [0.5, 1.5], "peak_force": [12.0, 0.3],
        "duration": [1e-5, 2e-3], "kind": ["impact", "rubbing"],
    })
    tr = make_trace(
        t, z, source="simulation", status="incomplete: step size underflow",
        groups={
            "balls": {"radius": rng.random((t, z)), "axial": np.zeros((t, z)), "spin": rng.random((t, z, 3))},
            "contacts": {n: rng.random((t, z)) for n in ("inner_normal", "outer_normal", "ball_ball_normal",
                                                        "inner_traction", "outer_traction")},
            "inner_ring": {"position": rng.random((t, 3)), "tilt": rng.random((t, 2))},
        },
        events=events,
    )
    path = write_trace(tmp_path / "sim.trace.h5", tr)
    back = read_trace(path)
    assert_same(tr, back)
    assert back.status.startswith("incomplete")
    with h5py.File(path) as f:  # the layout DESIGN §4 names
        assert f.attrs["schema"] == SCHEMA
        assert f["contacts/ball_ball_normal"].shape == (t, z)
        assert f["events"].shape == (2,)
        assert json.loads(f.attrs["scene_json"]) == {"speed_rpm": 3000}
        # the layout docs/traces.md gives: kind is fixed-length ASCII, bytes to h5py; read_trace decodes it
        assert f["events"].dtype["kind"] == np.dtype("S8") and f["events"]["kind"][0] == b"impact"
    assert list(back.events.kind) == ["impact", "rubbing"] and isinstance(back.events.kind[0], str)
    assert back.simulation.total_wall_s is None  # not recorded, as in traces from before it existed


def test_total_wall_time_round_trips_and_older_traces_read(tmp_path):
    import dataclasses

    tr = make_trace(source="simulation", simulation=dataclasses.replace(SIM, total_wall_s=2.25))
    path = write_trace(tmp_path / "t.trace.h5", tr)
    assert read_trace(path).simulation.total_wall_s == 2.25 and read_trace(path).simulation.wall_s == 1.5
    with h5py.File(path, "r+") as f:  # a trace written before total_wall_s existed
        del f.attrs["total_wall_s"]
    assert read_trace(path).simulation.total_wall_s is None


def test_empty_event_table_round_trips(tmp_path):
    tr = make_trace(source="simulation", events=trace_mod.empty_events())
    back = read_trace(write_trace(tmp_path / "e.trace.h5", tr))
    assert back.events is not None and len(back.events) == 0
    assert tuple(back.events.columns) == trace_mod.EVENT_COLUMNS


def test_interrupted_write_leaves_no_file(tmp_path, monkeypatch):
    path = tmp_path / "out.trace.h5"

    def boom(f, trace):
        f.create_dataset("time", data=trace.time)
        raise RuntimeError("disk on fire")

    monkeypatch.setattr(trace_mod, "_write_datasets", boom)
    with pytest.raises(RuntimeError, match="disk on fire"):
        write_trace(path, make_trace())
    assert list(tmp_path.iterdir()) == []


def test_interrupted_overwrite_keeps_the_old_file(tmp_path, monkeypatch):
    path = write_trace(tmp_path / "out.trace.h5", make_trace(speed_rpm=1800.0))
    monkeypatch.setattr(trace_mod, "_write_datasets", lambda f, t: 1 / 0)
    with pytest.raises(ZeroDivisionError):
        write_trace(path, make_trace(speed_rpm=6000.0))
    assert read_trace(path).speed_rpm == 1800.0
    assert [p.name for p in tmp_path.iterdir()] == ["out.trace.h5"]


def _rewrite(path, **attrs):
    with h5py.File(path, "a") as f:
        for k, v in attrs.items():
            if v is None:
                del f.attrs[k]
            else:
                f.attrs[k] = v


@pytest.mark.parametrize(
    ("attrs", "match"),
    [
        ({"schema": None}, "no 'schema' attribute"),
        ({"schema": "cageless-trace/2"}, "newer than this cageless reads.*Upgrade"),
        ({"schema": "other-format/1"}, "not 'cageless-trace/1'"),
        ({"n_balls": 13}, "n_balls = 13 but angle has 14"),
        ({"fps": None}, "lacks 'attribute fps'"),
    ],
)
def test_reader_rejects_bad_attributes(tmp_path, attrs, match):
    path = write_trace(tmp_path / "t.trace.h5", make_trace())
    _rewrite(path, **attrs)
    with pytest.raises(TraceFormatError, match=match) as err:
        read_trace(path)
    assert err.value.path == path


def test_minor_schema_revision_is_accepted(tmp_path):
    path = write_trace(tmp_path / "t.trace.h5", make_trace())
    _rewrite(path, schema="cageless-trace/1.3")
    assert read_trace(path).n_balls == 14


def test_reader_rejects_shape_mismatch_and_missing_data(tmp_path):
    path = write_trace(tmp_path / "t.trace.h5", make_trace())
    with h5py.File(path, "a") as f:
        del f["slip"]
        f["slip"] = np.zeros((5, 13))
    with pytest.raises(TraceFormatError, match=r"slip has shape \(5, 13\)"):
        read_trace(path)
    with h5py.File(path, "a") as f:
        del f["slip"]
    with pytest.raises(TraceFormatError, match="lacks 'dataset slip'"):
        read_trace(path)


def test_reader_rejects_non_hdf5_and_missing(tmp_path):
    bad = tmp_path / "bad.trace.h5"
    bad.write_bytes(b"not hdf5 at all")
    with pytest.raises(TraceFormatError, match="not a readable HDF5"):
        read_trace(bad)
    with pytest.raises(TraceFormatError, match="does not exist"):
        read_trace(tmp_path / "missing.trace.h5")


@pytest.mark.parametrize(
    ("changes", "match"),
    [
        ({"time": np.array([0.0, 1.0, 1.0, 2.0, 3.0])}, "strictly increasing"),
        ({"speed": np.zeros((5, 3))}, r"speed has shape \(5, 3\)"),
        ({"source": "camera"}, "must be 'video' or 'simulation'"),
        ({"video": None}, "needs its video attributes"),
        ({"direction": 0}, r"\+1 or -1"),
        ({"groups": {"balls": {"spin": np.zeros((5, 14))}}}, r"balls/spin has shape"),
    ],
)
def test_trace_refuses_inconsistent_data(changes, match):
    with pytest.raises(ValueError, match=match):
        make_trace(**changes)


def test_input_hash_names_its_algorithm(tmp_path):
    """BLAKE3 traces carry input_hash + input_hash_algorithm and no input_sha256; SHA-256 traces keep
    input_sha256, and a trace written before input_hash existed reads as SHA-256."""
    b3 = VideoInfo(fps=1e4, px_per_mm=12.5, centre_px=(1.0, 2.0), camera_roll_rad=0.0, input_file="x.cine",
                   input_hash="cd" * 32, input_hash_algorithm="blake3")
    path = write_trace(tmp_path / "b3.trace.h5", make_trace(video=b3))
    with h5py.File(path, "r") as f:
        assert "input_sha256" not in f.attrs and f.attrs["input_hash_algorithm"] == "blake3"
    assert read_trace(path).video == b3
    old = write_trace(tmp_path / "old.trace.h5", make_trace())  # VIDEO names only input_sha256
    with h5py.File(old, "r+") as f:
        del f.attrs["input_hash"], f.attrs["input_hash_algorithm"]
    back = read_trace(old).video
    assert (back.input_sha256, back.input_hash, back.input_hash_algorithm) == ("ab" * 32, "ab" * 32, "sha256")
    with h5py.File(old, "r+") as f:
        del f.attrs["input_sha256"]
    with pytest.raises(TraceFormatError, match="input_hash"):
        read_trace(old)
    with pytest.raises(ValueError, match="algorithm is 'blake3'"):
        VideoInfo(fps=1e4, px_per_mm=1.0, centre_px=(0.0, 0.0), camera_roll_rad=0.0, input_file="x",
                  input_sha256="ab" * 32, input_hash_algorithm="blake3")
