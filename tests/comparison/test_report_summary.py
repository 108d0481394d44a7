"""The report's opening summary: the tracking-QC verdict and one card per condition."""

from __future__ import annotations

from comparison.compare import ComparisonRow
from comparison.report.describe import QC_LIMITS, ConditionDescription, tracking_verdict
from comparison.report.render import render_html
from comparison.report.structure import build_report

GOOD = {"n_balls_found": 14, "n_balls_expected": 14, "detection_rate": [1.0] * 14, "interpolated_share": 0.0,
        "orbit_residual_px": 0.02, "warnings": []}


def test_verdict_passes_clean_qc_and_names_each_failed_limit():
    assert tracking_verdict(GOOD) == (True, [])
    bad = {**GOOD, "n_balls_found": 36, "detection_rate": [0.9] + [1.0] * 13, "interpolated_share": 0.08,
           "orbit_residual_px": 1.5, "warnings": ["glints"]}
    passed, reasons = tracking_verdict(bad)
    assert not passed and len(reasons) == 5
    assert reasons[0] == "36 balls found, 14 expected"
    assert "90.0 %" in reasons[1] and "8.0 %" in reasons[2] and "1.50 px" in reasons[3]
    assert reasons[4] == "tracker warning: glints"
    # exactly at the limits still passes
    edge = {**GOOD, "detection_rate": [QC_LIMITS["min_detection_rate"]] * 14,
            "interpolated_share": QC_LIMITS["max_interpolated_share"],
            "orbit_residual_px": QC_LIMITS["max_orbit_residual_px"]}
    assert tracking_verdict(edge)[0]
    assert tracking_verdict({}) == (False, ["no tracking QC record"])


def test_summary_card_precedes_the_table():
    row = ComparisonRow(3000, 500, 0, 2.26, 3.89, 1.17, 1.4, 2.0, label="n3000")
    failed = ComparisonRow(1800, 500, 0, float("nan"), float("nan"), float("nan"), float("nan"), float("nan"),
                           label="bad", status="failed", message="36 balls found, 14 expected")
    html = render_html(build_report([ConditionDescription(label="n3000", row=row, qc={**GOOD, "n_balls_found": 13})],
                                    failed_rows=[failed]))
    summary = html[html.index("<h2>Summary</h2>"):html.index("<h2>Conditions</h2>")]
    assert "model 2.26 %, experiment 3.89 %; MAE 1.17 pp" in summary
    assert "fail</span>: 13 balls found, 14 expected" in summary
    assert "bad</h3><span class=\"fail\">failed</span>: 36 balls found, 14 expected" in summary
