"""Compiled integrators (see :mod:`simulation.solve` for the public entry point)."""
