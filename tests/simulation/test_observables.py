"""The trace's contact observables are written by the compiled force functions (models/observables.py).

Checked against closed forms evaluated here in numpy from the state alone: the Hertz force K delta^1.5 of
each contact (delta from the ball and ring positions), the race traction law (through the plain-numpy
reference, models/planar_reference.py, which maps the models' own law; the law itself is checked against its
stated curve in test_parameters_ensemble.py) at the contact's sliding and entrainment speeds recomputed here, with the ring speed of the ramp at the sample's time, and the Hamrock-Dowson film
c_h u^0.67 Q^-0.067 (Hamrock & Dowson, J. Lubr. Technol. 99 (1977) 264; its coefficient from
simulation/traction.py). Under pure radial load and one strip per contact the spatial model's observables
are the planar model's (the two models' equivalence, simulation/models/spatial.py).
"""

from __future__ import annotations

import numpy as np

from cageless.conditions import OperatingConditions
from cageless.simulation.models import base as B
from cageless.simulation.models.observables import film_coefficients, kernel_observables
from cageless.simulation.models.planar_reference import tangential_force
from cageless.simulation.models.regime import race_tangential_array
from cageless.simulation.parameters import ModelParameters
from cageless.simulation.scene import Scene
from cageless.simulation.simulation import Choices, Simulation


def _moving_state(pr, seed=0):
    """The problem's quasi-static start with orbital speeds, spins and a ring velocity (seeded)."""
    rng = np.random.default_rng(seed)
    z = pr.n_balls
    y = pr.y0.copy()
    y[2 * z:3 * z] = rng.normal(0.0, 1e-3, z)  # radial rates (m/s)
    y[3 * z:4 * z] = 120.0 + rng.normal(0.0, 5.0, z)  # orbital speeds (rad/s)
    y[4 * z:5 * z] = -700.0 + rng.normal(0.0, 50.0, z)  # spins (rad/s)
    y[5 * z + 2:5 * z + 4] = rng.normal(0.0, 1e-3, 2)
    return y


def _closed_forms(pr, t, y, ramp_s):
    """(outer normal, inner normal, outer traction, inner traction, outer u_r, inner u_r, outer sliding speed,
    inner sliding speed) from the state."""
    p = pr.params
    z = pr.n_balls
    d, half = pr.parameter("D"), 0.5 * pr.parameter("D")
    r, th, rd, thd, om = (y[i * z:(i + 1) * z] for i in range(5))
    cy, cz, cvy, cvz = y[5 * z:5 * z + 4]
    w_i = pr.parameter("WI") * min(t / ramp_s, 1.0)
    outer = pr.parameter("KO") * np.clip(r + half - 0.5 * pr.parameter("DO"), 0, None) ** 1.5
    sx, sz = r * np.cos(th) - cy, r * np.sin(th) - cz
    ln = np.hypot(sx, sz)
    inner = pr.parameter("KI") * np.clip(0.5 * pr.parameter("DI") + half - ln, 0, None) ** 1.5
    u_o = r * thd + half * om
    ur_o = 0.5 * np.abs(u_o - pr.parameter("DO") * thd)
    vx, vz = rd * np.cos(th) - r * thd * np.sin(th) - cvy, rd * np.sin(th) + r * thd * np.cos(th) - cvz
    vt = (-vx * sz + vz * sx) / ln
    r_i = 0.5 * pr.parameter("DI")
    u_i = vt - half * om - w_i * r_i
    ur_i = 0.5 * np.abs(vt * (1 - 2 * r_i / ln) - half * om + w_i * r_i)
    assert d > 0
    if pr.parameter("F_FTRAC") > 0.5:  # traction by film regime: the law is checked by hand in test_film_traction_models
        f_o, f_i = -race_tangential_array(u_o, ur_o, outer, False, p), -race_tangential_array(u_i, ur_i, inner, True, p)
    else:
        f_o, f_i = -tangential_force(u_o, ur_o, outer, p), -tangential_force(u_i, ur_i, inner, p)
    return (outer, inner, f_o, f_i, np.where(outer > 0, ur_o, 0.0), np.where(inner > 0, ur_i, 0.0),
            np.where(outer > 0, u_o, 0.0), np.where(inner > 0, u_i, 0.0))


def test_planar_observables_are_the_closed_forms_at_the_sample():
    ramp = 4e-3
    scene = Scene(conditions=OperatingConditions(3000.0, 500.0), duration_s=1e-3, speed_ramp_s=ramp)
    sim = Simulation(scene)
    pr = sim.build()
    ts = np.array([1e-3, 2e-3, 6e-3])  # inside the ramp (1/4 and 1/2 of the ring speed) and after it
    ys = np.array([_moving_state(pr, seed) for seed in range(3)])
    film = film_coefficients(scene)
    out = kernel_observables(pr, ts, ys, film)
    assert out.shape == (3, B.N_OBS, pr.n_balls)
    for i, (t, y) in enumerate(zip(ts, ys, strict=True)):
        outer, inner, f_o, f_i, ur_o, ur_i, us_o, us_i = _closed_forms(pr, t, y, ramp)
        assert np.sum(inner > 10.0) >= 5 and np.sum(outer > 10.0) >= 5  # the loaded zone is in contact
        for field, expected in ((B.OBS_OUTER_NORMAL, outer), (B.OBS_INNER_NORMAL, inner), (B.OBS_OUTER_TRACTION, f_o),
                                (B.OBS_INNER_TRACTION, f_i), (B.OBS_OUTER_ENTRAIN, ur_o),
                                (B.OBS_INNER_ENTRAIN, ur_i), (B.OBS_OUTER_SLIDE, us_o), (B.OBS_INNER_SLIDE, us_i)):
            np.testing.assert_allclose(out[i, field], expected, rtol=1e-7, atol=1e-9 * np.max(np.abs(expected)),
                                       err_msg=B.OBSERVABLES[field])
        for field, q, u, c_h in ((B.OBS_OUTER_FILM, outer, ur_o, film[0]), (B.OBS_INNER_FILM, inner, ur_i, film[1])):
            loaded = q > 0
            np.testing.assert_allclose(out[i, field][loaded], c_h * np.maximum(u[loaded], 1e-6) ** 0.67
                                       * q[loaded] ** -0.067, rtol=1e-7)
            assert np.all(np.isnan(out[i, field][~loaded]))
    # the traction opposes the sliding it was evaluated at
    loaded = out[:, B.OBS_INNER_NORMAL] > 10.0
    assert np.all(out[:, B.OBS_INNER_TRACTION][loaded] * out[:, B.OBS_INNER_SLIDE][loaded] <= 0.0)
    # the ramp enters the inner contact's entrainment: at 1/4 of the ring speed it is not the full-speed value
    full = _closed_forms(pr, ramp, ys[0], ramp)[5]
    assert np.max(np.abs(out[0, B.OBS_INNER_ENTRAIN] - full)) > 0.5


def test_non_finite_samples_give_nan_rows():
    scene = Scene(conditions=OperatingConditions(3000.0, 500.0), duration_s=1e-3)
    pr = Simulation(scene).build()
    ys = np.array([_moving_state(pr), np.full(pr.y0.shape, np.nan)])
    out = kernel_observables(pr, np.array([0.0, 1e-4]), ys)
    films = [B.OBS_OUTER_FILM, B.OBS_INNER_FILM]
    others = [k for k in range(B.N_OBS) if k not in films]
    assert np.all(np.isfinite(out[0, others])) and np.all(np.isnan(out[0, films]))
    assert np.all(np.isnan(out[1]))


def test_spatial_observables_reduce_to_the_planar_ones():
    scene = Scene(conditions=OperatingConditions(3000.0, 500.0), duration_s=1e-3)
    par = ModelParameters(strips=1)
    planar = Simulation(scene, par).build()
    spatial = Simulation(scene, par, Choices(level="spatial")).build()
    z = planar.n_balls
    y_p = _moving_state(planar)
    y_s = spatial.y0.copy()
    y_s[:5 * z + 6] = y_p  # no axial motion, no transverse spin, no tilt: the planar state
    a = kernel_observables(planar, np.array([1e-3]), y_p[None])[0]
    b = kernel_observables(spatial, np.array([1e-3]), y_s[None])[0]
    # a race contact at zero overlap is closed in one model and open in the other by round-off (its force ~0)
    touching = {B.OBS_OUTER_ENTRAIN: a[B.OBS_OUTER_NORMAL] > 1e-3, B.OBS_INNER_ENTRAIN: a[B.OBS_INNER_NORMAL] > 1e-3,
                B.OBS_OUTER_SLIDE: a[B.OBS_OUTER_NORMAL] > 1e-3, B.OBS_INNER_SLIDE: a[B.OBS_INNER_NORMAL] > 1e-3}
    for field in [k for k in range(B.N_OBS) if k not in (B.OBS_OUTER_FILM, B.OBS_INNER_FILM)]:
        keep = touching.get(field, np.ones(z, dtype=bool))
        np.testing.assert_allclose(b[field][keep], a[field][keep], rtol=1e-6,
                                   atol=1e-9 * max(np.max(np.abs(a[field])), 1e-12), err_msg=B.OBSERVABLES[field])
    assert np.sum(a[B.OBS_INNER_NORMAL] > 10.0) >= 5 and np.max(np.abs(a[B.OBS_INNER_TRACTION])) > 0.1


def test_films_in_the_trace_use_the_oil_viscosity_at_its_temperature():
    """The reported films use eta(T), as the race forces do: Hamrock & Dowson (1977) give h_c ~ (eta u)^0.67, so
    at 60 degC the films are (eta(60)/eta(20))^0.67 of those at 20 degC on the same states."""
    from cageless.simulation.models.observables import observables

    scene = Scene(conditions=OperatingConditions(3000.0, 500.0), duration_s=1e-3)
    runs = {}
    for temp in (20.0, 60.0):
        pr = Simulation(scene, ModelParameters(oil_temperature_c=temp)).build()
        ys = np.array([_moving_state(pr, 0)])
        runs[temp] = (pr.parameter("ETA0"), observables(pr, np.array([6e-3]), ys, scene, True)["contacts"])
    (eta20, c20), (eta60, c60) = runs[20.0], runs[60.0]
    assert eta60 < 0.5 * eta20  # the paper's temperature coefficient thins the oil by more than half over 40 K
    for name in ("outer_film", "inner_film"):
        loaded = np.isfinite(c20[name])
        assert loaded.sum() >= 5
        np.testing.assert_allclose(c60[name][loaded] / c20[name][loaded], (eta60 / eta20) ** 0.67, rtol=1e-9)
