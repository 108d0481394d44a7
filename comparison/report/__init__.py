"""The model-vs-experiment report, built in three layers as ydata-profiling does.

1. :mod:`~cageless.comparison.report.describe`: the computed description (numbers and arrays);
2. :mod:`~cageless.comparison.report.structure`: a neutral structure of sections, tables and figures;
3. :mod:`~cageless.comparison.report.render`: one self-contained offline HTML file (Jinja2, figures as SVG data URIs).
"""

from cageless.comparison.report.describe import ConditionDescription, describe_condition
from cageless.comparison.report.render import render_html, write_report
from cageless.comparison.report.structure import build_report

__all__ = ["ConditionDescription", "describe_condition", "build_report", "render_html", "write_report"]
