"""Cited parameter sets. Each module documents its source and carries units in its names."""

from cageless.parameter_sets import wang2026

__all__ = ["wang2026"]
