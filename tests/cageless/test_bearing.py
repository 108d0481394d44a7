"""Validation of the bearing description: impossible geometries are refused with the rule named."""

from __future__ import annotations

import dataclasses
import math

import pytest

from cageless.bearing import Bearing, Geometry, Lubricant, Material, default_bearing
from cageless.config import bearing_from_config
from cageless.errors import GeometryError, ParameterError
from cageless.parameter_sets import wang2026


def _geometry(**changes):
    return dataclasses.replace(wang2026.geometry(), **changes)


def test_default_bearing_is_the_papers():
    b = default_bearing()
    assert b.name == "wang2026"
    assert b.geometry.n_balls == 14
    assert b.geometry.ball_diameter_m == 9.525e-3
    assert b.masses.ring_translational_mass_kg == pytest.approx(6.2356e-2 + 2.0)
    assert b.lubricant is not None and b.lubricant.dynamic_viscosity_pa_s == 0.04


def test_sixteen_balls_do_not_fit():
    with pytest.raises(GeometryError) as err:
        _geometry(n_balls=16)
    assert err.value.parameter == "geometry.n_balls"
    assert "at most 15 fit" in str(err.value)


def test_fifteen_balls_fit():
    assert _geometry(n_balls=15).n_balls == 15


@pytest.mark.parametrize("field", ["inner_curvature_factor", "outer_curvature_factor"])
@pytest.mark.parametrize("value", [0.5, 0.45])
def test_curvature_factor_must_exceed_half(field, value):
    with pytest.raises(GeometryError, match=r"must be > 0.5") as err:
        _geometry(**{field: value})
    assert err.value.parameter == f"geometry.{field}"


@pytest.mark.parametrize("value", [-9.525e-3, 0.0, math.nan, math.inf])
def test_ball_diameter_must_be_positive_and_finite(value):
    with pytest.raises(ParameterError, match="finite number > 0") as err:
        _geometry(ball_diameter_m=value)
    assert err.value.parameter == "geometry.ball_diameter_m"


def test_non_numbers_are_refused():
    with pytest.raises(ParameterError, match="must be a number"):
        _geometry(ball_diameter_m="9.5")
    with pytest.raises(GeometryError, match="whole number"):
        _geometry(n_balls=14.0)
    with pytest.raises(GeometryError, match="whole number"):
        _geometry(n_balls=True)


def test_races_must_make_room_for_the_ball():
    with pytest.raises(GeometryError, match="must exceed geometry.inner_race_diameter_m"):
        _geometry(outer_race_diameter_m=30e-3)
    with pytest.raises(GeometryError, match="does not fit between the races"):
        _geometry(ball_diameter_m=9.6e-3)


def test_a_clearance_moves_the_races_apart_about_the_pitch_circle():
    g = wang2026.geometry()
    c4 = g.with_diametral_clearance(40e-6)
    # P_d = d_o - d_i - 2D (Harris & Kotzalas, vol. 1, ch. 2), with d_m = (d_i + d_o) / 2 unchanged
    clearance = c4.outer_race_diameter_m - c4.inner_race_diameter_m - 2 * c4.ball_diameter_m
    assert clearance == pytest.approx(40e-6, abs=1e-12)
    assert c4.pitch_diameter_m == pytest.approx(g.pitch_diameter_m, abs=1e-12)
    assert c4.with_diametral_clearance(0.0).diametral_clearance_m == 0.0
    for bad in (-1e-6, math.nan):
        with pytest.raises(GeometryError, match="clearance") as err:
            g.with_diametral_clearance(bad)
        assert err.value.parameter == "geometry.diametral_clearance_m"


def test_the_clearance_is_a_bearing_override_and_the_default_has_none():
    """``geometry.diametral_clearance_m`` in overrides (and so in ``--config`` and sweeps) moves the races apart
    about the pitch circle; the default bearing is Table 1 of Wang et al. 2026 as printed, with P_d = 0."""
    b = default_bearing()
    assert b.geometry.diametral_clearance_m == 0.0
    c4 = b.with_overrides({"geometry.diametral_clearance_m": 32e-6})  # ISO 5753-1 C4 for a 25 mm bore: 23-41 um
    assert c4.geometry.diametral_clearance_m == pytest.approx(32e-6, rel=1e-9)
    assert c4.geometry.pitch_diameter_m == pytest.approx(b.geometry.pitch_diameter_m, abs=1e-15)
    # the other overrides first, then the clearance about the new pitch circle
    both = b.with_overrides({"geometry.diametral_clearance_m": 20e-6, "geometry.n_balls": 13})
    assert both.geometry.n_balls == 13 and both.geometry.diametral_clearance_m == pytest.approx(20e-6, rel=1e-9)
    for bad, kind in ((-1e-6, GeometryError), ("20 um", ParameterError), (True, ParameterError)):
        with pytest.raises(kind) as err:
            b.with_overrides({"geometry.diametral_clearance_m": bad})
        assert err.value.parameter == "geometry.diametral_clearance_m"


def test_the_clearance_from_a_config_file_reaches_explain_the_trace_and_sweeps(capsys, tmp_path):
    from cageless.app.cli import main
    from cageless.simulation.sweep import parse_vary
    from cageless.trace import read_trace

    assert main(["simulate", "--speed-rpm", "3000", "--explain"]) == 0
    line = capsys.readouterr().out.splitlines()[-1]
    assert line == "bearing: wang2026, diametral clearance 0.000 um (Table 1 of Wang et al. 2026 as printed)"
    config = tmp_path / "c4.toml"
    config.write_text("[bearing.geometry]\ndiametral_clearance_m = 32e-6\n", encoding="utf-8")
    assert main(["simulate", "--config", str(config), "--speed-rpm", "3000", "--explain"]) == 0
    assert "diametral clearance 32.000 um (as given" in capsys.readouterr().out
    out = tmp_path / "x.trace.h5"
    assert main(["simulate", "--config", str(config), "--speed-rpm", "3000", "--radial-load-n", "500",
                 "--duration", "0.003", "-q", "-o", str(out)]) == 0
    assert read_trace(out).config["clearance"]["diametral_clearance_m"] == pytest.approx(32e-6, rel=1e-9)
    config.write_text("[bearing.geometry]\ndiametral_clearance_m = -1e-6\n", encoding="utf-8")
    assert main(["simulate", "--config", str(config), "--speed-rpm", "3000", "--explain"]) == 2
    assert "geometry.diametral_clearance_m" in capsys.readouterr().err
    assert parse_vary(["geometry.diametral_clearance_m=0,32e-6"]) == {"geometry.diametral_clearance_m": [0.0, 32e-6]}


def test_material_and_lubricant_rules():
    with pytest.raises(ParameterError, match=r"\(-1, 0.5\)") as err:
        Material(density_kg_m3=7810.0, youngs_modulus_pa=208e9, poisson_ratio=0.5)
    assert err.value.parameter == "material.poisson_ratio"
    with pytest.raises(ParameterError) as err:
        dataclasses.replace(wang2026.lubricant(), dynamic_viscosity_pa_s=math.nan)
    assert err.value.parameter == "lubricant.dynamic_viscosity_pa_s"
    assert isinstance(wang2026.lubricant(), Lubricant)


def test_effective_modulus():
    # E' = E / (1 - nu^2) = 208 GPa / 0.91 = 228.5714 GPa
    assert wang2026.material().effective_modulus_pa == pytest.approx(228.5714e9, rel=1e-6)


def test_an_overridden_bearing_is_not_named_as_the_parameter_set():
    """A bearing with other geometry is not "wang2026" (the paper's Table 1): the outputs would claim a parameter
    set it is not. Its name carries the changes, and the scene a trace records (scene_json) carries the name."""
    from cageless.conditions import OperatingConditions
    from cageless.simulation.scene import Scene

    b = default_bearing()
    b13 = b.with_overrides({"geometry.n_balls": 13, "geometry.diametral_clearance_m": 32e-6})
    assert b13.name == "wang2026 (geometry.diametral_clearance_m = 3.2e-05, geometry.n_balls = 13)"
    assert b.with_overrides({"geometry.n_balls": 14}).name == "wang2026"  # the same bearing
    assert b.with_overrides({}) == b
    scene = Scene(conditions=OperatingConditions(3000.0, 500.0), bearing=b13)
    assert scene.to_dict()["bearing"]["name"] == b13.name


def test_dict_round_trip_and_overrides():
    b = default_bearing()
    assert Bearing.from_dict(b.to_dict()) == b
    b13 = b.with_overrides({"geometry.n_balls": 13})
    assert b13.geometry.n_balls == 13
    with pytest.raises(ParameterError, match="Did you mean 'geometry.n_balls'"):
        b.with_overrides({"geometry.n_ball": 13})
    with pytest.raises(GeometryError):
        b.with_overrides({"geometry.n_balls": 16})
    with pytest.raises(ParameterError, match="is missing"):
        Bearing.from_dict({"geometry": b.to_dict()["geometry"]})


def test_bearing_from_config():
    b = bearing_from_config({"bearing": {"geometry": {"n_balls": 12}, "lubricant": False}})
    assert b.geometry.n_balls == 12
    assert b.lubricant is None
    assert b.name == "wang2026 (geometry.n_balls = 12, lubricant = none)"
    assert bearing_from_config({"bearing": {"name": "rig B", "geometry": {"n_balls": 12}}}).name == "rig B"
    # an override that changes nothing keeps the named set
    assert bearing_from_config({"bearing": {"geometry": {"n_balls": 14}}}).name == "wang2026"
    assert bearing_from_config({}) == default_bearing()


def test_geometry_is_frozen():
    g = wang2026.geometry()
    with pytest.raises(dataclasses.FrozenInstanceError):
        g.n_balls = 3  # type: ignore[misc]
    assert isinstance(g, Geometry)


def test_a_ball_diameter_override_moves_the_races_and_scales_the_mass():
    """Another bearing by its ball and pitch diameters, as a lab folder's keys describe it
    (:func:`cageless.conditions.bearing_with_keys`): the races sit at d_m -/+ (D + P_d/2)
    (Harris & Kotzalas, *Rolling Bearing Analysis*, 5th ed., vol. 1, ch. 2) and a steel ball's mass
    scales as D^3. Before, ``ball_diameter_m = 8e-3`` alone kept Table 1's races: a 3.05 mm clearance,
    and the 9.525 mm ball's mass."""
    b = default_bearing()
    g = b.with_overrides({"geometry.ball_diameter_m": 8e-3, "geometry.n_balls": 12}).geometry
    assert g.diametral_clearance_m == 0.0  # Table 1's, kept
    assert g.pitch_diameter_m == pytest.approx(46.005e-3, rel=1e-12)
    assert (g.inner_race_diameter_m, g.outer_race_diameter_m) == pytest.approx((38.005e-3, 54.005e-3), rel=1e-12)
    small = b.with_overrides({"geometry.ball_diameter_m": 8e-3})
    # 3.5519 g (Table 1) * (8 / 9.525)^3 = 2.10443 g
    assert small.masses.ball_mass_kg == pytest.approx(3.5519e-3 * (8 / 9.525) ** 3, rel=1e-12)
    assert small.masses.ball_mass_kg == pytest.approx(2.10443e-3, rel=1e-5)
    given = b.with_overrides({"geometry.ball_diameter_m": 8e-3, "masses.ball_mass_kg": 2.09e-3})
    assert given.masses.ball_mass_kg == 2.09e-3
    other = b.with_overrides({"geometry.pitch_diameter_m": 40e-3, "geometry.ball_diameter_m": 8e-3,
                              "geometry.n_balls": 12, "geometry.diametral_clearance_m": 20e-6})
    assert other.geometry.pitch_diameter_m == pytest.approx(40e-3, rel=1e-12)
    assert other.geometry.diametral_clearance_m == pytest.approx(20e-6, rel=1e-9)
    # race diameters given: they are taken as they are (the clearance follows from them)
    races = b.with_overrides({"geometry.ball_diameter_m": 9e-3})
    literal = b.with_overrides({"geometry.ball_diameter_m": 9e-3, "geometry.inner_race_diameter_m": 36.48e-3})
    assert literal.geometry.diametral_clearance_m == pytest.approx(55.53e-3 - 36.48e-3 - 18e-3, rel=1e-9)
    assert races.geometry.diametral_clearance_m == 0.0


@pytest.mark.parametrize("overrides, parameter, words", [
    ({"geometry.ball_diameter_m": 8.0}, "geometry.ball_diameter_m", "metres"),  # 8 mm given as 8
    ({"geometry.pitch_diameter_m": -1.0}, "geometry.pitch_diameter_m", "> 0"),
    ({"geometry.pitch_diameter_m": 40e-3, "geometry.outer_race_diameter_m": 56e-3}, "geometry.pitch_diameter_m",
     "race diameters"),
])
def test_a_ball_or_pitch_diameter_override_that_cannot_be_is_refused(overrides, parameter, words):
    with pytest.raises(ParameterError, match=words) as err:
        default_bearing().with_overrides(overrides)
    assert err.value.parameter == parameter
