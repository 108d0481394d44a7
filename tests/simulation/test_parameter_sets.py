"""Named parameter sets: the calibrated default and the representative set (simulation/parameter_sets.py)."""

from __future__ import annotations

import pytest

from cageless.errors import ParameterError
from cageless.simulation.parameter_sets import CALIBRATION, DEFAULT_SET, PARAMETER_SETS, parameter_set, set_values
from cageless.simulation.parameters import ModelParameters
from cageless.simulation.ranges import DOCUMENTED_RANGES


def test_the_default_is_the_calibrated_set_inside_its_documented_range():
    assert DEFAULT_SET == "paper-table2" and PARAMETER_SETS[DEFAULT_SET] == ModelParameters()
    assert CALIBRATION["condition"] == "3000 rpm, 500 N radial, 0 N axial" and "7.79 %" in CALIBRATION["target"]
    for name, value in CALIBRATION["fitted"].items():
        low, high, _ = DOCUMENTED_RANGES[name]
        assert low <= value <= high and getattr(ModelParameters(), name) == value
    assert set_values(DEFAULT_SET) == {}


def test_the_representative_set_is_available_by_name():
    # fully flooded: the flooded end of the meniscus range, the paper's stated assumption
    assert set_values("representative") == {"meniscus_distance_m": 2.0e-3}
    assert parameter_set("representative").cho_n_s_m == 5000.0
    with pytest.raises(ParameterError, match="Did you mean 'representative'"):
        parameter_set("representativ")


def test_cli_parameter_set_reaches_the_run(capsys, tmp_path):
    from cageless.app.cli import main

    assert main(["simulate", "--speed-rpm", "3000", "--radial-load-n", "500", "--parameter-set", "representative",
                 "--explain", "--json"]) == 0
    assert main(["simulate", "--speed-rpm", "3000", "--radial-load-n", "500", "--parameter-set", "nope",
                 "-o", str(tmp_path / "x.trace.h5")]) == 2  # refused before anything compiles
    assert "is not a parameter set" in capsys.readouterr().err


def test_the_parameter_set_is_named_in_explain_the_run_and_its_trace(capsys, tmp_path):
    from cageless.app.cli import main
    from cageless.trace import read_trace

    assert main(["simulate", "--speed-rpm", "3000", "--parameter-set", "nope", "--explain"]) == 2  # checked as a run
    capsys.readouterr()
    assert main(["simulate", "--speed-rpm", "3000", "--explain", "--set", "cho_n_s_m=2500"]) == 0
    assert "parameters: set 'paper-table2', changed by --config/--set: cho_n_s_m" in capsys.readouterr().out
    out = tmp_path / "x.trace.h5"
    assert main(["simulate", "--speed-rpm", "3000", "--radial-load-n", "500", "--parameter-set", "representative",
                 "--duration", "0.003", "-q", "-o", str(out)]) == 0
    assert "parameters: set 'representative'" in capsys.readouterr().out
    trace = read_trace(out)
    assert trace.config["parameter_set"] == "representative"
    assert trace.config["parameters"]["meniscus_distance_m"] == 0.002  # the set's value (parameter_sets.py)


def test_lab_options_record_the_parameter_set():
    from cageless.app.lab import LabOptions

    assert LabOptions().to_dict()["parameter_set"] == "paper-table2"
    assert LabOptions(parameter_set="representative").to_dict()["parameter_set"] == "representative"
