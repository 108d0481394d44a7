"""The second renderer (tracking.synthetic.scene3d), its seed matrix and its scorer (issue 14, "A corpus that
does not flatter the tracker").

References: the highlight of a sphere under a distant light sits where the surface normal equals the half
vector h = normalise(l + v) (Blinn 1977), i.e. at the image offset R (h_x, -h_y) from the centre; a full
complement of Z touching balls on a pitch circle d_m has centre spacing D = d_m sin(pi (1 - gap)/Z) (chord
of the pitch circle); the slip rate is 1 - speed / omega_c with omega_c = omega_i (1 - D/d_m)/2 (pure rolling).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from cageless.kinematics import theoretical_cage_speed
from cageless.trace import Trace
from cageless.units import rpm_to_rad_s
from cageless.tracking.io import open_video
from cageless.tracking.synthetic.appearance import draw_params
from cageless.tracking.synthetic.corpus import clip_truth, render_clip, simulate_motion
from cageless.tracking.synthetic.matrix import FRESH, FRESH2, FRESH3, FRESH4, HOLDOUT, SETS, TUNING, TUNING2, coverage
from cageless.tracking.synthetic.scene3d import FrameState, SceneRenderer
from cageless.tracking.synthetic.score import BARS, ideal_trace, score_trace, truth_arrays

SMALL = next(s for s in TUNING if (draw_params(s).width, draw_params(s).height) == (640, 480))


def _state(params, k: int = 0) -> FrameState:
    m = simulate_motion(params, 5)
    return FrameState(time_s=float(m["times"][k]), angle=m["angle"][k], speed=m["speed"][k],
                      ring_angle=float(m["ring"][k]))


def test_draw_is_deterministic_and_seeds_differ():
    assert draw_params(SMALL) == draw_params(SMALL)
    assert draw_params(SMALL) != draw_params(SMALL + 1)


def test_frames_are_deterministic():
    p = draw_params(SMALL)
    a = SceneRenderer(p).frame(_state(p), 0)
    b = SceneRenderer(p).frame(_state(p), 0)
    c = SceneRenderer(p).frame(_state(p), 1)
    assert a.dtype == (np.uint8 if p.bit_depth == 8 else np.uint16)
    assert np.array_equal(a, b)
    assert not np.array_equal(a, c)  # the noise of another frame index


def test_geometry_is_a_full_complement():
    for s in TUNING[:8]:
        g = draw_params(s).geometry
        gap = draw_params(s).free_gap
        # Z chords of length D subtend 2 Z asin(D/d_m) = 2 pi (1 - gap)
        subtended = 2 * g.n_balls * math.asin(g.ball_diameter_m / g.pitch_diameter_m)
        assert subtended == pytest.approx(2 * math.pi * (1 - gap))
        assert g.max_ball_count == g.n_balls


@pytest.mark.parametrize("seed", [TUNING[0], TUNING[3], HOLDOUT[5]])
def test_rendered_highlight_is_where_the_truth_says(seed):
    """Intensity centroid of the specular lobe (sphere radiance with and without it) within 1 px of the truth."""
    p = dataclasses.replace(draw_params(seed), second_light_rel=0.0, elongation=1.0, highlight_peak=0.8,
                            exposure_s=1e-7, n_specks=0, n_turning_glints=0)
    r = SceneRenderer(p)
    st = _state(p)
    with_hl = r.radiance(st)
    r0 = SceneRenderer(dataclasses.replace(p, highlight_peak=0.0))
    lobe = (with_hl - r0.radiance(st)) / r.light_field
    _, truth, _ = clip_truth(seed)
    t0 = truth[truth.frame == 0]
    v, u = np.mgrid[0:p.height, 0:p.width]
    for _, row in t0.iterrows():
        if not row.highlight_visible:
            continue
        near = np.hypot(u - row.highlight_u_px, v - row.highlight_v_px) < max(4.0, 0.25 * r.r_px)
        w = np.where(near, np.clip(lobe, 0, None), 0)
        if w.sum() < 1e-3:
            continue
        cu, cv = (w * u).sum() / w.sum(), (w * v).sum() / w.sum()
        assert math.hypot(cu - row.highlight_u_px, cv - row.highlight_v_px) < 1.0


FACTOR_CHANGES = {
    "ring_face": lambda p: {"ring_face": "dark" if p.ring_face == "bright" else "bright"},
    "land_mode": lambda p: {"land_mode": "over" if p.land_mode == "hidden" else "hidden"},
    "ring_texture": lambda p: {"ring_texture": "machined" if p.ring_texture != "machined" else "brushed"},
    "saturation": lambda p: {"highlight_peak": 4.0 if p.highlight_peak < 1 else 0.5},
    "elongation": lambda p: {"elongation": 3.0 if p.elongation < 2 else 1.0},
    "second_light": lambda p: {"second_light_rel": 0.0 if p.second_light_rel else 0.8},
    "vignetting": lambda p: {"vignetting": 0.6 if p.vignetting < 0.3 else 0.0},
    "gradient": lambda p: {"gradient": 0.5 if p.gradient < 0.25 else 0.0},
    "flicker": lambda p: {"flicker_amplitude": 0.25 if p.flicker_amplitude < 0.1 else 0.0},
    "exposure (blur)": lambda p: {"exposure_s": 1e-7 if p.exposure_s > 2e-5 else 8e-5, "speed_rpm": 6000.0},
    "distortion": lambda p: {"distortion_k1": 0.02 if p.distortion_k1 <= 0 else -0.02},
    "roll": lambda p: {"roll_deg": p.roll_deg + 10},
    "offset": lambda p: {"centre_offset_px": (p.centre_offset_px[0] + 20, p.centre_offset_px[1])},
    "direction": lambda p: {"direction": -p.direction},
    "static glints": lambda p: {"n_static_glints": 12 if p.n_static_glints < 6 else 0},
    "turning glints": lambda p: {"n_turning_glints": 8 if p.n_turning_glints < 4 else 0},
    "dust": lambda p: {"n_dust": 30 if p.n_dust < 15 else 0},
    "specks": lambda p: {"n_specks": 10 if p.n_specks < 5 else 0},
    "hot pixels": lambda p: {"n_hot_pixels": 300 if p.n_hot_pixels < 150 else 0},
    "read noise": lambda p: {"read_noise_e": 40.0 if p.read_noise_e < 20 else 2.0},
    "black level": lambda p: {"black_level": 0.06 if p.black_level < 0.03 else 0.0},
    "jpeg": lambda p: {"bit_depth": 8, "container": "cine-8", "jpeg_quality": 30 if p.jpeg_quality == 0 else 0},
    "bit depth": lambda p: {"bit_depth": 8 if p.bit_depth != 8 else 16, "container": "cine-16"},
}


@pytest.mark.parametrize("factor", list(FACTOR_CHANGES))
def test_each_factor_changes_the_image(factor):
    """Changing one factor (everything else equal, the same noise) changes the frame measurably: > 0.2 % of
    full scale mean absolute difference, or at least 200 pixels (lint specks: 20) by more than 5 % of full
    scale; bit depth by its number of levels, read noise by the expected |difference| of the noise."""
    p = draw_params(SMALL)
    q = dataclasses.replace(p, **FACTOR_CHANGES[factor](p))
    a = SceneRenderer(p).frame(_state(p), 3).astype(float) / ((1 << p.bit_depth) - 1)
    b = SceneRenderer(q).frame(_state(q), 3).astype(float) / ((1 << q.bit_depth) - 1)
    d = np.abs(a - b)
    if factor == "bit depth":  # the quantisation: 256 levels against thousands
        assert min(len(np.unique(a)), len(np.unique(b))) <= 256 < max(len(np.unique(a)), len(np.unique(b)))
    elif factor == "read noise":  # 2 against 40 electrons over the same normal draws, in the darkest pixels
        dark = a <= np.quantile(a, 0.1)
        assert d[dark].mean() > 0.25 * 38 / p.full_well_e * math.sqrt(2 / math.pi)
    else:
        n_px = 20 if factor == "specks" else 200  # ten 3-px lint specks
        assert d.mean() > 0.002 or np.count_nonzero(d > 0.05) >= n_px, (factor, d.mean(), np.count_nonzero(d > 0.05))


#: Checks a set is known to miss: TUNING2's longest blur at 6000 rpm is 2.54 px (seed 7621; blur depends on speed,
#: exposure, scale and radius together, so no block guarantees 3 px, and none of 7632-7655 reaches it either).
_MISSED = {"TUNING2": ["motion blur: >= 3 px at 6000 rpm somewhere"]}


@pytest.mark.parametrize("name", list(SETS))
def test_each_set_covers_every_factor(name):
    missing = [f"{r['factor']}: {r['required']}" for r in coverage(SETS[name]) if not r["covered"]]
    assert missing == _MISSED.get(name, [])
    assert len(SETS[name]) >= 30


def test_sets_are_disjoint():
    assert not set(TUNING) & set(HOLDOUT)
    assert not (set(TUNING) | set(HOLDOUT)) & set(FRESH)
    assert not (set(TUNING) | set(HOLDOUT) | set(FRESH)) & set(FRESH2)
    assert not (set(TUNING) | set(HOLDOUT) | set(FRESH) | set(FRESH2)) & set(FRESH3)
    assert not (set(TUNING) | set(HOLDOUT) | set(FRESH) | set(FRESH2) | set(FRESH3)) & set(FRESH4)
    assert not (set(TUNING) | set(HOLDOUT) | set(FRESH) | set(FRESH2) | set(FRESH3) | set(FRESH4)) & set(TUNING2)


def test_each_set_is_whole_blocks():
    """Each set is whole blocks of 8 seeds starting at a multiple of 8 (the Latin hypercube of appearance.py)."""
    for seeds in SETS.values():
        assert len(seeds) % 8 == 0 and all(s % 8 == 0 for s in seeds[::8])
        assert list(seeds) == list(range(seeds[0], seeds[0] + len(seeds)))


# -- the scorer ------------------------------------------------------------------------------------------
def _truth_trace(params, truth, omega_c, angle=None, window=21) -> Trace:
    from cageless.tracking.kinematics import revolution_speed
    tr = truth_arrays(truth)
    a = tr["angle"] if angle is None else angle
    speed = revolution_speed(tr["time"], a, window, 2)
    g = params.geometry
    return Trace(source="video", time=tr["time"], angle=a, speed=speed,
                 slip=1 - speed / omega_c, valid=np.ones_like(a, bool), speed_rpm=params.speed_rpm,
                 radial_load_n=0.0, axial_load_n=0.0, ball_diameter_m=g.ball_diameter_m,
                 pitch_diameter_m=g.pitch_diameter_m, config={"tracking": {"window": window, "polyorder": 2}},
                 video=_video_info())


def _video_info():
    from cageless.trace import VideoInfo
    return VideoInfo(fps=1e4, px_per_mm=10.0, centre_px=(0.0, 0.0), camera_roll_rad=0.0, input_file="x",
                     input_sha256="")


@pytest.fixture(scope="module")
def clip():
    p, truth, omega_c = clip_truth(TUNING[1])
    assert omega_c == pytest.approx(theoretical_cage_speed(p.geometry, rpm_to_rad_s(p.speed_rpm)))
    return p, truth, omega_c


def test_perfect_trace_scores_zero(clip):
    p, truth, omega_c = clip
    s = score_trace(_truth_trace(p, truth, omega_c), truth, p.bearing)
    assert s.passed and s.n_found == s.n_balls == p.n_balls and s.swaps == 0
    assert s.angle_rms_mrad < 1e-9 and abs(s.offset_mrad) < 1e-9
    assert s.speed_rms_pct < 1e-9 and s.slip_mae_pp < 1e-9


def test_a_swap_is_counted(clip):
    p, truth, omega_c = clip
    a = truth_arrays(truth)["angle"].copy()
    half = len(a) // 2
    a[half:, [0, 1]] = a[half:, [1, 0]]  # tracks 0 and 1 exchange their balls half way
    s = score_trace(_truth_trace(p, truth, omega_c, a), truth, p.bearing)
    assert s.swaps == 2 and not s.passed


def test_a_constant_offset_is_reported_and_removed(clip):
    p, truth, omega_c = clip
    a = truth_arrays(truth)["angle"] + 0.02
    s = score_trace(_truth_trace(p, truth, omega_c, a), truth, p.bearing)
    assert s.offset_mrad == pytest.approx(20.0, abs=1e-6)
    assert s.angle_rms_mrad < 1e-6 and s.passed


def test_noise_and_extra_balls_fail_the_bars(clip):
    p, truth, omega_c = clip
    a = truth_arrays(truth)["angle"]
    noisy = a + np.random.default_rng(0).normal(0, 2e-3, a.shape)  # 2 mrad RMS
    s = score_trace(_truth_trace(p, truth, omega_c, noisy), truth, p.bearing)
    assert s.angle_rms_mrad == pytest.approx(2.0, rel=0.05)
    assert any(f.startswith("angle_rms") for f in s.failures)
    extra = np.column_stack([a, a[:, :1] + 0.5 * (a[:, 1:2] - a[:, :1])])
    s = score_trace(_truth_trace(p, truth, omega_c, extra), truth, p.bearing)
    assert s.n_found == p.n_balls + 1 and f"found {p.n_balls + 1} balls, not {p.n_balls}" in s.failures


def test_a_perfect_detector_meets_the_bars_on_every_clip():
    """Fairness of the corpus: true highlight positions, one circle fit and the tracker's speed filter pass
    every bar with room to spare on all 192 clips (lens distortion is limited for this)."""
    worst = 0.0
    for seed in (*TUNING, *HOLDOUT, *FRESH, *FRESH2, *FRESH3, *FRESH4):
        p, truth, _ = clip_truth(seed)
        s = score_trace(ideal_trace(p, truth), truth, p.bearing)
        assert s.passed, (seed, s.failures)
        worst = max(worst, s.angle_rms_mrad)
    assert worst < 0.5 * BARS["angle_rms_mrad"]


def test_written_clip_reads_back(tmp_path):
    """A rendered clip reads back through the tracker's reader: frame count, time stamps (dropped frames),
    sidecar conditions and truth rows agree."""
    seed = next(s for s in TUNING if draw_params(s).dropped_frame_rate >= 0.02 and draw_params(s).width <= 800)
    spec = render_clip(seed, tmp_path)
    assert spec.conditions.fps is None  # a cine's time stamps are not overridden
    times = truth_arrays(spec.truth)["time"]
    assert np.max(np.diff(times)) > 1.5 / spec.params.fps  # frames were dropped
    with open_video(spec.video, fps=spec.conditions.fps) as video:
        assert len(video) == spec.n_frames == len(times)
        assert np.allclose(video.times - video.times[0], times, atol=1e-7)
    again = render_clip(seed, tmp_path)  # reused, not re-rendered
    assert again.render_s == 0.0 and again.video == spec.video
