"""The model-vs-experiment report, built in three layers as ydata-profiling does.

1. :mod:`~comparison.report.describe`: the computed description (numbers and arrays);
2. :mod:`~comparison.report.structure`: a neutral structure of sections, tables and figures;
3. :mod:`~comparison.report.render`: one self-contained offline HTML file (Jinja2, figures as SVG data URIs).
"""

from comparison.report.describe import ConditionDescription, describe_condition
from comparison.report.render import render_html, write_report
from comparison.report.structure import build_report

__all__ = ["ConditionDescription", "describe_condition", "build_report", "render_html", "write_report"]
