"""benchmarks/ark_accuracy_means.py: its per-revolution sums, the statistics taken from them, the jackknife
standard error and the two one-sided tests' verdicts (the solves themselves are solver_speed's)."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest

sys.path.insert(0, str(Path(__file__).parent))
from effect_helpers import benchmark_module  # noqa: E402


@pytest.fixture(scope="module")
def mod():  # noqa: ANN201
    with benchmark_module("ark_accuracy_means") as module:
        yield module


def _uniform_run(cage: float, slips: list[float], revolutions: int, per_rev: int) -> tuple[np.ndarray, np.ndarray]:
    """Samples of balls turning at constant speeds cage (1 - s) (one column block each of angle and speed, as the
    planar layout places them: angles z:2z, speeds 3z:4z), over ``revolutions`` cage revolutions."""
    z = len(slips)
    period = 2 * math.pi / cage
    t = np.linspace(0.0, revolutions * period, revolutions * per_rev + 1)
    speed = cage * (1.0 - np.asarray(slips))
    y = np.zeros((t.size, 5 * z))
    y[:, z:2 * z] = t[:, None] * speed + np.arange(z) * 2 * math.pi / z
    y[:, 3 * z:4 * z] = speed
    return y, t


def test_mean_and_peak_of_constant_slips(mod) -> None:  # noqa: ANN001
    # Two balls at 2 % and 4 % slip all round: the mean slip over balls and samples is 3 pp (the definition
    # s = 1 - theta_dot / omega_c, cageless.kinematics.slip_rate). Two at 3 %: every bin of the mean profile is 3 pp,
    # hence its unloaded-zone peak too.
    cage = 124.5
    for slips, peak_pp in (([0.02, 0.04], None), ([0.03, 0.03], 3.0)):
        y, t = _uniform_run(cage, slips, 4, 3600)
        edges = np.linspace(0.0, t[-1], 5)
        sums = mod.batch_sums(y, t, 2, cage, edges)
        assert sums["bin_count"].shape == (4, 360) and sums["count"].sum() == 2 * t.size
        mean, peak = mod._statistics(sums, np.ones(4, dtype=bool))
        assert mean == pytest.approx(3.0, abs=1e-9)
        if peak_pp is not None:
            assert peak == pytest.approx(peak_pp, abs=1e-9)


def test_jackknife_of_the_mean_is_the_batch_means_error(mod) -> None:  # noqa: ANN001
    # For a mean over equal batches the delete-one-batch jackknife variance equals the batch means' s^2 / B
    # (Efron, The Jackknife, the Bootstrap and Other Resampling Plans, SIAM 1982, section 3.2; Kuensch,
    # Ann. Statist. 17 (1989) 1217, applied to non-overlapping blocks).
    rng = np.random.default_rng(0)
    b, bins = 8, 360
    count = np.full(b, 1000.0)
    a_mean, r_mean = 3.0 + 0.1 * rng.standard_normal(b), 3.0 + 0.1 * rng.standard_normal(b)
    a = {"total": a_mean * count, "count": count, "bin_total": np.ones((b, bins)), "bin_count": np.ones((b, bins))}
    r = {"total": r_mean * count, "count": count, "bin_total": np.ones((b, bins)), "bin_count": np.ones((b, bins))}
    d = mod.paired_difference(a, r)
    diff = a_mean - r_mean
    assert d["diff"][0] == pytest.approx(diff.mean(), rel=1e-12)
    assert d["se"][0] == pytest.approx(diff.std(ddof=1) / math.sqrt(b), rel=1e-9)
    assert d["diff"][1] == pytest.approx(0.0, abs=1e-12) and d["se"][1] == pytest.approx(0.0, abs=1e-12)


def test_two_one_sided_tests(mod) -> None:  # noqa: ANN001
    # The 90 % t interval with 9 degrees of freedom is +- 1.833 SE (the t table's 0.95 quantile for 9 degrees of
    # freedom, NIST/SEMATECH e-Handbook of Statistical Methods, section 1.3.6.7.2); Schuirmann's tests at 5 %
    # (J. Pharmacokinet. Biopharm. 15 (1987) 657) accept equivalence within +-bar when it lies inside.
    verdict, lo, hi = mod.decide(0.0, 0.005, 10, 0.01)
    assert verdict == "met" and hi == pytest.approx(1.833 * 0.005, rel=1e-3) and lo == pytest.approx(-hi)
    assert mod.decide(0.0, 0.006, 10, 0.01)[0] == "not decidable"  # 1.833 x 0.006 = 0.011 reaches past the bar
    assert mod.decide(0.05, 0.01, 10, 0.01)[0] == "missed"  # 0.05 - 0.0183 > 0.01
    assert mod.decide(-0.05, 0.01, 10, 0.01)[0] == "missed"


def test_segments_must_divide_the_run(mod) -> None:  # noqa: ANN001
    with pytest.raises(SystemExit, match="--segment"):
        mod.segmented(None, 124.5, "ark4", 25, 10, 1e4)


def test_batches_of_about_the_square_root(mod) -> None:  # noqa: ANN001
    # Flegal & Jones (Ann. Statist. 38 (2010) 1034): batches of floor(n^(1/2)) samples; 600 revolutions give 24.
    assert [mod.batch_revolutions(n) for n in (2, 10, 600)] == [1, 3, 24]
    sums = {"total": np.arange(10.0), "count": np.ones(10), "bin_total": np.ones((10, 3)), "bin_count": np.ones((10, 3))}
    grouped = mod.regroup(sums, 3)  # 0+1+2, 3+4+5, 6+7+8+9: the remainder joins the last batch
    assert grouped["total"].tolist() == [3.0, 12.0, 30.0] and grouped["count"].tolist() == [3.0, 3.0, 4.0]
    assert grouped["bin_total"].shape == (3, 3)


def test_onset_candidates_take_a_tenth_of_the_onset_step(mod, monkeypatch) -> None:  # noqa: ANN001
    # The candidates "ark4-onset10", "ark4-7-onset10" of benchmarks/solver_speed.py: ark4 at their tolerance on the
    # problem with Problem.onset_step divided by ten, nothing else changed.
    import solver_speed
    from dataclasses import dataclass

    @dataclass
    class _Pr:
        onset_step: float

    seen = []
    monkeypatch.setattr(solver_speed, "solve", lambda pr, t, method, rtol, **kw: seen.append(
        (pr.onset_step, method, rtol, kw)))
    for key in ("ark4-onset10", "ark4-7-onset10"):
        solver_speed._run(_Pr(1.44e-6), np.zeros(2), *solver_speed.CANDIDATES[key][1:])
    from cageless.simulation.auto_switch import default_max_step
    assert seen == [(pytest.approx(1.44e-7), "ark4", 1e-6, {"max_step": default_max_step("ark4")}),
                    (pytest.approx(1.44e-7), "ark4", 1e-7, {"max_step": default_max_step("ark4")})]
