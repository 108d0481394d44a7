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


def angle_crb_mrad(params: "ClipParams", n_frames: int = 6, highlight_only: bool = True,  # noqa: F821
                   eps_rad: float = 2e-5) -> float:
    """RMS Cramér-Rao bound (mrad) on a ball's orbital angle in one frame of a corpus clip.

    The Fisher information of the angle is ``I = sum_i (d mu_i / d theta)^2 / var_i`` over the pixels of
    the ball's patch (Ober, Ram & Ward 2004, as :func:`position_crb`), with ``mu`` the noise-free image
    of :class:`~cageless.tracking.synthetic.scene3d.SceneRenderer` in electrons (light field, motion
    blur, lands, saturation: a clipped pixel carries no information) and the derivative a central
    difference of two renders ``eps_rad`` apart; ``var = mu + read^2 + q^2 / 12``. Flicker, JPEG
    and hot pixels are left out, so the bound is optimistic: a clip where it exceeds the angle bar
    cannot be tracked to that bar by any unbiased estimator.

    With ``highlight_only`` the derivative is taken of the specular lobes alone (balls and rings
    otherwise black), the information a highlight tracker uses; else of the whole scene (the ball's
    silhouette on the ring faces too). Returns ``sqrt(mean over frames and balls of 1 / I)``.
    """
    import dataclasses

    from cageless.tracking.synthetic.corpus import simulate_motion
    from cageless.tracking.synthetic.scene3d import FrameState, SceneRenderer

    p = params
    full = SceneRenderer(p)
    probe = SceneRenderer(dataclasses.replace(p, ball_albedo=0.0, rim=0.0)) if highlight_only else full
    if highlight_only:
        probe.static = np.zeros_like(probe.static)
    m = simulate_motion(p, p.n_frames)
    max_dn = (1 << p.bit_depth) - 1
    q_e = p.full_well_e / max_dn
    crbs = []
    for i in np.linspace(0, len(m["times"]) - 1, n_frames).astype(int):
        state = FrameState(time_s=float(m["times"][i]), angle=m["angle"][i], speed=m["speed"][i],
                           ring_angle=float(m["ring"][i]))
        mu = np.clip(full.radiance(state) * p.full_well_e, 0, p.full_well_e)
        var = mu + p.read_noise_e**2 + q_e**2 / 12.0
        live = mu < p.full_well_e  # saturated pixels read full scale whatever the angle
        for j in range(len(state.angle)):
            th, om = float(state.angle[j]), float(state.speed[j])
            plus, minus = probe.static.copy(), probe.static.copy()
            probe._ball(plus, th + eps_rad, om)
            probe._ball(minus, th - eps_rad, om)
            d = (plus - minus) * (p.full_well_e / (2 * eps_rad))
            info = float(np.sum(np.where(live, d.astype(np.float64) ** 2 / var, 0.0)))
            crbs.append(1.0 / info if info > 0 else np.inf)
    return float(1e3 * np.sqrt(np.mean(crbs)))
