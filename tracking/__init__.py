"""tracking: from bearing video to per-ball orbital-angle, speed and slip traces.

The pipeline lands with the video-input and tracking issues; this package
imports only the shared core :mod:`cageless` and never ``simulation`` or
``comparison``.
"""
