"""Render end-face video of a cageless bearing, with known ground truth.

What the frames show (so tracking meets what real footage has):

* black-coated balls seen between the ring lands, each with one specular
  highlight offset from its centre by the light direction (the same offset for
  every ball), sometimes saturated into a flat top;
* brushed (concentrically turned) ring faces whose brightness varies with the
  angle to the light, static elongated glints on the outer ring and glints and
  dark marks that turn with the inner ring;
* illumination flicker, shot and read noise, optional highlight dropouts, hot
  pixels and dropped frames, and motion blur over the exposure.

Every random choice comes from ``seed``; frame ``i`` draws its noise from its own
stream, so any subset of frames renders identically in any order or process.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
import pandas as pd

from cageless.bearing import Geometry
from cageless.tracking.synthetic.camera import Appearance, Camera, RingRadii
from cageless.tracking.synthetic.motion import BallMotion

__all__ = ["Renderer", "TRUTH_COLUMNS"]

TRUTH_COLUMNS = ("frame", "time_s", "ball", "angle_rad", "radius_m", "centre_u_px", "centre_v_px",
                 "highlight_u_px", "highlight_v_px", "highlight_visible", "highlight_peak")

_BLUR_STEP_PX = 0.25  # one exposure sub-sample per this much motion


@dataclass(frozen=True)
class _Spot:
    """A glint or mark on a ring face, in ring polar coordinates."""

    radius_m: float
    angle: float
    sigma_m: float
    peak: float
    elongation: float


class Renderer:
    """Renders frames of one bearing seen by one camera.

    Parameters
    ----------
    geometry
        Bearing geometry (ball count and size, pitch circle, race diameters).
    camera
        The camera.
    appearance
        How the scene looks.
    seed
        Seed of every random choice (textures, glints, noise, dropouts, dropped frames).
    """

    def __init__(self, geometry: Geometry, camera: Camera, appearance: Appearance | None = None, seed: int = 0) -> None:
        self.geometry, self.camera, self.look = geometry, camera, appearance or Appearance()
        self.seed = seed
        self.radii = RingRadii.for_geometry(geometry)
        rng = np.random.default_rng([seed, 1])
        self._r, self._phi = self._pixel_polar()
        self._band = self._annulus(self.radii.inner_land, self.radii.outer_land)
        self._static = self._static_layer(rng).astype(np.float32)
        self._outer_glints = self._spots(rng, self.look.n_static_glints, self.radii.outer_land, self.radii.outer_diameter, self.look.glint_peak)
        self._inner_glints = self._spots(rng, self.look.n_turning_glints, self.radii.bore, self.radii.inner_land, self.look.glint_peak)
        self._marks = self._spots(rng, self.look.n_ring_marks, self.radii.bore, self.radii.inner_land, -0.25)
        self._hot = rng.integers(0, [camera.height, camera.width], size=(self.look.n_hot_pixels, 2))
        self._flicker_phase = rng.uniform(0, 2 * math.pi)
        ball_px = geometry.ball_diameter_m * camera.px_per_m
        self._ball_radius_px = 0.5 * ball_px
        self._light_px = (self.look.light_offset[0] * ball_px, -self.look.light_offset[1] * ball_px)
        self._sigma_px = self.look.highlight_sigma * ball_px

    # -- static scene --------------------------------------------------------------------------
    def _pixel_polar(self) -> tuple[np.ndarray, np.ndarray]:
        cam = self.camera
        v, u = np.mgrid[0:cam.height, 0:cam.width].astype(np.float64)
        cx, cy = cam.centre_px
        yi, zi = (u - cx) / cam.px_per_m, -(v - cy) / cam.px_per_m
        return np.hypot(yi, zi), np.arctan2(zi, yi) - math.radians(cam.roll_deg)

    def _annulus(self, r_in: float, r_out: float) -> np.ndarray:
        px = 1.0 / self.camera.px_per_m
        a = np.clip((self._r - r_in) / px + 0.5, 0, 1) * np.clip((r_out - self._r) / px + 0.5, 0, 1)
        return a.astype(np.float32)

    def _brushed(self, rng: np.random.Generator, r_in: float, r_out: float) -> np.ndarray:
        """Concentric turning marks: a smooth random radial profile, plus brightness varying with the angle to the light."""
        knots = np.linspace(r_in, r_out, 200)
        profile = np.convolve(rng.normal(size=knots.size), np.ones(5) / 5, mode="same")
        marks = np.interp(self._r, knots, profile / (np.abs(profile).max() + 1e-12))
        light = math.atan2(self.look.light_offset[1], self.look.light_offset[0])
        aniso = 0.25 * np.cos(2 * (self._phi - light))
        return self.look.ring_level * (1 + self.look.brushing_contrast * marks + aniso)

    def _static_layer(self, rng: np.random.Generator) -> np.ndarray:
        rr, look = self.radii, self.look
        img = np.full(self._r.shape, look.background_level)
        outer = self._annulus(rr.outer_land, rr.outer_diameter)
        inner = self._annulus(rr.bore, rr.inner_land)
        img = img * (1 - outer) + self._brushed(rng, rr.outer_land, rr.outer_diameter) * outer
        img = img * (1 - inner) + self._brushed(rng, rr.bore, rr.inner_land) * inner
        img = img * (1 - self._band) + look.cavity_level * self._band
        for edge in (rr.inner_land, rr.outer_land, rr.outer_diameter):  # dark chamfer lines
            img *= 1 - 0.5 * np.exp(-0.5 * ((self._r - edge) * self.camera.px_per_m / 0.8) ** 2)
        return img

    def _spots(self, rng: np.random.Generator, n: int, r_in: float, r_out: float, peak: float) -> list[_Spot]:
        d = self.geometry.ball_diameter_m
        return [
            _Spot(radius_m=rng.uniform(r_in + 0.1 * (r_out - r_in), r_out - 0.1 * (r_out - r_in)),
                  angle=rng.uniform(0, 2 * math.pi), sigma_m=rng.uniform(0.03, 0.06) * d,
                  peak=peak * rng.uniform(0.7, 1.0), elongation=rng.uniform(2.0, 4.0))
            for _ in range(n)
        ]

    # -- per frame -----------------------------------------------------------------------------
    def _to_image(self, y: np.ndarray, z: np.ndarray, direction: int) -> tuple[np.ndarray, np.ndarray]:
        return self.camera.to_pixels(direction * y, z)

    def _paint_spot(self, img: np.ndarray, spot: _Spot, ring_angle: float, direction: int) -> None:
        a = spot.angle + ring_angle
        u0, v0 = self._to_image(np.array(spot.radius_m * math.cos(a)), np.array(spot.radius_m * math.sin(a)), direction)
        s = spot.sigma_m * self.camera.px_per_m
        half = int(math.ceil(4 * s * spot.elongation))
        u_lo, v_lo = int(u0) - half, int(v0) - half
        sl = (slice(max(v_lo, 0), max(min(v_lo + 2 * half + 1, img.shape[0]), 0)),
              slice(max(u_lo, 0), max(min(u_lo + 2 * half + 1, img.shape[1]), 0)))
        v, u = np.mgrid[sl]
        du, dv = u - float(u0), v - float(v0)
        img_angle = math.atan2(-(float(v0) - self.camera.centre_px[1]), float(u0) - self.camera.centre_px[0])
        t_u, t_v = -math.sin(img_angle), -math.cos(img_angle)  # tangential direction in the image
        along = du * t_u + dv * t_v
        across = du * t_v - dv * t_u
        g = np.exp(-0.5 * ((along / (s * spot.elongation)) ** 2 + (across / s) ** 2))
        if spot.peak >= 0:
            img[sl] += spot.peak * g
        else:
            img[sl] *= 1 + spot.peak * g / self.look.ring_level

    def ball_positions(self, motion: BallMotion, k: int) -> tuple[np.ndarray, np.ndarray]:
        """Ball-centre pixel coordinates (u, v) at motion sample ``k``."""
        th, r = motion.angle[k], motion.radius[k]
        return self._to_image(r * np.cos(th), r * np.sin(th), motion.direction)

    def _paint_balls(self, img: np.ndarray, base: np.ndarray, u: np.ndarray, v: np.ndarray, peaks: np.ndarray,
                     weight: float) -> None:
        """Composite balls over ``base`` into ``img``: coverage-weighted black coating plus highlight."""
        rad, (lu, lv), sig = self._ball_radius_px, self._light_px, self._sigma_px
        half = int(math.ceil(rad + 2))
        for j in range(len(u)):
            u_lo, v_lo = int(round(u[j])) - half, int(round(v[j])) - half
            sl = (slice(max(v_lo, 0), max(min(v_lo + 2 * half + 1, img.shape[0]), 0)),
                  slice(max(u_lo, 0), max(min(u_lo + 2 * half + 1, img.shape[1]), 0)))
            vv, uu = np.mgrid[sl]
            cover = np.clip(rad - np.hypot(uu - u[j], vv - v[j]) + 0.5, 0, 1) * self._band[sl]
            hl = peaks[j] * np.exp(-0.5 * ((uu - u[j] - lu) ** 2 + (vv - v[j] - lv) ** 2) / sig**2)
            img[sl] += weight * cover * (self.look.ball_level - base[sl] + hl)

    def render_frame(self, motion: BallMotion, frame: int, subsamples: list[int], peaks: np.ndarray,
                     time_s: float) -> np.ndarray:
        """Render one frame from the motion samples ``subsamples`` (its exposure); returns DN values."""
        img = self._static.copy()
        ring_angle = float(np.mean(motion.ring_angle[subsamples]))
        for spot in (*self._inner_glints, *self._marks):
            self._paint_spot(img, spot, ring_angle, motion.direction)
        for spot in self._outer_glints:
            self._paint_spot(img, spot, 0.0, motion.direction)
        base = img.copy()
        for k in subsamples:
            u, v = self.ball_positions(motion, k)
            self._paint_balls(img, base, u, v, peaks, 1.0 / len(subsamples))
        look = self.look
        rng = np.random.default_rng([self.seed, 2, frame])
        light = 1 + look.flicker_amplitude * math.sin(2 * math.pi * look.flicker_hz * time_s + self._flicker_phase)
        light *= 1 + 0.005 * rng.standard_normal()
        return self._sensor(np.clip(img * light, 0, 1), rng)

    def _sensor(self, signal: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        cam = self.camera
        electrons = rng.poisson(signal * cam.full_well_e).astype(np.float32)
        electrons += cam.read_noise_e * rng.standard_normal(signal.shape, dtype=np.float32)
        dn = np.rint(electrons * (cam.max_dn / cam.full_well_e) + cam.black_level_dn)
        if len(self._hot):
            dn[self._hot[:, 0], self._hot[:, 1]] = cam.max_dn
        return np.clip(dn, 0, cam.max_dn).astype(np.uint8 if cam.bit_depth == 8 else np.uint16)

    # -- a whole clip ------------------------------------------------------------------------------
    def plan(self, n_frames: int) -> tuple[np.ndarray, np.ndarray]:
        """Frame indices the camera keeps (dropped frames left out) and their times (s)."""
        rng = np.random.default_rng([self.seed, 3])
        keep = rng.random(n_frames) >= self.look.dropped_frame_rate
        keep[0] = True
        idx = np.flatnonzero(keep)
        return idx, idx / self.camera.fps

    def exposure_offsets(self, motion_speed_px_s: float) -> np.ndarray:
        """Sub-sample times (s) across the exposure, relative to the frame time."""
        exp = self.camera.exposure_s
        n = max(1, int(math.ceil(motion_speed_px_s * exp / _BLUR_STEP_PX)))
        return exp * ((np.arange(n) + 0.5) / n - 0.5)

    def visibility(self, n_frames: int) -> np.ndarray:
        """Highlight visibility (T, Z): dropouts start at ``dropout_rate`` and last ~3 frames."""
        z = self.geometry.n_balls
        vis = np.ones((n_frames, z), dtype=bool)
        if self.look.dropout_rate > 0:
            # Whole arrays from separate streams: the first k rows never depend on n_frames.
            starts = np.random.default_rng([self.seed, 4]).random((n_frames, z)) < self.look.dropout_rate
            lengths = np.random.default_rng([self.seed, 6]).geometric(1 / 3, size=(n_frames, z))
            for i, j in zip(*np.nonzero(starts), strict=True):
                vis[i:i + 1 + lengths[i, j], j] = False
        return vis

    def peaks(self, n_frames: int) -> np.ndarray:
        """Highlight peak brightness (T, Z): a per-ball factor times a small per-frame spread."""
        rng = np.random.default_rng([self.seed, 5])
        z, look = self.geometry.n_balls, self.look
        ball = 1 + look.highlight_peak_spread * rng.standard_normal(z)
        frame = 1 + 0.3 * look.highlight_peak_spread * rng.standard_normal((n_frames, z))
        return np.clip(look.highlight_peak * ball * frame, 0.0, None)

    def frames(self, motion: BallMotion, frame_index: npt.NDArray[np.int64], times: np.ndarray,
               subsamples: int) -> Iterator[np.ndarray]:
        """Yield the frames whose motion samples are laid out ``subsamples`` per frame."""
        vis = self.visibility(len(times))
        peaks = self.peaks(len(times)) * vis
        for i in range(len(times)):
            yield self.render_frame(motion, int(frame_index[i]), list(range(i * subsamples, (i + 1) * subsamples)),
                                    peaks[i], float(times[i]))

    def truth(self, motion: BallMotion, frame_index: np.ndarray, times: np.ndarray, subsamples: int) -> pd.DataFrame:
        """Ground truth per frame and ball at mid-exposure (long table, ``TRUTH_COLUMNS``).

        ``highlight_peak`` is the highlight's peak brightness as a fraction of full scale before
        flicker (above 1 it saturates); 0 where the highlight is hidden.
        """
        vis = self.visibility(len(times))
        mid = np.arange(len(times)) * subsamples + (subsamples - 1) / 2.0
        lo, hi = np.floor(mid).astype(int), np.ceil(mid).astype(int)
        angle = 0.5 * (motion.angle[lo] + motion.angle[hi])
        radius = 0.5 * (motion.radius[lo] + motion.radius[hi])
        u, v = self._to_image(radius * np.cos(angle), radius * np.sin(angle), motion.direction)
        hu, hv = u + self._light_px[0], v + self._light_px[1]
        cx, cy = self.camera.centre_px
        r_hl = np.hypot(hu - cx, hv - cy) / self.camera.px_per_m  # highlights behind a ring land are hidden
        vis = vis & (r_hl > self.radii.inner_land) & (r_hl < self.radii.outer_land)
        peaks = self.peaks(len(times)) * vis
        t, z = angle.shape
        return pd.DataFrame({
            "frame": np.repeat(frame_index, z), "time_s": np.repeat(times, z), "ball": np.tile(np.arange(z), t),
            "angle_rad": angle.ravel(), "radius_m": radius.ravel(), "centre_u_px": u.ravel(), "centre_v_px": v.ravel(),
            "highlight_u_px": hu.ravel(), "highlight_v_px": hv.ravel(), "highlight_visible": vis.ravel(),
            "highlight_peak": peaks.ravel(),
        })
