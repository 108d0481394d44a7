"""Cramér-Rao bound on the position of a rendered highlight.

The bound used in the accuracy tests and ``cageless bench tracking``: the
Fisher information of a Gaussian spot sampled at pixel centres (exactly how
:mod:`cageless.tracking.synthetic.render` draws it),

    mu_i = A exp(-|x_i - x0|^2 / (2 s^2)) + b,

under independent Gaussian noise of variance ``mu_i`` (shot noise, in
electrons) + ``read^2`` + ``q^2 / 12`` (quantisation, q electrons per DN), with
amplitude A and background b known. Per axis, ``I_xx = sum_i (d mu_i / d x0)^2 / var_i``
and ``CRB_x = 1 / I_xx``; the 2-D bound is ``CRB_x + CRB_y``. See Ober, Ram & Ward,
"Localization accuracy in single-molecule microscopy", Biophys. J. 86 (2004)
1185-1200, for the pixelated-Fisher-information approach.
"""

from __future__ import annotations

import numpy as np

__all__ = ["position_crb"]


def position_crb(amplitude_e: float, sigma_px: float, background_e: float, read_noise_e: float,
                 electrons_per_dn: float, sub_pixel: tuple[float, float] = (0.0, 0.0)) -> float:
    """2-D Cramér-Rao bound (px^2) on the centre of one pixel-sampled Gaussian spot.

    Parameters
    ----------
    amplitude_e
        Peak of the spot above the background (electrons).
    sigma_px
        Gaussian standard deviation (px).
    background_e
        Background level under the spot (electrons).
    read_noise_e
        Read noise (electrons, standard deviation).
    electrons_per_dn
        Quantisation step (electrons per digital number).
    sub_pixel
        Spot centre offset from a pixel centre (px); the bound varies slightly with it.
    """
    r = int(np.ceil(6 * sigma_px)) + 1
    y, x = np.mgrid[-r:r + 1, -r:r + 1].astype(np.float64)
    dx, dy = x - sub_pixel[0], y - sub_pixel[1]
    g = amplitude_e * np.exp(-(dx**2 + dy**2) / (2 * sigma_px**2))
    var = g + background_e + read_noise_e**2 + electrons_per_dn**2 / 12.0
    ix = np.sum((g * dx / sigma_px**2) ** 2 / var)
    iy = np.sum((g * dy / sigma_px**2) ** 2 / var)
    return float(1.0 / ix + 1.0 / iy)
