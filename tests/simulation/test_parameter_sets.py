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
