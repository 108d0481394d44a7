"""Issue 14's bars on every clip of the independent corpus, all six seed sets (tracking/synthetic/matrix.py).

Bars (issue 14, "A corpus that does not flatter the tracker"): exactly Z balls, 0 identity swaps, angle
RMS <= 0.5 mrad, speed RMS <= 0.5 % of the cage speed, slip-profile MAE <= 0.3 pp (scorer:
tracking/synthetic/score.py; a perfect highlight detector passes all of them on every clip, see
test_corpus_renderer.py).

CI runs the first block of 8 seeds of each set (each block covers every factor's range ends); the other
clips and the long variants are ``slow`` (``--runslow``). The long variants are those of TUNING and HOLDOUT
(FRESH's to FRESH4's were not rendered). Clips render once per session into
``$CAGELESS_CORPUS_CACHE`` (default: a pytest temporary folder, each video deleted once scored) on two
processes.

Today's tracker fails most clips, so each known failure is a strict xfail: when a change makes a clip pass,
pytest reports XPASS(strict) as a failure and the seed must leave :data:`KNOWN_FAILURES`.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from cageless.tracking.synthetic.matrix import FRESH, FRESH2, FRESH3, FRESH4, HOLDOUT, TUNING
from cageless.tracking.synthetic.runner import run_seeds
from cageless.tracking.synthetic.score import BARS

CI_SEEDS = (*TUNING[:8], *HOLDOUT[:8], *FRESH[:8], *FRESH2[:8], *FRESH3[:8], *FRESH4[:8])
ALL = ([("TUNING", s) for s in TUNING] + [("HOLDOUT", s) for s in HOLDOUT] + [("FRESH", s) for s in FRESH]
       + [("FRESH2", s) for s in FRESH2] + [("FRESH3", s) for s in FRESH3] + [("FRESH4", s) for s in FRESH4])
ALL_LONG = [(name, s) for name, s in ALL if name in ("TUNING", "HOLDOUT")]

#: Seeds today's tracker fails on the short clips, with how (benchmarks/tracking_corpus.py, 2026-11-23: the
#: tracker of commit e3726da passed TUNING 4 of 32 and HOLDOUT 1 of 32; with the ball selection stage
#: (tracking/select.py) TUNING 14 and HOLDOUT 12; with the ball band found from motion on dark faces, on the
#: corpus of format 8, TUNING 13 and HOLDOUT 14; with the tapered centroid window TUNING 18 and HOLDOUT 16;
#: with the selection's tracklet gates, blob-centred candidates, hysteresis and low-quantile background, the
#: centroid mask on the highlight circle, window re-centring to convergence and the robust track fit
#: TUNING 25 and HOLDOUT 24, every clip with all Z balls; with the brighter of two lights' circles TUNING 26 and HOLDOUT 24;
#: with masked pixels left out of the centroid together with their mirror images TUNING 28 and HOLDOUT 23:
#: 1024, 1029, 7005, 7013 pass, 7026 2.22 -> 0.68 mrad, while 7011, 7012 and 7025 fail by 2-14 % of a bar
#: and 7020 goes from 0.78 to 1.12 mrad); with lighting dropouts left out of the motion map and of the noise
#: estimate, and the search band widened to whole balls when the band between the lands holds too few, the
#: same counts (1011 0.62 -> 0.68 mrad: its motion band, without the two dark frames, is the balls' scalloped
#: annulus instead of the whole bearing; a JPEG q30 clip the oracle fails too); with static glints up to 3 px
#: across masked as defects (a 5 x 5 median, was 3 x 3: 7020's saturated glint on the highlights' path pulled
#: the centroid by up to 10 mrad) TUNING 28 (no clip worse by more than 0.01 mrad; 1020 0.37 -> 0.14, 1029
#: 0.35 -> 0.14 mrad) and HOLDOUT 27: 7011, 7012, 7020 (1.12 -> 0.33 mrad), 7025 pass, 7018 1.46 -> 1.32 mrad,
#: while 7026 goes from 0.68 to 2.05 mrad (not diagnosed); with the static-defect test's second condition at
#: its stated 8 sigma (it read the frame-quartile index, 4 for 16 frames, as its threshold) the same counts,
#: no TUNING clip worse (1022 0.553 -> 0.545, 1029 0.136 -> 0.130 mrad), and held out 7026 2.05 -> 1.63 mrad;
#: with each frame's angles about its own centre (tracking/geometry.py frame_shifts: the translation the frame's
#: highlights share, from their radial residuals, smoothed over the speed window) TUNING 29: 1014 passes (angle
#: 0.83 -> 0.288 mrad, speed 0.346 -> 0.063 %: a doubled, saturated highlight under 25 % flicker, whose pull
#: towards its second lobe followed the light level), no clip fails anew, the largest changes 1020 0.137 ->
#: 0.156 mrad, 1002 0.444 -> 0.450 mrad, 1018 speed 0.244 -> 0.268 %; with the static pattern in front of the
#: balls subtracted (static.static_pattern: lint specks standing out of the median background and of the frames'
#: minimum by 8 times those images' own noise, up to 5 px across, with their tails; not where a pixel reads the
#: data's maximum) TUNING 30: 1012 passes (angle 0.541 -> 0.279 mrad, speed 0.776 -> 0.374 %, slip 0.313 ->
#: 0.158 pp), no clip fails anew; angle RMS over the set 3 % lower (geometric mean), better by over 10 % on 1003
#: (0.371 -> 0.304), 1018, 1019 (0.215 -> 0.175), worse by over 10 % on 1000 (0.316 -> 0.356), 1015 (0.255 ->
#: 0.292), 1020 (0.156 -> 0.174), 1023 (0.168 -> 0.206 mrad). HOLDOUT with both, run once as a final check:
#: 28 (7008 passes, 0.58 -> 0.445 mrad; no clip fails anew; 7018 1.32 -> 1.28 mrad, 7009 0.614 -> 0.625 mrad,
#: 7026 1.63 -> 2.18 mrad and speed 0.545 -> 1.71 %, not diagnosed). Tried and not adopted: the detector's
#: thresholds from the pixel noise (detect.pixel_noise; branch track-acc, commits 50d94af and dc7245f, reverted):
#: TUNING 30, no clip failing anew (1011 0.643 mrad, speed 0.735 %; 1022 0.597 mrad), but HOLDOUT, run once, 27:
#: 7022 failed (0.506 mrad, speed 0.545 %), 7004 speed 0.69 %, 7009 0.621, 7018 1.27, 7026 2.19 mrad.
#: With the error tied to a place on the circle removed (tracking/position_bias.py; 2026-11-27): TUNING 30
#: (1011 0.656 -> 0.573 mrad, speed 0.703 -> 0.664 %; 1022 0.553 -> 0.536 mrad; angle RMS 3.8 % lower, geometric
#: mean). HOLDOUT, run once: 28 (7018 1.28 -> 0.811 mrad, 7026 2.18 -> 1.28 mrad and speed 1.71 -> 0.472 %, 7009
#: 0.625 -> 0.618, 7004 speed 0.698 %). FRESH (seeds never run before), run once beside the tracker before the
#: change: 24 against 23 (7111 passes, 0.616 -> 0.469 mrad; none fails anew; 3 clips refused by both, the ball
#: selection finding 9, 17 and 12 of 16, 18 and 16 balls).
#: With a small bearing located in a wide frame (the faces and the motion re-thresholded on the full stretch when the
#: usual one finds no ring or splits the still pixels' noise) and the ball selection retried from 3-sigma candidates
#: when 4 sigma shows fewer than Z balls (2026-11-27; all four sets run once with the final change, the tree before
#: it beside it, tracked and scored as tracking/synthetic/runner.py does, without the oracle): TUNING 30 -> 30 (1011
#: 0.573 -> 0.592 mrad; 1029, located from the faces instead of the motion, 0.121 -> 0.448 mrad), HOLDOUT 28 -> 28
#: (7018 0.811 -> 0.651, 7009 0.618 -> 0.633 mrad), FRESH 24 -> 27 (7110, 7118 and 7123 pass: 0.120, 0.110, 0.179
#: mrad; no clip fails anew) and FRESH2 (seeds 7200-7231, added before the change and never tuned on) 25 -> 25 (7201
#: 2.32 -> 2.20 mrad, still failing; 7220 refused by both: 71 % of the ball positions lost; 7218 a trace 17.1 mrad
#: off with every ball found, both).
#: With the backward pass started from where the forward pass settled (tracking/link.py SETTLE_FRAMES; 2026-11-27,
#: all five sets run once with the final change, HOLDOUT, FRESH and FRESH2 beside main c3551a8, same renders, no
#: oracle): TUNING 30 (1011 0.592, 1022 0.536 mrad as before), HOLDOUT 28 -> 28 (7026 1.28 -> 3.09 mrad: the backward
#: pass slid onto the other light's lobe over frames 0-8 of one ball), FRESH 27 -> 27, FRESH2 25 -> 26 (7209 passes,
#: 0.736 -> 0.279 mrad; 7224 0.724 -> 0.690) and FRESH3 (7304-7335, added before this change, never tuned on, run
#: once) 28: 7304 and 7334 refused by the selection (7 of 16, 11 of 17 balls), 7317 and 7329 fail. The long variants
#: were not re-run with this change.
#: FRESH4 (7400-7431) was added before issue 14's third robustness round and scored once with main's tracker (commit
#: 8c12d80, benchmarks/tracking_corpus.py --sets FRESH4, 2026-11-28, with the oracle): 28 of 32 pass, 7415 refused by
#: the selection (11 of 12 balls), 7411, 7418 and 7430 fail; the oracle passes 23, and the Cramer-Rao bound on 7418
#: (0.890 mrad) is above the angle bar, the first clip of the corpus out of reach in principle. Its failures were not
#: looked into while the tracker was changed.
#: With a stated scale bounding the ball circle in the choice (tracking/select_circle.py: only circles within
#: PRIOR_RADIUS_TOL ball diameters of the pitch circle are hypotheses) and the located band required to hold the pitch
#: circle (tracking/pipeline.py _locate; else the band from the motion), 2026-11-28, all six sets run once with the final
#: change (benchmarks/tracking_corpus.py --no-oracle; FRESH2 and FRESH3 beside main 8c12d80 run after it on the same
#: renders, TUNING to FRESH against the values recorded here, FRESH4 against its first run): TUNING 30 -> 30, HOLDOUT 28 -> 28, FRESH 27 -> 27, FRESH2 26 -> 28 (7218
#: 0.296 mrad and 7220 0.156 mrad pass: the highlights' circle instead of the gaps'), FRESH3 28 -> 29 (7304 passes,
#: 0.249 mrad, band from the motion; 7334 still refused, 7 of 17) and FRESH4 28 -> 28 (7415 still refused, 10 of 12).
#: With a ball tracked on another light's lobe moved onto the others' (tracking/lobes.py; 2026-11-28, diagnosed on
#: TUNING and a new tuning set TUNING2, 7600-7631, scored by the benchmark only): TUNING 30 -> 30, TUNING2 26 -> 27
#: (7605 17.8 -> 0.116 mrad, one of 14 balls 7.1 px off all clip long); HOLDOUT to FRESH4, run once with the change
#: final (--no-oracle): the same counts, no ball moved on any of their 160 clips, so the same traces.
#: With the track fit's window chosen per clip by cross-validation (tracking/track_window.py; 2026-11-28, tuned on TUNING
#: and TUNING2 only, benchmarks/tracking_corpus.py --no-oracle): TUNING 30 -> 32 (1011 0.592 -> 0.361 mrad, 0.686 ->
#: 0.448 %, 0.407 -> 0.293 pp; 1022 0.536 -> 0.494 mrad), TUNING2 27 -> 29 (7606 0.615 -> 0.420, 7607 0.542 -> 0.232
#: mrad). The held-out sets, run once with the change final, against the figures recorded here: HOLDOUT 28 -> 29 (7018
#: passes, 0.65 -> 0.438 mrad; 7009 0.633 -> 0.563, 7026 3.09 -> 3.06 mrad), FRESH 27 -> 29 (7112 0.504 -> 0.409, 7116
#: 0.535 -> 0.471 mrad pass; 7124 1.35 -> 1.33 mrad, speed 0.711 -> 0.853 %), FRESH2 28 -> 29 (7228 0.74 -> 0.247 mrad
#: passes; 7201 2.2 -> 1.75 mrad), FRESH3 29 -> 29 (7317 1.02 -> 0.801, 7329 0.715 -> 0.689 mrad), FRESH4 28 -> 28
#: (7418 1.38 -> 1.10, 7430 0.53 -> 0.52 mrad); no clip fails anew.
#: Remove a seed when it passes.
KNOWN_FAILURES: dict[int, str] = {
    7004: "speed_rms 0.696 % of cage speed > 0.5",
    7009: "angle_rms 0.563 mrad > 0.5",
    7026: "angle_rms 3.06 mrad > 0.5; speed_rms 1.63 % of cage speed > 0.5; slip_mae 0.347 pp > 0.3",
    7117: "angle_rms 0.707 mrad > 0.5; speed_rms 0.641 % of cage speed > 0.5",
    7124: "angle_rms 1.33 mrad > 0.5; speed_rms 0.853 % of cage speed > 0.5",
    7134: "angle_rms 0.924 mrad > 0.5",
    7201: "angle_rms 1.75 mrad > 0.5; speed_rms 1.44 % of cage speed > 0.5; slip_mae 0.848 pp > 0.3 (JPEG q30 noise; "
          "the oracle reads 4.42 mrad)",
    7224: "angle_rms 0.69 mrad > 0.5; speed_rms 1.34 % of cage speed > 0.5; slip_mae 0.435 pp > 0.3 (two lobes in "
          "one window)",
    7226: "angle_rms 0.607 mrad > 0.5 (two lobes in one window)",
    7317: "angle_rms 0.801 mrad > 0.5",
    7329: "angle_rms 0.689 mrad > 0.5",
    7334: "refused: found 7 balls moving together along one circle, but 17 are expected (faint highlights: in the "
          "band of whole balls every candidate of the first burst is a wedge between balls, 39 or 50.5 px from the "
          "centre; the pitch circle is 45.3 px)",
    7411: "angle_rms 0.691 mrad > 0.5",
    7415: "refused: found 10 balls moving together along one circle, but 12 are expected (11 with main 8c12d80)",
    7418: "angle_rms 1.1 mrad > 0.5; speed_rms 1.49 % of cage speed > 0.5; slip_mae 0.616 pp > 0.3 (the Cramer-Rao "
          "bound is 0.890 mrad)",
    7430: "angle_rms 0.52 mrad > 0.5",
}

#: The same for the long variants (one cage revolution each), "" = passes: all 64 seeds measured with the tracker of
#: commit acd0318 (benchmarks/tracking_corpus.py --long, 2026-11-23: TUNING 28 and HOLDOUT 26 of 32, no refusal,
#: no wrong count, no swap; with commit d8b5436 on 49 seeds and a8bc98e on the other 15 it was TUNING 28 and
#: HOLDOUT 21, with 7010 and 7021 refused). 1012 and 1014 re-measured with commit 1b9ce63 (each frame's own centre,
#: lint subtracted): both pass (1012 angle 0.279 mrad, speed 0.357 %; 1014 angle 0.283 mrad, speed 0.065 %);
#: with commit 4946aa3, 7008 passes (0.561 -> 0.436 mrad) and 1000, 1023 still pass (0.366, 0.186 mrad);
#: all 64 re-measured with the place-bound error removed (tracking/position_bias.py, merge 304fdd1; 2026-11-27): the
#: 57 marked "" pass, the seven known failures still fail, and the reasons below are those runs. With the small-bearing
#: localisation and the selection retry (2026-11-27), the nine seeds whose short clip is now located differently were
#: re-measured (not the other 55): 1011 0.637 -> 0.701 mrad, 7009 0.604 -> 0.623, 7018 0.695 -> 0.641 (still failing);
#: 1029 passes at 0.487 mrad, 7002 0.328, and 1009, 7011, 7024, 7025 pass. All 64 re-measured with the tracker of
#: main 9422302 (with the backward pass started where the forward pass settled; run from branch trackprec, commits
#: 60a4470 and 43c244c, b72f028 and 0e041df once rebased onto main 3da97eb, whose precision estimate does not
#: change the trace: benchmarks/tracking_precision.py --long,
#: 2026-11-27): the same 57 pass and the same 7 fail; 7026 1.18 -> 1.20 mrad, 7018 0.641 -> 0.640, 1011 speed
#: 0.825 -> 0.824 %, the rest unchanged. With the track fit's window chosen by cross-validation (branch matrixacc,
#: 2026-11-28; benchmarks/tracking_corpus.py --long --no-oracle) the seven failing seeds were re-measured, not the 57
#: that pass: 7018 passes (0.64 -> 0.447 mrad), 1011 0.701 -> 0.554 mrad (speed 0.824 -> 0.738 %, slip 0.45 ->
#: 0.416 pp), 1022 0.575 -> 0.548, 7009 0.623 -> 0.554 mrad; 7004, 7026 and 7031 as before. All 64 re-measured with
#: the tracker of main 1f6ed9a (the cross-validated window; branch matrixacc2, 2026-11-28,
#: benchmarks/tracking_corpus.py --long --no-oracle --sets TUNING,HOLDOUT): TUNING 30 and HOLDOUT 28 of 32, no
#: status changed: the 58 marked "" pass (no swap, every ball found; nearest the bars 1029 0.487 mrad, 7018 0.447,
#: 1024 0.410, 7008 0.402 mrad, 7006 speed 0.388 %) and the six below fail with the figures recorded here.
_LONG_MEASURED: dict[int, str] = {
    1000: "",
    1001: "",
    1002: "",
    1003: "",
    1004: "",
    1005: "",
    1006: "",
    1007: "",
    1008: "",
    1009: "",
    1010: "",
    1011: "angle_rms 0.554 mrad > 0.5; speed_rms 0.738 % of cage speed > 0.5; slip_mae 0.416 pp > 0.3",
    1012: "",
    1013: "",
    1014: "",
    1015: "",
    1016: "",
    1017: "",
    1018: "",
    1019: "",
    1020: "",
    1021: "",
    1022: "angle_rms 0.548 mrad > 0.5",
    1023: "",
    1024: "",
    1025: "",
    1026: "",
    1027: "",
    1028: "",
    1029: "",
    1030: "",
    1031: "",
    7000: "",
    7001: "",
    7002: "",
    7003: "",
    7004: "angle_rms 0.632 mrad > 0.5; speed_rms 1.23 % of cage speed > 0.5",
    7005: "",
    7006: "",
    7007: "",
    7008: "",
    7009: "angle_rms 0.554 mrad > 0.5",
    7010: "",
    7011: "",
    7012: "",
    7013: "",
    7014: "",
    7015: "",
    7016: "",
    7017: "",
    7018: "",
    7019: "",
    7020: "",
    7021: "",
    7022: "",
    7023: "",
    7024: "",
    7025: "",
    7026: "angle_rms 1.2 mrad > 0.5",
    7027: "",
    7028: "",
    7029: "",
    7030: "",
    7031: "angle_rms 0.502 mrad > 0.5",
}
KNOWN_FAILURES_LONG: dict[int, str] = {s: why for s, why in _LONG_MEASURED.items() if why}

_REASON = "tracker not yet robust to this footage (issue 14)"


def _params(long: bool = False) -> list:
    out = []
    known = KNOWN_FAILURES_LONG if long else KNOWN_FAILURES
    for name, seed in ALL_LONG if long else ALL:
        marks = []
        if long or seed not in CI_SEEDS:
            marks.append(pytest.mark.slow)
        if seed in known:
            marks.append(pytest.mark.xfail(strict=True, reason=f"{_REASON}: {known[seed]}"))
        out.append(pytest.param(seed, id=f"{name}-{seed}", marks=marks))
    return out


@pytest.fixture(scope="session")
def corpus_dir(tmp_path_factory) -> Path:
    env = os.environ.get("CAGELESS_CORPUS_CACHE")
    return Path(env) if env else tmp_path_factory.mktemp("corpus")


@pytest.fixture(scope="session")
def corpus_results(request, corpus_dir):
    """Render, track and score once per session: the CI seeds, and all seeds with --runslow."""
    seeds = list(CI_SEEDS)
    if request.config.getoption("--runslow"):
        seeds += [s for _, s in ALL if s not in CI_SEEDS]
    keep = bool(os.environ.get("CAGELESS_CORPUS_CACHE"))  # else delete each video once scored (disk)
    return {r.seed: r for r in run_seeds(seeds, corpus_dir / "ci", workers=2, progress=False, keep=keep)}


@pytest.fixture(scope="session")
def corpus_results_long(corpus_dir):
    return {r.seed: r for r in run_seeds([s for _, s in ALL_LONG], corpus_dir / "long", workers=2, long=True,
                                         progress=False, keep=False)}


def test_every_long_variant_has_a_measured_entry():
    """Every seed's long clip was run with a recent tracker (no entry carried over from an older baseline)."""
    assert sorted(_LONG_MEASURED) == sorted(s for _, s in ALL_LONG)


def _assert_bars(result) -> None:
    assert result.status != "error", f"seed {result.seed}: the tracker gave no trace: {result.message}"
    s = result.score
    assert s["n_found"] == s["n_balls"], f"seed {result.seed}: found {s['n_found']} balls, not {s['n_balls']}"
    assert s["frames_matched"] == result.n_frames
    assert s["swaps"] == 0
    assert s["angle_rms_mrad"] <= BARS["angle_rms_mrad"]
    assert s["speed_rms_pct"] <= BARS["speed_rms_pct"]
    assert s["slip_mae_pp"] <= BARS["slip_mae_pp"]


@pytest.mark.parametrize("seed", _params())
def test_tracker_meets_the_bars(seed, corpus_results):
    _assert_bars(corpus_results[seed])


@pytest.mark.parametrize("seed", _params(long=True))
def test_tracker_meets_the_bars_long(seed, corpus_results_long):
    """The long variants: one cage revolution per clip (slow)."""
    _assert_bars(corpus_results_long[seed])
