"""Compiled integrators (see :mod:`cageless.simulation.solve` for the public entry point)."""
