"""Dynamical models assembled from the force laws of :mod:`cageless.simulation.forces`."""
