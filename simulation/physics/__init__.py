"""Lubricant physics as compiled scalar units, ready to plug into the models' effects.

Each module holds numba-compatible scalar functions in SI units with the equation and its source in the
docstring, and no dependence on a model's state layout or parameter vector, so that any model (planar,
spatial) can call them from its right-hand side:

* :mod:`cageless.simulation.physics.viscosity`: Barus and Roelands pressure-viscosity, exponential temperature-viscosity;
* :mod:`cageless.simulation.physics.rolling_force`: hydrodynamic rolling force and moment at a race contact (Chiu 1974,
  as used in Gupta's ADORE), with the inlet meniscus distance (starvation);
* :mod:`cageless.simulation.physics.film_traction`: traction by lubrication regime, from the film parameter
  Lambda = h / sigma: boundary, mixed, full film with a limiting shear stress (Bair & Winer);
* :mod:`cageless.simulation.physics.drag`: Reynolds-dependent sphere drag (Schiller-Naumann) and the churning moment on a
  spinning ball, with the oil-air mixture density.

The models join them to their state in :mod:`cageless.simulation.models.rolling` (the ``rolling_losses`` effect)
and :mod:`cageless.simulation.models.regime` (the ``film_traction`` effect). The equations, parameters, ranges and
sources are gathered in ``docs/physics/lubricant.md``.
"""
