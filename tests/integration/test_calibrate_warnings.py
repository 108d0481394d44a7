"""A calibration says when its target does not determine the fitted values (cageless.app.calibrate.fit_warnings).

The evaluation tables here are made by hand, so each case's verdict is known: no simulation runs.
"""

from __future__ import annotations

from cageless.app.calibrate import Bound, CalibrationResult, fit_warnings, target_from_peak


def _result(rows: list[tuple[float, float]], bounds: list[Bound], fitted: dict[str, float],
            peak: bool = True, spread: float = 0.1) -> CalibrationResult:
    name = bounds[0].name
    table = [{"index": i, name: x, "objective_pp": obj, "peak_slip_pct": 5.0, "seed_spread_pp": spread,
              "status": "ok", "runs_ok": 2} for i, (x, obj) in enumerate(rows)]
    for b in bounds[1:]:
        for r in table:
            r[b.name] = fitted[b.name]
    target = target_from_peak(3000.0, 500.0, 7.79)
    best = min(r["objective_pp"] for r in table)
    return CalibrationResult(fitted=fitted, objective_pp=best, evaluations=table, method="hand", budget=len(rows),
                             seeds=2, metric="mae", target=target, bounds=bounds, settle_s=None, fixed={})


CHO = Bound("cho_n_s_m", 2000.0, 8000.0)


def test_a_well_determined_fit_has_no_warnings():
    # a V-shaped objective, 3 pp deep against a 0.1 pp seed spread, minimum inside the range
    rows = [(2000.0, 3.0), (3500.0, 1.5), (5000.0, 0.05), (6500.0, 1.5), (8000.0, 3.0)]
    assert fit_warnings(_result(rows, [CHO], {"cho_n_s_m": 5000.0})) == []


def test_a_flat_objective_is_called_undetermined():
    rows = [(2000.0, 1.02), (3500.0, 1.00), (5000.0, 1.05), (6500.0, 0.98), (8000.0, 1.01)]  # ptp 0.07 < 0.1
    (text,) = fit_warnings(_result(rows, [CHO], {"cho_n_s_m": 6500.0}))
    assert "0.070 pp" in text and "does not determine" in text


def test_a_value_at_the_edge_of_its_range_is_named():
    rows = [(2000.0, 0.1), (3500.0, 1.5), (5000.0, 2.0), (6500.0, 2.5), (8000.0, 3.0)]
    (text,) = fit_warnings(_result(rows, [CHO], {"cho_n_s_m": 2000.0}))
    assert text.startswith("cho_n_s_m = 2000 is at the edge of its range 2000:8000")


def test_a_wide_valley_names_the_values_that_fit_as_well():
    # 3500 and 6500 are within the 0.1 pp spread of the best: half the range fits as well
    rows = [(2000.0, 3.0), (3500.0, 0.12), (5000.0, 0.05), (6500.0, 0.14), (8000.0, 3.0)]
    (text,) = fit_warnings(_result(rows, [CHO], {"cho_n_s_m": 5000.0}))
    assert text.startswith("cho_n_s_m from 3500 to 6500 fits as well")


def test_several_parameters_against_one_peak_are_underdetermined():
    rows = [(2000.0, 3.0), (3500.0, 1.5), (5000.0, 0.05), (6500.0, 1.5), (8000.0, 3.0)]
    bounds = [CHO, Bound("restitution", 0.5, 0.9)]
    texts = fit_warnings(_result(rows, bounds, {"cho_n_s_m": 5000.0, "restitution": 0.7}))
    assert texts[0].startswith("a peak slip is one number: it cannot determine 2 parameters")


def test_noise_is_judged_by_the_largest_seed_spread_and_one_seed_is_named():
    # the objective ranges over 0.57 pp while one evaluation's seeds differ by 0.62 pp: noise, not a fit
    rows = [(0.0252786, 4.493), (0.0252853, 5.060), (0.02, 4.8), (0.03, 4.9)]
    bound = Bound("traction_sliding_coefficient", 0.01, 0.03)
    res = _result(rows, [bound], {"traction_sliding_coefficient": 0.0252786}, spread=0.1)
    res.evaluations[1]["seed_spread_pp"] = 0.62
    assert any("within the seeds' spread (0.620 pp)" in w for w in fit_warnings(res))
    one = CalibrationResult(**{**res.__dict__, "seeds": 1})
    assert fit_warnings(one)[0].startswith("one seed per evaluation")
