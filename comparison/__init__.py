"""comparison: model-vs-experiment alignment, metrics and the report.

It lands with the comparison issue; this package imports only the shared
core :mod:`cageless` and never ``tracking`` or ``simulation``.
"""
