"""Each frame's angles about its own centre (tracking/geometry.py: frame_shifts, frame_jumps, orbital_angles)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from cageless.tracking.geometry import FRAME_JUMP, Orbit, frame_jumps, frame_shifts, orbital_angles


def _table(n: int = 400, z: int = 12, shake_px: float = 0.0, noise_px: float = 0.0, seed: int = 0):
    """Highlights on a 200-px circle at 100 rad/s, 10 kfps, every frame moved by a common slow shake."""
    rng = np.random.default_rng(seed)
    t = np.arange(n) / 10_000.0
    truth = 100.0 * t[:, None] + 2 * np.pi * np.arange(z)[None, :] / z
    shake = shake_px * np.column_stack([np.sin(2 * np.pi * t / 0.01), np.cos(2 * np.pi * t / 0.013)])
    u = 320 + 200 * np.cos(truth) + shake[:, :1] + rng.normal(0, noise_px, truth.shape)
    v = 240 - 200 * np.sin(truth) + shake[:, 1:] + rng.normal(0, noise_px, truth.shape)
    table = pd.DataFrame({"frame": np.repeat(np.arange(n), z), "time_s": np.repeat(t, z),
                          "ball": np.tile(np.arange(z), n), "u_px": u.ravel(), "v_px": v.ravel(),
                          "mass": 1.0, "detected": True})
    return t, truth, shake, table


def _angle_error(angle: np.ndarray, truth: np.ndarray) -> np.ndarray:
    d = angle - truth[:, np.argsort(np.mod(truth[0], 2 * np.pi))]
    return d - np.mean(d)


def test_a_common_shake_is_measured_and_leaves_the_angles():
    """A 0.5 px shake of the whole image (2.5 mrad on a 200 px circle about a fixed centre) is found to
    0.01 px and the angles come back to 0.01 mrad."""
    t, truth, shake, table = _table(shake_px=0.5)
    orbit = Orbit(centre=(320.0, 240.0), radius=200.0, residual=0.0)
    u = table.u_px.to_numpy().reshape(len(t), -1)
    v = table.v_px.to_numpy().reshape(len(t), -1)
    found = frame_shifts(t, u, v, orbit, frames=21)
    assert np.max(np.abs(found - shake)) < 0.01
    fixed, *_ = orbital_angles(table, orbit, steady=0)
    moving, *_ = orbital_angles(table, orbit, steady=21)
    assert np.sqrt(np.mean(_angle_error(fixed, truth) ** 2)) > 1e-3
    assert np.sqrt(np.mean(_angle_error(moving, truth) ** 2)) < 1e-5


def test_without_a_shake_the_noise_grows_little():
    """On still footage with white position noise the per-frame centre, smoothed over 21 frames, adds under
    2 % to the angle noise."""
    t, truth, _, table = _table(n=2000, noise_px=0.05)
    orbit = Orbit(centre=(320.0, 240.0), radius=200.0, residual=0.0)
    fixed, *_ = orbital_angles(table, orbit, steady=0)
    moving, *_ = orbital_angles(table, orbit, steady=21)
    rms_fixed = np.sqrt(np.mean(_angle_error(fixed, truth) ** 2))
    rms_moving = np.sqrt(np.mean(_angle_error(moving, truth) ** 2))
    assert rms_moving < 1.02 * rms_fixed


def test_an_outlier_does_not_move_the_frame():
    """A glint pulling one highlight 3 px outwards in one frame is left out of that frame's centre."""
    t, _, _, table = _table(n=100, noise_px=0.01)
    u = table.u_px.to_numpy().reshape(len(t), -1).copy()
    v = table.v_px.to_numpy().reshape(len(t), -1)
    u[50, 0] += 3.0
    orbit = Orbit(centre=(320.0, 240.0), radius=200.0, residual=0.0)
    found = frame_shifts(t, u, v, orbit, frames=1)
    assert np.max(np.abs(found[50])) < 0.03


def test_a_frame_whose_highlights_jump_together_is_not_valid():
    """FRESH2 seed 7209: the tracker started on the second light's highlights and drifted onto the first over two
    frames, every highlight of frame 0 moved alike by 6.2 px and of frame 1 by 4.3 px (0.049 and 0.034 of the
    127.5 px radius; 46 mrad at worst). Those frames' samples are flagged not valid; a smooth 0.5 px shake is not."""
    t, truth, _, table = _table(n=100, noise_px=0.01)
    u = table.u_px.to_numpy().reshape(len(t), -1).copy()
    v = table.v_px.to_numpy().reshape(len(t), -1).copy()
    u[0] += 6.1 * 200 / 127.5
    v[0] -= 3.2 * 200 / 127.5
    u[1] += 4.3 * 200 / 127.5
    v[1] -= 2.2 * 200 / 127.5
    jumped = table.assign(u_px=u.ravel(), v_px=v.ravel())
    orbit = Orbit(centre=(320.0, 240.0), radius=200.0, residual=0.0)
    _, jump = frame_jumps(t, u, v, orbit, frames=21)
    assert jump[0] > 9.0 and jump[1] > 6.5 and jump[2:].max() < 0.05
    _, valid, _, _ = orbital_angles(jumped, orbit, steady=21)
    assert np.flatnonzero(~valid.all(axis=1)).tolist() == [0, 1] and valid[2:].all()
    _, _, _, still = _table(n=100, shake_px=0.5)
    assert FRAME_JUMP * 200 == 2.0
    assert orbital_angles(still, orbit, steady=21)[1].all()
