"""The effects table: what each scene switches on, the reasons, and overrides (DESIGN §6)."""

from __future__ import annotations

import dataclasses
import json

import pytest

from cageless.bearing import default_bearing
from cageless.app.cli import main
from cageless.conditions import OperatingConditions
from cageless.errors import ParameterError, UsageError
from cageless.simulation.effects import EFFECTS, choose_model
from cageless.simulation.scene import Scene


def scene(**kw):
    cond = kw.pop("conditions", OperatingConditions(3000.0, 500.0))
    return Scene(conditions=cond, **kw)


def test_radial_lubricated_scene():
    c = choose_model(scene())
    assert c.level == "planar"
    assert c.active == ("race_contact", "lubricant_damping", "race_traction", "ehl_film", "film_traction",
                        "rolling_losses", "ball_ball_contact", "ball_ball_friction", "ball_ball_film", "gravity", "drag")
    # drag is on by default in a lubricated scene, in the 5 % oil-air mixture: 0.05 x 826 + 0.95 x 1.204 = 42.44
    assert {e.name: e.reason for e in c.effects}["drag"].startswith("lubricated: oil-air mixture of 42.4 kg/m^3")
    off = choose_model(scene(oil_air_density_kg_m3=0.0))
    assert "drag" not in off.active


def test_scene_rules():
    dry = scene(bearing=dataclasses.replace(default_bearing(), lubricant=None), gravity_m_s2=0.0,
                oil_air_density_kg_m3=4.0)
    c = choose_model(dry)
    assert set(c.active) == {"race_contact", "race_traction", "ball_ball_contact", "ball_ball_friction", "drag",
                            "dry_friction"}
    axial = choose_model(scene(conditions=OperatingConditions(3000.0, 500.0, 300.0)))
    assert axial.level == "spatial" and "axial load 300 N" in axial.level_reason
    assert choose_model(scene(misalignment_rad=1e-3)).level == "spatial"
    assert choose_model(scene(orientation="vertical")).level == "spatial"


def _reasons(sc):
    c = choose_model(sc)
    return c.level_reason, {e.name: e.reason for e in c.effects}["race_contact"]


def test_the_reasons_fit_the_scene():
    """Each reason says what holds for its scene. Before, a scene with no load at all was "pure radial load", and
    the race contact read "balls always touch the races" even with a 150 um clearance, where centrifugal force
    holds the balls on the outer race and the inner race carries them only in the loaded zone."""
    level, race = _reasons(scene())
    assert level == "pure radial load of 500 N on an aligned bearing: ball centres stay in the mid-plane"
    assert race.startswith("zero clearance: the balls touch both races at rest")
    level, _ = _reasons(scene(conditions=OperatingConditions(3000.0)))
    assert "radial and axial load 0 N" in level and "ring's weight its only load" in level
    assert "pure radial" not in level
    level, _ = _reasons(scene(conditions=OperatingConditions(3000.0), gravity_m_s2=0.0))
    assert level.startswith("radial and axial load 0 N on an aligned bearing:") and "weight" not in level
    level, _ = _reasons(scene(conditions=OperatingConditions(3000.0, 0.0, 400.0)))
    assert level == "needed for axial load 400 N"
    loose = default_bearing().with_overrides({"geometry.diametral_clearance_m": 150e-6})
    _, race = _reasons(scene(bearing=loose))
    assert race == ("diametral clearance 150 um: centrifugal force holds the balls on the outer race; they touch "
                    "the inner race where the load closes the clearance")
    _, race = _reasons(scene(bearing=loose, conditions=OperatingConditions(3000.0), gravity_m_s2=0.0))
    assert race.endswith("no load or gravity closes it, so the inner ring floats among them")


def test_explain_names_the_degrees_of_freedom_of_the_level():
    """--explain and a trace's effects_json say what each level integrates and leaves out, with the states of
    simulation/models/planar.py (5 Z + 6: r, theta, their rates and the spin per ball; ring y, z) and spatial.py
    (9 Z + 12: also x, its rate and the spin about y and z; ring x and tilt). Before, they named the level only."""
    planar = choose_model(scene())
    lines = planar.explain().splitlines()
    assert lines[1].startswith("  degrees of freedom: per ball the orbital radius and angle and the spin about the "
                               "shaft (3 DOF)") and "left out: the balls' axial motion" in lines[1]
    spatial = choose_model(scene(conditions=OperatingConditions(6000.0, 500.0, 100.0)))
    assert "full spin vector (6 DOF)" in spatial.explain().splitlines()[1]
    assert "gyroscopic" in json.loads(spatial.to_json())["degrees_of_freedom"]


def test_overrides():
    with pytest.raises(UsageError, match="Did you mean 'gravity'"):
        choose_model(scene(), effects={"gravty": False})
    with pytest.raises(UsageError, match="contradicts the scene.*--force"):
        choose_model(scene(), effects={"gravity": False})
    c = choose_model(scene(), effects={"gravity": False}, force=True)
    assert not dict((e.name, e.on) for e in c.effects)["gravity"]
    assert [e.forced for e in c.effects if e.name == "gravity"] == [True]
    with pytest.raises(UsageError, match="needs a lubricant"):
        choose_model(scene(bearing=dataclasses.replace(default_bearing(), lubricant=None)),
                     effects={"ehl_film": True}, force=True)
    with pytest.raises(UsageError, match="needs the dry_friction effect"):  # the traction curve is lubricated
        choose_model(scene(bearing=dataclasses.replace(default_bearing(), lubricant=None)),
                     effects={"dry_friction": False}, force=True)
    with pytest.raises(UsageError, match="contradicts the scene"):
        choose_model(scene(), effects={"dry_friction": True})
    assert "dry_friction" in choose_model(scene(), effects={"dry_friction": True}, force=True).active
    axial = scene(conditions=OperatingConditions(3000.0, 0.0, 300.0))
    with pytest.raises(UsageError, match="--level planar contradicts the scene"):
        choose_model(axial, level="planar")
    assert choose_model(axial, level="planar", force=True).level == "planar"
    assert choose_model(scene(), level="spatial").level == "spatial"  # more general: allowed
    with pytest.raises(UsageError, match="Did you mean 'planar'"):
        choose_model(scene(), level="planr")


def test_impossible_scenes_fail_before_anything_runs():
    with pytest.raises(ParameterError, match="speed_rpm"):
        OperatingConditions(0.0)
    with pytest.raises(ParameterError, match="scene.duration_s"):
        scene(duration_s=float("nan"))
    with pytest.raises(ParameterError, match="scene.gravity_m_s2"):
        scene(gravity_m_s2=-1.0)


def test_the_parameter_layout_comes_from_the_table():
    """Every effect's flag and parameter slots are named slots of both models' parameter vectors, and the
    flags a builder writes are those of the effects it is given (an unnamed effect is off)."""
    from cageless.simulation.effects import effect_flags
    from cageless.simulation.models import planar, spatial

    for layout in (planar.LAYOUT, spatial.LAYOUT):
        for e in EFFECTS:
            assert e.flag in layout and all(s in layout for s in e.slots)
    assert effect_flags({"drag": True}) == {e.flag: float(e.name == "drag") for e in EFFECTS}
    with pytest.raises(UsageError, match="Did you mean 'drag'"):
        effect_flags({"drga": True})


def test_every_effect_has_a_rule_and_physics():
    assert len({e.name for e in EFFECTS}) == len(EFFECTS) == 13
    for e in EFFECTS:
        on, reason = e.rule(scene())
        assert isinstance(on, bool) and reason and e.physics


def test_simulate_explain_cli(capsys):
    assert main(["simulate", "--speed-rpm", "3000", "--radial-load-n", "500", "--axial-load-n", "400",
                 "--explain", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    assert d["level"] == "spatial" and len(d["effects"]) == 13
    assert main(["simulate", "--speed-rpm", "3000", "--effect", "drag=maybe", "--explain"]) == 2
    assert "write NAME=on or NAME=off" in capsys.readouterr().err
    assert main(["simulate", "--speed-rpm", "3000", "--set", "cho_n_s=1"]) == 2
    assert "Did you mean 'cho_n_s_m'" in capsys.readouterr().err


def test_an_effect_with_nothing_to_act_on_is_off_with_its_reason():
    """``acts_on``: film_traction changes race_traction's law, dry_friction that of both friction effects; with
    their targets off they are off, saying why, so no flag claims a law that is not evaluated."""
    c = choose_model(scene(), effects={"race_traction": False}, force=True)
    by = {e.name: e for e in c.effects}
    assert not by["film_traction"].on and by["film_traction"].reason == "nothing to act on: race_traction is off"
    assert by["ball_ball_friction"].on  # its own unit now: not switched by the race traction
    dry = Scene(conditions=OperatingConditions(3000.0, 500.0), bearing=dataclasses.replace(default_bearing(),
                                                                                        lubricant=None))
    c = choose_model(dry, effects={"race_traction": False, "ball_ball_friction": False}, force=True)
    by = {e.name: e for e in c.effects}
    assert not by["dry_friction"].on
    assert by["dry_friction"].reason == "nothing to act on: race_traction and ball_ball_friction are off"
    with pytest.raises(UsageError, match="--effect film_traction=on changes the law of race_traction"):
        choose_model(scene(), effects={"race_traction": False, "film_traction": True}, force=True)
    with pytest.raises(UsageError, match="ball_ball_friction on a dry bearing needs the dry_friction effect"):
        choose_model(dry, effects={"race_traction": False, "dry_friction": False}, force=True)
