"""Today's unloaded-zone slip is gravity trading speed for height (a closed form, issue "lubricant physics").

A ball leaves the loaded zone at the horizontal rolling at the pure-rolling orbital speed v. It then touches only
the outer race. With nothing taking energy from it, it keeps its kinetic energy of rolling
1/2 m v^2 + 1/2 I w^2 = 0.7 m v^2 (homogeneous sphere, I = m D^2 / 10, rolling on the outer race, w = 2 v / D)
less the potential energy of the climb. At the top, a height r above the horizontal:

    0.7 m v_top^2 = 0.7 m v^2 - m g r   =>   slip_top = 1 - v_top / v = 1 - sqrt(1 - g r / (0.7 v^2))

(energy conservation, e.g. Meriam & Kraige, *Engineering Mechanics: Dynamics*, §6/6, rolling without slipping).
Here:

* r is the **pitch radius** d_m / 2 = 23.0025 mm: the ball centre's orbit. The clearance is zero, and the
  outer-race deflection under the centrifugal force is < 1 um.
* v is the **orbital speed at pure rolling**, r w_c, with the cage speed w_c = w_i (1 - D / d_m) / 2 (Harris &
  Kotzalas, *Essential Concepts of Bearing Technology*, §8.2, :func:`cageless.kinematics.theoretical_cage_speed`).

Measured on the traces of these runs, the inner contact ends at -0.3, -0.2 and -1.3 deg from the horizontal
(median over passes) at 1800, 3000 and 6000 rpm. So the exit is at the horizontal, as the closed form assumes.

**The losses that are off.** The rolling losses (hydrodynamic rolling force at the race contacts) and drag are
switched off (forced). The restitution is the default (0.8).

**The lubricant damping stays on.** It acts only on the normal approach speed at the race contacts, so a ball
rolling on the outer race at constant radius feels none of it. Without it, the ring and balls ring undamped
after the start: measured peak slips were then 3.37 / 1.20 / 0.33 %, *below* the closed form, because
vibration energy feeds the balls. So switching it off is not possible here.

**What is compared.** The quantity compared is the peak of the mean slip profile in the unloaded zone
(:func:`cageless.simulation.run.peak_unloaded_slip`), over 0.1 s after the start-up. That is 1.2 / 2.0 / 4.0 cage
revolutions at the three speeds. With 0.05 s the 1800 rpm peak moved to 6.01 % (+0.40 pp), less than one
revolution being covered. The remaining excess, 0.1-0.2 pp, comes from the ball-ball impacts of the full
complement.

**With gravity off,** and the losses off, nothing slows a ball in the unloaded zone, and its slip stays at 0
(measured -0.001 %). With the losses on, the rolling force alone slows it: slip above 0, and falling with speed,
because the ball's momentum grows as v while the rolling force grows more slowly (C_0 ~ u, Fbar ~ ln of the
film, which thickens with speed).
"""

from __future__ import annotations

import math

import pytest

from cageless.bearing import default_bearing
from cageless.conditions import OperatingConditions
from cageless.kinematics import startup_duration, theoretical_cage_speed
from cageless.simulation.effects import choose_model
from cageless.simulation.run import peak_unloaded_slip, simulate
from cageless.simulation.scene import Scene

G = 9.81
WINDOW_S = 0.1


def gravity_slip(rpm: float) -> float:
    """1 - sqrt(1 - g r / (0.7 v^2)) with r the pitch radius and v the pure-rolling orbital speed."""
    geo = default_bearing().geometry
    r = 0.5 * geo.pitch_diameter_m
    v = r * theoretical_cage_speed(geo, rpm * math.pi / 30.0)
    return 1.0 - math.sqrt(1.0 - G * r / (0.7 * v * v))


def _peak(rpm: float, gravity: float, window: float, losses: bool = False) -> float:
    geo = default_bearing().geometry
    settle = startup_duration(rpm, geo.ball_diameter_m, geo.pitch_diameter_m)
    scene = Scene(conditions=OperatingConditions(rpm, 500.0), duration_s=settle + window, gravity_m_s2=gravity)
    choice = choose_model(scene, effects={} if losses else {"rolling_losses": False, "drag": False}, force=True)
    assert ("rolling_losses" in choice.active) == losses and "lubricant_damping" in choice.active
    assert losses or "drag" not in choice.active
    return peak_unloaded_slip(simulate(scene, choice, progress=False).trace, settle)


def test_closed_form_values():
    # v = 0.0230025 m x 188.496 rad/s x (1 - 9.525 / 46.005) / 2 = 0.0230025 x 74.734 = 1.71906 m/s at 1800 rpm;
    # g r / (0.7 v^2) = 9.81 x 0.0230025 / (0.7 x 2.955168) = 0.225655 / 2.068617 = 0.109085;
    # 1 - sqrt(0.890915) = 1 - 0.943883 = 5.612 %. Speed scales v, so at 3000 rpm the ratio is
    # 0.109085 x (1800/3000)^2 = 0.0392706 -> 1.983 %, and at 6000 rpm 0.00981765 -> 0.4921 %.
    # The issue quotes 5.6 / 2.0 / 0.49 %.
    assert gravity_slip(1800) == pytest.approx(0.05612, abs=2e-5)
    assert gravity_slip(3000) == pytest.approx(0.01983, abs=2e-5)
    assert gravity_slip(6000) == pytest.approx(0.004921, abs=2e-6)


@pytest.mark.slow
@pytest.mark.parametrize("rpm", [1800.0, 3000.0, 6000.0])
def test_unloaded_zone_slip_is_the_gravity_energy_value(rpm):
    peak = _peak(rpm, G, WINDOW_S)
    assert abs(peak - gravity_slip(rpm)) < 0.003, (peak, gravity_slip(rpm))


@pytest.mark.slow
@pytest.mark.parametrize("rpm", [1800.0, 6000.0])
def test_no_gravity_no_slip(rpm):
    # with g = 0 and the losses off nothing slows a ball leaving the loaded zone: zero within 0.01 pp
    # (measured -0.001 %)
    assert abs(_peak(rpm, 0.0, 0.03)) < 1e-4


@pytest.mark.slow
def test_no_gravity_losses_on_slip_above_zero_and_falling_with_speed():
    peaks = [_peak(rpm, 0.0, 0.05, losses=True) for rpm in (1800.0, 3000.0, 6000.0)]
    assert peaks[0] > peaks[1] > peaks[2] > 1e-3, peaks
