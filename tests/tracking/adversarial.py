"""Test helper: the bundled renderer with a look it was not tuned to (issue: footage from another set-up).

The ball band is not a dark cavity: the balls pass over brightly lit, brushed ring faces, so every gap
between two balls shows bright ring and the edges of the dark balls make bright points in a
background-subtracted frame; a few static glints brighter than the highlights sit in the band itself.
This reproduces what a second camera set-up showed ("the video shows 36 balls but the bearing has 14").
"""

from __future__ import annotations

import math

import numpy as np

from cageless.tracking.synthetic.render import Renderer, _Spot

__all__ = ["BrightBandRenderer"]


class BrightBandRenderer(Renderer):
    """Renderer whose ball band shows bright textured ring faces and static band glints."""

    def __init__(self, *args, band_level: float = 0.5, band_glints: int = 4, glint_peak: float = 1.6, **kw):
        self._band_level, self._n_band_glints, self._band_glint_peak = band_level, band_glints, glint_peak
        super().__init__(*args, **kw)
        rng = np.random.default_rng([self.seed, 9])
        rr, d = self.radii, self.geometry.ball_diameter_m
        self._outer_glints = self._outer_glints + [
            _Spot(radius_m=rng.uniform(rr.inner_land + 0.05 * d, rr.outer_land - 0.05 * d),
                  angle=rng.uniform(0, 2 * math.pi), sigma_m=rng.uniform(0.04, 0.07) * d,
                  peak=glint_peak, elongation=rng.uniform(1.0, 1.5))
            for _ in range(band_glints)]

    def _static_layer(self, rng):
        img = super()._static_layer(rng)
        rr = self.radii
        bright = self._brushed(rng, rr.inner_land, rr.outer_land) * (self._band_level / self.look.ring_level)
        return img * (1 - self._band) + bright * self._band
