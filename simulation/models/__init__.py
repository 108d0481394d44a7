"""Dynamical models assembled from the force laws of :mod:`simulation.forces`."""
