"""Camera and scene appearance of the synthetic bearing video.

Image convention: pixel centres sit at integer (u, v), u the
column and v the row. A bearing-frame point (y, z) maps to

    u = cx + s (y cos(roll) - z sin(roll)),   v = cy - s (y sin(roll) + z cos(roll)),

with s pixels per metre, (cx, cy) the bearing centre in the image and ``roll``
how far the image is turned counter-clockwise from the bearing frame. So an
image angle is the bearing angle plus the roll.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from cageless.bearing import Geometry
from cageless.errors import ParameterError

__all__ = ["Camera", "Appearance", "RingRadii"]


@dataclass(frozen=True)
class Camera:
    """A monochrome high-speed camera looking at the bearing's end face.

    Parameters
    ----------
    width, height
        Resolution (px).
    px_per_mm
        Image scale (pixels per mm).
    fps
        Frame rate (frames/s).
    centre_offset_px
        Bearing centre relative to the image centre (px, +u right, +v down).
    roll_deg
        Camera roll (deg): the image is turned this far counter-clockwise from the bearing frame.
    bit_depth
        8, 10, 12, 14 or 16 significant bits.
    exposure_s
        Exposure time (s); motion during it blurs the image.
    full_well_e
        Electrons at saturation (sets the shot noise).
    read_noise_e
        Read noise (electrons, standard deviation).
    black_level_dn
        Offset added to every pixel (in DN at this bit depth).
    """

    width: int = 1280
    height: int = 800
    px_per_mm: float = 12.5
    fps: float = 10_000.0
    centre_offset_px: tuple[float, float] = (0.0, 0.0)
    roll_deg: float = 0.0
    bit_depth: int = 12
    exposure_s: float = 10e-6
    full_well_e: float = 12_000.0
    read_noise_e: float = 12.0
    black_level_dn: float = 0.0

    def __post_init__(self) -> None:
        for name in ("px_per_mm", "fps", "exposure_s", "full_well_e"):
            v = getattr(self, name)
            if not math.isfinite(v) or v <= 0:
                raise ParameterError(f"camera.{name}", "must be a finite number > 0", v)
        if self.width < 16 or self.height < 16:
            raise ParameterError("camera.width", "the image must be at least 16 x 16 px", (self.width, self.height))
        if self.bit_depth not in (8, 10, 12, 14, 16):
            raise ParameterError("camera.bit_depth", "must be 8, 10, 12, 14 or 16", self.bit_depth)
        if self.exposure_s > 1.0 / self.fps:
            raise ParameterError("camera.exposure_s", "cannot exceed the frame period 1/fps", self.exposure_s)

    @property
    def px_per_m(self) -> float:
        """Image scale in pixels per metre."""
        return self.px_per_mm * 1e3

    @property
    def centre_px(self) -> tuple[float, float]:
        """Bearing centre (u, v) in pixel coordinates."""
        return (0.5 * (self.width - 1) + self.centre_offset_px[0], 0.5 * (self.height - 1) + self.centre_offset_px[1])

    @property
    def max_dn(self) -> int:
        """Largest pixel value."""
        return (1 << self.bit_depth) - 1

    def to_pixels(self, y: npt.ArrayLike, z: npt.ArrayLike) -> tuple[np.ndarray, np.ndarray]:
        """Map bearing-frame points (m) to pixel coordinates (u, v)."""
        y, z = np.asarray(y, dtype=np.float64), np.asarray(z, dtype=np.float64)
        c, s = math.cos(math.radians(self.roll_deg)), math.sin(math.radians(self.roll_deg))
        cx, cy = self.centre_px
        return cx + self.px_per_m * (y * c - z * s), cy - self.px_per_m * (y * s + z * c)


@dataclass(frozen=True)
class RingRadii:
    """Radii (m) of the visible end-face features, from the bore outward."""

    bore: float
    inner_land: float
    outer_land: float
    outer_diameter: float

    @classmethod
    def for_geometry(cls, g: Geometry) -> RingRadii:
        """Proportions of a 6206-type deep-groove bearing scaled to ``g``.

        For the paper's bearing this gives a 30 mm bore, ring lands at 40.3 and 51.7 mm
        diameter and a 62 mm outside diameter: the balls are seen between the lands.
        """
        rp, d = 0.5 * g.pitch_diameter_m, g.ball_diameter_m
        return cls(bore=0.5 * g.inner_race_diameter_m - 0.35 * d, inner_land=rp - 0.30 * d,
                   outer_land=rp + 0.30 * d, outer_diameter=0.5 * g.outer_race_diameter_m + 0.34 * d)


@dataclass(frozen=True)
class Appearance:
    """How the scene looks; every value is a fraction of full scale unless its name says otherwise.

    Parameters
    ----------
    light_offset
        Highlight offset from the ball centre as a fraction of the ball diameter, (right, up) in
        the image; the same for every ball (distant light and camera).
    highlight_sigma
        Highlight Gaussian width as a fraction of the ball diameter.
    highlight_peak
        Highlight peak brightness; > 1 saturates into a flat top.
    highlight_peak_spread
        Relative ball-to-ball and frame-to-frame spread of the highlight peak.
    ball_level, cavity_level, background_level
        Brightness of the black ball coating, the cavity between balls, and the surround.
    ring_level
        Mean brightness of the brushed ring faces.
    brushing_contrast
        Contrast of the concentric turning marks on the ring faces.
    n_static_glints, n_turning_glints
        Glints on the outer ring (static) and on the inner ring (turning with it).
    glint_peak
        Peak brightness of glints (they may saturate).
    n_ring_marks
        Dark marks (laser text, scratches) on the inner ring face that turn with it.
    flicker_amplitude, flicker_hz
        Illumination flicker, relative amplitude and frequency (100 Hz: 50 Hz mains).
    dropout_rate
        Chance per ball and frame that its highlight drops out (and stays out a few frames).
    n_hot_pixels
        Stuck-bright pixels.
    dropped_frame_rate
        Chance that the camera drops a frame (a gap in the time stamps).
    """

    light_offset: tuple[float, float] = (-0.08, 0.09)
    highlight_sigma: float = 0.055
    highlight_peak: float = 1.25
    highlight_peak_spread: float = 0.15
    ball_level: float = 0.04
    cavity_level: float = 0.09
    background_level: float = 0.02
    ring_level: float = 0.42
    brushing_contrast: float = 0.12
    n_static_glints: int = 6
    n_turning_glints: int = 4
    glint_peak: float = 1.1
    n_ring_marks: int = 3
    flicker_amplitude: float = 0.04
    flicker_hz: float = 100.0
    dropout_rate: float = 0.0
    n_hot_pixels: int = 0
    dropped_frame_rate: float = 0.0

    def __post_init__(self) -> None:
        for name in ("dropout_rate", "dropped_frame_rate"):
            v = getattr(self, name)
            if not 0.0 <= v < 0.5:
                raise ParameterError(f"appearance.{name}", "must lie in [0, 0.5)", v)
        if self.highlight_sigma <= 0:
            raise ParameterError("appearance.highlight_sigma", "must be > 0", self.highlight_sigma)
