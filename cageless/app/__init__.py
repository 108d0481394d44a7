"""The application layer: the command line, the lab-folder workflow and calibration.

It sits on top of the three science packages (:mod:`cageless.tracking`,
:mod:`cageless.simulation`, :mod:`cageless.comparison`) and of the shared core
(the rest of :mod:`cageless`). Nothing below imports it.
"""
