"""A second, independent renderer of bearing end-face video: shaded spheres, textured rings, a real camera.

It shares no drawing code with :mod:`cageless.tracking.synthetic.render` and does not
look like it. What it draws, from a :class:`~cageless.tracking.synthetic.appearance.ClipParams`:

* **balls** as black-coated spheres under one or two distant lights, shaded per
  pixel from the sphere normal ``n``: a weak Lambert term, a Fresnel-like rim
  that brightens the silhouette, and a specular lobe around the half vector
  ``h = normalise(l + v)`` (Blinn's construction, J. F. Blinn, SIGGRAPH 1977),
  Gaussian in ``n - h`` with an elongation along a chosen image direction. The
  highlight therefore sits where ``n = h``, at the light-fixed image offset
  ``R (h_x, -h_y)`` from the ball centre, the same for every ball; a second light
  doubles it; a lobe brighter than full scale saturates into a plateau;
* **rings** as textured annuli (brushed, machined or scratched) that may be
  brighter or darker than the balls, with an anisotropic sheen from the light;
  the ring lands either hide part of each ball (``land_mode = "hidden"``) or the
  balls are drawn over the ring faces (``"over"``);
* glints fixed on the outer ring and glints turning with the inner ring, dust
  on the sensor, bright lint specks, vignetting and a lighting gradient, mains
  flicker, dark frames, motion blur over the exposure (a line kernel along each
  ball's image velocity), barrel/pincushion distortion, shot and read noise,
  black level, hot pixels, bit depth and JPEG artefacts.

Image convention: pixel centres at integer (u, v). A point at angle ``theta``
(the law frame, where the ring turns +theta) and radius ``rho`` is mirrored
(``y -> direction * y``), turned by the camera roll (counter-clockwise), scaled
to pixels about the bearing centre, then distorted radially about the image
centre: ``p_u - c = (p_d - c) (1 + k1 |p_d - c|^2 / r_n^2)`` with ``r_n`` the
half-diagonal.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from cageless.tracking.synthetic.appearance import ClipParams, _outer_radius_factor

__all__ = ["SceneRenderer", "FrameState"]

F32 = np.float32


@dataclass(frozen=True)
class FrameState:
    """What one frame shows: ball angles and speeds (law frame, rad and rad/s), the ring angle, light."""

    time_s: float
    angle: np.ndarray
    speed: np.ndarray
    ring_angle: float
    dark: bool = False


class SceneRenderer:
    """Renders the frames of one corpus clip (see the module docstring).

    Parameters
    ----------
    params
        The clip's parameters.
    geometry_only
        Set up only the projection (radii, lights, :meth:`to_pixels`), not the images: enough for the truth.
    """

    def __init__(self, params: ClipParams, geometry_only: bool = False) -> None:
        p = self.p = params
        g = params.geometry
        self.rng = np.random.default_rng([params.seed, 11])
        self.s = params.px_per_mm * 1e3  # px per m
        self.rp = 0.5 * g.pitch_diameter_m
        self.d = g.ball_diameter_m
        self.r_px = 0.5 * self.d * self.s
        self.c0 = (0.5 * (p.width - 1), 0.5 * (p.height - 1))
        self.centre = (self.c0[0] + p.centre_offset_px[0], self.c0[1] + p.centre_offset_px[1])
        self.r_norm2 = self.c0[0] ** 2 + self.c0[1] ** 2
        self._radii()
        self._lights()
        if geometry_only:
            return
        self._maps()
        self.light_field = self._light_field()
        self.static = self._static_scene() * self.light_field
        self.glints = self._glints()
        self.specks = self._specks()
        self.hot = self.rng.integers(0, [p.height, p.width], size=(p.n_hot_pixels, 2))
        self.flicker_phase = float(self.rng.uniform(0, math.pi))

    # -- geometry ----------------------------------------------------------------------------------
    def _radii(self) -> None:
        p, rp, d = self.p, self.rp, self.d
        if p.land_mode == "hidden":
            w = 0.5 * (0.8 + 0.2 * p.land_frac) * d  # see appearance.draw_params
            self.r_il, self.r_ol = rp - w, rp + w
        else:  # the ring faces reach under the balls; the balls are drawn over them
            w = 0.5 * (0.45 + 0.4 * p.land_frac) * d
            self.r_il, self.r_ol = rp - w, rp + w
        self.r_bore = rp - (0.95 + 0.1 * p.land_frac) * d
        self.r_od = rp + _outer_radius_factor(p.land_frac) * d

    def to_pixels(self, theta: np.ndarray, rho: np.ndarray | float) -> tuple[np.ndarray, np.ndarray]:
        """Distorted pixel coordinates (u, v) of law-frame points at angle ``theta`` (rad), radius ``rho`` (m)."""
        uu, vu = self.to_undistorted(theta, rho)
        return self.distort(uu, vu)

    def to_undistorted(self, theta: np.ndarray, rho: np.ndarray | float) -> tuple[np.ndarray, np.ndarray]:
        """Undistorted pixel coordinates of law-frame points."""
        p = self.p
        y = p.direction * rho * np.cos(theta)
        z = rho * np.sin(theta)
        c, s = math.cos(math.radians(p.roll_deg)), math.sin(math.radians(p.roll_deg))
        return self.centre[0] + self.s * (y * c - z * s), self.centre[1] - self.s * (y * s + z * c)

    def distort(self, uu: np.ndarray, vu: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Invert ``p_u - c = (p_d - c)(1 + k1 r_d^2 / r_n^2)`` by fixed-point iteration."""
        k1 = self.p.distortion_k1
        du, dv = np.asarray(uu, float) - self.c0[0], np.asarray(vu, float) - self.c0[1]
        ud, vd = du.copy(), dv.copy()
        for _ in range(30):
            f = 1 + k1 * (ud**2 + vd**2) / self.r_norm2
            ud, vd = du / f, dv / f
        return ud + self.c0[0], vd + self.c0[1]

    def _maps(self) -> None:
        p = self.p
        v, u = np.mgrid[0:p.height, 0:p.width].astype(np.float64)
        du, dv = u - self.c0[0], v - self.c0[1]
        f = 1 + p.distortion_k1 * (du**2 + dv**2) / self.r_norm2
        self.uu = (self.c0[0] + du * f).astype(F32)  # undistorted coordinates of each pixel
        self.vu = (self.c0[1] + dv * f).astype(F32)
        y_r = (self.uu - self.centre[0]) / self.s
        z_r = -(self.vu - self.centre[1]) / self.s
        self.r = np.hypot(y_r, z_r).astype(F32)
        self.phi_img = np.arctan2(z_r, y_r).astype(F32)  # image angle (light is fixed in the image)
        px = 1.0 / self.s
        band = np.clip((self.r - self.r_il) / px + 0.5, 0, 1) * np.clip((self.r_ol - self.r) / px + 0.5, 0, 1)
        self.visible = band.astype(F32) if p.land_mode == "hidden" else np.ones_like(self.r)

    def _lights(self) -> None:
        p = self.p
        t = math.radians(p.light_tilt_deg)
        self.h = []
        for az_deg, rel in ((p.light_azimuth_deg, 1.0), (p.second_light_azimuth_deg, p.second_light_rel)):
            if rel <= 0:
                continue
            az = math.radians(az_deg if rel == 1.0 else p.light_azimuth_deg + 60 + (az_deg % 240))
            self.h.append((np.array([math.sin(t / 2) * math.cos(az), math.sin(t / 2) * math.sin(az),
                                     math.cos(t / 2)]), rel))
        az = math.radians(p.light_azimuth_deg)
        self.l_main = np.array([math.sin(t) * math.cos(az), math.sin(t) * math.sin(az), math.cos(t)])

    @property
    def highlight_offset_px(self) -> tuple[float, float]:
        """Undistorted image offset (du, dv) of the primary highlight from the ball centre."""
        h = self.h[0][0]
        return self.r_px * h[0], -self.r_px * h[1]

    # -- static scene ------------------------------------------------------------------------------
    def _light_field(self) -> np.ndarray:
        p = self.p
        du, dv = (self.uu - self.c0[0]) / math.sqrt(self.r_norm2), (self.vu - self.c0[1]) / math.sqrt(self.r_norm2)
        a = math.radians(p.gradient_angle_deg)
        field = (1 - p.vignetting * (du**2 + dv**2)) * (1 + p.gradient * (du * math.cos(a) - dv * math.sin(a)))
        return (np.clip(field, 0.05, None) * self._dust()).astype(F32)

    def _dust(self) -> np.ndarray:
        p = self.p
        t = np.ones((p.height, p.width), F32)
        for _ in range(p.n_dust):
            u0, v0 = self.rng.uniform(0, p.width), self.rng.uniform(0, p.height)
            rad, depth = self.rng.uniform(3, 12), self.rng.uniform(0.05, 0.25)  # defocused sensor dust
            sl, du, dv = _window(u0, v0, rad + 3, t.shape)
            t[sl] *= 1 - depth * np.clip(rad - np.hypot(du, dv) + 0.5, 0, 1) * np.exp(-0.5 * (du**2 + dv**2) / rad**2)
        return t

    def _texture(self, kind: str, r_in: float, r_out: float) -> np.ndarray:
        """Relative brightness variation of a ring face (mean 1)."""
        rng, r = self.rng, self.r
        n = max(64, int((r_out - r_in) * self.s * 4))
        knots = np.linspace(r_in, r_out, n)
        if kind == "brushed":  # fine concentric grooves of random depth
            prof = 0.25 * np.convolve(rng.normal(size=n), np.ones(3) / 3, mode="same")
        else:  # machined: periodic turning marks; scratched: light grooves plus random straight scratches
            period = rng.uniform(0.04, 0.25) * 1e-3
            prof = (0.3 if kind == "machined" else 0.1) * np.sin(2 * np.pi * (knots - r_in) / period)
        tex = 1 + np.interp(r, knots, prof).astype(F32)
        if kind == "scratched":
            tex = self._scratches(tex, r_in, r_out)
        return tex

    def _scratches(self, tex: np.ndarray, r_in: float, r_out: float) -> np.ndarray:
        rng, p = self.rng, self.p
        for _ in range(int(rng.integers(15, 40))):
            a, rr = rng.uniform(0, 2 * np.pi), rng.uniform(r_in, r_out)
            u0, v0 = self.centre[0] + self.s * rr * math.cos(a), self.centre[1] - self.s * rr * math.sin(a)
            length, ang = rng.uniform(10, 60), rng.uniform(0, np.pi)
            u1, v1 = u0 + length * math.cos(ang), v0 + length * math.sin(ang)
            cv2.line(tex, (int(u0), int(v0)), (int(u1), int(v1)), float(rng.choice([0.4, 1.8])), 1, cv2.LINE_AA)
        return np.where((self.r >= r_in) & (self.r <= r_out), tex, 1).astype(F32)

    def _static_scene(self) -> np.ndarray:
        p, r = self.p, self.r
        level = 0.3 + 0.55 * p.ring_level if p.ring_face == "bright" else 0.03 + 0.12 * p.ring_level
        sheen = 1 + 0.35 * np.cos(2 * (self.phi_img - math.radians(p.light_azimuth_deg)))
        img = np.full(r.shape, p.background_level, F32)
        px = 1.0 / self.s

        def ann(a: float, b: float) -> np.ndarray:
            return (np.clip((r - a) / px + 0.5, 0, 1) * np.clip((b - r) / px + 0.5, 0, 1)).astype(F32)

        outer, inner, bore = ann(self.r_ol, self.r_od), ann(self.r_bore, self.r_il), ann(0, self.r_bore)
        img = img * (1 - bore) + 0.5 * p.background_level * bore
        img = img * (1 - outer) + level * sheen * self._texture(p.ring_texture, self.r_ol, self.r_od) * outer
        tex_in = "brushed" if p.ring_texture == "scratched" else p.ring_texture  # the inner face turns
        img = img * (1 - inner) + level * sheen * self._texture(tex_in, self.r_bore, self.r_il) * inner
        band = ann(self.r_il, self.r_ol)
        img = img * (1 - band) + p.cavity_level * (0.7 + 0.3 * sheen) * band
        for edge in (self.r_il, self.r_ol, self.r_od, self.r_bore):  # chamfers: bright or dark lines
            sign = self.rng.choice([-0.6, 0.8])
            img *= 1 + sign * np.exp(-0.5 * ((r - edge) * self.s / 1.2) ** 2).astype(F32)
        for _ in range(p.n_static_glints):  # glints fixed on the outer ring face
            self._spot(img, self.rng.uniform(self.r_ol, self.r_od), self.rng.uniform(0, 2 * np.pi))
        return np.clip(img, 0, None).astype(F32)

    def _spot_shape(self) -> tuple[float, float, float, float]:
        rng, p = self.rng, self.p
        return (rng.uniform(0.6, 2.0), rng.uniform(1.0, 4.0), rng.uniform(0, np.pi),
                p.glint_rel * p.highlight_peak * rng.uniform(0.6, 1.0))

    def _spot(self, img: np.ndarray, rho: float, theta: float, shape: tuple[float, ...] | None = None,
              scale: np.ndarray | None = None) -> None:
        sig, el, ang, peak = shape or self._spot_shape()
        u, v = self.to_pixels(np.array(theta), rho)
        sl, du, dv = _window(float(u), float(v), 4 * sig * el + 2, img.shape)
        a = du * math.cos(ang) + dv * math.sin(ang)
        b = -du * math.sin(ang) + dv * math.cos(ang)
        blob = peak * np.exp(-0.5 * ((a / (sig * el)) ** 2 + (b / sig) ** 2)).astype(F32)
        img[sl] += blob * (self.light_field[sl] if scale is None else scale)

    def _glints(self) -> list[tuple[float, float, tuple[float, float, float, float]]]:
        """Glints on the inner ring face: (radius m, angle rad, shape); they turn with the ring."""
        return [(self.rng.uniform(self.r_bore + 0.1 * (self.r_il - self.r_bore), self.r_il),
                 self.rng.uniform(0, 2 * np.pi), self._spot_shape()) for _ in range(self.p.n_turning_glints)]

    def _specks(self) -> list[tuple[float, float, float]]:
        """Bright lint on the front glass (u, v, peak): static, in front of everything, even the balls."""
        p = self.p
        out = []
        for _ in range(p.n_specks):
            a, rr = self.rng.uniform(0, 2 * np.pi), self.rp + self.rng.uniform(-0.6, 0.6) * self.d
            u, v = self.to_pixels(np.array(a), rr)
            out.append((float(u), float(v), p.highlight_peak * self.rng.uniform(0.3, 1.2)))
        return out

    # -- one frame ---------------------------------------------------------------------------------
    def radiance(self, state: FrameState) -> np.ndarray:
        """Scene radiance of one frame (fraction of full scale), before flicker and the sensor."""
        img = self.static.copy()
        for rho, theta, shape in self.glints:
            self._spot(img, rho, theta + state.ring_angle, shape)
        for j in range(len(state.angle)):
            self._ball(img, float(state.angle[j]), float(state.speed[j]))
        for u, v, peak in self.specks:
            sl, du, dv = _window(u, v, 4.0, img.shape)
            img[sl] += peak * np.exp(-0.5 * (du**2 + dv**2) / 0.8**2).astype(F32)
        return img

    def _ball(self, img: np.ndarray, theta: float, omega: float) -> None:
        p = self.p
        uc, vc = self.to_undistorted(np.array(theta), self.rp)
        ud, vd = self.distort(uc, vc)
        blur = abs(omega) * p.exposure_s * self.rp * self.s
        sl, _, _ = _window(float(ud), float(vd), self.r_px * 1.08 + blur / 2 + 3, img.shape)
        dx = self.uu[sl] - F32(uc)
        dy = self.vu[sl] - F32(vc)
        rho2 = (dx * dx + dy * dy) / F32(self.r_px**2)
        inside = rho2 < 1
        cover = np.clip(F32(self.r_px) - np.sqrt(rho2) * F32(self.r_px) + 0.5, 0, 1)
        nx, ny = dx / F32(self.r_px), -dy / F32(self.r_px)
        nz = np.sqrt(np.clip(1 - rho2, 0, 1))
        lm = self.l_main
        rad = F32(0.8 * p.ball_albedo) * np.clip(nx * lm[0] + ny * lm[1] + nz * lm[2], 0, None)
        rad += F32(p.rim) * (1 - nz) ** 3 * F32(0.3 + 0.7 * min(1.0, 2 * p.ring_level))
        e_ang = math.radians(p.elongation_angle_deg)
        ca, sa = F32(math.cos(e_ang)), F32(math.sin(e_ang))
        sig_b = F32(2 * p.highlight_sigma)
        sig_a = sig_b * F32(p.elongation)
        for h, rel in self.h:
            ex, ey = nx - F32(h[0]), ny - F32(h[1])
            a, b = ex * ca + ey * sa, -ex * sa + ey * ca
            rad += F32(p.highlight_peak * rel) * np.exp(-0.5 * ((a / sig_a) ** 2 + (b / sig_b) ** 2)) * inside
        # Over the exposure the ball covers the scene behind it: the blurred image is the time average
        # blur(cover * ball) + (1 - blur(cover)) * behind. (Blurring cover * (ball - behind) instead, as
        # before, let the texture behind an opaque ball leak through it as behind - blur(behind).)
        ball = cover * rad * self.light_field[sl]
        if blur > 0.3:
            kernel = _line_kernel(blur, self._velocity_angle(theta))
            ball = cv2.filter2D(ball, -1, kernel, borderType=cv2.BORDER_CONSTANT)
            cover = cv2.filter2D(cover.astype(F32), -1, kernel, borderType=cv2.BORDER_CONSTANT)
        img[sl] += (ball - cover * img[sl]) * self.visible[sl]

    def _velocity_angle(self, theta: float) -> float:
        """Image direction (rad, in (u, v)) of a ball's motion at ``theta``."""
        u0, v0 = self.to_undistorted(np.array([theta - 1e-4, theta + 1e-4]), self.rp)
        return math.atan2(float(v0[1] - v0[0]), float(u0[1] - u0[0]))

    def frame(self, state: FrameState, frame_index: int) -> np.ndarray:
        """One frame as the camera stores it (uint8 or uint16 DN, JPEG artefacts for 8-bit when set)."""
        p = self.p
        light = 1.0 + p.flicker_amplitude * (abs(math.sin(math.pi * p.flicker_hz * state.time_s
                                                          + self.flicker_phase)) * math.pi / 2 - 1)
        if state.dark:
            light *= 0.02 + 0.25 * ((frame_index * 7919) % 100) / 100.0
        max_dn = (1 << p.bit_depth) - 1
        e = self.radiance(state)
        e *= F32(light * p.full_well_e)
        np.clip(e, 0, p.full_well_e, out=e)
        cv2.setRNGSeed(int((p.seed * 1_000_003 + frame_index * 7_777 + 12345) % (2**31 - 1)))
        noise = cv2.randn(np.empty(e.shape, F32), 0.0, 1.0)
        e += np.sqrt(e + F32(p.read_noise_e**2)) * noise
        e *= F32(max_dn / p.full_well_e)
        e += F32(p.black_level * max_dn)
        dn = np.clip(np.rint(e), 0, max_dn).astype(np.uint8 if p.bit_depth == 8 else np.uint16)
        if len(self.hot):
            dn[self.hot[:, 0], self.hot[:, 1]] = max_dn
        if p.bit_depth == 8 and p.jpeg_quality and p.container != "avi-mjpg":
            ok, buf = cv2.imencode(".jpg", dn, [cv2.IMWRITE_JPEG_QUALITY, int(p.jpeg_quality)])
            dn = cv2.imdecode(buf, cv2.IMREAD_GRAYSCALE)
        return dn


def _window(u: float, v: float, half: float,
            shape: tuple[int, ...]) -> tuple[tuple[slice, slice], np.ndarray, np.ndarray]:
    """A square window around (u, v) clipped to the image, with pixel offsets (du, dv) from (u, v)."""
    h = int(math.ceil(half))
    u0, v0 = int(round(u)) - h, int(round(v)) - h
    rs = slice(min(max(v0, 0), shape[0]), min(max(v0 + 2 * h + 1, 0), shape[0]))
    cs = slice(min(max(u0, 0), shape[1]), min(max(u0 + 2 * h + 1, 0), shape[1]))
    dv = (np.arange(rs.start, rs.stop, dtype=F32) - F32(v))[:, None]
    du = (np.arange(cs.start, cs.stop, dtype=F32) - F32(u))[None, :]
    return (rs, cs), du, dv


def _line_kernel(length: float, angle: float) -> np.ndarray:
    """A normalised, anti-aliased line of ``length`` px at ``angle`` (rad in (u, v)), centred."""
    half = int(math.ceil(length / 2)) + 1
    k = np.zeros((2 * half + 1, 2 * half + 1), F32)
    n = max(8, int(4 * length))
    for t in np.linspace(-length / 2, length / 2, n):
        x, y = half + t * math.cos(angle), half + t * math.sin(angle)
        x0, y0 = int(math.floor(x)), int(math.floor(y))
        fx, fy = x - x0, y - y0
        k[y0, x0] += (1 - fx) * (1 - fy)
        k[y0, x0 + 1] += fx * (1 - fy)
        k[y0 + 1, x0] += (1 - fx) * fy
        k[y0 + 1, x0 + 1] += fx * fy
    return k / k.sum()
