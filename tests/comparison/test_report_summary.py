"""The report's opening summary: the tracking-QC verdict and one card per condition."""

from __future__ import annotations

from cageless.comparison.compare import ComparisonRow
from cageless.comparison.report.describe import ConditionDescription, tracking_verdict
from cageless.comparison.report.render import render_html
from cageless.comparison.report.structure import build_report

GOOD = {"n_balls_found": 14, "n_balls_expected": 14, "detection_rate": [1.0] * 14, "interpolated_share": 0.0,
        "orbit_residual_px": 0.02, "warnings": []}


def test_verdict_passes_clean_qc_and_names_each_failure():
    """The verdict takes the tracker's own QC warnings (its limits live in tracking.qc) and the ball count."""
    assert tracking_verdict(GOOD) == (True, [])
    bad = {**GOOD, "n_balls_found": 13, "warnings": ["detection rate below 90% for balls [3]", "glints"]}
    passed, reasons = tracking_verdict(bad)
    assert not passed
    assert reasons == ["13 balls found, 14 expected", "tracker warning: detection rate below 90% for balls [3]",
                       "tracker warning: glints"]
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


def test_reproduction_names_version_commit_and_python(monkeypatch):
    """The reproduction table says what produced the report: the software version, the git commit of the
    source tree when there is one (a copy outside git shows none) and the Python it ran on."""
    import sys

    from cageless import __version__
    from cageless.comparison.report import structure

    monkeypatch.setattr(structure, "git_commit", lambda: "0123abc-dirty")
    repro = dict(build_report([])["reproduction"])
    assert repro["software version"] == __version__
    assert repro["git commit"] == "0123abc-dirty"
    assert repro["Python"].startswith(sys.version.split()[0] + " on ")
    monkeypatch.setattr(structure, "git_commit", lambda: None)
    assert "git commit" not in dict(build_report([])["reproduction"])
